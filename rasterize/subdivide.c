/* subdivide: the recursion. A task's cell is subdivided depth-first,
 * children in slot order, so every depth's nodes come out in Morton order.
 * Above the finest MEAN_VALUE_LEVELS a child is tested on its own with its
 * parent's pruned tapes (cell_test_surviving); there and below, all eight at once with
 * the mean-value form (child_enclosures). */
#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"

#define MEAN_VALUE_LEVELS 3   /* the finest levels whose cells the mean-value form tests */
_Static_assert(MEAN_VALUE_LEVELS >= 2, "leaf-parents reuse their parent's gradient enclosure");
/* Cells of depth below this (larger than 1/256 of the cube) are too big for
 * a gradient enclosure to be tight: there the plain interval test runs too,
 * and either may drop the cell. From levels 10 up the mean-value levels are
 * all this deep, so the cost is paid on coarse grids only. */
#define MEAN_VALUE_ALONE_DEPTH 8

static uint8_t visit_node(worker *wk, unsigned depth, const uint64_t cell[3]);

/* For a leaf-parent: f and its gradient at the centres of the children that
 * the mean-value form leaves to the centred re-test, surface by surface, one
 * pass over the tape for all of them (tape_eval_grad_lanes), into wk->cf8. */
static void leaf_centres(worker *wk, unsigned depth, const uint8_t *ok, interval T[][8],
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
            wk->cf8_have[s] |= (uint8_t)(1u << lane[l]);
        }
        if (wk->kinked[(size_t)pidx * ns + s])
            wk->cf8_have[s] = 0;
    }
}

/* For a leaf-parent, after leaf_centres: the children whose re-tests drop
 * them, per surface (index k as in ok): the form centred on each voxel, then
 * on a tape with a kink the plain interval test too (there the gradient
 * enclosure spans both branches and the forms are loose where the interval
 * is not: csg, gyroid). Each test runs on all the children at once. Bit i of
 * centred[k] marks a drop by the form, of plain[k] by the plain test. */
static void leaf_retests(worker *wk, unsigned depth, const uint8_t *ok, interval T[][8],
                         child_boxes *cb, uint8_t *centred, uint8_t *plain)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k];
        centred[k] = plain[k] = 0;
        if (!ok[k])
            continue;
        uint8_t cand = 0;
        for (unsigned i = 0; i < 8; i++)
            if (!(T[k][i].lo > 0.0 || T[k][i].hi < 0.0) && child_box(cb, i))
                cand |= (uint8_t)(1u << i);
        const tape *t = &wk->tapes[(size_t)pidx * ns + s];
        centred[k] = centred_form_drops(wk, t, &wk->grad[((size_t)pidx * ns + s) * 3], cb, cand,
                                        wk->cf8 + (size_t)s * 32);
        if (wk->kinked[(size_t)pidx * ns + s])
            plain[k] = plain_test_drops(wk, t, s, cb, (uint8_t)(cand & ~centred[k]));
    }
}

/* Whether the tests a child of the node (depth) faces after the node's
 * mean-value form (ok: that form was available for surface s) drop it.
 * Without the form, or on coarse cells, the plain interval test. At the
 * voxels, the re-tests leaf_retests made (retest: bit 0 a drop by the form
 * centred on the voxel, bit 1 by the plain test). */
static int child_dropped(worker *wk, unsigned depth, unsigned s, int ok, const interval box[3],
                         const double centre[3], unsigned retest)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    const tape *t = &wk->tapes[(size_t)pidx * ns + s];
    if (!ok || depth + 1 < MEAN_VALUE_ALONE_DEPTH) {
        if (cell_may_cross(wk, t, s, depth + 1, box, centre))
            return 0;
        wk->st.taylor_drops += (unsigned)ok;
        return 1;
    }
    if (depth + 1 < c->levels)
        return 0;
    wk->st.taylor_drops += retest & 1;
    return retest != 0;
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
    memcpy(wk->ncen[pidx], pc, sizeof pc);
    /* A leaf-parent reuses its parent's gradient enclosure: the parent's box
     * holds its own, one evaluation fewer for a slightly wider form. */
    int reuse = depth + 1 == c->levels; /* its parent ran here too: MEAN_VALUE_LEVELS >= 2 */
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k];
        interval *G = &wk->grad[((size_t)pidx * ns + s) * 3];
        interval *fc = &wk->fcen[(size_t)pidx * ns + s];
        int r = reuse && wk->grad_ok[(size_t)depth * ns + s];
        if (r) {
            memcpy(G, &wk->grad[((size_t)depth * ns + s) * 3], 3 * sizeof *G);
            *fc = wk->fcen[(size_t)depth * ns + s];
        }
        ok[k] = (uint8_t)child_enclosures(wk, &wk->tapes[(size_t)pidx * ns + s], pbox, depth, cell,
                                          r ? wk->ncen[depth] : pc, fc, G, r, T[k]);
        wk->grad_ok[(size_t)pidx * ns + s] = ok[k];
    }
    child_boxes cb; /* most children fall to T alone: boxes are made lazily */
    child_boxes_init(c, depth, cell, pbox, &cb);
    int retest = depth + 1 == c->levels && depth + 1 >= MEAN_VALUE_ALONE_DEPTH;
    newton nw[8];
    uint8_t child[8], surf[8], centred[OCT_MAX_SURFACES], plain[OCT_MAX_SURFACES];
    unsigned np = 0;
    if (retest) {
        leaf_centres(wk, depth, ok, T, &cb);
        leaf_retests(wk, depth, ok, T, &cb, centred, plain);
    }
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
            unsigned rt = retest && ok[k] ? ((centred[k] >> i) & 1u) | ((plain[k] >> i) & 1u) << 1 : 0;
            if (child_dropped(wk, depth, s, ok[k], box, centre, rt)) {
                wk->cf_ok[s] = 0;
                continue;
            }
            wk->act[(size_t)cidx * ns + n++] = (uint8_t)s;
            wk->tapes[(size_t)cidx * ns + s] = *t;
            wk->kinked[(size_t)cidx * ns + s] = wk->kinked[(size_t)pidx * ns + s];
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
            if (!shard_meets(c, depth + 1, cc) || /* outside this shard's piece */
                !cell_test_surviving(wk, depth + 1, depth + 1, cc, box, centre))
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

void run_task(worker *wk, uint64_t task, task_out *out)
{
    const build_ctx *c = wk->c;
    uint64_t cell[3];
    morton_decode(task, c->task_depth, cell);
    wk->out = out;
    interval box[3];
    double centre[3];
    if (shard_meets(c, c->task_depth, cell) && cell_test_surviving(wk, 0, c->task_depth, cell, box, centre))
        out->nonempty = visit_node(wk, c->task_depth, cell) != 0;
}
