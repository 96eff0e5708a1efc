/* subdivide: the recursion. A task's cell is subdivided depth-first,
 * children in slot order, so every depth's nodes come out in Morton order.
 * Above the finest c->mv_levels levels (build_mean_value_levels) a child is
 * tested with its parent's pruned tapes by the plain interval test
 * (cell_test_surviving; with one surface the eight together,
 * children_may_cross); there and below, all eight at once with the
 * mean-value form (child_enclosures); a leaf-parent's voxels then take the
 * re-tests of voxel_retest.c. */
#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"
#include "rasterize/voxel_retest.h"

/* Cells of depth below this (larger than 1/256 of the cube) are too big for
 * a gradient enclosure to be tight: there the plain interval test runs too,
 * and either may drop the cell. From levels 10 (12 for a scene with five
 * mean-value levels) the mean-value levels are all this deep. */
#define MEAN_VALUE_ALONE_DEPTH 8

static uint8_t visit_node(worker *wk, unsigned depth, const uint64_t cell[3],
                          const node_form *given);

static unsigned bits8(uint8_t m)
{
    unsigned n = 0;
    for (; m; m &= (uint8_t)(m - 1))
        n++;
    return n;
}

/* Whether tapes a and b evaluate alike: the same instructions, root and
 * constants. */
static int same_tape(const tape *a, const tape *b)
{
    return a->n == b->n && a->root == b->root && a->nconst == b->nconst &&
           !memcmp(a->insn, b->insn, a->n * sizeof *a->insn) &&
           !memcmp(a->konst, b->konst, a->nconst * sizeof *a->konst);
}

/* Whether a child of the node (depth) takes the plain interval test for
 * surface k after the node's mean-value form (ok: that form was available):
 * without the form, or on coarse cells. */
static int takes_plain_test(unsigned depth, int ok)
{
    return !ok || depth + 1 < MEAN_VALUE_ALONE_DEPTH;
}

/* The plain tests of the node's children (those takes_plain_test names,
 * inside the bounds, not dropped by the form, fx), all at once: bit i of
 * drop[k] set when the test proves child i empty of surface k. */
static void children_plain_tests(worker *wk, unsigned depth, const uint8_t *ok, const uint8_t *fx,
                                 child_boxes *cb, uint8_t *drop)
{
    const unsigned ns = wk->c->nsurf, pidx = depth + 1;
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k], n = 0;
        drop[k] = 0;
        if (!takes_plain_test(depth, ok[k]))
            continue;
        retest_item it[8];
        uint8_t child[8], d[8];
        for (unsigned i = 0; i < 8; i++)
            if (!(ok[k] && ((fx[k] >> i) & 1)) && child_box(cb, i)) {
                retest_item r = {cb->box[i], cb->centre[i], 0.0};
                child[n] = (uint8_t)i;
                it[n++] = r;
            }
        plain_test_drops(wk, &wk->tapes[(size_t)pidx * ns + s], s, it, n, d);
        for (unsigned j = 0; j < n; j++)
            drop[k] |= (uint8_t)(d[j] << child[j]);
    }
}

/* Whether the tests a child of the node (depth) faces after the node's
 * mean-value form (ok) drop it: the plain interval test where
 * takes_plain_test says so (its result in plain_drop), or at the voxels the
 * re-tests leaf_retests made (retest: bit 0 a drop by the form centred on
 * the voxel, bit 1 by the plain test). */
static int child_dropped(worker *wk, unsigned depth, int ok, int plain_drop, unsigned retest)
{
    if (takes_plain_test(depth, ok)) {
        wk->st.taylor_drops += (unsigned)(ok && plain_drop);
        return plain_drop;
    }
    if (depth + 1 < wk->c->levels)
        return 0;
    wk->st.taylor_drops += retest & 1;
    return retest != 0;
}

/* The n nodes (depth, cell[j], slot[j] of their parent) that the parent's
 * visit_children let through, of a single-surface scene, on the mean-value
 * levels above the leaf-parents' parents: they share their parent's tape,
 * so their own forms (G, f at the centre) are made together (node_forms),
 * then each is visited in slot order. Returns their mask bits. */
