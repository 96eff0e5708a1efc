/* cell_test: whether a surface may cross a cell. The plain interval test
 * (Duff 1992), the mean-value (first-order Taylor) form over a node's
 * children and at the voxels, and the Lipschitz bound (Kalra & Barr 1989).
 *
 * Soundness. A cell is dropped only when an enclosure of f over it proves
 * f != 0 everywhere in it, so no voxel holding a point of the surface is
 * lost. The surface is the set of points of `bounds` where f is defined and
 * equal to 0: a cell where f is defined nowhere (the NaN interval) holds no
 * such point and is dropped; a cell where f may be undefined somewhere is
 * judged by the enclosure of its defined part (interval.h) and counted in
 * nan_cells. */
#include <math.h>

#include "common/expr/interval_lanes.h"
#include "common/expr/tape_hess.h"
#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"

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
 * point-interval evaluation, the costly part, runs only when fd lies within
 * RETEST_MARGIN of the width of G . (box - c) from where the form could
 * exclude 0. Elsewhere the form cannot succeed, f([c]) being within rounding
 * (and the half-width of pruned constants, a thousandth of f's spread over a
 * voxel) of fd, and the voxel is kept. Skipping a test only keeps a voxel, so
 * soundness does not rest on the margin; it only makes the skip agree with
 * the full test (docs/perf-log.md, rasterize). Where an a-priori bound on
 * fd's rounding stands for the evaluation (centre_err), none runs:
 * f([c]) is fd widened by it. */
#define RETEST_MARGIN 0.03125

/* The ends of g x off in plain double (the forms' terms). */
static inline void form_product(interval g, interval off, double *lo, double *hi)
{
    double p1 = g.lo * off.lo, p2 = g.lo * off.hi, p3 = g.hi * off.lo, p4 = g.hi * off.hi;
    *lo = min2(min2(p1, p2), min2(p3, p4));
    *hi = max2(max2(p1, p2), max2(p3, p4));
}

/* Where a form's end summed in plain double clears 0 by more than this,
 * terms of total magnitude mag, its outward-rounded sum lies on the same
 * side of 0 (the argument: form_decide, below). */
static inline double form_margin(double mag) { return 0x1p-44 * mag + 0x1p-1000; }

/* G . (box - c) in plain double: its ends (wlo, whi) and, with mag, the
 * magnitude of its terms; the margins below cover the rounding. */
static inline void centred_products(const interval G[3], const interval box[3],
                                    const double centre[3], double *wlo, double *whi,
                                    double *mag)
{
    double lo = 0.0, hi = 0.0, mg = 0.0;
    for (int k = 0; k < 3; k++) {
        const double rl = box[k].lo - centre[k], rh = box[k].hi - centre[k];
        double l, h;
        form_product(G[k], (interval){rl, rh}, &l, &h);
        lo += l;
        hi += h;
        if (mag)
            mg += fabs(l) + fabs(h);
    }
    *wlo = lo;
    *whi = hi;
    if (mag)
        *mag = mg;
}

/* Whether the form centred on the voxel may exclude 0 at all: 0 when fd lies
 * too far inside the width of G . (box - c) (see above). */
static inline int centred_form_may_exclude(const interval G[3], const interval box[3],
                                           const double centre[3], double fd)
{
    double wlo, whi;
    centred_products(G, box, centre, &wlo, &whi, NULL);
    double m = RETEST_MARGIN * (whi - wlo);
    return !(fd + m + wlo <= 0.0 && fd - m + whi >= 0.0); /* false on NaN or inf */
}

/* Whether the form centred on the voxel fails whatever f([cv]) the tape
 * gives, judged without evaluating it: f(cv) lies in E = fc + G . (cv - c),
 * the node's form at that point (fc an enclosure of f at the form's centre
 * c, G of the gradient over a box holding c and the voxel), and f([cv]).lo
 * <= f(cv) <= f([cv]).hi. The form's lower end is at most f([cv]).lo +
 * sum_k min(G_k x (box_k - cv_k)) <= E.hi + that sum, its upper end at
 * least E.lo + sum_k max(...). When the first bound is <= 0 and the second
 * >= 0, the form cannot exclude 0: centred_form_drops keeps the voxel
 * whatever f([cv]) is, so its value need not be made. The sums are in plain
 * double with a margin far above their rounding (and above flushed
 * subnormals); a non-finite term gives 0 (evaluate). Each axis's term
 * depends on the child's half of that axis only: the six are made once for
 * the eight children. */
