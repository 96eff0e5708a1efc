/* build: the public entry point, the thread pool and the streaming order.
 *
 * Tasks are the cells of depth S (up to 512); a worker builds a whole
 * subtree depth-first (subdivide.c), which emits every depth's nodes in
 * Morton order. The calling thread appends finished subtrees to the writer
 * in task order, so the file does not depend on the number of threads, then
 * adds the few nodes above depth S. */
#include "rasterize/build.h"

#include <math.h>
#include <pthread.h>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_err_cell.h"
#include "rasterize/build_internal.h"

#define TASK_DEPTH 3          /* 8^3 = 512 subtrees: enough to balance two cores */

typedef struct pool {
    const build_ctx *c;
    task_out *tasks;
    uint64_t ntasks;
    atomic_uint_fast64_t next;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    build_stats st;
    int failed;
} pool;

static void stats_add(build_stats *a, const build_stats *b)
{
    a->voxels += b->voxels;
    a->nodes += b->nodes;
    a->interval_evals += b->interval_evals;
    a->gradient_evals += b->gradient_evals;
    a->point_evals += b->point_evals;
    a->insns_evaluated += b->insns_evaluated;
    a->insns_full += b->insns_full;
    a->taylor_drops += b->taylor_drops;
    a->nan_cells += b->nan_cells;
    a->normal_fallbacks += b->normal_fallbacks;
}

/* Subnormal operands and results cost a microcode assist each on x86, and
 * blobs such as exp(-196 (x - a)^4) underflow into them all over space. The
 * workers flush them to zero (FTZ and DAZ). That stays sound: every interval
 * bound is stepped outward after each operation, and a step from 0 reaches
 * +-DBL_MIN, beyond any flushed value (common/expr/interval.h). */
static void flush_subnormals(void)
{
#if defined(__SSE2__)
    _mm_setcsr(_mm_getcsr() | 0x8040u); /* FTZ (bit 15) | DAZ (bit 6) */
#endif
}

static void *worker_main(void *arg)
{
    pool *pl = arg;
    flush_subnormals();
    worker wk;
    int failed = worker_init(&wk, pl->c) != 0;
    for (;;) {
        uint64_t t = atomic_fetch_add(&pl->next, 1);
        if (t >= pl->ntasks)
            break;
        if (!failed) {
            run_task(&wk, t, &pl->tasks[t]);
            failed = wk.failed;
        }
        pthread_mutex_lock(&pl->lock);
        pl->tasks[t].done = 1;
        pl->failed |= failed;
        pthread_cond_broadcast(&pl->cond);
        pthread_mutex_unlock(&pl->lock);
    }
    pthread_mutex_lock(&pl->lock);
    stats_add(&pl->st, &wk.st);
    pl->failed |= failed;
    pthread_mutex_unlock(&pl->lock);
    worker_free(&wk);
    return NULL;
}

/* Nodes above the task depth, from which tasks came out non-empty. */
static oct_err add_upper_levels(const build_ctx *c, const uint8_t *nonempty, oct_writer *w,
                                build_stats *st)
{
    uint64_t n = (uint64_t)1 << (3 * c->task_depth);
    uint8_t *cur = malloc(n), *up = malloc(n / 8 + 1);
    if (!cur || !up) {
        free(cur); free(up);
        return OCT_ENOMEM;
    }
    memcpy(cur, nonempty, n);
    oct_err err = OCT_OK;
    for (unsigned d = c->task_depth; d-- > 0 && err == OCT_OK;) {
        n /= 8;
        for (uint64_t u = 0; u < n && err == OCT_OK; u++) {
            uint8_t mask = 0;
            for (unsigned i = 0; i < 8; i++)
                mask |= (uint8_t)((cur[8 * u + i] ? 1u : 0u) << i);
            up[u] = mask != 0;
            if (mask) {
                err = oct_writer_add_masks(w, d, &mask, 1);
                st->nodes++;
            }
        }
        memcpy(cur, up, n);
    }
    free(cur);
    free(up);
    return err;
}

