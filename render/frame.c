/* frame: multi-threaded tile renderer for one view. */
#include "render/frame.h"
#include "render/frame_impl.h"
#include "render/frame_srgb.h"

#include <errno.h>
#include <float.h>
#include <pthread.h>
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include "common/limits.h"
#include "common/test_hooks.h"
#include "render/ao.h"
#include "render/beam.h"
#include "render/map_guard.h"
#include "render/shadow.h"

/* What the threads of a frame share and change. */
typedef struct frame_sync {
    /* A band of tiles a thread (frame_bands_init): its first tile (low 32
     * bits) and one past its last (high 32 bits). */
    atomic_uint_fast64_t band[THREADS_MAX];
    unsigned nbands; /* the pass's threads (at most THREADS_MAX) */
    atomic_uint next_slot; /* a thread's band and exact worker */
    atomic_uint_fast64_t done;
    atomic_int changed; /* set when map_guard abandoned a thread's work */
    pthread_mutex_t lock; /* guards the sums below */
    frame_acc sum;
    double pass_ns; /* thread time of the passes, secondary rays left out */
    double shadow_ns, ao_ns, sample_ns; /* the threads' frame_acc ticks, in ns */
    exact_worker *exact; /* with --exact: one per thread of a pass, else NULL */
} frame_sync;

/* The tiles split into one band a thread (a run of tiles in row order),
 * each taken from its front by its own thread and from its back by threads whose
 * band is done: a thread meets the same part of the image frame after
 * frame, and the threads' parts are apart, so that what a thread keeps
 * (its --exact worker's sub-cells) is made once and stays warm, where tiles
 * dealt out in turn make each thread build what the other did. Which
 * thread renders a tile never changes its pixels. */
static void frame_bands_init(frame_sync *sy, uint64_t total)
{
    for (unsigned k = 0; k < sy->nbands; k++) {
        const uint64_t a = total * k / sy->nbands, b = total * (k + 1) / sy->nbands;
        atomic_store(&sy->band[k], b << 32 | a);
    }
}

/* A tile of band r, from its front or (back) its back: 1, or 0 when the
 * band is done. */
static int band_take(atomic_uint_fast64_t *r, int back, uint64_t *tile)
{
    uint_fast64_t cur = atomic_load_explicit(r, memory_order_relaxed);
    for (;;) {
        const uint64_t a = cur & 0xffffffffu, b = cur >> 32;
        if (a >= b)
            return 0;
        const uint64_t nxt = back ? (b - 1) << 32 | a : b << 32 | (a + 1);
        if (atomic_compare_exchange_weak(r, &cur, nxt)) {
            *tile = back ? b - 1 : a;
            return 1;
        }
    }
}

/* The next tile for the thread of band `own`: its band's front, then the
 * back of the others in turn. */
static int next_tile(frame_sync *sy, unsigned own, uint64_t *tile)
{
    for (unsigned k = 0; k < sy->nbands; k++)
        if (band_take(&sy->band[(own + k) % sy->nbands], k != 0, tile))
            return 1;
    return 0;
}

double frame_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

#if defined(__x86_64__) || defined(__i386__)
double frame_ticks(void)
{
    return (double)__rdtsc();
}
#else
double frame_ticks(void)
{
    return frame_now_ns();
}
#endif

/* Pixel (i, j)'s probe in the tile's. */
static inline aa_probe *tile_probe(frame_tile *tl, uint32_t i, uint32_t j)
{
    return &tl->p[(size_t)(j - tl->j0) * FRAME_TILE + (i - tl->i0)];
}

/* A sub-block start as the probes keep it: rounded down, never late. */
static float tile_start(double t_lo)
{
    float f = (float)t_lo;
    if ((double)f > t_lo)
        f = nextafterf(f, -INFINITY);
    return f;
}

/* Traces, shades and stores pixel (i, j)'s centre ray; r is its prepared
 * ray, or NULL for a ray known to miss; t_lo its sub-block's start
 * (tile_start). */
