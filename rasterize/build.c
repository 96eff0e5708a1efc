/* build: one recursive subdivision of space around f = 0, parallel over
 * subtrees, streamed in Morton order into the .oct writer.
 *
 * Soundness. A cell is dropped only when an enclosure of f over it (interval
 * arithmetic, Duff 1992; the first-order Taylor form at the voxels; or the
 * Lipschitz bound of Kalra & Barr 1989) proves f != 0 everywhere in it, so no
 * voxel holding a point of the surface is lost. The surface is the set of
 * points of `bounds` where f is defined and equal to 0: a cell where f is
 * defined nowhere (the NaN interval) holds no such point and is dropped; a
 * cell where f may be undefined somewhere is judged by the enclosure of its
 * defined part (interval.h) and counted in nan_cells.
 *
 * Order. Tasks are the cells of depth S (up to 512); a worker builds a whole
 * subtree depth-first, visiting children in slot order, which emits every
 * depth's nodes in Morton order. The calling thread appends finished
 * subtrees to the writer in task order, so the file does not depend on the
 * number of threads, then adds the few nodes above depth S. */
#include "rasterize/build.h"

#include <math.h>
#include <pthread.h>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/interval.h"
#include "common/expr/tape.h"
#include "format/oct_normal.h"

#define TASK_DEPTH 3          /* 8^3 = 512 subtrees: enough to balance two cores */
#define MEAN_VALUE_LEVELS 3   /* the finest levels whose cells the mean-value form tests */
_Static_assert(MEAN_VALUE_LEVELS >= 2, "leaf-parents reuse their parent's gradient enclosure");
/* Cells of depth below this (larger than 1/256 of the cube) are too big for
 * a gradient enclosure to be tight: there the plain interval test runs too,
 * and either may drop the cell. From levels 10 up the mean-value levels are
 * all this deep, so the cost is paid on coarse grids only. */
#define MEAN_VALUE_ALONE_DEPTH 8
#define NEWTON_STEPS 4        /* guarded Newton steps from the voxel centre onto f = 0 */
#define NEWTON_TOL 0.25       /* stop once a step is below this fraction of a voxel: the
                                 linearisation error there, curvature x step^2 / 2, is far
                                 below the 1/128-voxel offset step at any level where the
                                 surface is resolved */
#define HALF_DIAGONAL 0.8660254037844386 /* sqrt(3)/2: farthest a plane can be and still cut a voxel */

/* fmin and fmax without the library call; a NaN a gives b. */
static double min2(double a, double b) { return a < b ? a : b; }
static double max2(double a, double b) { return a > b ? a : b; }

/* --- growable buffers -------------------------------------------------- */

typedef struct buf {
    uint8_t *p;
    size_t n, cap; /* in bytes */
} buf;