static uint8_t visit_siblings(worker *wk, unsigned depth, uint64_t cell[][3], const uint8_t *slot,
                              unsigned n)
{
    const build_ctx *c = wk->c;
    interval box[8][3];
    double centre[8][3];
    node_form nf[8];
    for (unsigned j = 0; j < n; j++)
        cell_box(c, depth, cell[j], box[j], centre[j]);
    node_forms(wk, &wk->tapes[depth + 1], wk->kinked[depth], n, box, (const double(*)[3])centre,
               nf);
    uint8_t mask = 0;
    for (unsigned j = 0; j < n && !wk->failed; j++) {
        wk->nact[depth + 1] = 1; /* a later sibling dropped may have cleared it */
        /* a kink of the parent's tape may be decided over this node's box:
         * its leaf-parents then skip the plain re-test and take Hessians */
        wk->kinked[depth + 1] = nf[j].kinked;
        if (visit_node(wk, depth, cell[j], &nf[j]))
            mask |= (uint8_t)(1u << slot[j]);
    }
    return mask;
}

/* The children of the node (depth, cell) in slot order, with the node's
 * forms (ok, fx) and boxes (cb) made: their tests, then the voxels' records
 * (retest: a leaf-parent, its re-tests in centred and plain), or the
 * recursion. With batch, the children that would be recursed into are
 * appended to it instead (*nb of them), their mask bits left to the caller. */
static uint8_t visit_children(worker *wk, unsigned depth, const uint64_t cell[3],
                              const uint8_t *ok, const uint8_t *fx, child_boxes *cb, int retest,
                              const uint8_t *centred, const uint8_t *plain, leaf_parent *batch,
                              unsigned *nb)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1, cidx = depth + 2;
    newton nw[8];
    uint8_t child[8], surf[8], mask = 0, coarse[OCT_MAX_SURFACES];
    unsigned np = 0, nd = 0;
    uint64_t dcell[8][3]; /* the siblings deferred to visit_siblings */
    const int defer = !retest && !batch && ns == 1 && depth + 2 < c->levels;
    children_plain_tests(wk, depth, ok, fx, cb, coarse);
    for (unsigned i = 0; i < 8 && !wk->failed; i++) {
        const interval *box = cb->box[i];
        const double *centre = cb->centre[i];
        unsigned n = 0;
        for (unsigned k = 0; k < wk->nact[pidx]; k++) {
            unsigned s = wk->act[(size_t)pidx * ns + k];
            const tape *t = &wk->tapes[(size_t)pidx * ns + s];
            if (ok[k] && ((fx[k] >> i) & 1)) {
                wk->st.taylor_drops++;
                continue;
            }
            if (!child_box(cb, i))
                break; /* outside the bounds */
            if (retest && ok[k]) {
                memcpy(wk->cf + 4 * (size_t)s, wk->cf8 + ((size_t)s * 8 + i) * 4, 4 * sizeof *wk->cf);
                wk->cf_ok[s] = 1;
            }
            unsigned rt = retest && ok[k] ? ((centred[k] >> i) & 1u) | ((plain[k] >> i) & 1u) << 1 : 0;
            if (child_dropped(wk, depth, ok[k], (coarse[k] >> i) & 1, rt)) {
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
        uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1), 2 * cell[2] + (i >> 2)};
        if (retest) { /* records made below, all together */
            child[np] = (uint8_t)i;
            surf[np] = (uint8_t)(c->par->shell_only ? shell_surface(wk, cidx, centre) /* --shell-only */
                                                    : voxel_surface(wk, cidx, centre, &nw[np]));
            np++;
            mask |= (uint8_t)(1u << i);
        } else if (depth + 1 == c->levels) {
            if (emit_voxel(wk, box, centre))
                mask |= (uint8_t)(1u << i);
        } else if (batch) {
            leaf_parent *lp = &batch[(*nb)++];
            memcpy(lp->cell, cc, sizeof cc);
            lp->slot = i;
        } else if (defer) {
            memcpy(dcell[nd], cc, sizeof cc);
            child[nd++] = (uint8_t)i;
        } else if (visit_node(wk, depth + 1, cc, NULL)) { /* the few children that go on */
            mask |= (uint8_t)(1u << i);
        }
    }
    if (np)
        emit_voxels(wk, cb, child, surf, nw, np);
    if (nd && !wk->failed)
        mask |= visit_siblings(wk, depth + 1, dcell, child, nd);
    return wk->failed ? 0 : mask;
}