static inline void render_pixel(const frame_shared *sh, frame_acc *acc, uint32_t i, uint32_t j,
                                const double dir[3], const trace_ray *r, const trace_anchor *an,
                                float t_lo)
{
    const frame_job *job = sh->job;
    trace_hit h;
    if (r) {
        sh->traverse(job->tree, &job->opts, r, an, &h);
    } else { /* trace_ray_cast's miss */
        h.hit = 0;
        h.t = INFINITY;
        h.steps = 0;
    }
    float rgb[3], n[3];
    frame_shade_sample(sh, acc, &h, dir, i, j, 0, job->shade.ao_rays, job->shade.ao_rays, rgb, n);
    const size_t px = (size_t)j * job->cam->width + i;
    for (int a = 0; a < 3; a++)
        job->rgb[3 * px + (size_t)a] = frame_srgb8_ready(rgb[a]);
    if (job->depth)
        job->depth[px] = h.t > FLT_MAX ? (isinf(h.t) ? INFINITY : FLT_MAX) : (float)h.t;
    if (job->normals)
        for (int a = 0; a < 3; a++)
            job->normals[3 * px + (size_t)a] =
                h.hit ? (uint8_t)((n[a] * 0.5f + 0.5f) * 255.0f + 0.5f) : 0;
    if (job->normals_f)
        for (int a = 0; a < 3; a++)
            job->normals_f[3 * px + (size_t)a] = h.hit ? n[a] : 0.0f;
    if (job->alpha)
        job->alpha[px] = h.hit ? 255 : 0;
    if (sh->tile) {
        aa_probe *p = tile_probe(sh->tile, i, j);
        p->hit = (uint8_t)h.hit;
        p->need = 0;
        p->t = h.hit ? (float)h.t : INFINITY;
        p->surface = shade_surface(job->tree, &h);
        for (int a = 0; a < 3; a++)
            p->n[a] = n[a];
        p->t_lo = t_lo;
    }
    acc->hits += (uint64_t)h.hit;
    acc->steps += h.steps;
}

/* The beam's edge trigger (aa.h): a sub-block whose pyramid may meet an
 * occupied voxel though none of its centre rays hit one holds something
 * between them, so each of its pixels [i0, i1) x [j0, j1) is sampled. */
static void mark_beam_edge(const frame_shared *sh, frame_acc *acc, uint32_t i0, uint32_t i1,
                           uint32_t j0, uint32_t j1)
{
    for (uint32_t j = j0; j < j1; j++)
        for (uint32_t i = i0; i < i1; i++)
            tile_probe(sh->tile, i, j)->need = 1;
    acc->marked++;
}

/* The pixels [i0, i1) x [j0, j1): with the beam, each sub-block's rays are
 * traced from its start only, from its anchor, and none at all when its
 * pyramid touches no occupied cell. */