static int buf_push(buf *b, const void *data, size_t n)
{
    if (b->n + n > b->cap) {
        size_t cap = b->cap ? b->cap * 2 : 256;
        while (cap < b->n + n)
            cap *= 2;
        uint8_t *p = realloc(b->p, cap);
        if (!p)
            return -1;
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
    return 0;
}

static void buf_free(buf *b)
{
    free(b->p);
    memset(b, 0, sizeof *b);
}

/* --- shared, read-only context ----------------------------------------- */

typedef struct build_ctx {
    const scene *sc;
    const build_params *par;
    unsigned levels, nsurf, task_depth;
    double origin[3], edge;
    double cell_edge[OCT_MAX_LEVELS + 1]; /* edge / 2^depth, exact (a power-of-two scaling) */
    double bmax[3];            /* bounds' max corner: cells are clipped to it */
    const tape **full;         /* full tape of each surface */
    uint32_t *tape_off;        /* offset of each surface's prune buffer */
    uint32_t tape_total;       /* sum of tape lengths */
    uint32_t *konst_off;       /* offset of each surface's pruned constant pool */
    uint32_t konst_total;      /* sum of (constants + instructions) over the surfaces */
    uint32_t max_len;
} build_ctx;

/* What one task produced: the subtree below one depth-S cell. */
typedef struct task_out {
    buf masks[OCT_MAX_LEVELS];
    buf voxels, surfaces;
    int nonempty;
    int done;
} task_out;

/* --- per-thread state --------------------------------------------------- */

typedef struct worker {
    const build_ctx *c;
    interval *slots, *slots2;
    tape_idual *islots;
    tape_dual *dslots;
    tape_dual_lanes *lslots;
    uint32_t *scratch;
    tape_insn *prune;      /* [(levels + 2) * tape_total] */
    tape_const *prune_konst; /* [(levels + 2) * konst_total] */
    tape *tapes;           /* [(levels + 2) * nsurf]: index depth+1 holds the cell's tapes */
    uint8_t *act;          /* [(levels + 2) * nsurf]: surfaces that may cross the cell */
    unsigned *nact;        /* [levels + 2] */
    interval *grad;        /* [(levels + 2) * nsurf * 3]: gradient enclosure over the cell */
    double *cf;            /* [nsurf * 4]: f and its gradient at the current voxel's centre */
    uint8_t *cf_ok;        /* [nsurf]: cf holds them for that surface (voxel_surface clears) */
    double *cf8;           /* [nsurf * 8 * 4]: the same for the 8 children of a leaf-parent */
    uint8_t *grad_ok;      /* [(levels + 2) * nsurf]: that enclosure is valid */
    task_out *out;
    build_stats st;
    int failed;
} worker;

static int worker_init(worker *wk, const build_ctx *c)
{
    memset(wk, 0, sizeof *wk);
    wk->c = c;
    size_t depths = (size_t)c->levels + 2, len = c->max_len ? c->max_len : 1;
    wk->slots = malloc(len * sizeof *wk->slots);
    wk->slots2 = malloc(len * sizeof *wk->slots2);
    wk->islots = malloc(len * sizeof *wk->islots);
    wk->dslots = malloc(len * sizeof *wk->dslots);
    wk->scratch = malloc(len * sizeof *wk->scratch);
    wk->prune = malloc(depths * c->tape_total * sizeof *wk->prune);
    wk->prune_konst = malloc(depths * c->konst_total * sizeof *wk->prune_konst);
    wk->tapes = calloc(depths * c->nsurf, sizeof *wk->tapes);
    wk->act = calloc(depths * c->nsurf, 1);
    wk->nact = calloc(depths, sizeof *wk->nact);
    wk->grad = calloc(depths * c->nsurf * 3, sizeof *wk->grad);
    wk->grad_ok = calloc(depths * c->nsurf, 1);
    wk->cf = malloc((size_t)c->nsurf * 4 * sizeof *wk->cf);
    wk->cf_ok = calloc(c->nsurf, 1);
    wk->cf8 = malloc((size_t)c->nsurf * 32 * sizeof *wk->cf8);
    wk->lslots = malloc(len * sizeof *wk->lslots);
    if (!wk->cf || !wk->cf_ok || !wk->cf8 || !wk->lslots || !wk->slots || !wk->slots2 || !wk->islots || !wk->dslots || !wk->scratch || !wk->prune ||
        !wk->prune_konst ||
        !wk->tapes || !wk->act || !wk->nact || !wk->grad || !wk->grad_ok)
        return -1;
    for (unsigned s = 0; s < c->nsurf; s++) { /* index 0: the full tapes, valid everywhere */
        wk->tapes[s] = *c->full[s];
        wk->act[s] = (uint8_t)s;
    }
    wk->nact[0] = c->nsurf;
    return 0;
}

static void worker_free(worker *wk)
{
    free(wk->slots); free(wk->slots2); free(wk->islots); free(wk->dslots);
    free(wk->scratch); free(wk->prune); free(wk->prune_konst); free(wk->tapes); free(wk->act);
    free(wk->nact);
    free(wk->grad); free(wk->grad_ok);
    free(wk->cf); free(wk->cf_ok); free(wk->cf8); free(wk->lslots);
}

/* --- cell tests ----------------------------------------------------------- */

/* Axis k of the cell with integer coordinate ck at depth: its span rounded
 * outward and clipped to the bounds. 0 when it lies beyond them. */
static int cell_span(const build_ctx *c, unsigned depth, uint64_t ck, int k, interval *span)
{
    double h = c->cell_edge[depth];
    /* Coordinates are below 2^OCT_MAX_LEVELS: the signed conversion is
     * exact, like the unsigned one, and cheaper on x86. */
    span->lo = interval_next_down(c->origin[k] + (double)(int64_t)ck * h);
    span->hi = interval_next_up(c->origin[k] + (double)(int64_t)(ck + 1) * h);
    if (span->hi > c->bmax[k])
        span->hi = c->bmax[k];
    return span->lo <= span->hi;
}

/* World box of a cell, rounded outward and clipped to bounds. 0 if empty. */
static int cell_box(const build_ctx *c, unsigned depth, const uint64_t cell[3], interval box[3],
                    double centre[3])
{
    for (int k = 0; k < 3; k++) {
        if (!cell_span(c, depth, cell[k], k, &box[k]))
            return 0;
        centre[k] = 0.5 * (box[k].lo + box[k].hi);
    }
    return 1;
}

/* f over the degenerate box [c, c]: a sound enclosure of f(c). */
static int eval_at_centre(worker *wk, const tape *t, const double centre[3], interval *fc)
{
    interval cb[3];
    for (int k = 0; k < 3; k++)
        cb[k].lo = cb[k].hi = centre[k];
    unsigned fl = 0;
    *fc = tape_eval_interval(t, cb, wk->slots2, &fl);
    wk->st.interval_evals++;
    return !fl && !interval_is_nan(*fc);
}

/* The mean-value form centred on the voxel itself, f([c]) + G . (box - c),
 * with G the enclosure made for its parent: tighter than the node-centred
 * form by the width of G times the offset of the centres, for one
 * point-interval evaluation. Run on the voxels that form let through.
 *
 * fd is f(c) in double (the normal's first evaluation, made anyway). The
 * point-interval evaluation, the costly part (it dropped under 2% of the
 * voxels it ran on in the blob scenes), runs only when fd lies within
 * RETEST_MARGIN of the width of G . (box - c) from where the form could
 * exclude 0. Elsewhere the form cannot succeed, f([c]) being within rounding
 * (and the half-width of pruned constants, a thousandth of f's spread over a
 * voxel) of fd, and the voxel is kept. Skipping a test only keeps a voxel, so
 * soundness does not rest on the margin; it only makes the skip agree with
 * the full test, which it did on every scene at levels 5, 7, 8 and 9 and on
 * the blob scenes at level 10 when it was introduced (a quarter of the margin
 * did too). */
#define RETEST_MARGIN 0.03125
static int centred_form_excludes_zero(worker *wk, const tape *t, const interval G[3],
                                      const interval box[3], const double centre[3], double fd)
{
    double wlo = 0.0, whi = 0.0; /* G . (box - c) in plain double: the margin covers rounding */
    for (int k = 0; k < 3; k++) {
        double rl = box[k].lo - centre[k], rh = box[k].hi - centre[k];
        double p1 = G[k].lo * rl, p2 = G[k].lo * rh, p3 = G[k].hi * rl, p4 = G[k].hi * rh;
        wlo += min2(min2(p1, p2), min2(p3, p4));
        whi += max2(max2(p1, p2), max2(p3, p4));
    }
    double m = RETEST_MARGIN * (whi - wlo);
    if (fd + m + wlo <= 0.0 && fd - m + whi >= 0.0) /* false on NaN or inf */
        return 0;
    interval fc;
    if (!eval_at_centre(wk, t, centre, &fc))
        return 0;
    unsigned fl = 0;
    interval sum = fc;
    for (int k = 0; k < 3; k++) {
        interval r = {interval_next_down(box[k].lo - centre[k]), interval_next_up(box[k].hi - centre[k])};
        sum = interval_add(sum, interval_mul(G[k], r, &fl), &fl);
    }
    return !fl && !interval_is_nan(sum) && (sum.lo > 0.0 || sum.hi < 0.0);
}

/* Kalra-Barr: |f(p) - f(c)| <= sum_k sup|df/dk| * r_k over the box. 1 when
 * |f(c)| exceeds that bound. */
static int lipschitz_excludes_zero(worker *wk, const tape *t, const interval box[3],
                                   const double centre[3])
{
    interval g[3], fc;
    unsigned fl = 0;
    tape_eval_interval_grad(t, box, g, wk->islots, &fl);
    wk->st.gradient_evals++;
    if (fl || !eval_at_centre(wk, t, centre, &fc))
        return 0;
    double bound = 0.0;
    for (int k = 0; k < 3; k++) {
        double gk = fmax(fabs(g[k].lo), fabs(g[k].hi));
        double rk = fmax(centre[k] - box[k].lo, box[k].hi - centre[k]);
        bound += gk * rk;
    }
    if (!isfinite(bound))
        return 0;
    bound = bound * (1.0 + 0x1p-40) + 0x1p-1000; /* cover the rounding of the sum */
    return fc.lo > bound || fc.hi < -bound;
}

/* The plain test of one surface on one cell: 0 when the cell provably holds
 * no point of it. Leaves the slot enclosures in wk->slots for pruning and
 * sets *flags. */
static int surface_may_cross(worker *wk, const tape *t, unsigned s, unsigned depth,
                             const interval box[3], const double centre[3], unsigned *flags)
{
    const build_ctx *c = wk->c;
    *flags = 0;
    interval v = tape_eval_interval(t, box, wk->slots, flags);
    wk->st.interval_evals++;
    wk->st.insns_evaluated += t->n;
    wk->st.insns_full += c->full[s]->n;
    if (interval_is_nan(v)) { /* defined nowhere in the cell: no surface point */
        wk->st.nan_cells++;
        return 0;
    }
    if (*flags) {
        wk->st.nan_cells++;
        return v.lo <= 0.0 && v.hi >= 0.0;
    }
    if (v.lo > 0.0 || v.hi < 0.0)
        return 0;
    if (c->par->method == BUILD_LIPSCHITZ && lipschitz_excludes_zero(wk, t, box, centre)) {
        if (depth == c->levels)
            wk->st.taylor_drops++;
        return 0;
    }
    return 1;
}

static int cell_may_cross(worker *wk, const tape *t, unsigned s, unsigned depth,
                          const interval box[3], const double centre[3])
{
    unsigned flags;
    return surface_may_cross(wk, t, s, depth, box, centre, &flags);
}

/* Tests the cell (depth, cell) for every surface that may cross its parent
 * (lists at index pidx). Fills the cell's lists at index depth + 1 and, when
 * it will be subdivided, its pruned tapes; box and centre receive the cell's
 * box. Returns how many surfaces may cross it. */
static unsigned test_cell(worker *wk, unsigned pidx, unsigned depth, const uint64_t cell[3],
                          interval box[3], double centre[3])
{
    const build_ctx *c = wk->c;
    if (!cell_box(c, depth, cell, box, centre))
        return 0;
    unsigned idx = depth + 1, n = 0, ns = c->nsurf;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k];
        const tape *t = &wk->tapes[(size_t)pidx * ns + s];
        unsigned flags;
        if (!surface_may_cross(wk, t, s, depth, box, centre, &flags))
            continue;
        wk->act[(size_t)idx * ns + n++] = (uint8_t)s;
        tape *child = &wk->tapes[(size_t)idx * ns + s];
        if (depth < c->levels) {
            /* Inherited by the whole subtree: decided min/max keep their
             * winner, and terms that no longer vary over the cell (a far
             * blob's exp(-50)) become constants. "No longer vary": narrower
             * than a thousandth of f's spread over one voxel, estimated from
             * its enclosure over this cell. */
            interval v = wk->slots[t->root];
            double tiny = 1e-3 * ldexp(v.hi - v.lo, -(int)(c->levels - depth));
            tape_insn *out = wk->prune + (size_t)idx * c->tape_total + c->tape_off[s];
            tape_const *konst = wk->prune_konst + (size_t)idx * c->konst_total + c->konst_off[s];
            tape_prune_const(t, wk->slots, flags, isfinite(tiny) ? tiny : -1.0, out, konst,
                             wk->scratch, child);
        } else {
            *child = *t;
        }
    }
    wk->nact[idx] = n;
    return n;
}

