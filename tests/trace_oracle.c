/* trace_oracle: see trace_oracle.h. */
#include "tests/trace_oracle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/trace_impl.h"

long trace_oracle_first(const trace_ray *r, unsigned levels, const uint32_t (*vox)[3], size_t n,
                        double *t_out)
{
    const uint32_t lim = UINT32_C(1) << levels;
    long best = -1;
    double best_t = INFINITY;
    for (size_t i = 0; i < n; i++) {
        double lo = 0.0, hi = INFINITY;
        int ok = 1;
        for (int a = 0; a < 3 && ok; a++) {
            double k = (double)vox[i][a];
            if (!(r->active >> a & 1)) {
                double f = floor(r->o[a]);
                uint32_t kz = f >= (double)lim ? lim - 1 : (uint32_t)f;
                ok = vox[i][a] == kz;
                continue;
            }
            double en = trace_plane_time(r, a, r->sgn[a] > 0 ? k : k + 1);
            double ex = trace_plane_time(r, a, r->sgn[a] > 0 ? k + 1 : k);
            if (en > lo)
                lo = en;
            if (ex < hi)
                hi = ex;
        }
        if (ok && lo < hi && lo < best_t) {
            best_t = lo;
            best = (long)i;
        }
    }
    *t_out = best_t;
    return best;
}

/* xyz is the voxel the traversal stopped in; an empty tree stops before
 * any, leaving it unset. */
static int same_hit(const oct_tree *tree, const trace_hit *a, const trace_hit *b)
{
    if (a->hit != b->hit || a->steps != b->steps)
        return 0;
    if (tree->node_count[0] != 0 &&
        (a->xyz[0] != b->xyz[0] || a->xyz[1] != b->xyz[1] || a->xyz[2] != b->xyz[2]))
        return 0;
    if (!a->hit)
        return 1;
    return a->voxel == b->voxel && (a->t == b->t || (isnan(a->t) && isnan(b->t)));
}

/* The any-hit walk of every implementation, from the anchor and from the
 * root: the traversal's answer (hit), and one step count for all. */
static void check_occluded(const oct_tree *tree, const trace_ray *r, const trace_anchor *a,
                           const trace_hit *hit)
{
    uint32_t steps0 = 0;
    for (unsigned i = 0; i < trace_impl_count; i++)
        for (int root = 0; root <= (a != NULL); root++) {
            uint32_t steps;
            const int occ = trace_impls[i].occluded(tree, r, root ? NULL : a, &steps);
            if (i == 0 && root == 0)
                steps0 = steps;
            if (occ != hit->hit || steps != steps0) {
                fprintf(stderr,
                        "any-hit walk differs (anchor depth %u, %s, %s): occluded %d steps %u; "
                        "traversal hit %d, first walk's steps %u\n",
                        a ? a->depth : 0u, root ? "from the root" : "from the anchor",
                        trace_impls[i].name, occ, steps, hit->hit, steps0);
                abort();
            }
        }
}

static int run_all(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                   const trace_anchor *a, trace_hit *hit)
{
    trace_impls[0].traverse(tree, opts, r, a, hit);
    for (unsigned i = 1; i < trace_impl_count; i++) {
        trace_hit h;
        trace_impls[i].traverse(tree, opts, r, a, &h);
        if (!same_hit(tree, hit, &h)) {
            fprintf(stderr,
                    "trace implementations differ (K=%u refine=%d, anchor depth %u): %s hit %d "
                    "(%u %u %u) t %a steps %u; %s hit %d (%u %u %u) t %a steps %u\n",
                    opts->split, opts->refine, a ? a->depth : 0u, trace_impls[0].name, hit->hit,
                    hit->xyz[0], hit->xyz[1], hit->xyz[2], hit->t, hit->steps, trace_impls[i].name,
                    h.hit, h.xyz[0], h.xyz[1], h.xyz[2], h.t, h.steps);
            abort();
        }
    }
    if (!opts->refine && !opts->exact)
        check_occluded(tree, r, a, hit);
    return hit->hit;
}

int trace_cast_all(const oct_tree *tree, const trace_opts *opts, const double eye[3],
                   const double dir[3], trace_hit *hit)
{
    trace_ray r;
    if (!trace_setup(tree, eye, dir, &r))
        return trace_ray_cast(tree, opts, eye, dir, hit); /* the miss, as it reports it */
    return run_all(tree, opts, &r, NULL, hit);
}

int trace_prepared_all(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit)
{
    return run_all(tree, opts, r, NULL, hit);
}

int trace_anchored_all(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit)
{
    return run_all(tree, opts, r, a, hit);
}