/* Appends a node's child mask as visit_node does. */
static void push_mask(worker *wk, unsigned depth, uint8_t mask)
{
    if (mask && !wk->failed) {
        if (buf_push(&wk->out->masks[depth], &mask, 1)) {
            wk->failed = 1;
            return;
        }
        wk->st.nodes++;
    }
}

/* What visit_children makes of a leaf-parent of a single-surface batch
 * whose form was available (p->ok), without its per-child bookkeeping: the
 * children the form and the re-tests left are its voxels (returned, the
 * drops counted). With --shell-only each goes out as an empty record here;
 * otherwise their records are made by batch_records. */
static uint8_t kept_voxels(worker *wk, const leaf_parent *p)
{
    static const uint32_t empty[8];
    _Static_assert(sizeof empty == 32, "buf_push_small reads 32 bytes");
    uint8_t keep = (uint8_t)(p->cand & ~(p->centred[0] | p->plain[0]));
    wk->st.taylor_drops += bits8(p->fx[0]) + bits8(p->centred[0]);
    if (!wk->c->par->shell_only)
        return keep;
    unsigned n = bits8(keep);
    if (n && buf_push_small(&wk->out->voxels, empty, n * sizeof *empty)) {
        wk->failed = 1;
        return 0;
    }
    wk->st.voxels += n;
    return keep;
}

/* The leaf-parents (depth = levels - 1) of one node of a single-surface
 * scene, each what visit_mean_value would make of it, with the evaluations
 * pooled: f and its gradient at the candidate voxels' centres of all of
 * them, in passes of TAPE_LANES points, then their re-tests likewise. The
 * node's own form serves them all (their reuse). Returns the node's mask
 * bits for them; their masks and voxels go out in slot order. */
static uint8_t leaf_batch(worker *wk, unsigned depth, leaf_parent *lp, unsigned nb)
{
    const build_ctx *c = wk->c;
    const unsigned pidx = depth + 1;
    for (int k = 0; k < 3; k++) /* (as a memcpy, GCC made it a slow-starting rep movs) */
        wk->grad[pidx * 3 + k] = wk->grad[depth * 3 + k];
    wk->fcen[pidx] = wk->fcen[depth];
    batch_centres(wk, depth, lp, nb);
    batch_retests(wk, pidx, lp, nb);
    double *cf8 = wk->cf8;
    uint8_t mask = 0;
    leaf_voxels lv[8]; /* leaf-parents whose records are pending, in order */
    unsigned nl = 0;
    for (unsigned b = 0; b < nb && !wk->failed; b++) {
        leaf_parent *p = &lp[b];
        uint8_t pm;
        if (p->ok[0]) { /* no per-child bookkeeping: the mask, the records pooled */
            pm = kept_voxels(wk, p);
            if (!c->par->shell_only && pm) {
                leaf_voxels v = {&p->cb, p->cf8, pm, wk->kinked[pidx] ? 0 : p->cf8_have};
                lv[nl++] = v;
            }
        } else {
            if (nl) /* the records so far first: voxels go out in order */
                batch_records(wk, lv, nl);
            nl = 0;
            memcpy(wk->ncen[pidx], p->pc, sizeof p->pc);
            wk->grad_ok[pidx] = p->ok[0];
            wk->act[pidx] = 0;
            wk->nact[pidx] = 1;
            wk->cf8 = p->cf8;
            wk->cf8_have[0] = wk->kinked[pidx] ? 0 : p->cf8_have;
            pm = visit_children(wk, depth, p->cell, p->ok, p->fx, &p->cb, 1, p->centred,
                                p->plain, NULL, NULL);
            wk->cf8 = cf8;
        }
        push_mask(wk, depth, pm);
        if (pm)
            mask |= (uint8_t)(1u << p->slot);
    }
    if (nl && !wk->failed)
        batch_records(wk, lv, nl);
    return wk->failed ? 0 : mask;
}

/* The finest levels: children are tested with child_enclosures, inheriting
 * the node's tapes (pruning no longer pays this deep); voxels are emitted,
 * deeper nodes recursed into. Where the mean-value form is not available for
 * a surface (f or its gradient may be undefined), the plain test is used. */