/* --- voxels ------------------------------------------------------------- */

static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* Normal and plane offset of a voxel for a surface: guarded Newton
 * steps from the centre towards f = 0, kept inside the voxel; the normal is
 * the normalised gradient there, the offset the signed distance (in voxel
 * edges) from the centre to the linearised surface along it. A gradient that
 * is zero or not finite there and at the centre falls back to +z with offset
 * 0 (counted in normal_fallbacks). */
typedef struct newton {
    double p[3], f, g[3]; /* the iterate and f, grad f there */
    double fg[4];         /* f and grad f at the centre */
    int step;
} newton;

static void newton_start(newton *nw, const double centre[3], const double fg_centre[4])
{
    memcpy(nw->p, centre, sizeof nw->p);
    memcpy(nw->fg, fg_centre, sizeof nw->fg);
    nw->f = fg_centre[0];
    memcpy(nw->g, fg_centre + 1, sizeof nw->g);
    nw->step = 0;
}

/* With f and its gradient at the iterate known: 1 when the iterate moved
 * and they are wanted at the new one, 0 when the iteration has stopped. */
static int newton_advance(newton *nw, const interval box[3], double h)
{
    double f = nw->f, *g = nw->g, *p = nw->p;
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (nw->step == NEWTON_STEPS || !(g2 > 0.0) || !isfinite(g2) || !isfinite(f) || f == 0.0)
        return 0;
    double q[3], moved = 0.0;
    for (int k = 0; k < 3; k++) {
        q[k] = min2(max2(p[k] - f / g2 * g[k], box[k].lo), box[k].hi); /* NaN gives lo */
        moved = max2(moved, fabs(q[k] - p[k]));
    }
    if (moved < NEWTON_TOL * h)
        return 0; /* the linearisation at p places the surface well enough */
    memcpy(p, q, sizeof q);
    nw->step++;
    return 1;
}

