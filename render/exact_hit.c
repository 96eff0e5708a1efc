/* exact_hit: interval bisection along a ray segment, Illinois refinement to
 * adjacent doubles (see exact_hit.h). */
#include "render/exact_hit.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define MAX_DEPTH 60 /* halvings of one segment: 2^-60 of a voxel is below the resolution */

void *exact_line_alloc(size_t n, size_t size)
{
    if (size && n > (SIZE_MAX - 63) / size)
        return NULL;
    const size_t bytes = n * size;
    return aligned_alloc(64, bytes ? (bytes + 63) & ~(size_t)63 : 64);
}

int exact_scratch_init(exact_scratch *w, uint32_t n)
{
    if (n < 1)
        n = 1;
    w->n = n;
    w->slots = exact_line_alloc(n, sizeof *w->slots);
    w->islots = exact_line_alloc(n, sizeof *w->islots);
    w->gslots = exact_line_alloc(n, sizeof *w->gslots);
    w->dslots = exact_line_alloc(n, sizeof *w->dslots);
    w->idir = exact_line_alloc(n, sizeof *w->idir);
    w->dir = exact_line_alloc(n, sizeof *w->dir);
    w->dirg = exact_line_alloc(n, sizeof *w->dirg);
    w->edir = exact_line_alloc(n, sizeof *w->edir);
    w->cerr = exact_line_alloc(n, sizeof *w->cerr);
    w->nbound = w->nretry = w->nrescue = 0;
    if (!w->slots || !w->islots || !w->gslots || !w->dslots || !w->idir || !w->dir || !w->dirg ||
        !w->edir || !w->cerr) {
        exact_scratch_free(w);
        return -1;
    }
    return 0;
}

void exact_scratch_free(exact_scratch *w)
{
    free(w->slots);
    free(w->islots);
    free(w->gslots);
    free(w->dslots);
    free(w->idir);
    free(w->dir);
    free(w->dirg);
    free(w->edir);
    free(w->cerr);
    w->cerr = NULL;
    w->edir = NULL;
    w->idir = NULL;
    w->dir = NULL;
    w->dirg = NULL;
    w->slots = NULL;
    w->islots = NULL;
    w->gslots = NULL;
    w->dslots = NULL;
    w->n = 0;
}

void exact_segment_box(const exact_line *l, double a, double b, interval box[3])
{
    for (int k = 0; k < 3; k++) {
        const double pa = l->o[k] + a * l->d[k], pb = l->o[k] + b * l->d[k];
        const double lo = pa < pb ? pa : pb, hi = pa < pb ? pb : pa;
        box[k].lo = interval_next_down(interval_next_down(lo));
        box[k].hi = interval_next_up(interval_next_up(hi));
    }
}

static double g_at(const tape *t, exact_scratch *w, const exact_line *l, double s)
{
    return tape_eval(t, l->o[0] + s * l->d[0], l->o[1] + s * l->d[1], l->o[2] + s * l->d[2],
                     w->slots);
}

/* (see exact_hit.h) */
double exact_refine(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                    double ga, double gb)
{
    if (ga == 0.0)
        return a;
    if (gb == 0.0)
        return b;
    /* (an infinite end is a pole's value, not a scale) */
    const double fa = isinf(ga) ? 0.0 : fabs(ga), fb = isinf(gb) ? 0.0 : fabs(gb);
    const double gmax = fa > fb ? fa : fb;
    int side = 0;
    for (unsigned it = 0; it < 400; it++) {
        double c = 0.5 * (a + b);
        if (!(c > a && c < b))
            break; /* adjacent doubles */
        if (it % 4 != 3) {
            const double s = (a * gb - b * ga) / (gb - ga);
            if (s > a && s < b)
                c = s;
        }
        const double gc = g_at(t, w, l, c);
        if (gc == 0.0)
            return c;
        if (gc != gc) {
            b = c;
            gb = ga > 0.0 ? -1.0 : 1.0;
            side = 0;
            continue;
        }
        if ((gc < 0.0) == (ga < 0.0)) {
            a = c;
            ga = gc;
            if (side == -1)
                gb *= 0.5;
            side = -1;
        } else {
            b = c;
            gb = gc;
            if (side == 1)
                ga *= 0.5;
            side = 1;
        }
    }
    if (fabs(ga) > gmax && fabs(gb) > gmax)
        return INFINITY;
    return fabs(ga) <= fabs(gb) ? a : b;
}

