/* voxel_normal: a voxel's record. The surface it belongs to, guarded Newton
 * steps from its centre onto f = 0 (at a leaf-parent, where its siblings'
 * gradients give second derivatives, one step on the second-order model
 * instead; in a batch, a leaf-parent lacking some takes them from its
 * nearest sibling that has them all), and the normal and plane offset
 * packed from where they stop (format/oct_normal.h). */
#include <math.h>

#include "format/oct_normal.h"
#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"

#define NEWTON_STEPS 4        /* guarded Newton steps from the voxel centre onto f = 0 */
#define NEWTON_TOL 0.25       /* stop once a step is below this fraction of a voxel: the
                                 linearisation error there, curvature x step^2 / 2, is far
                                 below the 1/128-voxel offset step at any level where the
                                 surface is resolved */
#define HALF_DIAGONAL 0.8660254037844386 /* sqrt(3)/2: farthest a plane can be and still cut a voxel */

/* Normal and plane offset of a voxel for a surface: guarded Newton
 * steps from the centre towards f = 0, kept inside the voxel; the normal is
 * the normalised gradient there, the offset the signed distance (in voxel
 * edges) from the centre to the linearised surface along it. A gradient that
 * is zero or not finite there and at the centre falls back to +z with offset
 * 0 (counted in normal_fallbacks). */

static void newton_start(newton *nw, const double centre[3], const double fg_centre[4])
{
    memcpy(nw->p, centre, sizeof nw->p);
    memcpy(nw->fg, fg_centre, sizeof nw->fg);
    nw->f = fg_centre[0];
    memcpy(nw->g, fg_centre + 1, sizeof nw->g);
    nw->step = 0;
}

/* The Newton step from p (f and grad f there: f, g), kept inside the voxel
 * (box), into q, and the step q - p into dq; 0 when it cannot be taken (q
 * and dq untouched). (dq is made here, from q in registers: read back from
 * q's three stores as one vector load, the stores would not be forwarded
 * and the load would wait for them to retire; docs/perf-log.md.) */
static inline int newton_step(const double p[3], double f, const double g[3],
                              const interval box[3], double q[3], double dq[3])
{
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0.0) || !isfinite(g2) || !isfinite(f) || f == 0.0)
        return 0;
    for (int k = 0; k < 3; k++) {
        q[k] = min2(max2(p[k] - f / g2 * g[k], box[k].lo), box[k].hi); /* NaN gives lo */
        dq[k] = q[k] - p[k];
    }
    return 1;
}

/* With f and its gradient at the iterate known: 1 when the iterate moved
 * and they are wanted at the new one, 0 when the iteration has stopped. */
static int newton_advance(newton *nw, const interval box[3], double h)
{
    double q[3], dq[3];
    if (nw->step == NEWTON_STEPS)
        return 0;
    if (!newton_step(nw->p, nw->f, nw->g, box, q, dq))
        return 0; /* no step */
    double moved = 0.0; /* max norm */
    for (int k = 0; k < 3; k++)
        moved = max2(moved, fabs(dq[k]));
    if (moved < NEWTON_TOL * h)
        return 0; /* the linearisation at p places the surface well enough */
    memcpy(nw->p, q, sizeof q);
    nw->step++;
    return 1;
}

/* What a voxel's record is packed from: the normal's direction g (not
 * unit) with g2 = |g|^2 > 0, and s, the offset's numerator (record_pack).
 * The records of a batch are made in two passes, these first, then each
 * packed: the packing's sqrt and division, dependent on each other, would
 * otherwise hold up each voxel in turn (docs/perf-log.md). */
typedef struct record_in {
    double g[3], g2, s;
} record_in;

/* The voxel's record_in from an iterate p with f and grad f there (f, g);
 * the centre's values fg are the fallback where those fail, +z with offset 0
 * where those fail too (counted in normal_fallbacks). The linearisation's
 * zero set {x : f + g . (x - q) = 0} lies at signed distance
 * (g . (q - centre) - f) / |g| from the centre along g / |g|. */
static void record_in_at(worker *wk, const double p[3], double f, const double gi[3],
                         const double fg[4], const double centre[3], record_in *ri)
{
    const double *q = p, *g = gi;
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0.0) || !isfinite(g2) || !isfinite(f)) { /* g2 finite: so is each g[k] */
        q = centre;
        f = fg[0];
        g = fg + 1;
        g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0.0) || !isfinite(g2)) {
            wk->st.normal_fallbacks++;
            *ri = (record_in){{0.0, 0.0, 1.0}, 1.0, 0.0};
            return;
        }
        if (!isfinite(f))
            f = 0.0;
    }
    double s = -f;
    for (int k = 0; k < 3; k++)
        s += g[k] * (q[k] - centre[k]);
    *ri = (record_in){{g[0], g[1], g[2]}, g2, s};
}

