/* ao: cosine-weighted hemisphere rays, deterministic per pixel. */
#include "render/ao.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

#include "render/ao_grid.h"
#include "render/basis.h"
#include "render/shadow.h"

/* cos and sin of 2 pi frac(k phi), k < AO_MAX_RAYS: the pattern's azimuths,
 * made once; a hit turns them by its pixel's angle (ao_basis). */
static double azimuth[AO_MAX_RAYS][2];
/* sqrt(u_k) and sqrt(1 - u_k) of ray k of M <= STRATA_TABLED, at
 * M (M - 1) / 2 + k: made once, off each ray's chain of dependent
 * operations (a division and two square roots) */
#define STRATA_TABLED 64u
static double strata[STRATA_TABLED * (STRATA_TABLED + 1) / 2][2];
static pthread_once_t azimuth_once = PTHREAD_ONCE_INIT;

/* sqrt(u) and sqrt(1 - u) of ray k of m, u = (k + 1/2) / m */
static void stratum(unsigned k, unsigned m, double rc[2])
{
    const double u = ((double)k + 0.5) / (double)m;
    rc[0] = sqrt(u);
    rc[1] = sqrt(1.0 - u);
}

static void azimuth_init(void)
{
    for (unsigned k = 0; k < AO_MAX_RAYS; k++) {
        double turns = (double)k * 0.61803398874989484820;
        turns -= floor(turns);
        azimuth[k][0] = cos(2.0 * M_PI * turns);
        azimuth[k][1] = sin(2.0 * M_PI * turns);
    }
    for (unsigned m = 1; m <= STRATA_TABLED; m++)
        for (unsigned k = 0; k < m; k++)
            stratum(k, m, strata[m * (m - 1) / 2 + k]);
}

uint32_t ao_seed(uint32_t i, uint32_t j)
{
    uint64_t x = ((uint64_t)j << 32 | i) + UINT64_C(0x9e3779b97f4a7c15);
    x = (x ^ (x >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    x = (x ^ (x >> 27)) * UINT64_C(0x94d049bb133111eb);
    return (uint32_t)((x ^ (x >> 31)) >> 32);
}

void ao_basis(const float n[3], uint32_t seed, ao_frame *f)
{
    pthread_once(&azimuth_once, azimuth_init);
    const double turn = 2.0 * M_PI * ((double)seed * 0x1p-32);
    f->cs = cos(turn);
    f->ss = sin(turn);
    double *nn = f->n;
    for (int a = 0; a < 3; a++)
        nn[a] = n[a];
    const double len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    for (int a = 0; a < 3; a++)
        nn[a] /= len;
    basis_across(nn, f->t, f->b);
}

void ao_direction_in(const ao_frame *f, unsigned k, unsigned m, double d[3])
{
    double rc[2];
    if (m <= STRATA_TABLED)
        memcpy(rc, strata[m * (m - 1) / 2 + k], sizeof rc);
    else
        stratum(k, m, rc);
    const double r = rc[0], c = rc[1];
    const double ca = azimuth[k][0], sa = azimuth[k][1]; /* turned by the pixel's angle */
    const double x = r * (ca * f->cs - sa * f->ss), y = r * (sa * f->cs + ca * f->ss);
    for (int a = 0; a < 3; a++)
        d[a] = x * f->t[a] + y * f->b[a] + c * f->n[a];
}

void ao_direction(const float n[3], unsigned k, unsigned m, uint32_t seed, double d[3])
{
    ao_frame f;
    ao_basis(n, seed, &f);
    ao_direction_in(&f, k, m, d);
}

int ao_grid_wanted(const trace_opts *opts, trace_traverse_fn traverse)
{
#if TRACE_HAVE_SSE
    /* the grid's walk is the SSE any-hit walk's, with the empty space
       between the occupied cells crossed by the grid */
    return shadow_any_hit(opts, traverse) == trace_occluded_sse;
#else
    (void)opts;
    (void)traverse;
    return 0;
#endif
}

/* The unoccluded fraction of the rays k0 .. k0 + count - 1 from the grid
 * position e, started at anchor an, each reach cube edges long. */
static float open_fraction(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                           const trace_eye *e, const trace_anchor *an, const float n[3],
                           unsigned k0, unsigned count, unsigned m, uint32_t seed, double reach,
                           const ao_grid *grid, uint64_t *steps)
{
    const double dist = reach * tree->edge;
    ao_frame f;
    ao_basis(n, seed, &f);
    unsigned open = 0;
    /* shadow_cast's choice, made once for the hit's rays */
    const trace_occluded_fn occluded = shadow_any_hit(opts, traverse);
    if (!ao_grid_wanted(opts, traverse))
        grid = NULL;
#if !TRACE_HAVE_SSE
    (void)grid; /* none is wanted in this build */
#endif
    for (unsigned k = k0; k < k0 + count; k++) {
        double d[3];
        ao_direction_in(&f, k, m, d);
        trace_ray r;
        if (!trace_setup_eye(e, d, &r) || !trace_clip(&r, 0.0, dist)) {
            open++;
            continue;
        }
        if (occluded) {
            uint32_t ray_steps;
#if TRACE_HAVE_SSE
            if (grid)
                open += !trace_occluded_grid_sse(tree, grid, &r, an, &ray_steps);
            else
#endif
                open += !occluded(tree, &r, an, &ray_steps);
            *steps += ray_steps;
        } else {
            open += !shadow_cast(tree, opts, traverse, &r, an, steps);
        }
    }
    return (float)open / (float)count;
}

float ao_factor(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                const double o[3], const float n[3], unsigned k0, unsigned count, unsigned m,
                uint32_t seed, double reach, uint64_t *steps)
{
    /* the rays share their start: its grid position once, and the deepest
       occupied cell around it, where every ray's descent would arrive */
    trace_eye e;
    if (!trace_eye_init(tree, o, &e))
        return 1.0f; /* as trace_setup: no ray, nothing in the way */
    trace_anchor an;
    an.depth = 0;
    if (e.inside[0] && e.inside[1] && e.inside[2]) {
        const double margin = 0x1p-10 + 0x1p-36 * e.n;
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = e.o[a] - margin;
            hi[a] = e.o[a] + margin;
        }
        trace_anchor_find(tree, lo, hi, &an);
    }
    return open_fraction(tree, opts, traverse, &e, &an, n, k0, count, m, seed, reach, NULL, steps);
}

float ao_factor_from(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                     const shadow_start *s, const float n[3], unsigned k0, unsigned count,
                     unsigned m, uint32_t seed, double reach, const ao_grid *grid,
                     uint64_t *steps)
{
    if (!s->eye.ok)
        return 1.0f;
    return open_fraction(tree, opts, traverse, &s->eye, &s->anchor, n, k0, count, m, seed, reach,
                         grid, steps);
}
