/* exact_sub: sub-cells of the coarse cells, made on first use per worker
 * (see exact_sub.h). */
#include "render/exact_sub.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/exact_scene.h"

#define FAN (1u << (3 * EXACT_SUB_STEP)) /* sub-cells of a sub-cell */
#define NONE UINT32_MAX
#define CHUNK_INSNS (1u << 16)

struct exact_sub_node {
    double hmag[TAPE_HN];
    const tape_insn *insn; /* the sub-cell's tape: the cell's, an ancestor's or its own */
    uint32_t n, root;
    uint32_t child; /* block of its own sub-cells, NONE: not made yet */
    int empty;      /* the surface has no point in the sub-cell */
    unsigned kinks; /* tape_hess_kinks of its tape over its box */
};

int exact_sub_init(exact_sub_cache *c, uint32_t ncand, uint32_t max_n)
{
    memset(c, 0, sizeof *c);
    if (max_n < 1)
        max_n = 1;
    c->ncand = ncand;
    c->max_nodes = EXACT_SUB_NODES;
    c->chunk_size = max_n > CHUNK_INSNS ? max_n : CHUNK_INSNS;
    c->top = exact_line_alloc((size_t)ncand + 1, sizeof *c->top);
    c->islots = exact_line_alloc(max_n, sizeof *c->islots);
    c->hslots = exact_line_alloc(max_n, sizeof *c->hslots);
    c->tmp_insn = exact_line_alloc(max_n, sizeof *c->tmp_insn);
    c->tmp_mark = exact_line_alloc(max_n, sizeof *c->tmp_mark);
    if (!c->top || !c->islots || !c->hslots || !c->tmp_insn || !c->tmp_mark) {
        exact_sub_free(c);
        return -1;
    }
    memset(c->top, 0xff, ((size_t)ncand + 1) * sizeof *c->top);
    memset(c->last_k, 0xff, sizeof c->last_k);
    return 0;
}

void exact_sub_free(exact_sub_cache *c)
{
    for (uint32_t k = 0; k < c->nchunk; k++)
        free(c->chunk[k]);
    free(c->chunk);
    free(c->node);
    free(c->block);
    free(c->top);
    free(c->islots);
    free(c->hslots);
    free(c->tmp_insn);
    free(c->tmp_mark);
    memset(c, 0, sizeof *c);
}

static void reset(exact_sub_cache *c)
{
    c->nnode = 0;
    c->nblock = 0;
    c->cur = 0;
    c->chunk_used = 0;
    memset(c->top, 0xff, ((size_t)c->ncand + 1) * sizeof *c->top);
    memset(c->last_k, 0xff, sizeof c->last_k);
    c->resets++;
}

void exact_sub_reserve(exact_sub_cache *c)
{
    if (c->nnode >= c->max_nodes || (uint64_t)c->cur * c->chunk_size >= EXACT_SUB_INSNS)
        reset(c);
}

static int grow(void **p, uint32_t *cap, uint32_t need, size_t size)
{
    if (need <= *cap)
        return 0;
    uint32_t n = *cap ? *cap : 256;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, (size_t)n * size);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

/* A new block of FAN sub-cells, none made: its index, or NONE. */
static uint32_t new_block(exact_sub_cache *c)
{
    if (grow((void **)&c->block, &c->cap_block, (c->nblock + 1) * FAN, sizeof *c->block))
        return NONE;
    memset(c->block + (size_t)c->nblock * FAN, 0xff, FAN * sizeof *c->block);
    return c->nblock++;
}

/* Room for n instructions that will not move until the next reset. */
static tape_insn *arena(exact_sub_cache *c, uint32_t n)
{
    if (c->cur < c->nchunk && c->chunk_used + n > c->chunk_size) {
        c->cur++;
        c->chunk_used = 0;
    }
    if (c->cur == c->nchunk) {
        if (grow((void **)&c->chunk, &c->cap_chunk, c->nchunk + 1, sizeof *c->chunk))
            return NULL;
        c->chunk[c->nchunk] = malloc((size_t)c->chunk_size * sizeof **c->chunk);
        if (!c->chunk[c->nchunk])
            return NULL;
        c->nchunk++;
        c->chunk_used = 0;
    }
    tape_insn *p = c->chunk[c->cur] + c->chunk_used;
    c->chunk_used += n;
    return p;
}

/* The sub-cell of depth `depth` with corner cc (in cells of that depth),
 * from its parent's tape p: its enclosure of f over the sub-cell's box
 * (the box every span tested there lies in) says whether the surface can be
 * there; p pruned with that evaluation's slot enclosures (a min/max whose
 * operands separate keeps its winner: bit for bit p's value at every point
 * of the box, tape_prune) and the Hessian bound of the pruned tape. Its
 * index, or NONE when out of memory. */