/* The record: the octahedral code of g (scale-free: no division by |g|)
 * and the offset s / |g| in voxel edges (h), clamped. */
static uint32_t record_pack(const record_in *ri, double h)
{
    double d = ri->s / (sqrt(ri->g2) * h);
    if (!isfinite(d))
        d = 0.0;
    d = min2(max2(d, -HALF_DIAGONAL), HALF_DIAGONAL);
    return oct_voxel_pack(ri->g, d);
}

/* The voxel's record_in from where the iteration stopped. */
static void newton_record(worker *wk, const newton *nw, const double centre[3], record_in *ri)
{
    record_in_at(wk, nw->p, nw->f, nw->g, nw->fg, centre, ri);
}

unsigned voxel_surface(worker *wk, unsigned idx, const double centre[3], newton *nw)
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

unsigned shell_surface(worker *wk, unsigned idx, const double centre[3])
{
    newton nw;
    if (wk->nact[idx] > 1)
        return voxel_surface(wk, idx, centre, &nw);
    unsigned s = wk->act[(size_t)idx * wk->c->nsurf];
    wk->cf_ok[s] = 0;
    return s;
}

int emit_voxel(worker *wk, const interval box[3], const double centre[3])
{
    const build_ctx *c = wk->c;
    unsigned idx = c->levels + 1;
    if (c->par->shell_only) /* --shell-only: the writer stores no record */
        return push_voxel(wk, 0, shell_surface(wk, idx, centre));
    newton nw;
    unsigned best = voxel_surface(wk, idx, centre, &nw);
    const tape *t = &wk->rec[best];
    double h = c->cell_edge[c->levels];
    while (newton_advance(&nw, box, h)) {
        nw.f = tape_eval_grad(t, nw.p, nw.g, wk->dslots);
        wk->st.point_evals++;
    }
    record_in ri;
    newton_record(wk, &nw, centre, &ri);
    return push_voxel(wk, record_pack(&ri, h), best);
}

/* The finite-difference columns of a leaf-parent's Hessian, from the
 * gradients at its children's centres (fg: f and grad f of child i at
 * fg[4 i], for the children set in have): column k of D the mean of the
 * differences over the pairs of children that differ in bit k alone. Returns
 * the axes that have such a pair (bit k for column k). */
static unsigned leaf_columns(const double *fg, unsigned have, const child_boxes *cb, double D[3][3])
{
    /* the children whose bit k is 0: the lower ones of the pairs along axis k */
    static const uint8_t lower[3] = {0x55, 0x33, 0x0f};
    unsigned axes = 0;
    for (unsigned k = 0; k < 3; k++) {
        const unsigned bk = 1u << k;
        /* every pair's centres differ along k by the two halves' middles */
        const double dx = cb->mid[k][1] - cb->mid[k][0];
        double d[3] = {0.0, 0.0, 0.0};
        unsigned pairs = 0;
        /* the pairs present, lower child first, in increasing order */
        for (unsigned m = have & (have >> bk) & lower[k]; m; m &= m - 1) {
            const unsigned lo = (unsigned)__builtin_ctz(m), hi = lo | bk;
            const double *ga = fg + 4 * lo + 1, *gb = fg + 4 * hi + 1;
            d[0] += (gb[0] - ga[0]) / dx;
            d[1] += (gb[1] - ga[1]) / dx;
            d[2] += (gb[2] - ga[2]) / dx;
            pairs++;
        }
        if (!pairs)
            continue;
        for (unsigned r = 0; r < 3; r++)
            D[r][k] = d[r] / (double)pairs;
        axes |= bk;
    }
    return axes;
}

/* A leaf-parent's Hessian from its columns D (axes: leaf_columns's),
 * symmetrised; entries with neither axis among the columns taken from a
 * sibling's Hessian B (NULL: none). 0 when some entry has no value. */
static int leaf_hessian(const double D[3][3], unsigned axes, const double (*B)[3], double H[3][3])
{
    if (axes == 7) {
        for (unsigned r = 0; r < 3; r++)
            for (unsigned k = 0; k < 3; k++) {
                H[r][k] = 0.5 * (D[r][k] + D[k][r]);
                if (!isfinite(H[r][k]))
                    return 0;
            }
        return 1;
    }
    for (unsigned r = 0; r < 3; r++)
        for (unsigned k = 0; k < 3; k++) {
            const unsigned ar = (axes >> r) & 1, ak = (axes >> k) & 1;
            if (ar && ak)
                H[r][k] = 0.5 * (D[r][k] + D[k][r]);
            else if (ak) /* d(grad_r)/dk from this leaf-parent's own column k */
                H[r][k] = D[r][k];
            else if (ar)
                H[r][k] = D[k][r];
            else if (B)
                H[r][k] = B[r][k];
            else
                return 0;
            if (!isfinite(H[r][k]))
                return 0;
        }
    return 1;
}

