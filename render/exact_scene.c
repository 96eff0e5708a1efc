/* exact_scene: per coarse cell the surfaces present and their pruned
 * tapes; the exact hit test of one voxel (see exact_scene.h). */
#include "render/exact_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_hess.h"
#include "render/exact_fast.h"
#include "render/trace_impl.h"

/* Growable pools while building; pointers are set once they stop moving. */
typedef struct builder {
    exact_scene *es;
    const tape *tapes;
    uint32_t nsurf;
    uint32_t cap_cells, cap_cand;
    size_t n_insn, cap_insn, n_konst, cap_konst;
    struct {
        uint64_t exact[2], cull[2]; /* insn, konst pool offsets; UINT64_MAX: the whole tape */
    } *off;                         /* per candidate */
    interval *slots, *kslots;
    tape_ihess *hslots;
    tape_insn *tmp_insn;
    tape_const *tmp_konst;
    uint32_t *tmp_scratch;
} builder;

static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * size);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

void exact_scene_box(const exact_scene *es, unsigned d, const uint32_t c[3], interval box[3])
{
    /* (2^(levels - d) exactly, without a libm call: this runs per sub-cell) */
    const double m = 0x1p-8, size = (double)(UINT64_C(1) << (es->tree->levels - d));
    for (int a = 0; a < 3; a++) {
        const double lo = es->tree->origin[a] + ((double)c[a] * size - m) * es->h;
        const double hi = es->tree->origin[a] + ((double)(c[a] + 1) * size + m) * es->h;
        box[a].lo = interval_next_down(interval_next_down(lo));
        box[a].hi = interval_next_up(interval_next_up(hi));
    }
}

/* t pruned with `tiny` for the box whose slot intervals b->slots holds,
 * appended to the pools (*off: its offsets, fixed up once they stop
 * moving), or t itself (off UINT64_MAX) when pruning saves not a quarter. */
static int store_pruned(builder *b, const tape *t, unsigned flags, double tiny, tape *out,
                        uint64_t off[2], uint64_t *insns)
{
    exact_scene *es = b->es;
    tape p;
    tape_prune_const(t, b->slots, flags, isfinite(tiny) ? tiny : -1.0, b->tmp_insn, b->tmp_konst,
                     b->tmp_scratch, &p);
    if ((uint64_t)p.n * 4 > (uint64_t)t->n * 3) {
        *out = *t;
        out->owned = 0;
        off[0] = off[1] = UINT64_MAX;
        *insns += t->n;
        return 0;
    }
    if (grow((void **)&es->insn_pool, &b->cap_insn, b->n_insn + p.n, sizeof(tape_insn)) ||
        grow((void **)&es->konst_pool, &b->cap_konst, b->n_konst + p.nconst, sizeof(tape_const)))
        return -1;
    memcpy(es->insn_pool + b->n_insn, p.insn, p.n * sizeof(tape_insn));
    memcpy(es->konst_pool + b->n_konst, p.konst, p.nconst * sizeof(tape_const));
    *out = p;
    out->owned = 0;
    off[0] = b->n_insn;
    off[1] = b->n_konst;
    b->n_insn += p.n;
    b->n_konst += p.nconst;
    *insns += p.n;
    return 0;
}

/* Registers coarse cell c: every surface whose enclosure over the cell
 * may hold 0 becomes a candidate with two tapes pruned for the cell. The
 * exact one turns into constants only terms narrower there than 2^-30 of
 * f's spread over one voxel (their midpoint for the point evaluator: a root
 * moves by about 2^-30 of a voxel at most, far below the targets); the
 * culling one, whose interval alone is used (to drop segments: sound for
 * any tiny, tape.h), takes the rasterizer's 10^-3, so a far blob costs
 * nothing there. */
