/* refcast: the exact reference, a direct interval ray caster of a scene's
 * functions (Duff 1992): first root along each ray, refined to ~1e-12. */
#ifndef REFCAST_H
#define REFCAST_H

#include <stdint.h>

#include "common/view/camera.h"
#include "common/expr/scene.h"

/* What one ray found. t is +inf on a miss. */
typedef struct refcast_hit {
    double t;         /* distance along the unit ray */
    double normal[3]; /* unit gradient at the root, facing the viewer; 0 on a miss */
    uint32_t surface; /* index of the surface hit */
    int touch;        /* 1: a tangential touch (no sign change), see refcast_ray */
} refcast_hit;

/* Per-thread scratch for refcast_ray; NULL when out of memory. */
typedef struct refcast_scratch refcast_scratch;
refcast_scratch *refcast_scratch_new(const scene *s);
void refcast_scratch_free(refcast_scratch *w); /* accepts NULL */

/* Counters of one ray, summed by callers for statistics. */
typedef struct refcast_stats {
    uint64_t interval_evals, grad_evals, point_evals, touches;
} refcast_stats;

/* Casts eye + t*dir (dir a unit vector), t >= 0, against every surface of s
 * inside its bounds box; the nearest root wins.
 *
 * Method: the ray is clipped to the bounds; each surface's [t0, t1] is
 * bisected front to back. A segment is dropped when the interval of f over
 * the box its points span excludes 0 (sound: outward-rounded hull of the
 * end points). A segment on which the interval of the directional
 * derivative grad f . dir excludes 0 is monotone: it holds a root exactly
 * when f changes sign between its ends, and that bracket is refined with
 * the Illinois method (bracketing regula falsi) on the point evaluator to
 * REFCAST_REL_TOL relative. Other segments are halved, down to a width of
 * REFCAST_REL_TOL * max(1, t1): such a last segment that still cannot be
 * excluded is a root if f changes sign over it, else a tangential touch (f
 * reaches 0 without crossing, or the ray grazes within rounding of it),
 * reported as a hit at its midpoint with touch = 1. Where f may be
 * undefined (a NaN flag) the segment is halved the same way, and a last
 * segment whose ends are NaN is not a hit. */
#define REFCAST_REL_TOL 1e-12
void refcast_ray(const scene *s, refcast_scratch *w, const double eye[3], const double dir[3],
                 refcast_hit *hit, refcast_stats *st);

/* A whole image on `threads` threads (rows handed out dynamically). depth:
 * w*h floats (+inf on miss), normals: w*h*3 floats (0 on miss), surface:
 * w*h bytes, hit index or 255 on a miss; any may be NULL. Returns 0, or -1
 * when out of memory. */
int refcast_image(const scene *s, const camera *cam, unsigned threads, float *depth,
                  float *normals, uint8_t *surface, refcast_stats *st);

#endif