uint8_t centred_form_cannot_exclude(interval fc, const interval G[3], const double c[3],
                                    const child_boxes *cb, uint8_t cand)
{
    double tu[3][2], tl[3][2], tm[3][2];
    for (int k = 0; k < 3; k++)
        for (int b = 0; b < 2; b++) {
            double cv = cb->mid[k][b], d = cv - c[k];
            double rl = cb->half[k][b].lo - cv, rh = cb->half[k][b].hi - cv;
            double e1 = G[k].lo * d, e2 = G[k].hi * d;
            double p1 = G[k].lo * rl, p2 = G[k].lo * rh, p3 = G[k].hi * rl, p4 = G[k].hi * rh;
            tu[k][b] = max2(e1, e2) + min2(min2(p1, p2), min2(p3, p4));
            tl[k][b] = min2(e1, e2) + max2(max2(p1, p2), max2(p3, p4));
            tm[k][b] = (fabs(G[k].lo) + fabs(G[k].hi)) * (fabs(d) + fabs(rl) + fabs(rh));
        }
    uint8_t m = 0;
    for (unsigned i = 0; i < 8; i++) {
        if (!((cand >> i) & 1))
            continue;
        const unsigned bit[3] = {i & 1, (i >> 1) & 1, i >> 2};
        double up = fc.hi, lo = fc.lo, mag = fabs(fc.lo) + fabs(fc.hi);
        for (int k = 0; k < 3; k++) {
            up += tu[k][bit[k]];
            lo += tl[k][bit[k]];
            mag += tm[k][bit[k]];
        }
        double margin = 0x1p-40 * mag + 0x1p-1000;
        if (up + margin <= 0.0 && lo - margin >= 0.0) /* false on NaN */
            m |= (uint8_t)(1u << i);
    }
    return m;
}

/* The form itself, from fc = f([c]) and its flags fl. */
static int centred_form_excludes(interval fc, unsigned fl, const interval G[3],
                                 const interval box[3], const double centre[3])
{
    if (fl || interval_is_nan(fc))
        return 0;
    interval sum = fc;
    for (int k = 0; k < 3; k++) {
        interval r = {interval_next_down(box[k].lo - centre[k]), interval_next_up(box[k].hi - centre[k])};
        sum = interval_add(sum, interval_mul(G[k], r, &fl), &fl);
    }
    return !fl && !interval_is_nan(sum) && (sum.lo > 0.0 || sum.hi < 0.0);
}

/* The enclosures over n boxes: the lane evaluator for two or more, the
 * scalar one (the same bits) for one, where a pass over lanes would cost
 * more than it shares. */
static void lanes_or_one(worker *wk, const tape *t, unsigned n, interval box[][3], interval out[],
                         unsigned fl[])
{
    if (n == 1)
        out[0] = tape_eval_interval(t, box[0], wk->slots2, &fl[0]);
    else
        tape_eval_interval_lanes(t, n, (const interval(*)[3])box, out, fl, wk->ilslots);
}

/* centred_form_excludes(fc, fl, ...), first from the products of G with
 * the voxel's offsets in plain double (centred_products): where the form's
 * ends clear 0, or straddle it, by more than form_margin, the
 * outward-rounded form agrees; only the rest take centred_form_excludes
 * itself. */
static int centred_form_decide(interval fc, unsigned fl, const interval G[3],
                               const interval box[3], const double centre[3])
{
    double wlo, whi, mag; /* (made again with mag: only for the few the filter lets through) */
    centred_products(G, box, centre, &wlo, &whi, &mag);
    const double lo = fc.lo + wlo, hi = fc.hi + whi;
    const double margin = form_margin(mag + fabs(fc.lo) + fabs(fc.hi));
    if (!fl && (lo > margin || hi < -margin))
        return 1;
    if (lo <= -margin && hi >= margin)
        return 0;
    return centred_form_excludes(fc, fl, G, box, centre); /* (also NaN) */
}