static uint8_t visit_mean_value(worker *wk, unsigned depth, const uint64_t cell[3],
                                const node_form *given)
{
    const build_ctx *c = wk->c;
    const unsigned ns = c->nsurf, pidx = depth + 1;
    interval pbox[3];
    /* the centre made in place (a local copy, stored a coordinate at a time
     * and copied as a vector, made the copy wait for the stores to retire:
     * docs/perf-log.md); deeper calls write other depths' entries */
    double *pc = wk->ncen[pidx];
    uint8_t ok[OCT_MAX_SURFACES], fx[OCT_MAX_SURFACES]; /* fx: children the form drops */
    cell_box(c, depth, cell, pbox, pc);
    /* The first mean-value node of its task's subtree: the records below
     * it evaluate the tapes made for its box. */
    if ((depth == c->task_depth || depth + c->mv_levels == c->levels) &&
        !(c->par->shell_only && ns == 1))
        record_tapes(wk, pidx, pbox);
    /* A leaf-parent reuses its parent's gradient enclosure: the parent's box
     * holds its own, one evaluation fewer for a slightly wider form. */
    int reuse = depth + 1 == c->levels; /* its parent ran here too: mv_levels >= 2 */
    for (unsigned k = 0; k < wk->nact[pidx]; k++) {
        unsigned s = wk->act[(size_t)pidx * ns + k];
        interval *G = &wk->grad[((size_t)pidx * ns + s) * 3];
        interval *fc = &wk->fcen[(size_t)pidx * ns + s];
        int r = reuse && wk->grad_ok[(size_t)depth * ns + s];
        if (r) {
            memcpy(G, &wk->grad[((size_t)depth * ns + s) * 3], 3 * sizeof *G);
            *fc = wk->fcen[(size_t)depth * ns + s];
        } else if (given) { /* made with its siblings' (ns == 1) */
            memcpy(G, given->G, 3 * sizeof *G);
            *fc = given->fc;
        }
        if (given && !given->ok)
            ok[k] = 0;
        else
            ok[k] = (uint8_t)child_enclosures(wk, &wk->tapes[(size_t)pidx * ns + s], pbox, depth,
                                              cell, r ? wk->ncen[depth] : pc, fc, G, r || given,
                                              &fx[k]);
        wk->grad_ok[(size_t)pidx * ns + s] = ok[k];
    }
    child_boxes cb; /* most children fall to the form alone: boxes are made lazily */
    child_boxes_init(c, depth, cell, pbox, &cb);
    int retest = depth + 1 == c->levels && depth + 1 >= MEAN_VALUE_ALONE_DEPTH;
    uint8_t centred[OCT_MAX_SURFACES], plain[OCT_MAX_SURFACES];
    if (retest) {
        leaf_centres(wk, depth, ok, fx, &cb);
        leaf_retests(wk, depth, ok, fx, &cb, centred, plain);
    }
    /* The parent of leaf-parents, one surface, its form there for them to
     * reuse: they go to one batch. */
    if (depth + 2 == c->levels && depth + 2 >= MEAN_VALUE_ALONE_DEPTH && ns == 1 &&
        wk->nact[pidx] == 1 && ok[0]) {
        leaf_parent batch[8];
        unsigned nb = 0;
        uint8_t mask = visit_children(wk, depth, cell, ok, fx, &cb, 0, NULL, NULL, batch, &nb);
        return nb && !wk->failed ? mask | leaf_batch(wk, depth + 1, batch, nb) : mask;
    }
    return visit_children(wk, depth, cell, ok, fx, &cb, retest, centred, plain, NULL, NULL);
}

/* The forms of the node's children that may be crossed (live), the
 * mean-value levels' first nodes, with their tapes made (child_prune):
 * those whose tapes are alike (same_tape) together, on one of them
 * (node_forms: the bits each one's own evaluations would give). */
