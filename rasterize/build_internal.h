/* build_internal: what the files of the octree build share (private to
 * rasterize/). build_ctx is the read-only context of one build, worker the
 * scratch of one thread, task_out what one task hands to the writer. The
 * small helpers that cross files are static inline here so the hot paths
 * inline them as they did within one file. */
#ifndef BUILD_INTERNAL_H
#define BUILD_INTERNAL_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/interval.h"
#include "common/expr/tape.h"
#include "rasterize/build.h"

/* fmin and fmax without the library call; a NaN a gives b. */
static inline double min2(double a, double b) { return a < b ? a : b; }
static inline double max2(double a, double b) { return a > b ? a : b; }

/* --- growable buffers -------------------------------------------------- */

typedef struct buf {
    uint8_t *p;
    size_t n, cap; /* in bytes */
} buf;

/* Room for n more bytes: 0, or -1 when out of memory. */
static inline int buf_reserve(buf *b, size_t n)
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
    return 0;
}

static inline int buf_push(buf *b, const void *data, size_t n)
{
    if (buf_reserve(b, n))
        return -1;
    memcpy(b->p + b->n, data, n);
    b->n += n;
    return 0;
}

/* buf_push of n <= 32 bytes of data, which holds 32: all 32 are copied (a
 * fixed-size copy is two vector moves, where GCC made the variable one a
 * rep movsb, slow to start), the length grows by n. */
static inline int buf_push_small(buf *b, const void *data, size_t n)
{
    if (buf_reserve(b, 32))
        return -1;
    memcpy(b->p + b->n, data, 32);
    b->n += n;
    return 0;
}

static inline void buf_free(buf *b)
{
    free(b->p);
    memset(b, 0, sizeof *b);
}

/* --- shared, read-only context ----------------------------------------- */

typedef struct build_ctx {
    const scene *sc;
    const build_params *par;
    unsigned levels, nsurf, task_depth;
    unsigned mv_levels;        /* build_mean_value_levels */
    double origin[3], edge;
    double cell_edge[OCT_MAX_LEVELS + 1]; /* edge / 2^depth, exact (a power-of-two scaling) */
    double bmax[3];            /* bounds' max corner: cells are clipped to it */
    const tape **full;         /* full tape of each surface */
    uint32_t *tape_off;        /* offset of each surface's prune buffer */
    uint32_t tape_total;       /* sum of tape lengths */
    uint32_t *konst_off;       /* offset of each surface's pruned constant pool */
    uint32_t konst_total;      /* sum of (constants + instructions) over the surfaces */
    uint32_t max_len;
    double *centre_ev;         /* [nsurf]: a bound on the rounding of each full tape's value in
                                  double anywhere in the cube, or NaN (centre_rounding_bounds) */
    const build_shard *shard;  /* NULL: the whole grid */
} build_ctx;

/* build.c: the context of a build with parameters p (p->levels, method,
 * shard; threads unused); -1 when memory runs out. build_ctx_free releases
 * it, also after a failed build_ctx_init. */
int build_ctx_init(build_ctx *c, const scene *sc, const build_params *p);
void build_ctx_free(build_ctx *c);

/* The Morton code of a cell at depth (its coordinates' bits interleaved,
 * x lowest). */
static inline uint64_t morton_encode(const uint64_t cell[3], unsigned depth)
{
    uint64_t m = 0;
    for (unsigned b = 0; b < depth; b++)
        m |= ((cell[0] >> b) & 1) << (3 * b) | ((cell[1] >> b) & 1) << (3 * b + 1) |
             ((cell[2] >> b) & 1) << (3 * b + 2);
    return m;
}

/* Whether the cell (depth, cell) holds part of the shard's piece: a cell at
 * or above the shard depth when its descendants there meet [lo, hi), a
 * deeper one when its ancestor there lies in it. Always 1 without a shard. */
static inline int shard_meets(const build_ctx *c, unsigned depth, const uint64_t cell[3])
{
    const build_shard *sh = c->shard;
    if (!sh)
        return 1;
    uint64_t m = morton_encode(cell, depth), first, end;
    if (depth <= sh->depth) {
        first = m << (3 * (sh->depth - depth));
        end = (m + 1) << (3 * (sh->depth - depth));
    } else {
        first = m >> (3 * (depth - sh->depth));
        end = first + 1;
    }
    return first < sh->hi && end > sh->lo;
}