void centred_form_drops(worker *wk, const tape *t, const interval G[3], double ev,
                        const retest_item *it, unsigned n, uint8_t *drop)
{
    if (ev == ev) { /* f(c) within ev of fd: the form with no evaluation */
        for (unsigned j = 0; j < n; j++) {
            drop[j] = 0;
            if (!centred_form_may_exclude(G, it[j].box, it[j].centre, it[j].fd))
                continue;
            const interval fc = {interval_next_down(it[j].fd - ev),
                                 interval_next_up(it[j].fd + ev)};
            drop[j] = (uint8_t)centred_form_decide(fc, 0, G, it[j].box, it[j].centre);
        }
        return;
    }
    interval pts[TAPE_LANES][3], out[TAPE_LANES];
    unsigned fl[TAPE_LANES], lane[TAPE_LANES], m = 0;
    for (unsigned j = 0; j < n; j++) {
        drop[j] = 0;
        /* the lane written always, kept when the form may exclude 0 (that
         * outcome, as a branch, was often mispredicted) */
        for (int k = 0; k < 3; k++)
            pts[m][k].lo = pts[m][k].hi = it[j].centre[k];
        lane[m] = j;
        m += (unsigned)centred_form_may_exclude(G, it[j].box, it[j].centre, it[j].fd);
        if (m == TAPE_LANES || (m && j + 1 == n)) { /* a full pass, or the last */
            lanes_or_one(wk, t, m, pts, out, fl);
            wk->st.interval_evals += m;
            for (unsigned l = 0; l < m; l++)
                drop[lane[l]] = (uint8_t)centred_form_decide(out[l], fl[l], G, it[lane[l]].box,
                                                             it[lane[l]].centre);
            m = 0;
        }
    }
}

/* Whether t has an abs or min/max that its slots' enclosures leave
 * undecided (tape_prune_kinks), the enclosures read from the scalar interval
 * gradient evaluator's slots (sc) or from lane l of the lane evaluator's
 * (sl), through wk->slots. */
static uint8_t slots_kinked(worker *wk, const tape *t, const tape_idual *sc,
                            const tape_idual_lanes *sl, unsigned l)
{
    for (uint32_t i = 0; i < t->n; i++) {
        interval v = sc ? sc[i].v : (interval){sl[i].v.lo[l], sl[i].v.hi[l]};
        wk->slots[i] = v;
    }
    return tape_prune_kinks(t, wk->slots, NULL, t) != 0;
}