static void children_forms(worker *wk, coarse_children *cc, uint8_t live, node_form nf[8])
{
    uint8_t left = live;
    while (left) {
        const unsigned r = (unsigned)__builtin_ctz(left); /* the group's first */
        interval box[8][3];
        double centre[8][3];
        uint8_t member[8];
        unsigned n = 0;
        for (unsigned m = left; m; m &= m - 1) {
            const unsigned i = (unsigned)__builtin_ctz(m);
            if (i != r && !same_tape(&cc->tape[i], &cc->tape[r]))
                continue;
            memcpy(box[n], cc->box[i], sizeof box[n]);
            memcpy(centre[n], cc->centre[i], sizeof centre[n]);
            member[n++] = (uint8_t)i;
            left &= (uint8_t)~(1u << i);
        }
        node_form f[8];
        node_forms(wk, &cc->tape[r], 0, n, box, (const double(*)[3])centre, f);
        for (unsigned j = 0; j < n; j++)
            nf[member[j]] = f[j];
    }
}

/* The children of a node above the mean-value levels, of a single-surface
 * scene: their plain tests together (children_may_cross), then each that
 * may be crossed visited in slot order with its pruned tape. */
static uint8_t visit_coarse(worker *wk, unsigned depth, const uint64_t cell[3])
{
    const build_ctx *c = wk->c;
    coarse_children cc;
    uint8_t want = 0, mask = 0;
    for (unsigned i = 0; i < 8; i++) {
        cc.cell[i][0] = 2 * cell[0] + (i & 1);
        cc.cell[i][1] = 2 * cell[1] + ((i >> 1) & 1);
        cc.cell[i][2] = 2 * cell[2] + (i >> 2);
        want |= (uint8_t)(shard_meets(c, depth + 1, cc.cell[i]) << i); /* this shard's piece */
    }
    const uint8_t live = children_may_cross(wk, depth, want, &cc);
    if (depth + 1 + c->mv_levels != c->levels) {
        for (unsigned m = live; m && !wk->failed; m &= m - 1) {
            const unsigned i = (unsigned)__builtin_ctz(m);
            child_take(wk, depth, &cc, i);
            if (visit_node(wk, depth + 1, cc.cell[i], NULL))
                mask |= (uint8_t)(1u << i);
        }
        return mask;
    }
    /* the mean-value levels' first nodes: all their tapes, then their
     * forms, then each visited */
    node_form nf[8];
    for (unsigned m = live; m; m &= m - 1)
        child_prune(wk, depth, &cc, (unsigned)__builtin_ctz(m));
    children_forms(wk, &cc, live, nf);
    for (unsigned m = live; m && !wk->failed; m &= m - 1) {
        const unsigned i = (unsigned)__builtin_ctz(m);
        wk->tapes[depth + 2] = cc.tape[i];
        wk->kinked[depth + 2] = cc.kinked[i];
        wk->act[depth + 2] = 0;
        wk->nact[depth + 2] = 1;
        if (visit_node(wk, depth + 1, cc.cell[i], &nf[i]))
            mask |= (uint8_t)(1u << i);
    }
    return mask;
}

/* Builds the subtree of a cell already tested non-empty; returns its child
 * mask (0 when nothing below it survived). */
static uint8_t visit_node(worker *wk, unsigned depth, const uint64_t cell[3],
                          const node_form *given)
{
    const build_ctx *c = wk->c;
    uint8_t mask = 0;
    if (depth + c->mv_levels >= c->levels && c->par->method == BUILD_INTERVAL) {
        mask = visit_mean_value(wk, depth, cell, given);
    } else if (c->nsurf == 1 && c->par->method == BUILD_INTERVAL && depth + 1 < c->levels &&
               wk->coarse_slots) {
        mask = visit_coarse(wk, depth, cell);
    } else {
        for (unsigned i = 0; i < 8 && !wk->failed; i++) {
            uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1),
                              2 * cell[2] + (i >> 2)};
            interval box[3];
            double centre[3];
            if (!shard_meets(c, depth + 1, cc) || /* outside this shard's piece */
                !cell_test_surviving(wk, depth + 1, depth + 1, cc, box, centre))
                continue;
            if (depth + 1 == c->levels ? emit_voxel(wk, box, centre)
                                       : visit_node(wk, depth + 1, cc, NULL))
                mask |= (uint8_t)(1u << i);
        }
    }
    push_mask(wk, depth, mask);
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
        out->nonempty = visit_node(wk, c->task_depth, cell, NULL) != 0;
}