static void render_block(const frame_shared *sh, frame_acc *acc, const trace_eye *eye,
                         const double *us, uint32_t us0, uint32_t i0, uint32_t i1, uint32_t j0,
                         uint32_t j1)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    beam_grid g;
    int any = 1;
    if (job->beam_size) {
        any = beam_starts(job->tree, cam, i0, i1, j0, j1, &g);
    } else { /* one sub-block, the whole ray */
        g.cols = g.rows = 1;
        g.col[0] = i0;
        g.col[1] = i1;
        g.row[0] = j0;
        g.row[1] = j1;
        g.t_lo[0][0] = 0.0;
    }
    if (!any) { /* every ray misses: shade one miss (no direction needed), copy it */
        render_pixel(sh, acc, i0, j0, cam->forward, NULL, NULL, INFINITY);
        const size_t p0 = (size_t)j0 * cam->width + i0, w = i1 - i0;
        uint8_t *row0 = job->rgb + 3 * p0;
        for (size_t k = 1; k < w; k++)
            memcpy(row0 + 3 * k, row0, 3);
        aa_probe *pr0 = sh->tile ? tile_probe(sh->tile, i0, j0) : NULL;
        for (size_t k = 1; pr0 && k < w; k++)
            pr0[k] = pr0[0];
        for (uint32_t j = j0; j < j1; j++) {
            const size_t px = (size_t)j * cam->width + i0;
            if (j > j0)
                memcpy(job->rgb + 3 * px, row0, 3 * w);
            if (job->depth)
                for (size_t k = 0; k < w; k++)
                    job->depth[px + k] = INFINITY;
            if (job->normals)
                memset(job->normals + 3 * px, 0, 3 * w);
            if (job->normals_f)
                memset(job->normals_f + 3 * px, 0, 3 * w * sizeof(float));
            if (job->alpha)
                memset(job->alpha + px, 0, w);
            if (pr0 && j > j0)
                memcpy(tile_probe(sh->tile, i0, j), pr0, w * sizeof *pr0);
        }
        return;
    }
    for (unsigned sr = 0; sr < g.rows; sr++)
        for (unsigned sc = 0; sc < g.cols; sc++) {
            const double t_lo = g.t_lo[sr][sc];
            const float start = tile_start(t_lo);
            if (!(t_lo < INFINITY)) { /* every ray of the sub-block misses: no direction */
                for (uint32_t j = g.row[sr]; j < g.row[sr + 1]; j++)
                    for (uint32_t i = g.col[sc]; i < g.col[sc + 1]; i++)
                        render_pixel(sh, acc, i, j, cam->forward, NULL, NULL, INFINITY);
                continue;
            }
            /* the sub-block's rays all start at t_lo: where they do, the
             * descent from the root is shared (not with --beam 0: rays
             * traced whole, the reference the beam is tested against) */
            trace_anchor an;
            an.depth = 0;
            if (eye->ok && job->beam_size) {
                double lo[3], hi[3];
                beam_start_box(cam, eye->o, eye->scale, g.col[sc], g.col[sc + 1], g.row[sr],
                               g.row[sr + 1], t_lo, lo, hi);
                trace_anchor_find(job->tree, lo, hi, &an);
            }
            const uint64_t hits0 = acc->hits;
            for (uint32_t j = g.row[sr]; j < g.row[sr + 1]; j++) {
                const double v = camera_v(cam, j);
                for (uint32_t i = g.col[sc]; i < g.col[sc + 1]; i++) {
                    double dir[3];
                    camera_ray_uv(cam, us[i - us0], v, dir);
                    trace_ray r;
                    const int traced =
                        trace_setup_eye(eye, dir, &r) && trace_clip(&r, t_lo, INFINITY);
                    render_pixel(sh, acc, i, j, dir, traced ? &r : NULL, &an, start);
                }
            }
            if (sh->tile && job->beam_size && !job->no_beam_edge && acc->hits == hits0)
                mark_beam_edge(sh, acc, g.col[sc], g.col[sc + 1], g.row[sr], g.row[sr + 1]);
        }
}

static void render_tile(const frame_shared *sh, frame_acc *acc, uint32_t tx, uint32_t ty)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    const uint32_t i0 = tx * FRAME_TILE, j0 = ty * FRAME_TILE;
    const uint32_t i1 = i0 + FRAME_TILE < cam->width ? i0 + FRAME_TILE : cam->width;
    const uint32_t j1 = j0 + FRAME_TILE < cam->height ? j0 + FRAME_TILE : cam->height;
    const uint32_t bs = job->beam_size ? job->beam_size : FRAME_TILE;
    double us[FRAME_TILE]; /* camera_u of column i0 + k */
    trace_eye eye;
    trace_eye_init(job->tree, cam->eye, &eye); /* eye.ok = 0: every ray misses */
    if (sh->phase == 1) {
        frame_aa_border(sh, acc, &eye, tx, ty, i0, i1, j0, j1);
        return;
    }
    if (sh->tile) {
        sh->tile->i0 = i0;
        sh->tile->j0 = j0;
    }
    const uint64_t hits0 = acc->hits, marked0 = acc->marked;
    for (uint32_t i = i0; i < i1; i++)
        us[i - i0] = camera_u(cam, i);
    for (uint32_t bj = j0; bj < j1; bj += bs)
        for (uint32_t bi = i0; bi < i1; bi += bs)
            render_block(sh, acc, &eye, us, i0, bi, bi + bs < i1 ? bi + bs : i1, bj,
                         bj + bs < j1 ? bj + bs : j1);
    if (sh->tile)
        frame_aa_tile(sh, acc, &eye, acc->hits != hits0 || acc->marked != marked0, tx, ty, i0, i1,
                      j0, j1);
}