/* The voxel's record from where the iteration stopped. */
static uint32_t newton_record(worker *wk, const newton *nw, const double centre[3], double h)
{
    double p[3], g[3], f = nw->f;
    memcpy(p, nw->p, sizeof p);
    memcpy(g, nw->g, sizeof g);
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0.0) || !isfinite(g2) || !finite3(g) || !isfinite(f)) {
        memcpy(p, centre, sizeof p);
        f = nw->fg[0];
        memcpy(g, nw->fg + 1, sizeof g);
        g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0.0) || !isfinite(g2) || !finite3(g)) {
            wk->st.normal_fallbacks++;
            static const double up[3] = {0.0, 0.0, 1.0};
            return oct_voxel_pack(up, 0.0);
        }
        if (!isfinite(f))
            f = 0.0;
    }
    double len = sqrt(g2), n[3], d = 0.0;
    for (int k = 0; k < 3; k++) {
        n[k] = g[k] / len;
        double s = p[k] - f / g2 * g[k]; /* surface point of the linearisation */
        d += n[k] * (s - centre[k]);
    }
    d /= h;
    if (!isfinite(d))
        d = 0.0;
    d = min2(max2(d, -HALF_DIAGONAL), HALF_DIAGONAL);
    return oct_voxel_pack(n, d);
}

/* f and its gradient at the voxel centre for surface s, into wk->cf.
 * Normals, plane offsets and the surface choice use the whole function, not
 * the cell's pruned tape: a term frozen into a constant kept f's value to a
 * thousandth of a voxel but lost its gradient (normals off by up to 3.5
 * degrees, offsets by 0.18 voxel on blobs_b at level 8). */
static const double *centre_fg(worker *wk, unsigned s, const double centre[3])
{
    double *fg = wk->cf + 4 * (size_t)s;
    if (!wk->cf_ok[s]) {
        fg[0] = tape_eval_grad(wk->c->full[s], centre, fg + 1, wk->dslots);
        wk->st.point_evals++;
        wk->cf_ok[s] = 1;
    }
    return fg;
}

/* The surface a voxel belongs to (lists at index idx): with several, the
 * one nearest its centre by the first-order distance |f| / |grad f|. Starts
 * its Newton iteration and forgets the centre values (wk->cf). */
static unsigned voxel_surface(worker *wk, unsigned idx, const double centre[3], newton *nw)
{
    const unsigned ns = wk->c->nsurf;
    unsigned best = wk->act[(size_t)idx * ns];
    if (wk->nact[idx] > 1) {
        double best_dist = INFINITY;
        for (unsigned k = 0; k < wk->nact[idx]; k++) {
            unsigned s = wk->act[(size_t)idx * ns + k];
            const double *fg = centre_fg(wk, s, centre);
            const double *g = fg + 1;
            double dist = fabs(fg[0]) / sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            if (isnan(dist))
                dist = INFINITY;
            if (k == 0 || dist < best_dist) {
                best_dist = dist;
                best = s;
            }
        }
    }
    newton_start(nw, centre, centre_fg(wk, best, centre));
    for (unsigned k = 0; k < wk->nact[idx]; k++)
        wk->cf_ok[wk->act[(size_t)idx * ns + k]] = 0;
    return best;
}

static int push_voxel(worker *wk, uint32_t rec, unsigned surface)
{
    uint8_t surf = (uint8_t)surface;
    if (buf_push(&wk->out->voxels, &rec, sizeof rec) ||
        (wk->c->nsurf > 1 && buf_push(&wk->out->surfaces, &surf, 1))) {
        wk->failed = 1;
        return 0;
    }
    wk->st.voxels++;
    return 1;
}

/* --shell-only: the voxel's surface (lists at index idx) without a record:
 * no normal, no Newton steps; the centre values are forgotten as in
 * voxel_surface. */
static unsigned shell_surface(worker *wk, unsigned idx, const double centre[3])
{
    newton nw;
    if (wk->nact[idx] > 1)
        return voxel_surface(wk, idx, centre, &nw);
    unsigned s = wk->act[(size_t)idx * wk->c->nsurf];
    wk->cf_ok[s] = 0;
    return s;
}

/* Appends the voxel's record (lists at index levels + 1). */
static int emit_voxel(worker *wk, const interval box[3], const double centre[3])
{
    const build_ctx *c = wk->c;
    unsigned idx = c->levels + 1;
    if (c->par->shell_only) /* the writer stores no record */
        return push_voxel(wk, 0, shell_surface(wk, idx, centre));
    newton nw;
    unsigned best = voxel_surface(wk, idx, centre, &nw);
    const tape *t = c->full[best];
    double h = c->cell_edge[c->levels];
    while (newton_advance(&nw, box, h)) {
        nw.f = tape_eval_grad(t, nw.p, nw.g, wk->dslots);
        wk->st.point_evals++;
    }
    return push_voxel(wk, newton_record(wk, &nw, centre, h), best);
}