static int add_cell(builder *b, const uint32_t c[3])
{
    exact_scene *es = b->es;
    const unsigned D = es->depth, L = es->tree->levels;
    size_t cap = b->cap_cells;
    if (grow((void **)&es->first, &cap, (size_t)es->ncells + 2, sizeof *es->first))
        return -1;
    b->cap_cells = (uint32_t)cap;
    interval box[3];
    exact_scene_box(es, D, c, box);
    es->first[es->ncells] = es->ncand;
    for (uint32_t s = 0; s < b->nsurf; s++) {
        const tape *t = &b->tapes[s];
        unsigned flags = 0;
        const interval F = tape_eval_interval(t, box, b->slots, &flags);
        if (interval_is_nan(F) || F.lo > 0.0 || F.hi < 0.0)
            continue; /* not here (exact_first_root's rule) */
        size_t cc = b->cap_cand;
        if (grow((void **)&es->cand, &cc, (size_t)es->ncand + 1, sizeof *es->cand))
            return -1;
        size_t co = b->cap_cand;
        if (grow((void **)&b->off, &co, (size_t)es->ncand + 1, sizeof *b->off))
            return -1;
        b->cap_cand = (uint32_t)(cc < co ? cc : co);
        exact_cand *k = &es->cand[es->ncand];
        k->surface = s;
        const double per_voxel = ldexp(F.hi - F.lo, -(int)(L - D));
        es->whole_insns += t->n;
        if (store_pruned(b, t, flags, ldexp(per_voxel, -30), &k->t, b->off[es->ncand].exact,
                         &es->pruned_insns))
            return -1;
        /* (k->t's arrays are still those tape_prune_const wrote, or t's) */
        tape_hess_mags(&k->t, box, b->hslots, k->hmag, k->hbranch);
        /* the kinks from t's evaluation above (k->t is t, or t pruned with
         * those slots and b->tmp_scratch); a flagged one, rare, again */
        if (flags)
            k->kinks = tape_hess_kinks(&k->t, box, b->kslots);
        else
            k->kinks = tape_prune_kinks(t, b->slots,
                                        b->off[es->ncand].exact[0] == UINT64_MAX ? NULL
                                                                                 : b->tmp_scratch,
                                        &k->t);
        if (store_pruned(b, t, flags, 1e-3 * per_voxel, &k->cull, b->off[es->ncand].cull,
                         &es->cull_insns))
            return -1;
        es->ncand++;
    }
    const uint32_t dim = UINT32_C(1) << D;
    es->cell_slot[((size_t)c[2] * dim + c[1]) * dim + c[0]] = es->ncells;
    es->ncells++;
    es->first[es->ncells] = es->ncand;
    return 0;
}

/* The tree's cells of depth D below node n of depth d (corner c in cells
 * of depth d), in storage order. Depth <= 20: the recursion is shallow. */
static int visit(builder *b, unsigned d, uint64_t n, const uint32_t c[3])
{
    const exact_scene *es = b->es;
    if (d == es->depth)
        return add_cell(b, c);
    const oct_children ch = oct_node_children(es->tree->groups[d], n);
    uint64_t k = ch.first;
    for (unsigned i = 0; i < 8; i++) {
        if (!(ch.mask >> i & 1u))
            continue;
        const uint32_t cc[3] = {2 * c[0] + (i & 1u), 2 * c[1] + (i >> 1 & 1u),
                                2 * c[2] + (i >> 2 & 1u)};
        if (visit(b, d + 1, k++, cc))
            return -1;
    }
    return 0;
}