void node_forms(worker *wk, const tape *t, int kinks, unsigned n, interval box[][3],
                const double centre[][3], node_form *nf)
{
    interval pts[TAPE_LANES][3], out[TAPE_LANES];
    unsigned fl[TAPE_LANES], lane[TAPE_LANES], m = 0;
    interval v[TAPE_LANES];
    unsigned gf[TAPE_LANES];
    if (n == 1) { /* one alone: the scalar evaluator, the same bits */
        tape_eval_interval_grad(t, box[0], nf[0].G, wk->islots, &gf[0]);
        nf[0].kinked = kinks && (gf[0] || slots_kinked(wk, t, wk->islots, NULL, 0));
    } else {
        interval G[TAPE_LANES][3];
        tape_eval_interval_grad_lanes(t, n, (const interval(*)[3])box, v, G, gf, wk->iglslots);
        for (unsigned j = 0; j < n; j++) {
            memcpy(nf[j].G, G[j], sizeof G[j]);
            nf[j].kinked = kinks && (gf[j] || slots_kinked(wk, t, NULL, wk->iglslots, j));
        }
    }
    wk->st.gradient_evals += n;
    for (unsigned j = 0; j < n; j++) {
        nf[j].ok = 0;
        if (gf[j])
            continue;
        for (int k = 0; k < 3; k++)
            pts[m][k].lo = pts[m][k].hi = centre[j][k];
        lane[m++] = j;
    }
    if (!m)
        return;
    lanes_or_one(wk, t, m, pts, out, fl);
    wk->st.interval_evals += m;
    for (unsigned l = 0; l < m; l++) {
        nf[lane[l]].fc = out[l];
        nf[lane[l]].ok = !fl[l] && !interval_is_nan(out[l]);
    }
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

/* surface_may_cross's decision from the enclosure v of f over the cell and
 * its flags (BUILD_INTERVAL), with its counts. */
static int may_cross_from(worker *wk, const tape *t, unsigned s, interval v, unsigned flags)
{
    wk->st.interval_evals++;
    wk->st.insns_evaluated += t->n;
    wk->st.insns_full += wk->c->full[s]->n;
    if (interval_is_nan(v)) { /* defined nowhere in the cell: no surface point */
        wk->st.nan_cells++;
        return 0;
    }
    if (flags) {
        wk->st.nan_cells++;
        return v.lo <= 0.0 && v.hi >= 0.0;
    }
    return !(v.lo > 0.0 || v.hi < 0.0);
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
    if (!may_cross_from(wk, t, s, v, *flags))
        return 0;
    if (c->par->method == BUILD_LIPSCHITZ && !*flags && lipschitz_excludes_zero(wk, t, box, centre)) {
        if (depth == c->levels)
            wk->st.taylor_drops++;
        return 0;
    }
    return 1;
}

void plain_test_drops(worker *wk, const tape *t, unsigned s, const retest_item *it, unsigned n,
                      uint8_t *drop)
{
    interval boxes[TAPE_LANES][3], out[TAPE_LANES];
    unsigned fl[TAPE_LANES];
    for (unsigned j0 = 0; j0 < n; j0 += TAPE_LANES) {
        unsigned m = n - j0 < TAPE_LANES ? n - j0 : TAPE_LANES;
        for (unsigned l = 0; l < m; l++)
            memcpy(boxes[l], it[j0 + l].box, sizeof boxes[l]);
        lanes_or_one(wk, t, m, boxes, out, fl);
        for (unsigned l = 0; l < m; l++) /* surface_may_cross's rules, BUILD_INTERVAL */
            drop[j0 + l] = (uint8_t)!may_cross_from(wk, t, s, out[l], fl[l]);
    }
}

/* t pruned for the cell (depth < levels) from the slot enclosures over it
 * in wk->slots with their flags, into child (instructions out, constants
 * konst). Inherited by the whole subtree: decided min/max keep their
 * winner, and terms that no longer vary over the cell (a far blob's
 * exp(-50)) become constants. "No longer vary": narrower than a thousandth
 * of f's spread over one voxel, estimated from its enclosure over this
 * cell. Returns whether child has a kink. */
static uint8_t prune_for_cell(worker *wk, const tape *t, unsigned depth, unsigned flags,
                              tape_insn *out, tape_const *konst, tape *child)
{
    interval v = wk->slots[t->root];
    double tiny = 1e-3 * ldexp(v.hi - v.lo, -(int)(wk->c->levels - depth));
    tape_prune_const(t, wk->slots, flags, isfinite(tiny) ? tiny : -1.0, out, konst, wk->scratch,
                     child);
    return tape_has_kink(child);
}

/* The tape of surface s for the cell (depth) that may cross it, from its
 * parent's (lists at index pidx) and its slot enclosures in wk->slots with
 * their flags, into the cell's lists (index depth + 1). */
static void cell_tape(worker *wk, unsigned pidx, unsigned depth, unsigned s, unsigned flags)
{
    const build_ctx *c = wk->c;
    const unsigned idx = depth + 1, ns = c->nsurf;
    const tape *t = &wk->tapes[(size_t)pidx * ns + s];
    tape *child = &wk->tapes[(size_t)idx * ns + s];
    if (depth < c->levels) {
        wk->kinked[(size_t)idx * ns + s] =
            prune_for_cell(wk, t, depth, flags, wk->prune + (size_t)idx * c->tape_total + c->tape_off[s],
                           wk->prune_konst + (size_t)idx * c->konst_total + c->konst_off[s], child);
    } else {
        *child = *t;
        wk->kinked[(size_t)idx * ns + s] = wk->kinked[(size_t)pidx * ns + s];
    }
}

unsigned cell_test_surviving(worker *wk, unsigned pidx, unsigned depth, const uint64_t cell[3],
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
        cell_tape(wk, pidx, depth, s, flags);
    }
    wk->nact[idx] = n;
    return n;
}

/* (see build_internal.h) */
uint8_t children_may_cross(worker *wk, unsigned depth, uint8_t want, coarse_children *cc)
{
    const build_ctx *c = wk->c;
    const tape *t = &wk->tapes[depth + 1];
    interval box[8][3], out[8];
    unsigned fl[8], n = 0;
    uint8_t child[8]; /* a lane's */
    for (unsigned m = want; m; m &= m - 1) {
        const unsigned i = (unsigned)__builtin_ctz(m);
        child[n] = (uint8_t)i;
        n += (unsigned)cell_box(c, depth + 1, cc->cell[i], box[n], cc->centre[i]);
    }
    if (!n)
        return 0;
    tape_ilanes *sl = wk->coarse_slots + (size_t)depth * c->max_len;
    tape_eval_interval_lanes(t, n, (const interval(*)[3])box, out, fl, sl);
    uint8_t live = 0;
    for (unsigned l = 0; l < n; l++) {
        const unsigned i = child[l];
        memcpy(cc->box[i], box[l], sizeof box[l]);
        cc->flags[i] = fl[l];
        cc->slot_lane[i] = (uint8_t)l;
        live |= (uint8_t)(may_cross_from(wk, t, 0, out[l], fl[l]) << i);
    }
    return live;
}