/* The record of a voxel (centre c, box, f and grad f at c in fg) of a
 * leaf-parent whose Hessian H is known: the first Newton step from c however
 * short (newton_step's), then f and grad f there from the second-order
 * model about c, without evaluating them, and the record from those. Over a
 * voxel the model's error is third order in its size, below what more
 * Newton steps would correct (docs/perf-log.md, rasterize). */
static void model_record(worker *wk, const double c[3], const double fg[4],
                         const interval box[3], const double H[3][3], record_in *ri)
{
    const double f0 = fg[0], *g0 = fg + 1;
    double p[3], d[3];
    if (!newton_step(c, f0, g0, box, p, d)) {
        memcpy(p, c, sizeof p); /* no step: the model at c itself */
        d[0] = d[1] = d[2] = 0.0;
    }
    /* the model at p, H d in registers (an array of it, stored a term at a
     * time, was read back as one vector load: docs/perf-log.md) */
    const double Hd0 = H[0][0] * d[0] + H[0][1] * d[1] + H[0][2] * d[2];
    const double Hd1 = H[1][0] * d[0] + H[1][1] * d[1] + H[1][2] * d[2];
    const double Hd2 = H[2][0] * d[0] + H[2][1] * d[1] + H[2][2] * d[2];
    double f = f0 + g0[0] * d[0];
    f += g0[1] * d[1];
    f += g0[2] * d[2];
    f += 0.5 * (d[0] * Hd0 + d[1] * Hd1 + d[2] * Hd2);
    const double g[3] = {g0[0] + Hd0, g0[1] + Hd1, g0[2] + Hd2};
    record_in_at(wk, p, f, g, fg, c, ri);
}

#define ROUND_MAX 64 /* voxels of a leaf_batch: 8 leaf-parents of 8 */

/* The Newton iterations w[j] (boxes box[j]) on tape t that still move
 * (live[j]), to their end: each round evaluates all of them that moved,
 * TAPE_LANES at a time (tape_eval_grad_lanes, so each gets the bits of its
 * own evaluation whoever shares the pass). n <= ROUND_MAX. */
static void newton_rounds(worker *wk, const tape *t, newton *const *w,
                          const interval *const *box, uint8_t *live, unsigned n, double h)
{
    for (;;) {
        unsigned m = 0, idx[ROUND_MAX];
        for (unsigned j = 0; j < n; j++)
            if (live[j])
                idx[m++] = j;
        if (!m)
            return;
        for (unsigned a = 0; a < m; a += TAPE_LANES) {
            unsigned k = m - a < TAPE_LANES ? m - a : TAPE_LANES;
            double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES], f[TAPE_LANES], g[3][TAPE_LANES];
            for (unsigned l = 0; l < k; l++) {
                const newton *v = w[idx[a + l]];
                x[l] = v->p[0];
                y[l] = v->p[1];
                z[l] = v->p[2];
            }
            tape_eval_grad_lanes(t, k, x, y, z, f, g, wk->lslots);
            wk->st.point_evals += k;
            for (unsigned l = 0; l < k; l++) {
                unsigned j = idx[a + l];
                newton *v = w[j];
                v->f = f[l];
                v->g[0] = g[0][l];
                v->g[1] = g[1][l];
                v->g[2] = g[2][l];
                live[j] = (uint8_t)newton_advance(v, box[j], h);
            }
        }
    }
}

void emit_voxels(worker *wk, const child_boxes *cb, const uint8_t *child,
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
    double H[3][3];
    int hs = -1, have_h = 0; /* the surface H was made for, and whether it could be */
    record_in ri[8];
    uint8_t modelled[8]; /* the record made from the model, no iteration */
    for (unsigned j = 0; j < np; j++) {
        if ((int)surf[j] != hs) {
            hs = surf[j];
            double D[3][3];
            have_h = leaf_columns(wk->cf8 + (size_t)surf[j] * 32, wk->cf8_have[surf[j]], cb, D) == 7 &&
                     leaf_hessian(D, 7, NULL, H);
        }
        modelled[j] = (uint8_t)have_h;
        live[j] = 0;
        if (have_h)
            model_record(wk, cb->centre[child[j]], nw[j].fg, cb->box[child[j]],
                         (const double (*)[3])H, &ri[j]);
        else
            live[j] = (uint8_t)newton_advance(&nw[j], cb->box[child[j]], h);
    }
    for (unsigned j0 = 0; j0 < np; j0++) { /* surface by surface, those still moving */
        if (!live[j0])
            continue;
        const unsigned s = surf[j0];
        newton *w[8];
        const interval *box[8];
        uint8_t lv[8];
        unsigned n = 0;
        for (unsigned j = j0; j < np; j++)
            if (live[j] && surf[j] == s) {
                w[n] = &nw[j];
                box[n] = cb->box[child[j]];
                lv[n++] = 1;
                live[j] = 0;
            }
        newton_rounds(wk, &wk->rec[s], w, box, lv, n, h);
    }
    for (unsigned j = 0; j < np; j++)
        if (!modelled[j])
            newton_record(wk, &nw[j], cb->centre[child[j]], &ri[j]);
    for (unsigned j = 0; j < np && !wk->failed; j++)
        push_voxel(wk, record_pack(&ri[j], h), surf[j]);
}

