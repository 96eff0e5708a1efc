/* exact_voxel: a thread's worker for the exact hit test, and the test of
 * one voxel: the certified fast path, the root past the voxel, kinks off
 * the surface, the fallback (see exact_scene.h; RENDER.md, "--exact"). */
#include "render/exact_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_hess.h"
#include "render/exact_fast.h"
#include "render/trace_impl.h"

void exact_worker_new_frame(exact_worker *w)
{
    w->key_slot = UINT32_MAX;
    w->key_t = 0.0;
    w->have = 0;
    w->have_curv = 0;
    w->exit_t = NAN;
    w->clear_to = -INFINITY;
    w->line_new = 1;
    memset(w->key, 0, sizeof w->key);
    /* (no ray's: its d is finite and not all 0) */
    for (int a = 0; a < 6; a++)
        w->ray_od[a] = NAN;
}

int exact_worker_init(exact_worker *w, const exact_scene *es)
{
    w->scene = es;
    w->fast = w->slow = w->beyond = w->skipped = 0;
    w->bound_min_n = EXACT_BOUND_MIN_N;
    exact_worker_new_frame(w);
    w->bound = exact_line_alloc(es->ncand ? es->ncand : 1, sizeof *w->bound);
    w->bound_state = exact_line_alloc(es->ncand ? es->ncand : 1, 1);
    if (w->bound_state)
        memset(w->bound_state, 0, es->ncand ? es->ncand : 1);
    if (!w->bound || !w->bound_state || exact_scratch_init(&w->scratch, es->max_n)) {
        free(w->bound);
        free(w->bound_state);
        return -1;
    }
    if (exact_sub_init(&w->sub, es->ncand, es->max_n)) {
        exact_scratch_free(&w->scratch);
        free(w->bound);
        free(w->bound_state);
        return -1;
    }
    return 0;
}

/* Candidate k's a-priori bound over its cell (the box its Hessian bound
 * holds on), made on first use; NULL where there is none. It depends on
 * the candidate alone, so images do not depend on which worker made it. */
static const exact_bound *cell_bound(exact_worker *w, uint32_t k, const uint32_t v[3])
{
    if (w->bound_state[k] == 0) {
        const exact_scene *es = w->scene;
        const unsigned shift = es->tree->levels - es->depth;
        const uint32_t c[3] = {v[0] >> shift, v[1] >> shift, v[2] >> shift};
        exact_bound *b = &w->bound[k];
        exact_scene_box(es, es->depth, c, b->box);
        b->hmag = es->cand[k].hmag;
        w->bound_state[k] =
            tape_err_cell(&es->cand[k].t, b->box, &b->e, w->scratch.gslots, w->scratch.cerr) ? 1
                                                                                              : 2;
    }
    return w->bound_state[k] == 1 ? &w->bound[k] : NULL;
}

void exact_worker_free(exact_worker *w)
{
    exact_sub_free(&w->sub);
    exact_scratch_free(&w->scratch);
    free(w->bound);
    free(w->bound_state);
    w->bound = NULL;
    w->bound_state = NULL;
    w->scene = NULL;
}

/* The ray's line in world units, local t: p(t) = origin + (o + t d) h, and
 * the span's widening, 2^-16 voxel along the ray (made when the ray's o or
 * d is not the last one's: once for a ray's voxels). */
static __attribute__((noinline)) void make_line(exact_worker *w, const trace_ray *r)
{
    const exact_scene *es = w->scene;
    const oct_tree *tree = es->tree;
    double dd = 0.0;
    for (int a = 0; a < 3; a++) {
        w->line.o[a] = tree->origin[a] + r->o[a] * es->h;
        w->line.d[a] = r->d[a] * es->h;
        dd += r->d[a] * r->d[a];
    }
    w->widen = 0x1p-16 / sqrt(dd);
    w->line_new = memcmp(w->key, w->line.o, sizeof w->line.o) ||
                  memcmp(w->key + 3, w->line.d, sizeof w->line.d);
    memcpy(w->ray_od, r->o, sizeof r->o);
    memcpy(w->ray_od + 3, r->d, sizeof r->d);
}

/* The hit at local t of the surface whose exact tape is t: its normal and
 * surface (out of line: most voxels tested hold no root). */
static __attribute__((noinline)) void finish_hit(exact_worker *w, const tape *t,
                                                 const double grad[3], double best,
                                                 uint32_t surface, trace_hit *hit)
{
    const exact_line *l = &w->line;
    if (grad[0] == grad[0]) { /* the fast path's final evaluation gave it */
        exact_normal_of(grad, l->d, hit->normal);
    } else {
        double p[3];
        for (int k = 0; k < 3; k++)
            p[k] = l->o[k] + best * l->d[k];
        exact_normal(t, &w->scratch, p, l->d, hit->normal);
    }
    hit->exact = 1;
    hit->surface = surface;
}

