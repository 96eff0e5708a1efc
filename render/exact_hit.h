/* exact_hit: the first root of a surface function along a ray segment, by
 * interval arithmetic (common/expr/interval.h, outward rounding) and a
 * bracketed refinement to full double precision: what `render --exact`
 * runs in every occupied voxel a ray crosses (RENDER.md, "--exact"). */
#ifndef EXACT_HIT_H
#define EXACT_HIT_H

#include <math.h>
#include <stdint.h>

#include "common/expr/tape.h"
#include "common/expr/tape_dir.h"
#include "common/expr/tape_err.h"
#include "common/expr/tape_err_cell.h"

/* A line p(t) = o + t * d in the tape's (world) coordinates. */
typedef struct exact_line {
    double o[3], d[3];
} exact_line;

/* Caller scratch for tapes of up to n instructions. */
typedef struct exact_scratch {
    uint32_t n;
    double *slots;
    interval *islots;
    tape_idual *gslots;
    tape_dual *dslots;
    tape_idir1 *idir; /* the fast path's (render/exact_fast.c) */
    tape_dir1 *dir;
    tape_dir4 *dirg; /* the fast path's final evaluation, with the gradient */
    tape_edir *edir;
    tape_cerr *cerr;       /* tape_err_cell's */
    /* statistics: evaluations with an a-priori bound; models whose a-priori
     * bound did not decide (the per-point one tried), and of those the ones
     * the per-point bound decided */
    uint64_t nbound, nretry, nrescue;
} exact_scratch;

/* n elements of `size` bytes in cache lines of their own (64-byte aligned,
 * the size rounded up): each thread's worker writes its arrays all the
 * time, and two threads' arrays sharing a line slow both (docs/perf-log.md,
 * "the threads' workers in cache lines of their own"). free() releases it;
 * NULL when out of memory or on overflow. */
void *exact_line_alloc(size_t n, size_t size);

/* Allocates scratch for tapes of up to n instructions: 0, or -1 when out
 * of memory (then nothing is held). */
int exact_scratch_init(exact_scratch *w, uint32_t n);
void exact_scratch_free(exact_scratch *w); /* accepts a zeroed or freed one */

/* The box spanned by the line's points for t in [a, b] (a <= b): each end
 * is two roundings (product, sum) from the real point, so two steps out. */
void exact_segment_box(const exact_line *l, double a, double b, interval box[3]);

/* The root in [a, b] (a < b) where g's double evaluations ga = g(a) and
 * gb = g(b) differ in sign (or one is 0): Illinois regula falsi, every
 * fourth step a bisection so the bracket always shrinks, until no double
 * lies strictly between its ends; then the end where |g| is smaller (a on
 * a tie). A NaN inside (only on a flagged segment) moves the far end in, as
 * refcast does. A sign change through a pole is no root: there |g| grows as
 * the bracket closes, and a bracket whose ends both end above the larger of
 * its first ends' finite |g| gives +inf. */
double exact_refine(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                    double ga, double gb);

/* Segments no wider than this share of max(1, |t|) are the resolution
 * limit: the finder decides there (see exact_first_root). */
#define EXACT_REL_RES 0x1p-40

/* What a search found besides the root. */
enum {
    EXACT_ROOT = 1,  /* a sign change of f, converged to adjacent doubles */
    EXACT_TOUCH = 2, /* f reaches 0 (within the evaluator's enclosure) without a
                        sign change at the resolution limit: a tangential touch */
};

/* The first root of g(t) = f(o + t d) for t in [a, b] (a <= b, both finite),
 * or +inf when there is none; *kind (may be NULL) receives EXACT_ROOT or
 * EXACT_TOUCH on a hit. `cull` (NULL: t) is the tape whose interval drops
 * segments: t or one whose interval evaluation encloses t's on the boxes
 * tested (a tape_prune_const of t for a box holding them, however coarse its
 * `tiny`); the derivative and every point value come from t.
 *
 * Front-to-back bisection: a segment is dropped when the interval of f over
 * the box its points span (outward-rounded hull of its ends) excludes 0 or
 * is NaN (that interval encloses f wherever f is defined, flagged or not;
 * NaN: defined nowhere); a
 * segment on which the interval of g' = grad f . d excludes 0 is monotone
 * and holds a root exactly when g changes sign between its ends, which is
 * then refined (Illinois regula falsi with bisection steps) until no double
 * lies between the bracket's ends; the end where |g| is smaller is the
 * root. Other segments are halved. At the resolution limit (width <=
 * EXACT_REL_RES * max(1, |t|), or 60 halvings) a segment that still cannot be
 * dropped is a root if g changes sign over it (refined as above; a sign
 * change through a pole, where |g| grows as the bracket closes, is none), a
 * touch at its midpoint if g is finite at both ends, and nothing when g is
 * undefined (NaN) or infinite at an end: where f is undefined there is no
 * surface (docs/evaluation.md), and a pole is none either. */
double exact_first_root(const tape *t, const tape *cull, exact_scratch *w, const exact_line *ray,
                        double a, double b, int *kind);

/* The unit normal at p: grad f(p) normalised, turned to face against d;
 * -d/|d| where the gradient is zero or not finite. */
void exact_normal(const tape *t, exact_scratch *w, const double p[3], const double d[3],
                  double n[3]);
/* The same from a gradient g already at hand (inline: once per hit). */
static inline void exact_normal_of(const double g[3], const double d[3], double n[3])
{
    const double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(len > 0.0) || !isfinite(len)) { /* singular point: face the viewer */
        const double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; a++)
            n[a] = -d[a] / dl;
        return;
    }
    const double facing = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
    const double sgn = facing > 0.0 ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++)
        n[a] = sgn * g[a] / len;
}

#endif