static uint8_t visit_node(worker *wk, unsigned depth, const uint64_t cell[3]);

/* The mean-value enclosures of a node's eight children. With c the node's
 * centre, fc an enclosure of f(c) and G one of the gradient over the node,
 * every point p of child i satisfies f(p) in fc + sum_k G_k (p_k - c_k), and
 * p_k - c_k lies in the lower or upper half-offset of axis k according to
 * bit k of i. The six products are formed once, so a child costs three
 * interval additions and no tape evaluation. The form's excess width shrinks
 * with the square of the cell size, so on the finest levels it is tighter
 * than the plain interval as well as cheaper. Returns 0 when G or f(c) may be
 * undefined (then the caller tests the children one by one). */
static int child_enclosures(worker *wk, const tape *t, const interval pbox[3], const double pc[3],
                            unsigned depth, const uint64_t cell[3], interval G[3], int reuse_G,
                            interval out[8])
{
    const build_ctx *c = wk->c;
    interval fc, half[3][2];
    unsigned fl = 0;
    if (!reuse_G) {
        tape_eval_interval_grad(t, pbox, G, wk->islots, &fl);
        wk->st.gradient_evals++;
    }
    if (fl || !eval_at_centre(wk, t, pc, &fc))
        return 0;
    for (int k = 0; k < 3; k++) {
        /* The children's shared face, rounded as cell_box rounds it. */
        double m = c->origin[k] + (double)(2 * cell[k] + 1) * c->cell_edge[depth + 1];
        interval lo = {interval_next_down(pbox[k].lo - pc[k]), interval_next_up(interval_next_up(m) - pc[k])};
        interval hi = {interval_next_down(interval_next_down(m) - pc[k]), interval_next_up(pbox[k].hi - pc[k])};
        half[k][0] = interval_mul(G[k], lo, &fl);
        half[k][1] = interval_mul(G[k], hi, &fl);
    }
    /* fc + x-half, + y-half, + z-half, summed in that order for every
     * child; children that share the first terms share their partial sums
     * (2 + 4 + 8 additions instead of 3 x 8, the same values). */
    interval s1[2], s2[4];
    for (unsigned i = 0; i < 2; i++)
        s1[i] = interval_add(fc, half[0][i], &fl);
    for (unsigned i = 0; i < 4; i++)
        s2[i] = interval_add(s1[i & 1], half[1][i >> 1], &fl);
    for (unsigned i = 0; i < 8; i++)
        out[i] = interval_add(s2[i & 3], half[2][i >> 2], &fl);
    return !fl;
}

/* The boxes of a node's children, made lazily: a child's box is its lower
 * or upper half on each axis, each half a cell_span. */
typedef struct child_boxes {
    interval half[3][2];
    double mid[3][2];
    uint8_t half_ok[3][2]; /* that half lies inside the bounds */
    int8_t have[8];        /* child's box made (1), outside the bounds (0), not yet (-1) */
    interval box[8][3];
    double centre[8][3];
} child_boxes;

/* The halves' outer ends are the node's own (pbox): cell_span rounds the
 * same value there, 2c * h/2 being c * h exactly. Only the middle face is
 * rounded here, both ways, as cell_span rounds it. */
static void child_boxes_init(const build_ctx *c, unsigned depth, const uint64_t cell[3],
                             const interval pbox[3], child_boxes *cb)
{
    double h = c->cell_edge[depth + 1];
    for (int k = 0; k < 3; k++) {
        double m = c->origin[k] + (double)(int64_t)(2 * cell[k] + 1) * h;
        interval *lo = &cb->half[k][0], *hi = &cb->half[k][1];
        lo->lo = pbox[k].lo;
        lo->hi = min2(interval_next_up(m), c->bmax[k]);
        hi->lo = interval_next_down(m);
        hi->hi = pbox[k].hi;
        for (unsigned b = 0; b < 2; b++) {
            interval *span = &cb->half[k][b];
            cb->half_ok[k][b] = span->lo <= span->hi;
            cb->mid[k][b] = 0.5 * (span->lo + span->hi);
        }
    }
    memset(cb->have, -1, sizeof cb->have);
}

/* 1 when child i lies (in part) inside the bounds; then its box is made. */
static int child_box(child_boxes *cb, unsigned i)
{
    if (cb->have[i] < 0) {
        unsigned b[3] = {i & 1, (i >> 1) & 1, i >> 2};
        cb->have[i] = 1;
        for (int k = 0; k < 3; k++) {
            cb->have[i] &= cb->half_ok[k][b[k]];
            cb->box[i][k] = cb->half[k][b[k]];
            cb->centre[i][k] = cb->mid[k][b[k]];
        }
    }
    return cb->have[i];
}

/* The records of a leaf-parent's np voxels (children child[j], surfaces
 * surf[j], iterations started in nw[j]), appended in child order: the
 * Newton steps of all of them that still move are evaluated together, one
 * pass over the tape per round (tape_eval_grad_lanes). */
