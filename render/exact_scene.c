/* exact_scene: per coarse cell the surfaces present and their pruned
 * tapes (see exact_scene.h); the test of a voxel is exact_voxel.c. */
#include "render/exact_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_hess.h"

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
