/* voxel_retest: the tests of a leaf-parent's candidate voxels after the
 * node's mean-value form (private to rasterize/): f and its gradient at
 * their centres, then the form centred on each voxel and, on a tape with a
 * kink, the plain interval test. One leaf-parent at a time (leaf_centres,
 * leaf_retests) or a batch of a single-surface scene's leaf-parents pooled
 * into the lane evaluators' passes (batch_centres, batch_retests); the
 * recursion that calls them is rasterize/subdivide.c. */
#ifndef VOXEL_RETEST_H
#define VOXEL_RETEST_H

#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"

/* For a leaf-parent: f and its gradient at the centres of the children that
 * the mean-value form (ok, fx: per surface as in wk->act at depth + 1)
 * leaves to the centred re-test, surface by surface, one pass over the tape
 * for all of them (tape_eval_grad_lanes), into wk->cf8. */
void leaf_centres(worker *wk, unsigned depth, const uint8_t *ok, const uint8_t *fx,
                  child_boxes *cb);

/* For a leaf-parent, after leaf_centres: the children whose re-tests drop
 * them, per surface (index k as in ok): the form centred on each voxel, then
 * on a tape with a kink the plain interval test too (there the gradient
 * enclosure spans both branches and the forms are loose where the interval
 * is not: csg, gyroid). Each test runs on all the children at once. Bit i of
 * centred[k] marks a drop by the form, of plain[k] by the plain test. */
void leaf_retests(worker *wk, unsigned depth, const uint8_t *ok, const uint8_t *fx,
                  child_boxes *cb, uint8_t *centred, uint8_t *plain);

/* A leaf-parent waiting in a batch (leaf_batch): a single-surface scene's
 * leaf-parents under one node are tested together, so that the lane
 * evaluators get the candidate voxels of all of them at once. */
typedef struct leaf_parent {
    uint64_t cell[3];
    unsigned slot; /* which child of its parent */
    interval pbox[3];
    double pc[3];
    uint8_t ok[1], fx[1], cand, nofd, cf8_have, centred[1], plain[1]; /* nofd: see skip_centres */
    child_boxes cb;
    double cf8[32];
} leaf_parent;
/* For a batch: the leaf-parents' forms (the node's, at index depth,
 * reused), their candidate voxels, and f and its gradient at the centres of
 * those that need them, in passes of TAPE_LANES points. */
void batch_centres(worker *wk, unsigned depth, leaf_parent *lp, unsigned nb);

/* For a batch, after batch_centres: the re-tests of all the leaf-parents'
 * candidates at once (lists at index pidx): the centred form on those with
 * f at their centre, then on a kinked tape the plain test on all that the
 * form left; into each one's centred[0] and plain[0]. */
void batch_retests(worker *wk, unsigned pidx, leaf_parent *lp, unsigned nb);

#endif