static void emit_voxels(worker *wk, const child_boxes *cb, const uint8_t *child,
                        const uint8_t *surf, newton *nw, unsigned np)
{
    const build_ctx *c = wk->c;
    double h = c->cell_edge[c->levels];
    uint8_t live[8];
    if (c->par->shell_only) { /* --shell-only: the writer stores no record */
        for (unsigned j = 0; j < np && !wk->failed; j++)
            push_voxel(wk, 0, surf[j]);
        return;
    }
    for (unsigned j = 0; j < np; j++)
        live[j] = (uint8_t)newton_advance(&nw[j], cb->box[child[j]], h);
    for (;;) {
        unsigned first = 0;
        while (first < np && !live[first])
            first++;
        if (first == np)
            break;
        unsigned s = surf[first], n = 0, lane[8];
        double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES], f[TAPE_LANES], g[3][TAPE_LANES];
        for (unsigned j = first; j < np; j++)
            if (live[j] && surf[j] == s) {
                x[n] = nw[j].p[0];
                y[n] = nw[j].p[1];
                z[n] = nw[j].p[2];
                lane[n++] = j;
            }
        tape_eval_grad_lanes(c->full[s], n, x, y, z, f, g, wk->lslots);
        wk->st.point_evals += n;
        for (unsigned l = 0; l < n; l++) {
            newton *w = &nw[lane[l]];
            w->f = f[l];
            w->g[0] = g[0][l];
            w->g[1] = g[1][l];
            w->g[2] = g[2][l];
            live[lane[l]] = (uint8_t)newton_advance(w, cb->box[child[lane[l]]], h);
        }
    }
    for (unsigned j = 0; j < np && !wk->failed; j++)
        push_voxel(wk, newton_record(wk, &nw[j], cb->centre[child[j]], h), surf[j]);
}

/* For a leaf-parent: f and its gradient at the centres of the children that
 * the mean-value form leaves to the centred re-test, surface by surface, one
 * pass over the tape for all of them (tape_eval_grad_lanes), into wk->cf8. */
static void leaf_centres(worker *wk, unsigned depth, const uint8_t *ok, interval T[][8],
                         child_boxes *cb)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        if (!ok[k])
            continue;
        unsigned s = wk->act[(size_t)pidx * ns + k], n = 0, lane[8];
        double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES], f[TAPE_LANES], g[3][TAPE_LANES];
        for (unsigned i = 0; i < 8; i++) {
            if (T[k][i].lo > 0.0 || T[k][i].hi < 0.0 || !child_box(cb, i))
                continue;
            x[n] = cb->centre[i][0];
            y[n] = cb->centre[i][1];
            z[n] = cb->centre[i][2];
            lane[n++] = i;
        }
        if (!n)
            continue;
        tape_eval_grad_lanes(c->full[s], n, x, y, z, f, g, wk->lslots);
        wk->st.point_evals += n;
        for (unsigned l = 0; l < n; l++) {
            double *fg = wk->cf8 + ((size_t)s * 8 + lane[l]) * 4;
            fg[0] = f[l];
            fg[1] = g[0][l];
            fg[2] = g[1][l];
            fg[3] = g[2][l];
        }
    }
}

/* The finest levels: children are tested with child_enclosures, inheriting
 * the node's tapes (pruning no longer pays this deep); voxels are emitted,
 * deeper nodes recursed into. Where the mean-value form is not available for
 * a surface (f or its gradient may be undefined), the plain test is used. */
static uint8_t visit_mean_value(worker *wk, unsigned depth, const uint64_t cell[3])
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1, cidx = depth + 2;
    interval pbox[3], T[OCT_MAX_SURFACES][8];
    double pc[3];
    uint8_t ok[OCT_MAX_SURFACES], mask = 0;
    cell_box(c, depth, cell, pbox, pc);
    /* A leaf-parent reuses its parent's gradient enclosure: the parent's box
     * holds its own, one evaluation fewer for a slightly wider form. */
    int reuse = depth + 1 == c->levels; /* its parent ran here too: MEAN_VALUE_LEVELS >= 2 */
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k];
        interval *G = &wk->grad[((size_t)pidx * ns + s) * 3];
        if (reuse && wk->grad_ok[(size_t)depth * ns + s])
            memcpy(G, &wk->grad[((size_t)depth * ns + s) * 3], 3 * sizeof *G);
        ok[k] = (uint8_t)child_enclosures(wk, &wk->tapes[(size_t)pidx * ns + s], pbox, pc, depth,
                                          cell, G, reuse && wk->grad_ok[(size_t)depth * ns + s],
                                          T[k]);
        wk->grad_ok[(size_t)pidx * ns + s] = ok[k];
    }
    child_boxes cb; /* most children fall to T alone: boxes are made lazily */
    child_boxes_init(c, depth, cell, pbox, &cb);
    int retest = depth + 1 == c->levels && depth + 1 >= MEAN_VALUE_ALONE_DEPTH;
    newton nw[8];
    uint8_t child[8], surf[8];
    unsigned np = 0;
    if (retest)
        leaf_centres(wk, depth, ok, T, &cb);
    for (unsigned i = 0; i < 8 && !wk->failed; i++) {
        const interval *box = cb.box[i];
        const double *centre = cb.centre[i];
        unsigned n = 0;
        for (unsigned k = 0; k < wk->nact[pidx]; k++) {
            unsigned s = wk->act[(size_t)pidx * ns + k];
            const tape *t = &wk->tapes[(size_t)pidx * ns + s];
            if (ok[k] && (T[k][i].lo > 0.0 || T[k][i].hi < 0.0)) {
                wk->st.taylor_drops++;
                continue;
            }
            if (!child_box(&cb, i))
                break; /* outside the bounds */
            if (retest && ok[k]) {
                memcpy(wk->cf + 4 * (size_t)s, wk->cf8 + ((size_t)s * 8 + i) * 4, 4 * sizeof *wk->cf);
                wk->cf_ok[s] = 1;
            }
            if (!ok[k] || depth + 1 < MEAN_VALUE_ALONE_DEPTH
                    ? !cell_may_cross(wk, t, s, depth + 1, box, centre)
                    : depth + 1 == c->levels &&
                          centred_form_excludes_zero(wk, t, &wk->grad[((size_t)pidx * ns + s) * 3],
                                                     box, centre, centre_fg(wk, s, centre)[0])) {
                wk->st.taylor_drops += ok[k];
                wk->cf_ok[s] = 0;
                continue;
            }
            wk->act[(size_t)cidx * ns + n++] = (uint8_t)s;
            wk->tapes[(size_t)cidx * ns + s] = *t;
        }
        wk->nact[cidx] = n;
        if (!n)
            continue;
        if (retest) { /* records made below, all together */
            child[np] = (uint8_t)i;
            surf[np] = (uint8_t)(c->par->shell_only ? shell_surface(wk, cidx, centre) /* --shell-only */
                                                    : voxel_surface(wk, cidx, centre, &nw[np]));
            np++;
            mask |= (uint8_t)(1u << i);
        } else if (depth + 1 == c->levels) {
            if (emit_voxel(wk, box, centre))
                mask |= (uint8_t)(1u << i);
        } else { /* the child's coordinates, for the few children that go on */
            uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1), 2 * cell[2] + (i >> 2)};
            if (visit_node(wk, depth + 1, cc))
                mask |= (uint8_t)(1u << i);
        }
    }
    if (np)
        emit_voxels(wk, &cb, child, surf, nw, np);
    return wk->failed ? 0 : mask;
}