/* Local t where the ray leaves the region whose corner, in cells of
 * 2^shift voxels, is c (or the ray's end), made once a line and region
 * (exit_key; the key's reset clears it). */
static inline double region_exit(exact_worker *w, const trace_ray *r, const uint32_t c[3],
                                 unsigned shift, uint64_t key)
{
    if (w->exit_t != w->exit_t || w->exit_key != key) {
        double te = r->t_end;
        for (int a = 0; a < 3; a++) { /* (+inf on a zero axis) */
            const uint64_t k = (uint64_t)c[a] + (r->sgn[a] > 0);
            const double ta = trace_plane_time(r, a, (double)(k << shift));
            te = ta < te ? ta : te;
        }
        w->exit_t = te;
        w->exit_key = key;
    }
    return w->exit_t;
}

/* The voxel's span [a, b] holds no root of the cell's one surface: the
 * model of the region (the coarse cell or its sub-cell: corner c, shift,
 * key) may still certify exactly one root on [a, e], e where the line
 * leaves the region (its box holds those points too, so the model's bounds
 * hold there), and place it. That root is the ray's hit (the cell has no
 * other surface, and voxels before a hold no root), so the region's next
 * voxels need no test. Where the whole span is undecided, the span to
 * BEYOND_NEAR voxels past b is asked. A span certified root-free instead
 * is kept (w->clear_to): the voxels inside it need no test either.
 * EXACT_FAST_ROOT with *t, grad; else EXACT_FAST_NONE (the voxel's own
 * answer). */
#define BEYOND_NEAR 2.0

/* Local t BEYOND_NEAR voxels past b along the ray (a voxel is crossed along
 * the major axis in 1 / max |d_k|). */
static double near_end(const trace_ray *r, double b)
{
    const double dx = fabs(r->d[0]), dy = fabs(r->d[1]), dz = fabs(r->d[2]);
    const double dm = dx > dy ? (dx > dz ? dx : dz) : (dy > dz ? dy : dz);
    return b + BEYOND_NEAR / dm;
}

/* The answer about a span [a, end] past the voxel tested: a root there is
 * the ray's hit (counted), a span certified root-free is kept for the
 * ray's next voxels (clear_to); else the voxel's own answer, no root. */
static int past_answer(exact_worker *w, int st, double end)
{
    if (st == EXACT_FAST_NONE)
        w->clear_to = end;
    if (st != EXACT_FAST_ROOT)
        return EXACT_FAST_NONE;
    w->beyond++;
    return EXACT_FAST_ROOT;
}

/* The span to BEYOND_NEAR voxels past b (within [a, e]), asked where the
 * span to e is undecided. */
static int root_near(exact_worker *w, const trace_ray *r, const tape *t_exact, double a, double b,
                     double e, double curv, double *t, double grad[3])
{
    const double near = near_end(r, b);
    if (!(near < e))
        return EXACT_FAST_NONE;
    return past_answer(
        w, exact_fast_decide(t_exact, &w->scratch, &w->line, a, near, curv, &w->model[0], t, grad),
        near);
}

static int root_beyond(exact_worker *w, const trace_ray *r, const uint32_t c[3], unsigned shift,
                       uint64_t key, const tape *t_exact, double a, double b, double curv,
                       double *t, double grad[3])
{
    const double e = region_exit(w, r, c, shift, key);
    if (!(e > b))
        return EXACT_FAST_NONE;
    const int st =
        exact_fast_decide(t_exact, &w->scratch, &w->line, a, e, curv, &w->model[0], t, grad);
    if (st == EXACT_FAST_UNDECIDED)
        return root_near(w, r, t_exact, a, b, e, curv, t, grad);
    return past_answer(w, st, e);
}

/* The test of a voxel [a, b] of the cell's one surface when its first
 * model is made (at m, inside [a, e], e > b where the line leaves the
 * region): that model is asked about [a, e] at once, the question
 * root_beyond asks after the voxel's own, which it mostly answers (the
 * root, or no root to e). Undecided there, the voxel's span [a, b] is
 * tested with it (exact_fast_root) and, holding no root, the span past b
 * to BEYOND_NEAR voxels (root_near). *have as for exact_fast_root. */