static int crosses(double ga, double gb)
{
    return ga == 0.0 || gb == 0.0 || (ga < 0.0) != (gb < 0.0);
}

typedef struct seg {
    double a, b;
    unsigned depth;
} seg;

double exact_first_root(const tape *t, const tape *cull, exact_scratch *w, const exact_line *l,
                        double a, double b, int *kind)
{
    if (!cull)
        cull = t;
    seg stack[MAX_DEPTH + 2];
    int top = 0;
    stack[top++] = (seg){a, b, 0};
    const double big = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    const double minw = EXACT_REL_RES * (big > 1.0 ? big : 1.0);
    while (top > 0) {
        const seg s = stack[--top];
        interval box[3];
        exact_segment_box(l, s.a, s.b, box);
        unsigned flags = 0;
        const interval F = tape_eval_interval(cull, box, w->islots, &flags);
        /* F encloses f wherever f is defined (flagged or not), and the NaN
         * interval means defined nowhere: either way no surface point here */
        if (interval_is_nan(F) || F.lo > 0.0 || F.hi < 0.0)
            continue;
        const int last = s.depth >= MAX_DEPTH || s.b - s.a <= minw;
        if (!flags && !last) {
            interval g[3];
            unsigned gf = 0;
            tape_eval_interval_grad(t, box, g, w->gslots, &gf);
            interval D = interval_mul(g[0], (interval){l->d[0], l->d[0]}, &gf);
            D = interval_add(D, interval_mul(g[1], (interval){l->d[1], l->d[1]}, &gf), &gf);
            D = interval_add(D, interval_mul(g[2], (interval){l->d[2], l->d[2]}, &gf), &gf);
            if (!gf && !interval_is_nan(D) && (D.lo > 0.0 || D.hi < 0.0)) {
                /* monotone: one root at most, there iff the ends differ in sign */
                const double ga = g_at(t, w, l, s.a), gb = g_at(t, w, l, s.b);
                if (crosses(ga, gb)) {
                    if (kind)
                        *kind = EXACT_ROOT;
                    return exact_refine(t, w, l, s.a, s.b, ga, gb); /* (no pole: monotone) */
                }
                continue;
            }
        }
        if (last) {
            const double ga = g_at(t, w, l, s.a), gb = g_at(t, w, l, s.b);
            if (ga != ga && gb != gb)
                continue; /* undefined here: not a surface point */
            if (ga == ga && gb == gb && crosses(ga, gb)) {
                const double r = exact_refine(t, w, l, s.a, s.b, ga, gb);
                if (r < INFINITY) {
                    if (kind)
                        *kind = EXACT_ROOT;
                    return r;
                }
                continue; /* a pole */
            }
            if (!isfinite(ga) || !isfinite(gb))
                continue; /* NaN or a pole at an end: no evidence of a touch */
            if (kind)
                *kind = EXACT_TOUCH;
            return 0.5 * (s.a + s.b);
        }
        const double m = 0.5 * (s.a + s.b);
        stack[top++] = (seg){m, s.b, s.depth + 1}; /* far half below */
        stack[top++] = (seg){s.a, m, s.depth + 1};
    }
    return INFINITY;
}

void exact_normal(const tape *t, exact_scratch *w, const double p[3], const double d[3],
                  double n[3])
{
    double g[3];
    tape_eval_grad(t, p, g, w->dslots);
    exact_normal_of(g, d, n);
}