/* Child i's slot enclosures, from its lane of children_may_cross, into
 * wk->slots. */
static void child_slots(worker *wk, unsigned depth, const coarse_children *cc, unsigned i)
{
    const tape *t = &wk->tapes[depth + 1];
    const tape_ilanes *sl = wk->coarse_slots + (size_t)depth * wk->c->max_len;
    const unsigned l = cc->slot_lane[i];
    for (uint32_t j = 0; j < t->n; j++) {
        wk->slots[j].lo = sl[j].lo[l];
        wk->slots[j].hi = sl[j].hi[l];
    }
}

/* (see build_internal.h) */
void child_take(worker *wk, unsigned depth, const coarse_children *cc, unsigned i)
{
    child_slots(wk, depth, cc, i);
    wk->act[depth + 2] = 0;
    wk->nact[depth + 2] = 1;
    cell_tape(wk, depth + 1, depth + 1, 0, cc->flags[i]);
}

/* (see build_internal.h) */
void child_prune(worker *wk, unsigned depth, coarse_children *cc, unsigned i)
{
    const build_ctx *c = wk->c;
    child_slots(wk, depth, cc, i);
    cc->kinked[i] = prune_for_cell(wk, &wk->tapes[depth + 1], depth + 1, cc->flags[i],
                                   wk->own_insn + (size_t)i * c->tape_total,
                                   wk->own_konst + (size_t)i * c->konst_total, &cc->tape[i]);
}

void record_tapes(worker *wk, unsigned idx, const interval box[3])
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf;
    for (unsigned k = 0; k < wk->nact[idx]; k++) {
        unsigned s = wk->act[(size_t)idx * ns + k], flags;
        if (!wk->kinked[s]) /* index 0: the full tape has no min, max or abs */
            continue;
        tape_eval_interval(c->full[s], box, wk->slots, &flags);
        wk->st.interval_evals++;
        tape_prune(c->full[s], wk->slots, flags, wk->rec_insn + c->tape_off[s], wk->scratch,
                   &wk->rec[s]);
    }
}

/* The enclosures fc + x-half + y-half + z-half of the eight children (half
 * the products of G with the offsets off), summed in that order; children
 * that share the first terms share their partial sums (2 + 4 + 8 additions
 * instead of 3 x 8, the same values). First with the operations' fast
 * paths, without branches (interval_lanes.h); where one does not apply, all
 * again with the operations themselves. Bit i of *fx set when child i's
 * enclosure excludes 0; 0 when a flag was raised. */
static int form_drops_exact(const interval *fc, const interval G[3], interval off[3][2],
                            uint8_t *fx)
{
    interval half[3][2], s1[2], s2[4], out[8];
    unsigned fl = 0;
    uint64_t good = 1;
    for (int k = 0; k < 3; k++)
        for (int b = 0; b < 2; b++)
            half[k][b] = il_mul(G[k], off[k][b], &good);
    for (unsigned i = 0; i < 2; i++)
        s1[i] = il_add(*fc, half[0][i], &good);
    for (unsigned i = 0; i < 4; i++)
        s2[i] = il_add(s1[i & 1], half[1][i >> 1], &good);
    for (unsigned i = 0; i < 8; i++)
        out[i] = il_add(s2[i & 3], half[2][i >> 2], &good);
    if (!good) {
        for (int k = 0; k < 3; k++)
            for (int b = 0; b < 2; b++)
                half[k][b] = interval_mul(G[k], off[k][b], &fl);
        for (unsigned i = 0; i < 2; i++)
            s1[i] = interval_add(*fc, half[0][i], &fl);
        for (unsigned i = 0; i < 4; i++)
            s2[i] = interval_add(s1[i & 1], half[1][i >> 1], &fl);
        for (unsigned i = 0; i < 8; i++)
            out[i] = interval_add(s2[i & 3], half[2][i >> 2], &fl);
    }
    *fx = 0;
    for (unsigned i = 0; i < 8; i++)
        *fx |= (uint8_t)((out[i].lo > 0.0 || out[i].hi < 0.0) << i);
    return !fl; /* the fast paths raise no flag */
}

