/* frame: multi-threaded tile renderer for one view. */
#include "render/frame.h"

#include <errno.h>
#include <float.h>
#include <pthread.h>
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/view/image.h"
#include "render/beam.h"

typedef struct frame_shared {
    const frame_job *job;
    uint32_t tiles_x, tiles_y;
    atomic_uint_fast64_t next, done, hits, steps;
    exact_worker *exact; /* one per thread with --exact, else NULL */
    atomic_uint next_exact;
} frame_shared;

/* image_srgb8 without pow: the code value is the number of thresholds at or
 * below the input, where threshold k is the least float whose image_srgb8
 * is >= k (found by bisection over the float bit patterns, image_srgb8 being
 * monotone). The count starts at the code of the input's bucket [i, i + 1) /
 * 4096 (i / 4096 is exact, so that code is a lower bound) and steps past
 * the one or two thresholds inside the bucket. Bit for bit image_srgb8, NaN
 * and out-of-range inputs included; tests/test_frame.c compares the two
 * over every float in [0, 1]. */
static float srgb_threshold[257]; /* [256] = NaN ends the count */
#define SRGB_BUCKETS 4096
static uint8_t srgb_bucket[SRGB_BUCKETS + 1];
static pthread_once_t srgb_once = PTHREAD_ONCE_INIT;

static float float_of_bits(uint32_t b)
{
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

static void srgb_init(void)
{
    srgb_threshold[0] = -INFINITY;
    for (unsigned k = 1; k < 256; k++) {
        uint32_t lo = 0, hi = 0x3f800000u; /* image_srgb8(1.0f) == 255 >= k */
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (image_srgb8(float_of_bits(mid)) >= k)
                hi = mid;
            else
                lo = mid + 1;
        }
        srgb_threshold[k] = float_of_bits(lo);
    }
    srgb_threshold[256] = NAN; /* no x is >= it, +inf included */
    for (unsigned i = 0; i <= SRGB_BUCKETS; i++)
        srgb_bucket[i] = image_srgb8((float)i / SRGB_BUCKETS);
}

static inline uint8_t srgb8_fast(float x)
{
    if (!(x > 0.0f)) /* misses on a black background, NaN */
        return 0;
    unsigned k = srgb_bucket[x < 1.0f ? (unsigned)(x * SRGB_BUCKETS) : SRGB_BUCKETS];
    while (x >= srgb_threshold[k + 1])
        k++;
    return (uint8_t)k;
}

uint8_t frame_srgb8(float x)
{
    pthread_once(&srgb_once, srgb_init);
    return srgb8_fast(x);
}

/* Traces, shades and stores pixel (i, j); r is its prepared ray, or NULL
 * for a ray known to miss. */
static inline void render_pixel(const frame_job *job, uint32_t i, uint32_t j, const double dir[3],
                                const trace_ray *r, const trace_anchor *an, uint64_t *hits,
                                uint64_t *steps)
{
    trace_hit h;
    if (r) {
        trace_ray_anchored(job->tree, &job->opts, r, an, &h);
    } else { /* trace_ray_cast's miss */
        h.hit = 0;
        h.t = INFINITY;
        h.steps = 0;
    }
    float rgb[3], n[3];
    shade_hit(job->tree, &job->shade, &h, dir, rgb, n);
    const size_t px = (size_t)j * job->cam->width + i;
    for (int a = 0; a < 3; a++)
        job->rgb[3 * px + (size_t)a] = srgb8_fast(rgb[a]);
    if (job->depth)
        job->depth[px] = h.t > FLT_MAX ? (isinf(h.t) ? INFINITY : FLT_MAX) : (float)h.t;
    if (job->normals)
        for (int a = 0; a < 3; a++)
            job->normals[3 * px + (size_t)a] =
                h.hit ? (uint8_t)((n[a] * 0.5f + 0.5f) * 255.0f + 0.5f) : 0;
    if (job->normals_f)
        for (int a = 0; a < 3; a++)
            job->normals_f[3 * px + (size_t)a] = h.hit ? n[a] : 0.0f;
    *hits += (uint64_t)h.hit;
    *steps += h.steps;
}

/* The pixels [i0, i1) x [j0, j1): with the beam, each sub-block's rays are
 * traced from its start only, from its anchor, and none at all when its
 * pyramid touches no occupied cell. */
static void render_block(const frame_job *job, const trace_eye *eye, const double *us, uint32_t us0,
                         uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1, uint64_t *hits,
                         uint64_t *steps)
{
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
        render_pixel(job, i0, j0, cam->forward, NULL, NULL, hits, steps);
        const size_t p0 = (size_t)j0 * cam->width + i0, w = i1 - i0;
        uint8_t *row0 = job->rgb + 3 * p0;
        for (size_t k = 1; k < w; k++)
            memcpy(row0 + 3 * k, row0, 3);
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
        }
        return;
    }
    for (unsigned sr = 0; sr < g.rows; sr++)
        for (unsigned sc = 0; sc < g.cols; sc++) {
            const double t_lo = g.t_lo[sr][sc];
            if (!(t_lo < INFINITY)) { /* every ray of the sub-block misses: no direction */
                for (uint32_t j = g.row[sr]; j < g.row[sr + 1]; j++)
                    for (uint32_t i = g.col[sc]; i < g.col[sc + 1]; i++)
                        render_pixel(job, i, j, cam->forward, NULL, NULL, hits, steps);
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
            for (uint32_t j = g.row[sr]; j < g.row[sr + 1]; j++) {
                const double v = camera_v(cam, j);
                for (uint32_t i = g.col[sc]; i < g.col[sc + 1]; i++) {
                    double dir[3];
                    camera_ray_uv(cam, us[i - us0], v, dir);
                    trace_ray r;
                    const int traced =
                        trace_setup_eye(eye, dir, &r) && trace_clip(&r, t_lo, INFINITY);
                    render_pixel(job, i, j, dir, traced ? &r : NULL, &an, hits, steps);
                }
            }
        }
}

