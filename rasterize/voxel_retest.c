/* voxel_retest: f at a leaf-parent's candidate voxels and their re-tests,
 * one leaf-parent at a time or a batch pooled (see voxel_retest.h). */
#include "rasterize/voxel_retest.h"

#include <math.h>

/* f and its gradient at n voxel centres (tape_eval_grad_lanes). With
 * --shell-only and one surface only f is wanted (the centred re-test's
 * skip; no record, no choice of surface): the value evaluator, the same
 * bits of f, and the gradients left 0. */
static void centre_values(worker *wk, const tape *t, unsigned n, const double *x, const double *y,
                          const double *z, double *f, double g[3][TAPE_LANES])
{
    wk->st.point_evals += n;
    if (wk->c->par->shell_only && wk->c->nsurf == 1) {
        tape_eval_lanes(t, n, x, y, z, f, wk->lslots);
        memset(g, 0, 3 * sizeof *g);
        return;
    }
    tape_eval_grad_lanes(t, n, x, y, z, f, g, wk->lslots);
}

/* The tape for f at voxel centres: the record tape (record_tapes), whose
 * bits the records take; with --shell-only and one surface, where f serves
 * only the centred re-test's skip (which only keeps voxels, its margin
 * covering the pruned constants), the node's pruned one. */
static const tape *centre_tape(const worker *wk, const tape *pruned, unsigned s)
{
    return wk->c->par->shell_only && wk->c->nsurf == 1 ? pruned : &wk->rec[s];
}

/* The bound that stands for the centred re-test's evaluation of f at the
 * centres of surface s's candidates under a node with tape t, or NaN. The
 * centres' values come from the centre tape: the full tape (the record
 * tape, which a tape with no kink keeps whole) or t. Where t froze no term
 * into a constant (its pool is the full tape's) and the full tape has no
 * kink, t is the full tape less dead code, the same bits; the full tape's
 * bound over the cube (build_ctx's centre_ev) holds for both, and the form,
 * whose G is t's gradient enclosure, holds f. (A frozen term's change
 * across the voxel is in neither G nor f at one point: there the interval
 * evaluation of t at the centre, which spans the constant, is run.) */
static double centre_err(const worker *wk, unsigned s, const tape *t)
{
    return t->nconst == wk->c->full[s]->nconst ? wk->c->centre_ev[s] : NAN;
}

/* With --shell-only and one surface, f at a child's centre serves only the
 * centred re-test: the candidates (cand) where the node's form (fc at
 * centre c, G) shows that the re-test keeps the child whatever f is there
 * are returned (their re-tests are not run, no evaluation), their entries
 * of cf8 filled with zeros. */
static uint8_t skip_centres(const worker *wk, interval fc, const interval G[3], const double c[3],
                            const child_boxes *cb, uint8_t cand, double *cf8)
{
    if (!wk->c->par->shell_only || wk->c->nsurf != 1 || !cand)
        return 0;
    uint8_t m = centred_form_cannot_exclude(fc, G, c, cb, cand);
    for (unsigned i = 0; i < 8; i++)
        if ((m >> i) & 1)
            memset(cf8 + 4 * i, 0, 4 * sizeof *cf8);
    return m;
}

/* (see voxel_retest.h) */
void leaf_centres(worker *wk, unsigned depth, const uint8_t *ok, const uint8_t *fx,
                  child_boxes *cb)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k], n = 0, lane[8];
        wk->cf8_have[s] = 0;
        if (!ok[k])
            continue;
        double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES], f[TAPE_LANES], g[3][TAPE_LANES];
        for (unsigned i = 0; i < 8; i++) {
            if ((fx[k] >> i) & 1 || !child_box(cb, i))
                continue;
            x[n] = cb->centre[i][0];
            y[n] = cb->centre[i][1];
            z[n] = cb->centre[i][2];
            lane[n++] = i;
        }
        if (!n)
            continue;
        centre_values(wk, centre_tape(wk, &wk->tapes[(size_t)pidx * ns + s], s), n, x, y, z, f, g);
        for (unsigned l = 0; l < n; l++) {
            double *fg = wk->cf8 + ((size_t)s * 8 + lane[l]) * 4;
            fg[0] = f[l];
            fg[1] = g[0][l];
            fg[2] = g[1][l];
            fg[3] = g[2][l];
            wk->cf8_have[s] |= (uint8_t)(1u << lane[l]);
        }
        if (wk->kinked[(size_t)pidx * ns + s])
            wk->cf8_have[s] = 0;
    }
}

/* (see voxel_retest.h) */
void leaf_retests(worker *wk, unsigned depth, const uint8_t *ok, const uint8_t *fx,
                  child_boxes *cb, uint8_t *centred, uint8_t *plain)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k], n = 0, m = 0;
        centred[k] = plain[k] = 0;
        if (!ok[k])
            continue;
        retest_item it[8];
        uint8_t child[8], drop[8];
        for (unsigned i = 0; i < 8; i++)
            if (!((fx[k] >> i) & 1) && child_box(cb, i)) {
                retest_item r = {cb->box[i], cb->centre[i], wk->cf8[((size_t)s * 8 + i) * 4]};
                child[n] = (uint8_t)i;
                it[n++] = r;
            }
        const tape *t = &wk->tapes[(size_t)pidx * ns + s];
        centred_form_drops(wk, t, &wk->grad[((size_t)pidx * ns + s) * 3], centre_err(wk, s, t),
                           it, n, drop);
        for (unsigned j = 0; j < n; j++) {
            if (drop[j])
                centred[k] |= (uint8_t)(1u << child[j]);
            else { /* the plain test's candidates */
                child[m] = child[j];
                it[m++] = it[j];
            }
        }
        if (!wk->kinked[(size_t)pidx * ns + s])
            continue;
        plain_test_drops(wk, t, s, it, m, drop);
        for (unsigned j = 0; j < m; j++)
            if (drop[j])
                plain[k] |= (uint8_t)(1u << child[j]);
    }
}