void build_cube(const scene *sc, double origin[3], double *edge)
{
    double e = 0.0;
    for (int k = 0; k < 3; k++) {
        origin[k] = sc->lo[k];
        e = fmax(e, sc->hi[k] - sc->lo[k]);
    }
    *edge = e;
}

void build_writer_params(const scene *sc, unsigned levels, float palette[3 * OCT_MAX_SURFACES],
                         oct_writer_params *wp)
{
    memset(wp, 0, sizeof *wp);
    wp->levels = levels;
    build_cube(sc, wp->origin, &wp->edge);
    wp->surface_count = (uint32_t)sc->nsurfaces;
    for (size_t s = 0; s < sc->nsurfaces && s < OCT_MAX_SURFACES; s++)
        for (int k = 0; k < 3; k++)
            palette[3 * s + k] = (float)sc->surfaces[s].color[k];
    wp->palette = palette;
}

/* For each surface whose full tape has no kink (abs, min, max), an
 * a-priori bound on the rounding error of its value in double at every
 * point of the cube (tape_err_cell), into c->centre_ev; NaN for the others
 * and where none is made. The centred re-tests take f at a voxel centre as
 * that value within it (centre_err, rasterize/voxel_retest.c). -1 when
 * memory runs out. */
static int centre_rounding_bounds(build_ctx *c)
{
    c->centre_ev = malloc(c->nsurf * sizeof *c->centre_ev);
    tape_idual *g = malloc((c->max_len ? c->max_len : 1) * sizeof *g);
    tape_cerr *e = malloc((c->max_len ? c->max_len : 1) * sizeof *e);
    const int ok = c->centre_ev && g && e;
    interval cube[3];
    for (int k = 0; k < 3; k++)
        cube[k] = (interval){c->origin[k], c->origin[k] + c->edge};
    for (unsigned s = 0; ok && s < c->nsurf; s++) {
        tape_cell_err ce;
        c->centre_ev[s] = NAN;
        if (!tape_has_kink(c->full[s]) && tape_err_cell(c->full[s], cube, &ce, g, e))
            c->centre_ev[s] = ce.ev;
    }
    free(g);
    free(e);
    return ok ? 0 : -1;
}

#define MEAN_VALUE_LEVELS_SMOOTH 5 /* one kink-free surface: pruning barely shortens its tape */
#define MEAN_VALUE_LEVELS_KINKED 3 /* otherwise: pruning above them decides min, max and abs */
_Static_assert(MEAN_VALUE_LEVELS_SMOOTH >= 2 && MEAN_VALUE_LEVELS_KINKED >= 2,
               "leaf-parents reuse their parent's gradient enclosure");

unsigned build_mean_value_levels(const scene *sc, build_method method)
{
    if (method != BUILD_INTERVAL || sc->nsurfaces != 1 || tape_has_kink(&sc->surfaces[0].tape))
        return MEAN_VALUE_LEVELS_KINKED;
    return MEAN_VALUE_LEVELS_SMOOTH;
}

int build_ctx_init(build_ctx *c, const scene *sc, const build_params *p)
{
    memset(c, 0, sizeof *c);
    c->sc = sc;
    c->par = p;
    c->shard = p->shard;
    c->levels = p->levels;
    c->nsurf = (unsigned)sc->nsurfaces;
    c->task_depth = p->levels - 1 < TASK_DEPTH ? p->levels - 1 : TASK_DEPTH;
    c->mv_levels = build_mean_value_levels(sc, p->method);
    build_cube(sc, c->origin, &c->edge);
    for (int k = 0; k < 3; k++)
        c->bmax[k] = sc->hi[k];
    for (unsigned d = 0; d <= c->levels; d++)
        c->cell_edge[d] = ldexp(c->edge, -(int)d);
    c->full = calloc(c->nsurf, sizeof *c->full);
    c->tape_off = calloc(c->nsurf, sizeof *c->tape_off);
    c->konst_off = calloc(c->nsurf, sizeof *c->konst_off);
    if (!c->full || !c->tape_off || !c->konst_off)
        return -1;
    for (unsigned s = 0; s < c->nsurf; s++) {
        c->full[s] = &sc->surfaces[s].tape;
        c->tape_off[s] = c->tape_total;
        c->tape_total += c->full[s]->n;
        if (c->full[s]->n > c->max_len)
            c->max_len = c->full[s]->n;
        c->konst_off[s] = c->konst_total;
        c->konst_total += c->full[s]->nconst + c->full[s]->n;
    }
    return centre_rounding_bounds(c);
}