static void work(const frame_shared *common, int caller)
{
    frame_shared mine = *common;
    frame_shared *sh = &mine;
    frame_sync *sy = sh->sync;
    frame_job own; /* with --exact: the job with this thread's exact worker */
    frame_tile tile; /* with --aa: the probes of the tile being rendered */
    sh->tile = sh->border ? &tile : NULL;
    /* (one a thread: at most job->threads of them run a pass) */
    const unsigned slot = atomic_fetch_add(&sy->next_slot, 1);
    if (sy->exact) {
        own = *sh->job;
        own.opts.exact = &sy->exact[slot];
        sh->job = &own;
    }
    const uint64_t total = (uint64_t)sh->tiles_x * sh->tiles_y;
    frame_acc acc;
    memset(&acc, 0, sizeof acc);
    const double t0 = sh->job->timing ? frame_now_ns() : 0.0;
    const double k0 = sh->job->timing ? frame_ticks() : 0.0;
    for (;;) {
        if (atomic_load_explicit(&sy->changed, memory_order_relaxed))
            break; /* another thread met the file changing: stop */
        uint64_t t;
        if (!next_tile(sy, slot % sy->nbands, &t))
            break;
        render_tile(sh, &acc, (uint32_t)(t % sh->tiles_x), (uint32_t)(t / sh->tiles_x));
        uint64_t d = atomic_fetch_add(&sy->done, 1) + 1;
        if (caller && sh->phase == 0 && sh->job->progress)
            sh->job->progress(sh->job->progress_ctx, d, total);
        if (caller && sh->phase == 0)
            test_hooks_tile(d);
    }
    const double ns = sh->job->timing ? frame_now_ns() - t0 : 0.0;
    const double ticks = sh->job->timing ? frame_ticks() - k0 : 0.0;
    const double ns_per_tick = ticks > 0.0 ? ns / ticks : 0.0;
    const double shadow_ns = acc.shadow_tk * ns_per_tick, ao_ns = acc.ao_tk * ns_per_tick;
    pthread_mutex_lock(&sy->lock);
    sy->sum.rays += acc.rays;
    sy->sum.hits += acc.hits;
    sy->sum.steps += acc.steps;
    sy->sum.aa_pixels += acc.aa_pixels;
    sy->sum.aa_full += acc.aa_full;
    sy->sum.shadow_rays += acc.shadow_rays;
    sy->sum.ao_rays += acc.ao_rays;
    sy->sum.secondary_steps += acc.secondary_steps;
    sy->shadow_ns += shadow_ns;
    sy->ao_ns += ao_ns;
    sy->sample_ns += acc.sample_tk * ns_per_tick;
    sy->pass_ns += ns - shadow_ns - ao_ns;
    pthread_mutex_unlock(&sy->lock);
}

typedef struct work_arg {
    frame_shared *sh;
    int caller;
} work_arg;

static void work_fn(void *arg)
{
    const work_arg *w = arg;
    work(w->sh, w->caller);
}

/* work under map_guard: a fault from the file changing ends this thread's
 * share and marks the frame. */
static void guarded_work(frame_shared *sh, int caller)
{
    work_arg w = {sh, caller};
    if (map_guard_run(work_fn, &w) != 0)
        atomic_store(&sh->sync->changed, 1);
}

static void *worker(void *arg)
{
    guarded_work(arg, 0);
    return NULL;
}

/* One pass over every tile on job->threads threads. Returns 0 or the errno
 * of a thread that could not be started (the pass is then done by fewer). */