static int cell_first(exact_worker *w, const trace_ray *r, const tape *t_exact, double a,
                      double b, double e, double curv, const exact_bound *cb, double m, int *have,
                      double *t, double grad[3])
{
    const exact_line *l = &w->line;
    int st = exact_fast_first(t_exact, &w->scratch, l, a, e, curv, cb, m, &w->model[0], have, t,
                              grad);
    if (st == EXACT_FAST_NONE) {
        w->clear_to = e;
        return st;
    }
    if (st == EXACT_FAST_ROOT) {
        if (*t > b)
            w->beyond++;
        return st;
    }
    st = exact_fast_root(t_exact, &w->scratch, l, a, b, curv, cb, NAN, &w->model[0], have, t, grad);
    if (st == EXACT_FAST_NONE && *have)
        st = root_near(w, r, t_exact, a, b, e, curv, t, grad);
    return st;
}

/* Candidate c of a coarse cell where its tape keeps a kink (hmag +inf) and
 * no sub-cell is taken (the gyroid's |G|, whose zero set runs a few voxels
 * from the surface: exact_sub.h), but whose Hessian bound with the kinks
 * allowed (hbranch) is finite: that bound holds on any part of the cell
 * where the tape has no kink (tape_hess_mags). So the certified test runs
 * on the voxel's span [a, b] where an interval evaluation over the span's
 * box finds no kink, with a model at the span's midpoint (inside it:
 * Taylor's bound then holds between the model's point and every point of
 * the span) and per-point error bounds (the cell's a-priori bound needs a
 * finite hmag). Where [a, b] holds no root and c is the cell's one surface
 * (alone), the span to BEYOND_NEAR voxels past b, inside the cell, the same
 * way when it is kink-free too (RENDER.md, "Kinks off the surface"); one
 * evaluation over that longer span's box then serves both. EXACT_FAST_ROOT
 * with *t and grad, EXACT_FAST_NONE, or EXACT_FAST_UNDECIDED: a kink on
 * the span, or the test could not decide (then the fallback). */
static int branch_test(exact_worker *w, const trace_ray *r, const exact_cand *c,
                       const uint32_t rc[3], unsigned rshift, int alone, double a, double b,
                       double *t, double grad[3])
{
    const exact_line *l = &w->line;
    /* one interval evaluation where the span past b is kink-free too, which
     * it mostly is; else a second for [a, b] alone */
    double end = b;
    if (alone) {
        const double e = region_exit(w, r, rc, rshift, 0), near = near_end(r, b);
        end = near < e ? near : e;
    }
    interval box[3];
    int past_ok = 0;
    if (end > b) {
        exact_segment_box(l, a, end, box);
        past_ok = !tape_hess_kinks(&c->t, box, w->scratch.islots);
    }
    if (!past_ok) {
        exact_segment_box(l, a, b, box);
        if (tape_hess_kinks(&c->t, box, w->scratch.islots))
            return EXACT_FAST_UNDECIDED;
    }
    const double curv = exact_fast_curv(c->hbranch, l->d);
    exact_model md;
    int have = 0;
    const int st =
        exact_fast_root(&c->t, &w->scratch, l, a, b, curv, NULL, NAN, &md, &have, t, grad);
    if (st != EXACT_FAST_NONE || !past_ok || !have)
        return st;
    return past_answer(w, exact_fast_decide(&c->t, &w->scratch, l, a, end, curv, &md, t, grad),
                       end);
}

/* Where the ray meets voxel n's stored plane (the paper's hit), clamped
 * into [a, e]: a first model there starts next to the root, so that one
 * Newton step less places it. NaN without records or plane crossing. */
static double plane_hint(const oct_tree *tree, const trace_ray *r, uint64_t n,
                         const uint32_t v[3], double a, double e)
{
    if (!tree->voxels)
        return NAN;
    double num, den;
    trace_voxel_plane(tree, r, n, v, &num, &den);
    const double tp = num / den;
    return tp > a ? (tp < e ? tp : e) : tp == tp ? a : NAN;
}