/* One pass of batch_centres: f and grad f at n centres, each stored in
 * its leaf-parent's cf8 (owner, child ch). */
static void centre_pass(worker *wk, const tape *ct, leaf_parent *lp, unsigned n,
                        const double *x, const double *y, const double *z,
                        const unsigned *owner, const unsigned *ch)
{
    double f[TAPE_LANES], g[3][TAPE_LANES];
    centre_values(wk, ct, n, x, y, z, f, g);
    for (unsigned l = 0; l < n; l++) {
        leaf_parent *q = &lp[owner[l]];
        double *fg = q->cf8 + 4 * ch[l];
        fg[0] = f[l];
        fg[1] = g[0][l];
        fg[2] = g[1][l];
        fg[3] = g[2][l];
        q->cf8_have |= (uint8_t)(1u << ch[l]);
    }
}

/* (see voxel_retest.h) */
void batch_centres(worker *wk, unsigned depth, leaf_parent *lp, unsigned nb)
{
    const build_ctx *c = wk->c;
    const unsigned pidx = depth + 1;
    const tape *t = &wk->tapes[pidx], *ct = centre_tape(wk, t, 0);
    interval *G = &wk->grad[pidx * 3];
    double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES];
    unsigned n = 0, owner[TAPE_LANES], ch[TAPE_LANES];
    for (unsigned b = 0; b < nb; b++) {
        leaf_parent *p = &lp[b];
        cell_box(c, depth, p->cell, p->pbox, p->pc);
        p->ok[0] = (uint8_t)child_enclosures(wk, t, p->pbox, depth, p->cell, wk->ncen[depth],
                                             &wk->fcen[pidx], G, 1, &p->fx[0]);
        child_boxes_init(c, depth, p->cell, p->pbox, &p->cb);
        p->cand = p->nofd = p->cf8_have = p->centred[0] = p->plain[0] = 0;
        /* (the loops below run over set bits: a test of each of the eight
         * bits was a branch the predictor missed often) */
        for (unsigned m = p->ok[0] ? (uint8_t)~p->fx[0] : 0u; m; m &= m - 1) {
            const unsigned i = (unsigned)__builtin_ctz(m);
            p->cand |= (uint8_t)((unsigned)child_box(&p->cb, i) << i);
        }
        p->nofd = skip_centres(wk, wk->fcen[depth], G, wk->ncen[depth], &p->cb, p->cand, p->cf8);
        /* f and grad f at the candidates' centres, in passes of TAPE_LANES */
        for (unsigned m = p->cand & (uint8_t)~p->nofd; m; m &= m - 1) {
            const unsigned i = (unsigned)__builtin_ctz(m);
            x[n] = p->cb.centre[i][0];
            y[n] = p->cb.centre[i][1];
            z[n] = p->cb.centre[i][2];
            owner[n] = b;
            ch[n++] = i;
            if (n == TAPE_LANES) {
                centre_pass(wk, ct, lp, n, x, y, z, owner, ch);
                n = 0;
            }
        }
    }
    if (n)
        centre_pass(wk, ct, lp, n, x, y, z, owner, ch);
}

/* (see voxel_retest.h) */
void batch_retests(worker *wk, unsigned pidx, leaf_parent *lp, unsigned nb)
{
    const tape *t = &wk->tapes[pidx];
    const interval *G = &wk->grad[pidx * 3];
    unsigned nit = 0;
    retest_item it[64];
    uint8_t it_lp[64], it_ch[64], drop[64];
    unsigned m = 0, nfd = 0, fdj[64];
    retest_item fit[64];
    uint8_t fdrop[64];
    for (unsigned b = 0; b < nb; b++)
        for (unsigned mk = lp[b].cand; mk; mk &= mk - 1) {
            const unsigned i = (unsigned)__builtin_ctz(mk);
            retest_item r = {lp[b].cb.box[i], lp[b].cb.centre[i], lp[b].cf8[4 * i]};
            it_lp[nit] = (uint8_t)b;
            it_ch[nit] = (uint8_t)i;
            drop[nit] = 0;
            fdj[nfd] = nit; /* (kept when the form is to run: no branch) */
            fit[nfd] = r;
            nfd += !((lp[b].nofd >> i) & 1);
            it[nit++] = r;
        }
    if (nfd) { /* (the guard also shows GCC that fit is written before it is read) */
        centred_form_drops(wk, t, G, centre_err(wk, 0, t), fit, nfd, fdrop);
        for (unsigned j = 0; j < nfd; j++)
            drop[fdj[j]] = fdrop[j];
    }
    for (unsigned j = 0; j < nit; j++) {
        if (drop[j]) {
            lp[it_lp[j]].centred[0] |= (uint8_t)(1u << it_ch[j]);
        } else {
            it_lp[m] = it_lp[j];
            it_ch[m] = it_ch[j];
            it[m++] = it[j];
        }
    }
    if (wk->kinked[pidx]) {
        plain_test_drops(wk, t, 0, it, m, drop);
        for (unsigned j = 0; j < m; j++)
            if (drop[j])
                lp[it_lp[j]].plain[0] |= (uint8_t)(1u << it_ch[j]);
    }
}
