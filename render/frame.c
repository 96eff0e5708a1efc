/* frame: multi-threaded tile renderer for one view. */
#include "render/frame.h"

#include <errno.h>
#include <float.h>
#include <pthread.h>
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>

#include "common/image.h"

typedef struct frame_shared {
    const frame_job *job;
    uint32_t tiles_x, tiles_y;
    atomic_uint_fast64_t next, done, hits, steps;
} frame_shared;

static void render_tile(const frame_job *job, uint32_t tx, uint32_t ty, uint64_t *hits,
                        uint64_t *steps)
{
    const camera *cam = job->cam;
    const uint32_t w = cam->width;
    uint32_t i1 = (tx + 1) * FRAME_TILE, j1 = (ty + 1) * FRAME_TILE;
    if (i1 > cam->width)
        i1 = cam->width;
    if (j1 > cam->height)
        j1 = cam->height;
    for (uint32_t j = ty * FRAME_TILE; j < j1; j++) {
        for (uint32_t i = tx * FRAME_TILE; i < i1; i++) {
            double dir[3];
            camera_ray(cam, i, j, dir);
            trace_hit h;
            trace_ray_cast(job->tree, &job->opts, cam->eye, dir, &h);
            float rgb[3], n[3];
            shade_hit(job->tree, &job->shade, &h, dir, rgb, n);
            size_t px = (size_t)j * w + i;
            for (int a = 0; a < 3; a++)
                job->rgb[3 * px + (size_t)a] = image_srgb8(rgb[a]);
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
    }
}

static void work(frame_shared *sh, int caller)
{
    const uint64_t total = (uint64_t)sh->tiles_x * sh->tiles_y;
    uint64_t hits = 0, steps = 0;
    for (;;) {
        uint64_t t = atomic_fetch_add(&sh->next, 1);
        if (t >= total)
            break;
        render_tile(sh->job, (uint32_t)(t % sh->tiles_x), (uint32_t)(t / sh->tiles_x), &hits,
                    &steps);
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
    frame_shared sh;
    sh.job = job;
    sh.tiles_x = (job->cam->width + FRAME_TILE - 1) / FRAME_TILE;
    sh.tiles_y = (job->cam->height + FRAME_TILE - 1) / FRAME_TILE;
    atomic_init(&sh.next, 0);
    atomic_init(&sh.done, 0);
    atomic_init(&sh.hits, 0);
    atomic_init(&sh.steps, 0);
    unsigned extra = job->threads > 1 ? job->threads - 1 : 0;
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
    stats->rays = (uint64_t)job->cam->width * job->cam->height;
    stats->hits = atomic_load(&sh.hits);
    stats->steps = atomic_load(&sh.steps);
    return rc;
}