/* Builds the subtree of a cell already tested non-empty; returns its child
 * mask (0 when nothing below it survived). */
static uint8_t visit_node(worker *wk, unsigned depth, const uint64_t cell[3])
{
    const build_ctx *c = wk->c;
    uint8_t mask = 0;
    if (depth + MEAN_VALUE_LEVELS >= c->levels && c->par->method == BUILD_INTERVAL) {
        mask = visit_mean_value(wk, depth, cell);
    } else {
        for (unsigned i = 0; i < 8 && !wk->failed; i++) {
            uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1),
                              2 * cell[2] + (i >> 2)};
            interval box[3];
            double centre[3];
            if (!test_cell(wk, depth + 1, depth + 1, cc, box, centre))
                continue;
            if (depth + 1 == c->levels ? emit_voxel(wk, box, centre) : visit_node(wk, depth + 1, cc))
                mask |= (uint8_t)(1u << i);
        }
    }
    if (mask) {
        if (buf_push(&wk->out->masks[depth], &mask, 1)) {
            wk->failed = 1;
            return 0;
        }
        wk->st.nodes++;
    }
    return wk->failed ? 0 : mask;
}

static void morton_decode(uint64_t m, unsigned depth, uint64_t cell[3])
{
    cell[0] = cell[1] = cell[2] = 0;
    for (unsigned b = 0; b < depth; b++) {
        cell[0] |= ((m >> (3 * b)) & 1) << b;
        cell[1] |= ((m >> (3 * b + 1)) & 1) << b;
        cell[2] |= ((m >> (3 * b + 2)) & 1) << b;
    }
}

static void run_task(worker *wk, uint64_t task, task_out *out)
{
    const build_ctx *c = wk->c;
    uint64_t cell[3];
    morton_decode(task, c->task_depth, cell);
    wk->out = out;
    interval box[3];
    double centre[3];
    if (test_cell(wk, 0, c->task_depth, cell, box, centre))
        out->nonempty = visit_node(wk, c->task_depth, cell) != 0;
}

/* --- threads ----------------------------------------------------------------- */

typedef struct pool {
    const build_ctx *c;
    task_out *tasks;
    uint64_t ntasks;
    atomic_uint_fast64_t next;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    build_stats st;
    int failed;
} pool;

static void stats_add(build_stats *a, const build_stats *b)
{
    a->voxels += b->voxels;
    a->nodes += b->nodes;
    a->interval_evals += b->interval_evals;
    a->gradient_evals += b->gradient_evals;
    a->point_evals += b->point_evals;
    a->insns_evaluated += b->insns_evaluated;
    a->insns_full += b->insns_full;
    a->taylor_drops += b->taylor_drops;
    a->nan_cells += b->nan_cells;
    a->normal_fallbacks += b->normal_fallbacks;
}

/* Subnormal operands and results cost a microcode assist each on x86, and
 * blobs such as exp(-196 (x - a)^4) underflow into them all over space. The
 * workers flush them to zero (FTZ and DAZ). That stays sound: every interval
 * bound is stepped outward after each operation, and a step from 0 reaches
 * +-DBL_MIN, beyond any flushed value (common/expr/interval.h). */
static void flush_subnormals(void)
{
#if defined(__SSE2__)
    _mm_setcsr(_mm_getcsr() | 0x8040u); /* FTZ (bit 15) | DAZ (bit 6) */
#endif
}

static void *worker_main(void *arg)
{
    pool *pl = arg;
    flush_subnormals();
    worker wk;
    int failed = worker_init(&wk, pl->c) != 0;
    for (;;) {
        uint64_t t = atomic_fetch_add(&pl->next, 1);
        if (t >= pl->ntasks)
            break;
        if (!failed) {
            run_task(&wk, t, &pl->tasks[t]);
            failed = wk.failed;
        }
        pthread_mutex_lock(&pl->lock);
        pl->tasks[t].done = 1;
        pl->failed |= failed;
        pthread_cond_broadcast(&pl->cond);
        pthread_mutex_unlock(&pl->lock);
    }
    pthread_mutex_lock(&pl->lock);
    stats_add(&pl->st, &wk.st);
    pl->failed |= failed;
    pthread_mutex_unlock(&pl->lock);
    worker_free(&wk);
    return NULL;
}