int exact_voxel(exact_worker *w, const trace_ray *r, const uint32_t v[3], double t_in,
                double t_out, double *t_hit, trace_hit *hit)
{
    const exact_scene *es = w->scene;
    const unsigned shift = es->tree->levels - es->depth;
    const uint32_t dim = UINT32_C(1) << es->depth;
    const uint32_t slot =
        es->cell_slot[((size_t)(v[2] >> shift) * dim + (v[1] >> shift)) * dim + (v[0] >> shift)];
    if (slot == UINT32_MAX)
        return 0; /* (a voxel's cell is always registered) */
    if (memcmp(w->ray_od, r->o, sizeof r->o) || memcmp(w->ray_od + 3, r->d, sizeof r->d))
        make_line(w, r);
    const exact_line *l = &w->line;
    /* a new line, cell, or traversal (a line traced again starts before
     * where it was last tested): the models start afresh, so that what a ray
     * finds depends on that ray alone */
    if (w->line_new || slot != w->key_slot || t_in < w->key_t) {
        memcpy(w->key, l->o, sizeof l->o);
        memcpy(w->key + 3, l->d, sizeof l->d);
        w->line_new = 0;
        w->key_slot = slot;
        w->have = 0;
        w->have_curv = 0;
        w->exit_t = NAN;
        w->clear_to = -INFINITY;
    }
    w->key_t = t_in;
    double a = t_in - w->widen, b = t_out + w->widen;
    if (b <= w->clear_to) { /* inside a span already certified root-free */
        w->skipped++;
        return 0;
    }
    if (a < -r->t_base)
        a = -r->t_base; /* the caller's t >= 0 */
    double best = INFINITY;
    tape win; /* the winner's exact tape */
    double win_grad[3] = {NAN}; /* its gradient from the fast path, if any */
    uint32_t best_k = 0;
    int reserved = 0; /* exact_sub_reserve called for this voxel */
    const uint32_t k0 = es->first[slot], k1 = es->first[slot + 1];
    for (uint32_t k = k0; k < k1; k++) {
        if (!(a <= b))
            break;
        /* the cell's tapes and bound, or where that is +inf its sub-cell's */
        const exact_cand *c = &es->cand[k];
        const tape *t_exact = &c->t, *t_cull = &c->cull;
        const double *hmag = c->hmag;
        uint64_t key = 0;
        uint32_t rc[3] = {v[0] >> shift, v[1] >> shift, v[2] >> shift}; /* the region's corner */
        unsigned rshift = shift;
        if (!(hmag[0] < INFINITY) && es->sub_max && exact_sub_wanted(c->kinks)) {
            if (!reserved) {
                exact_sub_reserve(&w->sub);
                reserved = 1;
            }
            const exact_region *rg = exact_sub_find(&w->sub, es, k, v);
            if (rg->empty) {
                w->fast++;
                continue;
            }
            t_exact = &rg->t;
            t_cull = &rg->cull;
            hmag = rg->hmag;
            key = rg->key;
            memcpy(rc, rg->corner, sizeof rc);
            rshift = rg->shift;
        }
        double t = INFINITY, grad[3]; /* (set when st is EXACT_FAST_ROOT) */
        int st = EXACT_FAST_UNDECIDED;
        const uint32_t j = k - k0;
        if (j < EXACT_MODELS) {
            const uint32_t bit = UINT32_C(1) << j;
            if (!(w->have_curv & bit) || w->curv_key[j] != key) {
                w->curv[j] = exact_fast_curv(hmag, l->d);
                w->curv_key[j] = key;
                w->have_curv |= bit;
            }
            const double curv = w->curv[j];
            if (curv < INFINITY) {
                int have = (w->have & bit) && w->model_key[j] == key;
                const exact_bound *cb =
                    key == 0 && t_exact->n >= w->bound_min_n ? cell_bound(w, k, v) : NULL;
                /* a first model at the stored plane's hit where it spares a
                 * Newton step of a long tape (one with the a-priori bound) */
                const int alone = k1 - k0 == 1;
                const double e = !have && cb && alone ? region_exit(w, r, rc, rshift, key) : NAN;
                const double m_new = e == e ? plane_hint(es->tree, r, hit->voxel, v, a, e) : NAN;
                if (m_new == m_new && e > b) {
                    st = cell_first(w, r, t_exact, a, b, e, curv, cb, m_new, &have, &t, grad);
                } else {
                    st = exact_fast_root(t_exact, &w->scratch, l, a, b, curv, cb, m_new,
                                         &w->model[j], &have, &t, grad);
                    if (st == EXACT_FAST_NONE && have && alone)
                        st = root_beyond(w, r, rc, rshift, key, t_exact, a, b, curv, &t, grad);
                }
                w->have = (w->have & ~bit) | (uint32_t)have << j;
                w->model_key[j] = key;
            }
        }
        if (st == EXACT_FAST_UNDECIDED && key == 0 && !(hmag[0] < INFINITY) &&
            c->hbranch[0] < INFINITY)
            st = branch_test(w, r, c, rc, rshift, k1 - k0 == 1, a, b, &t, grad);
        if (st == EXACT_FAST_UNDECIDED) {
            w->slow++;
            t = exact_first_root(t_exact, t_cull, &w->scratch, l, a, b, NULL);
        } else {
            w->fast++;
        }
        if (t < best) {
            best = t;
            best_k = k;
            win = *t_exact;
            win_grad[0] = NAN;
            if (st == EXACT_FAST_ROOT)
                memcpy(win_grad, grad, sizeof grad);
            b = t; /* a later surface must be nearer to win */
        }
    }
    if (!(best < INFINITY))
        return 0;
    finish_hit(w, &win, win_grad, best, es->cand[best_k].surface, hit);
    *t_hit = best;
    return 1;
}