/* form_drops_exact's decisions without its enclosures: the same sums in
 * plain double. Rounded outward, those enclosures lie within a few ulps of
 * the magnitude of their terms from the exact sums of the exact products,
 * as these do; so where a sum's end clears 0 by far more than that (the
 * margin, and beyond flushed subnormals) the two agree on which side of 0
 * it lies. 0 (undecided) where an end is nearer 0, or a term is not
 * finite: then the caller runs form_drops_exact. Here the decisions from
 * the products' ends (plo, phi) and the magnitude of all the terms (mag). */
static int form_decide(interval fc, double plo[3][2], double phi[3][2], double mag, uint8_t *fx)
{
    if (!(mag < INFINITY)) /* also NaN */
        return 0;
    const double margin = form_margin(mag);
    /* the comparisons combined without branches: which way each child goes
     * is data, and mispredicted branches on it were most of this loop's
     * time (docs/perf-log.md) */
    unsigned m = 0, undecided = 0;
    for (unsigned i = 0; i < 8; i++) {
        const unsigned bx = i & 1, by = (i >> 1) & 1, bz = i >> 2;
        double lo = fc.lo + plo[0][bx] + plo[1][by] + plo[2][bz];
        double hi = fc.hi + phi[0][bx] + phi[1][by] + phi[2][bz];
        const unsigned drop = (unsigned)(lo > margin) | (unsigned)(hi < -margin);
        const unsigned keep = (unsigned)(lo <= -margin) & (unsigned)(hi >= margin);
        m |= drop << i;
        undecided |= ~(drop | keep) & 1u;
    }
    if (undecided)
        return 0;
    *fx = (uint8_t)m;
    return 1;
}

static int form_drops_quick(const interval *fc, const interval G[3], interval off[3][2],
                            uint8_t *fx)
{
    double plo[3][2], phi[3][2], mag = fabs(fc->lo) + fabs(fc->hi);
    for (int k = 0; k < 3; k++)
        for (int b = 0; b < 2; b++) {
            form_product(G[k], off[k][b], &plo[k][b], &phi[k][b]);
            mag += fabs(plo[k][b]) + fabs(phi[k][b]);
        }
    return form_decide(*fc, plo, phi, mag, fx);
}

/* The mean-value enclosures of a node's eight children. With c the form's
 * centre, fc an enclosure of f(c) and G one of the gradient over a box that
 * holds c and the node, every point p of child i satisfies f(p) in
 * fc + sum_k G_k (p_k - c_k), and p_k - c_k lies in the lower or upper
 * half-offset of axis k according to bit k of i. A leaf-parent takes its
 * parent's form (reuse): offsets up to twice as long make it wider by about
 * the width of G times a voxel, a percent or two of it, for no evaluation.
 * The six products are formed once, so a child costs three additions and no
 * tape evaluation. The form's excess width shrinks with the square of the
 * cell size, so on the finest levels it is tighter than the plain interval
 * as well as cheaper. Only whether each enclosure excludes 0 is kept (bit i
 * of *fx), decided in plain double where that is certain. Returns 0 when G
 * or f(c) may be undefined (then the caller tests the children one by
 * one). */
int child_enclosures(worker *wk, const tape *t, const interval pbox[3], unsigned depth,
                     const uint64_t cell[3], const double fcc[3], interval *fc, interval G[3],
                     int reuse, uint8_t *fx)
{
    const build_ctx *c = wk->c;
    interval off[3][2];
    if (!reuse) {
        unsigned fl = 0;
        tape_eval_interval_grad(t, pbox, G, wk->islots, &fl);
        wk->st.gradient_evals++;
        if (fl || !eval_at_centre(wk, t, fcc, fc))
            return 0;
    }
    const double *pc = fcc;
    for (int k = 0; k < 3; k++) {
        /* The children's shared face, rounded as cell_box rounds it. */
        double m = c->origin[k] + (double)(2 * cell[k] + 1) * c->cell_edge[depth + 1];
        interval lo = {interval_next_down(pbox[k].lo - pc[k]), interval_next_up(interval_next_up(m) - pc[k])};
        interval hi = {interval_next_down(interval_next_down(m) - pc[k]), interval_next_up(pbox[k].hi - pc[k])};
        off[k][0] = lo;
        off[k][1] = hi;
    }
    return form_drops_quick(fc, G, off, fx) || form_drops_exact(fc, G, off, fx);
}
