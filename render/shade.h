/* shade: two-sided Lambert + ambient shading of a traced hit, one
 * directional light, the surface's palette colour; normal-as-colour. */
#ifndef SHADE_H
#define SHADE_H

#include "common/view/camera.h"
#include "format/oct.h"
#include "render/trace.h"

typedef struct shade_params {
    double light[3];      /* unit vector from the surface towards the light */
    float background[3];  /* linear RGB of rays that miss */
    float ambient;        /* 0..1, share of the colour lit regardless of the light */
} shade_params;

/* The default light: from over the viewer's (left) shoulder. */
void shade_default_light(const camera *cam, double light[3]);

/* Normalises `light` (any length) into p->light; -1 when it is zero or not
 * finite. */
int shade_set_light(shade_params *p, const double light[3]);

/* Linear RGB of the hit seen along unit `dir`, in rgb[3]; the normal turned to
 * face the viewer in n[3] (zero vector on a miss). */
void shade_hit(const oct_tree *tree, const shade_params *p, const trace_hit *hit,
               const double dir[3], float rgb[3], float n[3]);

#endif