/* What one task produced: the subtree below one depth-S cell. */
typedef struct task_out {
    buf masks[OCT_MAX_LEVELS];
    buf voxels, surfaces;
    int nonempty;
    int done;
} task_out;

/* 1 when t has an abs, min or max: a kink, where the gradient enclosure
 * spans both branches and the mean-value form is loose, so the plain
 * interval test may still drop a voxel the form keeps. */
static inline uint8_t tape_has_kink(const tape *t)
{
    for (uint32_t i = 0; i < t->n; i++)
        if (t->insn[i].op == TAPE_ABS || t->insn[i].op == TAPE_MIN || t->insn[i].op == TAPE_MAX)
            return 1;
    return 0;
}

/* --- per-thread state --------------------------------------------------- */

typedef struct worker {
    const build_ctx *c;
    interval *slots, *slots2;
    tape_idual *islots;
    tape_dual *dslots;
    tape_dual_lanes *lslots;
    tape_ilanes *ilslots;  /* the lane interval evaluator's scratch */
    tape_idual_lanes *iglslots; /* the lane interval gradient evaluator's */
    tape_ilanes *coarse_slots; /* [(levels + 2) * max_len], children_may_cross's, or NULL
                                  (over COARSE_LANES_BUDGET: cell_test_surviving alone) */
    tape_insn *own_insn;   /* [8 * tape_total]: child_prune's tapes, with coarse_slots */
    tape_const *own_konst; /* [8 * konst_total] */
    uint32_t *scratch;
    tape_insn *prune;      /* [(levels + 2) * tape_total] */
    tape *rec;             /* [nsurf]: the tapes the records evaluate (record_tapes) */
    tape_insn *rec_insn;   /* [tape_total]: their instructions */
    tape_const *prune_konst; /* [(levels + 2) * konst_total] */
    tape *tapes;           /* [(levels + 2) * nsurf]: index depth+1 holds the cell's tapes */
    uint8_t *act;          /* [(levels + 2) * nsurf]: surfaces that may cross the cell */
    uint8_t *kinked;       /* [(levels + 2) * nsurf]: the cell's tape of that surface has a kink
                              not known to be decided over the cell (index 0: the full tape) */
    unsigned *nact;        /* [levels + 2] */
    interval *grad;        /* [(levels + 2) * nsurf * 3]: gradient enclosure over the cell */
    double *cf;            /* [nsurf * 4]: f and its gradient at the current voxel's centre */
    uint8_t *cf_ok;        /* [nsurf]: cf holds them for that surface (voxel_surface clears) */
    double *cf8;           /* [nsurf * 8 * 4]: the same for the 8 children of a leaf-parent */
    uint8_t *cf8_have;     /* [nsurf]: the children whose cf8 entries are set, 0 on a tape with
                              a kink (their differences do not estimate second derivatives) */
    uint8_t *grad_ok;      /* [(levels + 2) * nsurf]: that enclosure is valid */
    interval *fcen;        /* [(levels + 2) * nsurf]: with it, f's enclosure at the form's centre */
    double (*ncen)[3];     /* [levels + 2]: the node's centre, the form's */
    task_out *out;
    build_stats st;
    int failed;
} worker;

/* worker.c: allocate a worker's scratch for the context c (index 0 of its
 * lists holds the full tapes); -1 when memory runs out. worker_free
 * releases it, also after a failed worker_init. */
int worker_init(worker *wk, const build_ctx *c);
void worker_free(worker *wk);

/* --- cell tests (cell_test.c) ------------------------------------------- */

typedef struct child_boxes child_boxes; /* rasterize/cell_geometry.h */

/* Tests the cell (depth, cell) for every surface that may cross its parent
 * (lists at index pidx). Fills the cell's lists at index depth + 1 and, when
 * it will be subdivided, its pruned tapes; box and centre receive the cell's
 * box. Returns how many surfaces may cross it. */
unsigned cell_test_surviving(worker *wk, unsigned pidx, unsigned depth, const uint64_t cell[3],
                             interval box[3], double centre[3]);