void build_ctx_free(build_ctx *c)
{
    free(c->full);
    free(c->tape_off);
    free(c->konst_off);
    free(c->centre_ev);
    memset(c, 0, sizeof *c);
}

oct_err build_octree(const scene *sc, const build_params *p, oct_writer *w, build_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    build_ctx c;
    oct_err err = OCT_ENOMEM;
    pool pl;
    memset(&pl, 0, sizeof pl);
    uint8_t *nonempty = NULL;
    pthread_t *th = NULL;
    unsigned started = 0;
    if (build_ctx_init(&c, sc, p) != 0)
        goto done;

    pl.c = &c;
    pl.ntasks = (uint64_t)1 << (3 * c.task_depth);
    pl.tasks = calloc(pl.ntasks, sizeof *pl.tasks);
    nonempty = calloc(pl.ntasks, 1);
    th = calloc(p->threads, sizeof *th);
    if (!pl.tasks || !nonempty || !th)
        goto done;
    atomic_init(&pl.next, 0);
    pthread_mutex_init(&pl.lock, NULL);
    pthread_cond_init(&pl.cond, NULL);
    for (; started < p->threads; started++)
        if (pthread_create(&th[started], NULL, worker_main, &pl) != 0)
            break;
    if (started == 0) {
        worker_main(&pl); /* no thread could start: do the work here */
    }

    /* Append finished subtrees in task order while the workers go on. */
    err = OCT_OK;
    for (uint64_t t = 0; t < pl.ntasks; t++) {
        pthread_mutex_lock(&pl.lock);
        while (!pl.tasks[t].done)
            pthread_cond_wait(&pl.cond, &pl.lock);
        int failed = pl.failed;
        pthread_mutex_unlock(&pl.lock);
        task_out *o = &pl.tasks[t];
        if (failed && err == OCT_OK)
            err = OCT_ENOMEM;
        if (err == OCT_OK && o->nonempty) {
            nonempty[t] = 1;
            for (unsigned d = c.task_depth; d < c.levels && err == OCT_OK; d++)
                err = oct_writer_add_masks(w, d, o->masks[d].p, o->masks[d].n);
            if (err == OCT_OK)
                err = oct_writer_add_voxels(w, (const uint32_t *)(const void *)o->voxels.p,
                                            c.nsurf > 1 ? o->surfaces.p : NULL,
                                            o->voxels.n / sizeof(uint32_t));
        }
        for (unsigned d = 0; d < OCT_MAX_LEVELS; d++)
            buf_free(&o->masks[d]);
        buf_free(&o->voxels);
        buf_free(&o->surfaces);
        if (p->progress)
            p->progress(p->progress_ctx, (double)(t + 1) / (double)pl.ntasks);
    }
    for (unsigned i = 0; i < started; i++)
        pthread_join(th[i], NULL);
    if (pl.failed && err == OCT_OK)
        err = OCT_ENOMEM;
    stats_add(stats, &pl.st);
    if (err == OCT_OK)
        err = add_upper_levels(&c, nonempty, w, stats);
    pthread_mutex_destroy(&pl.lock);
    pthread_cond_destroy(&pl.cond);
done:
    free(th);
    free(nonempty);
    free(pl.tasks);
    build_ctx_free(&c);
    return err;
}
