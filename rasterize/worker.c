/* worker: a build thread's scratch, sized once from the build context. */
#include "rasterize/build_internal.h"

int worker_init(worker *wk, const build_ctx *c)
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
    wk->rec = calloc(c->nsurf, sizeof *wk->rec);
    wk->rec_insn = malloc((c->tape_total ? c->tape_total : 1) * sizeof *wk->rec_insn);
    wk->tapes = calloc(depths * c->nsurf, sizeof *wk->tapes);
    wk->act = calloc(depths * c->nsurf, 1);
    wk->kinked = calloc(depths * c->nsurf, 1);
    wk->nact = calloc(depths, sizeof *wk->nact);
    wk->grad = calloc(depths * c->nsurf * 3, sizeof *wk->grad);
    wk->grad_ok = calloc(depths * c->nsurf, 1);
    wk->fcen = calloc(depths * c->nsurf, sizeof *wk->fcen);
    wk->ncen = calloc(depths, sizeof *wk->ncen);
    wk->cf = malloc((size_t)c->nsurf * 4 * sizeof *wk->cf);
    wk->cf_ok = calloc(c->nsurf, 1);
    wk->cf8 = malloc((size_t)c->nsurf * 32 * sizeof *wk->cf8);
    wk->cf8_have = calloc(c->nsurf, 1);
    wk->lslots = malloc(len * sizeof *wk->lslots);
    wk->ilslots = malloc(len * sizeof *wk->ilslots);
    wk->iglslots = malloc(len * sizeof *wk->iglslots);
    const int lanes = depths * len * sizeof *wk->coarse_slots <= COARSE_LANES_BUDGET;
    if (lanes) { /* (a depth's lanes kept while its subtree is built) */
        wk->coarse_slots = malloc(depths * len * sizeof *wk->coarse_slots);
        wk->own_insn = malloc(8 * (c->tape_total ? c->tape_total : 1) * sizeof *wk->own_insn);
        wk->own_konst = malloc(8 * (c->konst_total ? c->konst_total : 1) * sizeof *wk->own_konst);
    }
    if (!wk->ilslots || !wk->iglslots || !wk->slots || !wk->slots2 || !wk->islots || !wk->dslots || !wk->lslots || !wk->scratch ||
        !wk->prune || !wk->prune_konst || !wk->rec || !wk->rec_insn || !wk->tapes || !wk->act || !wk->kinked || !wk->nact || !wk->grad ||
        !wk->grad_ok || !wk->fcen || !wk->ncen || !wk->cf || !wk->cf_ok || !wk->cf8 || !wk->cf8_have)
        return -1;
    for (unsigned s = 0; s < c->nsurf; s++) { /* index 0: the full tapes, valid everywhere */
        wk->tapes[s] = *c->full[s];
        wk->rec[s] = *c->full[s];
        wk->act[s] = (uint8_t)s;
        wk->kinked[s] = tape_has_kink(c->full[s]);
    }
    wk->nact[0] = c->nsurf;
    if (lanes && (!wk->coarse_slots || !wk->own_insn || !wk->own_konst))
        return -1;
    return 0;
}

void worker_free(worker *wk)
{
    free(wk->slots); free(wk->slots2); free(wk->islots); free(wk->dslots);
    free(wk->scratch); free(wk->prune); free(wk->prune_konst); free(wk->rec); free(wk->rec_insn); free(wk->tapes); free(wk->act); free(wk->kinked);
    free(wk->nact);
    free(wk->grad); free(wk->grad_ok); free(wk->fcen); free(wk->ncen);
    free(wk->cf); free(wk->cf_ok); free(wk->cf8); free(wk->cf8_have); free(wk->lslots);
    free(wk->ilslots); free(wk->iglslots); free(wk->coarse_slots);
    free(wk->own_insn); free(wk->own_konst);
}