static uint32_t make_node(exact_sub_cache *c, const exact_scene *es, const exact_cand *cd,
                          const tape *p, unsigned depth, const uint32_t cc[3])
{
    if (grow((void **)&c->node, &c->cap_node, c->nnode + 1, sizeof *c->node))
        return NONE;
    exact_sub_node *nd = &c->node[c->nnode];
    interval box[3];
    exact_scene_box(es, depth, cc, box);
    unsigned flags = 0;
    const interval F = tape_eval_interval(p, box, c->islots, &flags);
    nd->insn = p->insn;
    nd->n = p->n;
    nd->root = p->root;
    nd->child = NONE;
    nd->empty = interval_is_nan(F) || F.lo > 0.0 || F.hi < 0.0;
    nd->kinks = 0;
    for (int e = 0; e < TAPE_HN; e++)
        nd->hmag[e] = INFINITY;
    if (!nd->empty) {
        tape q;
        tape_prune(p, c->islots, flags, c->tmp_insn, c->tmp_mark, &q);
        if (q.n < p->n) {
            tape_insn *dst = arena(c, q.n);
            if (!dst)
                return NONE;
            memcpy(dst, q.insn, q.n * sizeof *dst);
            q.insn = dst;
            nd->insn = dst;
            nd->n = q.n;
            nd->root = q.root;
        }
        q.insn = nd->insn;
        /* the cell's bound with kinks allowed holds where none is left (the
         * cheap way); without one (f may be undefined in the cell), the
         * sub-cell's own enclosure */
        /* (from p's evaluation above; a flagged one, rare, again on q) */
        nd->kinks = flags ? tape_hess_kinks(&q, box, c->islots)
                          : tape_prune_kinks(p, c->islots, c->tmp_mark, &q);
        if (!(cd->hbranch[0] < INFINITY))
            tape_hess_mag(&q, box, c->hslots, nd->hmag);
        else if (!nd->kinks)
            memcpy(nd->hmag, cd->hbranch, sizeof nd->hmag);
    }
    c->made++;
    return c->nnode++;
}

static void region_of(exact_region *out, const exact_cand *cd, const exact_sub_node *nd,
                      uint64_t key)
{
    out->t = cd->t;
    out->t.insn = nd->insn;
    out->t.n = nd->n;
    out->t.root = nd->root;
    /* the interval that drops segments: the shorter of the sub-cell's tape
     * and the cell's culling tape (both enclose f on the sub-cell) */
    out->cull = nd->n <= cd->cull.n ? out->t : cd->cull;
    memcpy(out->hmag, nd->hmag, sizeof out->hmag);
    out->key = key;
    out->empty = nd->empty;
}

/* *out: candidate cd's coarse cell, the one holding voxel v */
static void coarse_region(exact_region *out, const exact_scene *es, const exact_cand *cd,
                          const uint32_t v[3])
{
    out->t = cd->t;
    out->cull = cd->cull;
    memcpy(out->hmag, cd->hmag, sizeof out->hmag);
    out->key = 0;
    out->empty = 0;
    out->depth = es->depth;
    out->shift = es->tree->levels - es->depth;
    for (int a = 0; a < 3; a++)
        out->corner[a] = v[a] >> out->shift;
}

/* (exact_sub_find without the last regions; -1: out of memory; out of
 * line, as the last region is mostly the one) */
static __attribute__((noinline)) int lookup(exact_sub_cache *c, const exact_scene *es,
                                            uint32_t k, const uint32_t v[3], exact_region *out)
{
    const exact_cand *cd = &es->cand[k];
    const unsigned L = es->tree->levels, D = es->depth;
    if (!es->sub_max || cd->hmag[0] < INFINITY || !exact_sub_wanted(cd->kinks)) {
        coarse_region(out, es, cd, v);
        return 0;
    }
    uint32_t owner = NONE; /* the node whose block is searched; NONE: the candidate's */
    tape p = cd->t;
    for (unsigned r = 0;;) {
        const unsigned s = es->sub_max - r < EXACT_SUB_STEP ? es->sub_max - r : EXACT_SUB_STEP;
        r += s;
        uint32_t b = owner == NONE ? c->top[k] : c->node[owner].child;
        if (b == NONE) {
            if ((b = new_block(c)) == NONE) {
                coarse_region(out, es, cd, v);
                return -1;
            }
            if (owner == NONE)
                c->top[k] = b;
            else
                c->node[owner].child = b;
        }
        const unsigned shift = L - D - r;
        uint32_t cc[3], idx = 0;
        for (int a = 0; a < 3; a++) {
            cc[a] = v[a] >> shift;
            idx |= (cc[a] & ((UINT32_C(1) << s) - 1u)) << (a * s);
        }
        uint32_t i = c->block[(size_t)b * FAN + idx];
        if (i == NONE) {
            if ((i = make_node(c, es, cd, &p, D + r, cc)) == NONE) {
                coarse_region(out, es, cd, v);
                return -1;
            }
            c->block[(size_t)b * FAN + idx] = i;
        }
        const exact_sub_node *nd = &c->node[i];
        /* (deeper only while a min/max or a flag is in the way and no abs:
         * see exact_sub_wanted) */
        if (nd->empty || nd->hmag[0] < INFINITY || r >= es->sub_max ||
            !exact_sub_wanted(nd->kinks)) {
            const uint64_t key = (uint64_t)r << 60 | (uint64_t)cc[2] << 40 |
                                 (uint64_t)cc[1] << 20 | cc[0];
            region_of(out, cd, nd, key);
            out->depth = D + r;
            out->shift = L - D - r;
            memcpy(out->corner, cc, sizeof cc);
            return 0;
        }
        p.insn = nd->insn;
        p.n = nd->n;
        p.root = nd->root;
        owner = i;
    }
}

const exact_region *exact_sub_find(exact_sub_cache *c, const exact_scene *es, uint32_t k,
                                   const uint32_t v[3])
{
    const uint32_t i = k % EXACT_SUB_LAST;
    exact_region *r = &c->last[i];
    const unsigned s = r->shift;
    if (c->last_k[i] == k &&
        !((v[0] >> s ^ r->corner[0]) | (v[1] >> s ^ r->corner[1]) | (v[2] >> s ^ r->corner[2])))
        return r;
    /* (out of memory: the coarse cell's, in *r, not remembered) */
    c->last_k[i] = lookup(c, es, k, v, r) == 0 ? k : UINT32_MAX;
    return r;
}