/* Nodes above the task depth, from which tasks came out non-empty. */
static oct_err add_upper_levels(const build_ctx *c, const uint8_t *nonempty, oct_writer *w,
                                build_stats *st)
{
    uint64_t n = (uint64_t)1 << (3 * c->task_depth);
    uint8_t *cur = malloc(n), *up = malloc(n / 8 + 1);
    if (!cur || !up) {
        free(cur); free(up);
        return OCT_ENOMEM;
    }
    memcpy(cur, nonempty, n);
    oct_err err = OCT_OK;
    for (unsigned d = c->task_depth; d-- > 0 && err == OCT_OK;) {
        n /= 8;
        for (uint64_t u = 0; u < n && err == OCT_OK; u++) {
            uint8_t mask = 0;
            for (unsigned i = 0; i < 8; i++)
                mask |= (uint8_t)((cur[8 * u + i] ? 1u : 0u) << i);
            up[u] = mask != 0;
            if (mask) {
                err = oct_writer_add_masks(w, d, &mask, 1);
                st->nodes++;
            }
        }
        memcpy(cur, up, n);
    }
    free(cur);
    free(up);
    return err;
}

void build_cube(const scene *sc, double origin[3], double *edge)
{
    double e = 0.0;
    for (int k = 0; k < 3; k++) {
        origin[k] = sc->lo[k];
        e = fmax(e, sc->hi[k] - sc->lo[k]);
    }
    *edge = e;
}

void build_writer_params(const scene *sc, unsigned levels, float palette[3 * OCT_MAX_SURFACES],
                         oct_writer_params *wp)
{
    memset(wp, 0, sizeof *wp);
    wp->levels = levels;
    build_cube(sc, wp->origin, &wp->edge);
    wp->surface_count = (uint32_t)sc->nsurfaces;
    for (size_t s = 0; s < sc->nsurfaces && s < OCT_MAX_SURFACES; s++)
        for (int k = 0; k < 3; k++)
            palette[3 * s + k] = (float)sc->surfaces[s].color[k];
    wp->palette = palette;
}

oct_err build_octree(const scene *sc, const build_params *p, oct_writer *w, build_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    build_ctx c;
    memset(&c, 0, sizeof c);
    c.sc = sc;
    c.par = p;
    c.levels = p->levels;
    c.nsurf = (unsigned)sc->nsurfaces;
    c.task_depth = p->levels - 1 < TASK_DEPTH ? p->levels - 1 : TASK_DEPTH;
    build_cube(sc, c.origin, &c.edge);
    for (int k = 0; k < 3; k++)
        c.bmax[k] = sc->hi[k];
    for (unsigned d = 0; d <= c.levels; d++)
        c.cell_edge[d] = ldexp(c.edge, -(int)d);

    oct_err err = OCT_ENOMEM;
    pool pl;
    memset(&pl, 0, sizeof pl);
    uint8_t *nonempty = NULL;
    pthread_t *th = NULL;
    unsigned started = 0;
    c.full = calloc(c.nsurf, sizeof *c.full);
    c.tape_off = calloc(c.nsurf, sizeof *c.tape_off);
    c.konst_off = calloc(c.nsurf, sizeof *c.konst_off);
    if (!c.full || !c.tape_off || !c.konst_off)
        goto done;
    for (unsigned s = 0; s < c.nsurf; s++) {
        c.full[s] = &sc->surfaces[s].tape;
        c.tape_off[s] = c.tape_total;
        c.tape_total += c.full[s]->n;
        if (c.full[s]->n > c.max_len)
            c.max_len = c.full[s]->n;
        c.konst_off[s] = c.konst_total;
        c.konst_total += c.full[s]->nconst + c.full[s]->n;
    }

    pl.c = &c;
    pl.ntasks = (uint64_t)1 << (3 * c.task_depth);
    pl.tasks = calloc(pl.ntasks, sizeof *pl.tasks);
    nonempty = calloc(pl.ntasks, 1);
    th = calloc(p->threads, sizeof *th);
    if (!pl.tasks || !nonempty || !th)
        goto done;
    atomic_init(&pl.next, 0);
    pthread_mutex_init(&pl.lock, NULL);
    pthread_cond_init(&pl.cond, NULL);
    for (; started < p->threads; started++)
        if (pthread_create(&th[started], NULL, worker_main, &pl) != 0)
            break;
    if (started == 0) {
        worker_main(&pl); /* no thread could start: do the work here */
    }

    /* Append finished subtrees in task order while the workers go on. */
    err = OCT_OK;
    for (uint64_t t = 0; t < pl.ntasks; t++) {
        pthread_mutex_lock(&pl.lock);
        while (!pl.tasks[t].done)
            pthread_cond_wait(&pl.cond, &pl.lock);
        int failed = pl.failed;
        pthread_mutex_unlock(&pl.lock);
        task_out *o = &pl.tasks[t];
        if (failed && err == OCT_OK)
            err = OCT_ENOMEM;
        if (err == OCT_OK && o->nonempty) {
            nonempty[t] = 1;
            for (unsigned d = c.task_depth; d < c.levels && err == OCT_OK; d++)
                err = oct_writer_add_masks(w, d, o->masks[d].p, o->masks[d].n);
            if (err == OCT_OK)
                err = oct_writer_add_voxels(w, (const uint32_t *)(const void *)o->voxels.p,
                                            c.nsurf > 1 ? o->surfaces.p : NULL,
                                            o->voxels.n / sizeof(uint32_t));
        }
        for (unsigned d = 0; d < OCT_MAX_LEVELS; d++)
            buf_free(&o->masks[d]);
        buf_free(&o->voxels);
        buf_free(&o->surfaces);
        if (p->progress)
            p->progress(p->progress_ctx, (double)(t + 1) / (double)pl.ntasks);
    }
    for (unsigned i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    if (pl.failed && err == OCT_OK)
        err = OCT_ENOMEM;
    stats_add(stats, &pl.st);
    if (err == OCT_OK)
        err = add_upper_levels(&c, nonempty, w, stats);
    pthread_mutex_destroy(&pl.lock);
    pthread_cond_destroy(&pl.cond);
done:
    free(th);
    free(nonempty);
    free(pl.tasks);
    free(c.full);
    free(c.tape_off);
    free(c.konst_off);
    return err;
}