/* What a worker may spend on children_may_cross's lanes, kept for every
 * depth (128 bytes an instruction and a depth): a longer tape or a deeper
 * tree keeps the scalar test (cell_test_surviving). */
#define COARSE_LANES_BUDGET (1u << 20)

/* The children of a node above the mean-value levels, tested together
 * (children_may_cross) and taken one at a time (child_take). */
typedef struct coarse_children {
    uint64_t cell[8][3];   /* set by the caller */
    interval box[8][3];
    double centre[8][3];
    unsigned flags[8];
    uint8_t slot_lane[8];  /* a child's lane */
    tape tape[8];          /* child_prune's */
    uint8_t kinked[8];
} coarse_children;

/* With one surface and the interval method: the plain test of the children
 * of the node (depth) named by want (cc->cell set for them), together in
 * the lane evaluator; their slot enclosures stay in the worker for
 * child_take. Returns the children that may be crossed, the same bits and
 * counts as cell_test_surviving on each. Needs wk->coarse_slots. */
uint8_t children_may_cross(worker *wk, unsigned depth, uint8_t want, coarse_children *cc);
/* What cell_test_surviving leaves for child i of cc that may be crossed:
 * its lists and pruned tape at index depth + 2. */
void child_take(worker *wk, unsigned depth, const coarse_children *cc, unsigned i);
/* Child i's pruned tape as child_take makes it, into cc->tape[i] (and
 * cc->kinked[i]), its instructions in the worker's slot i for them, which
 * the next node's child_prune overwrites: only for children whose subtrees
 * prune no further, the mean-value levels' first nodes (their forms are
 * then made together). */
void child_prune(worker *wk, unsigned depth, coarse_children *cc, unsigned i);

/* The tapes the records of the voxels under the node (lists at index idx,
 * box) evaluate, into wk->rec: each surface's full tape with the min, max
 * and abs that its enclosures over the box decide pruned away, and nothing
 * else (tape_prune), so f and its gradient at any point of the box keep the
 * full tape's bits. */
void record_tapes(worker *wk, unsigned idx, const interval box[3]);

/* A cell to test: its box, its centre, f at the centre in double (for the
 * centred form). */
typedef struct retest_item {
    const interval *box;
    const double *centre;
    double fd;
} retest_item;

/* The tests of n cells for surface s (tape t), run TAPE_LANES at a time with
 * the lane interval evaluator (one alone with the scalar one); drop[j]
 * receives 1 when cell j is proved empty of the surface. centred_form_drops:
 * the mean-value form centred on each voxel, f([c]) + G . (box - c), G the
 * parent's gradient enclosure and fd f(c) in double (cell_test.c); where ev
 * is not NaN (centre_err), fd +- ev stands for f([c]), no evaluation.
 * plain_test_drops: the plain interval test over each cell's box (no point of
 * the surface where f is defined), on voxels or on a node's children. Same
 * decisions and counts as testing the cells one by one. */
/* Bit i set for the children i in cand (their boxes in cb) that
 * centred_form_drops would keep whatever f at their centres is found to be,
 * from the node's form (fc at centre c, G) alone: then f there need not be
 * evaluated (an fd of NaN keeps it). */
uint8_t centred_form_cannot_exclude(interval fc, const interval G[3], const double c[3],
                                    const child_boxes *cb, uint8_t cand);
void centred_form_drops(worker *wk, const tape *t, const interval G[3], double ev,
                        const retest_item *it, unsigned n, uint8_t *drop);
void plain_test_drops(worker *wk, const tape *t, unsigned s, const retest_item *it, unsigned n,
                      uint8_t *drop);

/* The mean-value enclosures of the eight children of the node (depth, cell)
 * with box pbox, the form centred on fcc: bit i of *fx set when child i's
 * excludes 0. Without reuse, G and fc
 * receive the gradient enclosure over the node and f's enclosure at fcc, the
 * node's centre; with reuse they hold those of a box holding the node (its
 * parent's), centred on fcc. 0 when unavailable. */
int child_enclosures(worker *wk, const tape *t, const interval pbox[3], unsigned depth,
                     const uint64_t cell[3], const double fcc[3], interval *fc, interval G[3],
                     int reuse, uint8_t *fx);