static int run_pass(frame_shared *sh, int phase)
{
    sh->phase = phase;
    frame_bands_init(sh->sync, (uint64_t)sh->tiles_x * sh->tiles_y);
    atomic_store(&sh->sync->done, 0);
    atomic_store(&sh->sync->next_slot, 0);
    unsigned extra = sh->job->threads > 1 ? sh->job->threads - 1 : 0;
    pthread_t *tid = extra ? calloc(extra, sizeof *tid) : NULL;
    int rc = 0;
    unsigned started = 0;
    if (extra && !tid)
        rc = ENOMEM; /* render on this thread alone */
    for (; tid && started < extra; started++) {
        rc = pthread_create(&tid[started], NULL, worker, sh);
        if (rc != 0)
            break;
    }
    guarded_work(sh, 1);
    for (unsigned k = 0; k < started; k++)
        pthread_join(tid[k], NULL);
    free(tid);
    return rc;
}

static void exact_workers_free(frame_keep *k)
{
    for (unsigned i = 0; k->exact && i < k->exact_n; i++)
        exact_worker_free(&k->exact[i]);
    free(k->exact);
    k->exact = NULL;
    k->exact_n = 0;
    k->exact_scene = NULL;
}

/* The exact workers' counters summed: voxel tests, of them by bisection,
 * voxels passed, hits past their voxel. */
static void exact_counts(const frame_keep *k, uint64_t c[4])
{
    c[0] = c[1] = c[2] = c[3] = 0;
    for (unsigned i = 0; k->exact && i < k->exact_n; i++) {
        c[0] += k->exact[i].fast + k->exact[i].slow;
        c[1] += k->exact[i].slow;
        c[2] += k->exact[i].skipped;
        c[3] += k->exact[i].beyond;
    }
}

/* One exact worker for each thread of a pass: those kept in k for the same
 * scene and as many threads, else made anew (and kept there); 0, or -1
 * when they cannot be had. */
static int exact_workers(frame_keep *k, const frame_job *job, exact_worker **out)
{
    *out = NULL;
    if (!job->exact)
        return 0;
    const unsigned n = job->threads > 1 ? job->threads : 1;
    if (k->exact && k->exact_scene == job->exact && k->exact_n == n) {
        for (unsigned i = 0; i < n; i++)
            exact_worker_new_frame(&k->exact[i]);
        *out = k->exact;
        return 0;
    }
    exact_workers_free(k);
    k->exact = exact_line_alloc(n, sizeof *k->exact);
    if (k->exact)
        memset(k->exact, 0, n * sizeof *k->exact);
    while (k->exact && k->exact_n < n && exact_worker_init(&k->exact[k->exact_n], job->exact) == 0)
        k->exact_n++;
    if (!k->exact || k->exact_n < n) {
        exact_workers_free(k);
        return -1;
    }
    k->exact_scene = job->exact;
    *out = k->exact;
    return 0;
}

static void border_free(frame_keep *k)
{
    frame_border_free(k->border, k->border_tiles);
    free(k->border_hit);
    k->border = NULL;
    k->border_hit = NULL;
    k->border_tiles = 0;
}

void frame_keep_free(frame_keep *k)
{
    shadow_map_cache_free(&k->maps);
    ao_grid_free(&k->grid);
    k->grid_tree = NULL;
    border_free(k);
    exact_workers_free(k);
}

/* Border probes for ntiles tiles in k: those kept when there are enough
 * (every probe is written before it is read), else made anew. -1 (none
 * kept) when the memory cannot be had. */
static int keep_border(frame_keep *k, size_t ntiles)
{
    if (k->border && k->border_tiles >= ntiles)
        return 0;
    border_free(k);
    k->border = frame_border_alloc(ntiles);
    k->border_hit = malloc(ntiles ? ntiles : 1);
    k->border_tiles = ntiles;
    if (k->border && k->border_hit)
        return 0;
    border_free(k);
    return -1;
}