int exact_scene_init(exact_scene *es, const oct_tree *tree, const tape *tapes, unsigned depth)
{
    memset(es, 0, sizeof *es);
    es->tree = tree;
    es->depth = depth > tree->levels ? tree->levels : depth;
    if (es->depth > EXACT_CELL_MAX_DEPTH)
        es->depth = EXACT_CELL_MAX_DEPTH;
    es->h = ldexp(tree->edge, -(int)tree->levels);
    /* sub-cells down to the voxels' parents */
    es->sub_max = tree->levels > es->depth + 1 ? tree->levels - 1 - es->depth : 0;
    if (es->sub_max > EXACT_SUB_MAX_REL)
        es->sub_max = EXACT_SUB_MAX_REL;
    builder b;
    memset(&b, 0, sizeof b);
    b.es = es;
    b.tapes = tapes;
    b.nsurf = tree->surface_count;
    uint32_t nmax = 1, cmax = 1;
    for (uint32_t s = 0; s < b.nsurf; s++) {
        if (tapes[s].n > nmax)
            nmax = tapes[s].n;
        if (tapes[s].nconst > cmax)
            cmax = tapes[s].nconst;
    }
    es->max_n = nmax;
    const size_t cells = (size_t)1 << (3 * es->depth);
    es->cell_slot = malloc(cells * sizeof *es->cell_slot);
    b.slots = malloc(nmax * sizeof *b.slots);
    b.kslots = malloc(nmax * sizeof *b.kslots);
    b.hslots = malloc(nmax * sizeof *b.hslots);
    b.tmp_insn = malloc(nmax * sizeof *b.tmp_insn);
    b.tmp_konst = malloc(((size_t)cmax + nmax) * sizeof *b.tmp_konst);
    b.tmp_scratch = malloc(nmax * sizeof *b.tmp_scratch);
    int rc = -1;
    if (es->cell_slot && b.slots && b.kslots && b.hslots && b.tmp_insn && b.tmp_konst && b.tmp_scratch) {
        memset(es->cell_slot, 0xff, cells * sizeof *es->cell_slot);
        const uint32_t root[3] = {0, 0, 0};
        rc = tree->node_count[0] ? visit(&b, 0, 0, root) : 0;
    }
    if (rc == 0 && !es->first) {
        es->first = calloc(1, sizeof *es->first);
        rc = es->first ? 0 : -1;
    }
    for (uint32_t k = 0; rc == 0 && k < es->ncand; k++) {
        if (b.off[k].exact[0] != UINT64_MAX) {
            es->cand[k].t.insn = es->insn_pool + b.off[k].exact[0];
            es->cand[k].t.konst = es->konst_pool + b.off[k].exact[1];
        }
        if (b.off[k].cull[0] != UINT64_MAX) {
            es->cand[k].cull.insn = es->insn_pool + b.off[k].cull[0];
            es->cand[k].cull.konst = es->konst_pool + b.off[k].cull[1];
        }
    }
    free(b.off);
    free(b.slots);
    free(b.kslots);
    free(b.hslots);
    free(b.tmp_insn);
    free(b.tmp_konst);
    free(b.tmp_scratch);
    if (rc != 0)
        exact_scene_free(es);
    return rc;
}

void exact_scene_free(exact_scene *es)
{
    free(es->cell_slot);
    free(es->first);
    free(es->cand);
    free(es->insn_pool);
    free(es->konst_pool);
    memset(es, 0, sizeof *es);
}

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
static int root_beyond(exact_worker *w, const trace_ray *r, const uint32_t c[3], unsigned shift,
                       uint64_t key, const tape *t_exact, double a, double b, double curv,
                       double *t, double grad[3])
{
    double e = region_exit(w, r, c, shift, key);
    if (!(e > b))
        return EXACT_FAST_NONE;
    int st = exact_fast_decide(t_exact, &w->scratch, &w->line, a, e, curv, &w->model[0], t, grad);
    if (st == EXACT_FAST_UNDECIDED) {
        /* local t crosses a voxel along the ray's major axis in 1 / max |d_k| */
        const double dx = fabs(r->d[0]), dy = fabs(r->d[1]), dz = fabs(r->d[2]);
        const double dm = dx > dy ? (dx > dz ? dx : dz) : (dy > dz ? dy : dz);
        const double near = b + BEYOND_NEAR / dm;
        if (!(near < e))
            return EXACT_FAST_NONE;
        e = near;
        st = exact_fast_decide(t_exact, &w->scratch, &w->line, a, e, curv, &w->model[0], t, grad);
    }
    if (st == EXACT_FAST_NONE)
        w->clear_to = e;
    if (st != EXACT_FAST_ROOT)
        return EXACT_FAST_NONE;
    w->beyond++;
    return EXACT_FAST_ROOT;
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
                const double m_new =
                    !have && cb && k1 - k0 == 1
                        ? plane_hint(es->tree, r, hit->voxel, v, a,
                                     region_exit(w, r, rc, rshift, key))
                        : NAN;
                st = exact_fast_root(t_exact, &w->scratch, l, a, b, curv, cb, m_new, &w->model[j],
                                     &have, &t, grad);
                w->have = (w->have & ~bit) | (uint32_t)have << j;
                w->model_key[j] = key;
                if (st == EXACT_FAST_NONE && have && k1 - k0 == 1)
                    st = root_beyond(w, r, rc, rshift, key, t_exact, a, b, curv, &t, grad);
            }
        }
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
