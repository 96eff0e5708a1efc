/* trace: the traversal's entry points (see trace.h): trace_ray_cast and the
 * prepared and anchored casts, on the implementation this build prefers.
 * Set-up, clipping and anchors are in trace_setup.c, the --refine test in
 * trace_refine.c, the traversal itself in trace_sse.c and trace_portable.c
 * (one algorithm, two implementations: trace_impl.h). */
#include "render/trace.h"

#include <math.h>
#include <stddef.h>

#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#define TRACE_TRAVERSE trace_traverse_sse
#else
#define TRACE_TRAVERSE trace_traverse_portable
#endif

const trace_impl trace_impls[] = {
#if TRACE_HAVE_SSE
    {"sse", trace_traverse_sse, trace_occluded_sse},
#endif
    {"portable", trace_traverse_portable, trace_occluded_portable},
};
const unsigned trace_impl_count = sizeof trace_impls / sizeof trace_impls[0];

trace_occluded_fn trace_occluded_for(trace_traverse_fn fn)
{
    for (unsigned k = 0; k < trace_impl_count; k++)
        if (trace_impls[k].traverse == fn)
            return trace_impls[k].occluded;
    return trace_impls[0].occluded;
}

int trace_ray_prepared(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit)
{
    return TRACE_TRAVERSE(tree, opts, r, NULL, hit);
}

int trace_ray_anchored(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit)
{
    return TRACE_TRAVERSE(tree, opts, r, a, hit);
}

int trace_ray_cast(const oct_tree *tree, const trace_opts *opts, const double eye[3],
                   const double dir[3], trace_hit *hit)
{
    trace_ray r;
    if (!trace_setup(tree, eye, dir, &r)) {
        hit->hit = 0;
        hit->t = INFINITY;
        hit->steps = 0;
        return 0;
    }
    return trace_ray_prepared(tree, opts, &r, hit);
}
