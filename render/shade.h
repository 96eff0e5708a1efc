/* shade: two-sided Lambert + ambient shading of a traced hit, one
 * directional light, the surface's palette colour; normal-as-colour. The
 * light's visibility (shadows) and the ambient's (ambient occlusion) come
 * from the caller (render/shadow.h, render/ao.h). */
#ifndef SHADE_H
#define SHADE_H

#include "common/view/camera.h"
#include "format/oct.h"
#include "render/trace.h"

typedef struct shade_params {
    double light[3];      /* unit vector from the surface towards the light */
    float background[3];  /* linear RGB of rays that miss */
    float ambient;        /* 0..1, share of the colour lit regardless of the light */
    int shadows;          /* 1: one shadow ray per lit hit (render/shadow.h) */
    unsigned ao_rays;     /* ambient occlusion rays per hit (render/ao.h); 0: none */
    double ao_distance;   /* their length, in cube edges (> 0 when ao_rays > 0) */
} shade_params;

/* The default light: from over the viewer's (left) shoulder. */
void shade_default_light(const camera *cam, double light[3]);

/* Normalises `light` (any length) into p->light; -1 when it is zero or not
 * finite. */
int shade_set_light(shade_params *p, const double light[3]);

/* The normal of the hit turned to face the viewer (seen along unit `dir`)
 * in n[3], and the Lambert term max(0, n . light) it gets; a miss gives the
 * zero vector and 0. */
double shade_normal(const oct_tree *tree, const shade_params *p, const trace_hit *hit,
                    const double dir[3], float n[3]);

/* shade_normal for a voxel hit whose stored normal ns (oct_normal_decode
 * of its record) the caller has already decoded: the same n and term. */
double shade_normal_stored(const shade_params *p, const float ns[3], const double dir[3],
                           float n[3]);

/* The palette index of a hit's surface: the root's with --exact, else the
 * voxel's; 0 for a miss. */
unsigned shade_surface(const oct_tree *tree, const trace_hit *hit);

/* Linear RGB of a hit with Lambert term `lam` (shade_normal's, times the
 * light's visibility) and ambient visibility `ao` (1: open), in rgb[3];
 * the background on a miss. */
void shade_color(const oct_tree *tree, const shade_params *p, const trace_hit *hit, double lam,
                 float ao, float rgb[3]);

/* shade_normal and shade_color with the light and the ambient unblocked. */
void shade_hit(const oct_tree *tree, const shade_params *p, const trace_hit *hit,
               const double dir[3], float rgb[3], float n[3]);

#endif