int frame_render(const frame_job *job, frame_stats *stats)
{
    frame_srgb_setup();
    memset(stats, 0, sizeof *stats);
    frame_sync sy;
    memset(&sy, 0, sizeof sy);
    frame_keep own = {0};
    frame_keep *keep = job->keep ? job->keep : &own;
    if (exact_workers(keep, job, &sy.exact) != 0)
        return -1;
    frame_shared sh;
    memset(&sh, 0, sizeof sh);
    sh.job = job;
    sh.sync = &sy;
    sh.traverse = job->traverse ? job->traverse : trace_impls[0].traverse;
    sh.tiles_x = (job->cam->width + FRAME_TILE - 1) / FRAME_TILE;
    sh.tiles_y = (job->cam->height + FRAME_TILE - 1) / FRAME_TILE;
    sy.nbands = job->threads < 1 ? 1 : job->threads > THREADS_MAX ? THREADS_MAX : job->threads;
    atomic_init(&sy.done, 0);
    atomic_init(&sy.changed, 0);
    atomic_init(&sy.next_slot, 0);
    pthread_mutex_init(&sy.lock, NULL);
    const size_t npx = (size_t)job->cam->width * job->cam->height;
    const size_t ntiles = (size_t)sh.tiles_x * sh.tiles_y;
    int rc = 0;
    if (job->shade.shadows) {
        /* made before the passes on all the threads (or kept from the last
           frame): its time is the shadow rays' */
        const double t0 = job->timing ? frame_now_ns() : 0.0;
        int built;
        sh.shadow_map =
            shadow_map_cached(&keep->maps, job->tree, job->shade.light,
                              shadow_map_up_for(job->tree, job->shadow_pixels ? job->shadow_pixels
                                                                              : npx),
                              job->threads, &built);
        if (job->timing && built)
            sy.shadow_ns += (frame_now_ns() - t0) * (job->threads > 1 ? job->threads : 1);
    }
    if (job->shade.ao_rays && ao_grid_wanted(&job->opts, sh.traverse)) {
        /* made once for the tree (a failure leaves the plain walk); its
           time is the AO rays' */
        if (keep->grid_tree != job->tree) {
            const double t0 = job->timing ? frame_now_ns() : 0.0;
            ao_grid_free(&keep->grid);
            keep->grid_tree = job->tree;
            ao_grid_build(job->tree, &keep->grid);
            if (job->timing)
                sy.ao_ns += (frame_now_ns() - t0) * (job->threads > 1 ? job->threads : 1);
        }
        if (keep->grid.n)
            sh.ao_grid = &keep->grid;
    }
    if (job->aa > 1) {
        if (keep_border(keep, ntiles) == 0) {
            sh.border = keep->border;
            sh.border_hit = keep->border_hit;
        } else {
            rc = ENOMEM; /* one ray a pixel */
        }
    }
    uint64_t x0[4], x1[4]; /* (the workers count across the frames they are kept) */
    exact_counts(keep, x0);
    int rc1 = run_pass(&sh, 0);
    if (sh.border && !atomic_load(&sy.changed)) {
        int rc2 = run_pass(&sh, 1);
        if (!rc1)
            rc1 = rc2;
    }
    exact_counts(keep, x1);
    stats->exact_tests = x1[0] - x0[0];
    stats->exact_bisected = x1[1] - x0[1];
    stats->exact_passed = x1[2] - x0[2];
    stats->exact_beyond = x1[3] - x0[3];
    frame_keep_free(&own);
    pthread_mutex_destroy(&sy.lock);
    stats->rays = (uint64_t)npx + sy.sum.rays;
    stats->hits = sy.sum.hits;
    stats->steps = sy.sum.steps;
    stats->aa_pixels = sy.sum.aa_pixels;
    stats->aa_full = sy.sum.aa_full;
    stats->shadow_rays = sy.sum.shadow_rays;
    stats->ao_rays = sy.sum.ao_rays;
    stats->secondary_steps = sy.sum.secondary_steps;
    stats->shadow_ns = sy.shadow_ns;
    stats->ao_ns = sy.ao_ns;
    stats->secondary_ns = sy.shadow_ns + sy.ao_ns;
    stats->centre_ns = sy.pass_ns - sy.sample_ns;
    stats->sample_ns = sy.sample_ns;
    stats->primary_ns = sy.pass_ns;
    stats->samples = sy.sum.rays;
    stats->file_changed = atomic_load(&sy.changed);
    return rc ? rc : rc1;
}