/* Squared distance between the centres of two leaf-parents. */
static double leaf_dist2(const child_boxes *a, const child_boxes *b)
{
    double d2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double d = (a->mid[k][0] + a->mid[k][1]) - (b->mid[k][0] + b->mid[k][1]);
        d2 += d * d;
    }
    return d2;
}

void batch_records(worker *wk, const leaf_voxels *lv, unsigned nb)
{
    const build_ctx *c = wk->c;
    double h = c->cell_edge[c->levels];
    newton nw[ROUND_MAX], *w[ROUND_MAX];
    const interval *box[ROUND_MAX];
    const double *centre[ROUND_MAX];
    uint8_t live[ROUND_MAX];
    unsigned n = 0, any = 0;
    double D[8][3][3], H[8][3][3];
    unsigned axes[8];
    int have_h[8]; /* leaf-parent b's Hessian in H[b]: its own (1), completed from a sibling's (2) */
    for (unsigned b = 0; b < nb; b++) {
        axes[b] = lv[b].keep ? leaf_columns(lv[b].cf8, lv[b].have, lv[b].cb, D[b]) : 0;
        have_h[b] = axes[b] == 7 && leaf_hessian(D[b], 7, NULL, H[b]);
    }
    /* A leaf-parent without a pair along some axis has no differences along
     * it: the entries of H with neither index among its own axes (the other
     * rows and columns of H come from its own columns, H being symmetric)
     * are those of the nearest sibling with a whole Hessian. */
    for (unsigned b = 0; b < nb; b++) {
        if (!lv[b].keep || have_h[b])
            continue;
        int from = -1;
        double best = INFINITY;
        for (unsigned a = 0; a < nb; a++)
            if (have_h[a] == 1 && leaf_dist2(lv[a].cb, lv[b].cb) < best) {
                best = leaf_dist2(lv[a].cb, lv[b].cb);
                from = (int)a;
            }
        if (from >= 0)
            have_h[b] = 2 * leaf_hessian(D[b], axes[b], (const double (*)[3])H[from], H[b]);
    }
    record_in ri[ROUND_MAX];
    uint8_t iterated[ROUND_MAX]; /* no Hessian: the record waits for the Newton rounds */
    for (unsigned b = 0; b < nb; b++) {
        const leaf_voxels *v = &lv[b];
        if (!v->keep)
            continue;
        const double (*Hb)[3] = have_h[b] ? (const double (*)[3])H[b] : NULL;
        for (unsigned mk = v->keep; mk; mk &= mk - 1) {
            const unsigned i = (unsigned)__builtin_ctz(mk);
            w[n] = &nw[n];
            box[n] = v->cb->box[i];
            centre[n] = v->cb->centre[i];
            iterated[n] = !Hb;
            live[n] = 0;
            if (Hb) {
                model_record(wk, centre[n], v->cf8 + 4 * i, box[n], Hb, &ri[n]);
                n++;
                continue;
            }
            newton_start(&nw[n], centre[n], v->cf8 + 4 * i);
            live[n] = (uint8_t)newton_advance(&nw[n], box[n], h);
            any |= live[n++];
        }
    }
    if (any)
        newton_rounds(wk, &wk->rec[0], w, box, live, n, h);
    for (unsigned j = 0; j < n; j++)
        if (iterated[j])
            newton_record(wk, &nw[j], centre[j], &ri[j]);
    if (wk->failed || !n)
        return;
    uint32_t rec[ROUND_MAX]; /* one surface: no surface indices, the records in one push */
    for (unsigned j = 0; j < n; j++)
        rec[j] = record_pack(&ri[j], h);
    if (buf_push(&wk->out->voxels, rec, n * sizeof *rec)) {
        wk->failed = 1;
        return;
    }
    wk->st.voxels += n;
}