/* A node's own mean-value form, as child_enclosures makes it without
 * reuse: G over its box, fc = f([c]) at its centre; ok 0 where either may
 * be undefined. kinked: the tape has a kink the enclosures over the node's
 * box do not decide (tape_prune_kinks' rules; 1 where flagged). */
typedef struct node_form {
    interval fc, G[3];
    int ok;
    uint8_t kinked;
} node_form;

/* The forms of n <= TAPE_LANES nodes (boxes box, centres centre) on one
 * tape, their gradient enclosures in one pass of the lane interval gradient
 * evaluator, their centres' in one of the lane interval evaluator: the same
 * bits as child_enclosures makes node by node. kinks: whether t may have an
 * undecided kink at all (else every nf[j].kinked is 0). */
void node_forms(worker *wk, const tape *t, int kinks, unsigned n, interval box[][3],
                const double centre[][3], node_form *nf);

/* --- voxels (voxel_normal.c) -------------------------------------------- */

/* A voxel's Newton iteration towards f = 0 (voxel_normal.c). */
typedef struct newton {
    double p[3], f, g[3]; /* the iterate and f, grad f there */
    double fg[4];         /* f and grad f at the centre */
    int step;
} newton;

/* f and its gradient at the voxel centre for surface s, into wk->cf.
 * Normals, plane offsets and the surface choice take the whole function's
 * bits (the record tape, record_tapes), not the cell's pruned tape: a term
 * frozen into a constant kept f's value to a thousandth of a voxel but lost
 * its gradient, which skews the normals and offsets (docs/perf-log.md,
 * rasterize). */
static inline const double *centre_fg(worker *wk, unsigned s, const double centre[3])
{
    double *fg = wk->cf + 4 * (size_t)s;
    if (!wk->cf_ok[s]) {
        fg[0] = tape_eval_grad(&wk->rec[s], centre, fg + 1, wk->dslots);
        wk->st.point_evals++;
        wk->cf_ok[s] = 1;
    }
    return fg;
}

/* The surface a voxel belongs to (lists at index idx): with several, the
 * one nearest its centre by the first-order distance |f| / |grad f|. Starts
 * its Newton iteration and forgets the centre values (wk->cf). */
unsigned voxel_surface(worker *wk, unsigned idx, const double centre[3], newton *nw);

/* --shell-only: the voxel's surface without a record (no normal, no Newton
 * steps); forgets the centre values as voxel_surface does. */
unsigned shell_surface(worker *wk, unsigned idx, const double centre[3]);

/* Appends the voxel's record (lists at index levels + 1). 0 when memory
 * runs out (then wk->failed is set). */
int emit_voxel(worker *wk, const interval box[3], const double centre[3]);

/* The records of a leaf-parent's np voxels (children child[j], surfaces
 * surf[j], iterations started in nw[j]), appended in child order. Where the
 * siblings' centre gradients (wk->cf8) give a Hessian, one Newton step on the
 * second-order model about the centre; elsewhere the Newton steps of all of
 * them that still move are evaluated together, one pass over the tape per
 * round (tape_eval_grad_lanes). */
void emit_voxels(worker *wk, const child_boxes *cb, const uint8_t *child, const uint8_t *surf,
                 newton *nw, unsigned np);

/* One leaf-parent of a single-surface batch for batch_records: its
 * children's boxes (made for the children kept), the children kept (keep),
 * f and grad f at their centres (child i at cf8[4 i]), and the children whose
 * values may give second differences (have; 0 on a tape with a kink). */
typedef struct leaf_voxels {
    const child_boxes *cb;
    const double *cf8;
    uint8_t keep, have;
} leaf_voxels;

/* The records of the voxels of nb leaf-parents of a single-surface scene,
 * appended leaf-parent by leaf-parent, each in child order: what
 * emit_voxels makes of each, except that a leaf-parent whose children give
 * no second differences along some axis takes the entries of its Hessian
 * it cannot make from the nearest of them that has a whole one; the Newton
 * evaluations of the rest pooled into passes of TAPE_LANES points. At most
 * 8 leaf-parents. */
void batch_records(worker *wk, const leaf_voxels *lv, unsigned nb);

/* --- the recursion (subdivide.c) ---------------------------------------- */

/* Builds the subtree of task cell `task` (Morton code at the task depth)
 * into out. */
void run_task(worker *wk, uint64_t task, task_out *out);

#endif