static void render_tile(const frame_job *job, uint32_t tx, uint32_t ty, uint64_t *hits,
                        uint64_t *steps)
{
    const camera *cam = job->cam;
    const uint32_t i0 = tx * FRAME_TILE, j0 = ty * FRAME_TILE;
    const uint32_t i1 = i0 + FRAME_TILE < cam->width ? i0 + FRAME_TILE : cam->width;
    const uint32_t j1 = j0 + FRAME_TILE < cam->height ? j0 + FRAME_TILE : cam->height;
    const uint32_t bs = job->beam_size ? job->beam_size : FRAME_TILE;
    double us[FRAME_TILE]; /* camera_u of column i0 + k */
    trace_eye eye;
    trace_eye_init(job->tree, cam->eye, &eye); /* eye.ok = 0: every ray misses */
    for (uint32_t i = i0; i < i1; i++)
        us[i - i0] = camera_u(cam, i);
    for (uint32_t bj = j0; bj < j1; bj += bs)
        for (uint32_t bi = i0; bi < i1; bi += bs)
            render_block(job, &eye, us, i0, bi, bi + bs < i1 ? bi + bs : i1, bj,
                         bj + bs < j1 ? bj + bs : j1, hits, steps);
}

static void work(frame_shared *sh, int caller)
{
    const uint64_t total = (uint64_t)sh->tiles_x * sh->tiles_y;
    uint64_t hits = 0, steps = 0;
    frame_job own; /* with --exact: the job with this thread's exact worker */
    const frame_job *job = sh->job;
    if (sh->exact) {
        own = *job;
        own.opts.exact = &sh->exact[atomic_fetch_add(&sh->next_exact, 1)];
        job = &own;
    }
    for (;;) {
        uint64_t t = atomic_fetch_add(&sh->next, 1);
        if (t >= total)
            break;
        render_tile(job, (uint32_t)(t % sh->tiles_x), (uint32_t)(t / sh->tiles_x), &hits, &steps);
        uint64_t d = atomic_fetch_add(&sh->done, 1) + 1;
        if (caller && sh->job->progress)
            sh->job->progress(sh->job->progress_ctx, d, total);
    }
    atomic_fetch_add(&sh->hits, hits);
    atomic_fetch_add(&sh->steps, steps);
}

static void *worker(void *arg)
{
    work(arg, 0);
    return NULL;
}

int frame_render(const frame_job *job, frame_stats *stats)
{
    pthread_once(&srgb_once, srgb_init);
    frame_shared sh;
    sh.job = job;
    sh.tiles_x = (job->cam->width + FRAME_TILE - 1) / FRAME_TILE;
    sh.tiles_y = (job->cam->height + FRAME_TILE - 1) / FRAME_TILE;
    atomic_init(&sh.next, 0);
    atomic_init(&sh.done, 0);
    atomic_init(&sh.hits, 0);
    atomic_init(&sh.steps, 0);
    atomic_init(&sh.next_exact, 0);
    unsigned extra = job->threads > 1 ? job->threads - 1 : 0;
    sh.exact = NULL;
    if (job->exact) {
        sh.exact = calloc(extra + 1, sizeof *sh.exact);
        unsigned k = 0;
        while (sh.exact && k <= extra && exact_worker_init(&sh.exact[k], job->exact) == 0)
            k++;
        if (!sh.exact || k <= extra) {
            for (unsigned i = 0; sh.exact && i < k; i++)
                exact_worker_free(&sh.exact[i]);
            free(sh.exact);
            stats->rays = stats->hits = stats->steps = 0;
            return -1;
        }
    }
    pthread_t *tid = extra ? calloc(extra, sizeof *tid) : NULL;
    int rc = 0;
    unsigned started = 0;
    if (extra && !tid)
        rc = ENOMEM; /* render on this thread alone */
    for (; tid && started < extra; started++) {
        rc = pthread_create(&tid[started], NULL, worker, &sh);
        if (rc != 0)
            break;
    }
    work(&sh, 1);
    for (unsigned k = 0; k < started; k++)
        pthread_join(tid[k], NULL);
    free(tid);
    for (unsigned k = 0; sh.exact && k <= extra; k++)
        exact_worker_free(&sh.exact[k]);
    free(sh.exact);
    stats->rays = (uint64_t)job->cam->width * job->cam->height;
    stats->hits = atomic_load(&sh.hits);
    stats->steps = atomic_load(&sh.steps);
    return rc;
}
