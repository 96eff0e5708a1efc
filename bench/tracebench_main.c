/* tracebench: micro-benchmark of the traversal on a synthetic sphere shell
 * (radius 0.4 * 2^L, centred in the grid), one frame per split K, through
 * the threaded frame renderer. Prints Mrays/s per K.
 *   tracebench [LEVELS=10] [SIZE=1024] [THREADS=online CPUs] [K_MIN] [K_MAX] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "common/view/camera.h"
#include "common/view/image.h"
#include "format/oct_normal.h"
#include "render/frame.h"
#include "bench/tree_util.h"

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* Voxels whose cube the sphere |p - c| = r passes through: the nearest point
 * of the cube is inside the sphere and the farthest is outside. */
static oct_tree *sphere_shell(unsigned levels)
{
    const uint32_t n = UINT32_C(1) << levels;
    const double c = 0.5 * n, r = 0.4 * n;
    size_t cap = 1024, cnt = 0;
    uint32_t (*xyz)[3] = malloc(cap * sizeof *xyz);
    uint32_t *attr = malloc(cap * sizeof *attr);
    if (!xyz || !attr)
        return NULL;
    for (uint32_t z = 0; z < n; z++)
        for (uint32_t y = 0; y < n; y++) {
            double dy0 = fabs(y + 0.5 - c), dz0 = fabs(z + 0.5 - c);
            double ny = dy0 > 0.5 ? dy0 - 0.5 : 0, nz = dz0 > 0.5 ? dz0 - 0.5 : 0;
            double fy = dy0 + 0.5, fz = dz0 + 0.5;
            double rest_near = r * r - ny * ny - nz * nz;
            if (rest_near < 0)
                continue;
            /* only x where |x + 0.5 - c| can satisfy both tests */
            double far_yz = fy * fy + fz * fz;
            double dlo = r * r > far_yz ? sqrt(r * r - far_yz) - 1.0 : 0.0;
            double dhi = sqrt(rest_near) + 1.0;
            double xa = floor(c - dhi - 0.5), xb = ceil(c + dhi - 0.5);
            for (double xd = xa < 0 ? 0 : xa; xd <= xb && xd < n; xd++) {
                uint32_t x = (uint32_t)xd;
                double dx0 = fabs(x + 0.5 - c);
                if (dx0 < dlo)
                    continue;
                double nx = dx0 > 0.5 ? dx0 - 0.5 : 0, fx = dx0 + 0.5;
                if (nx * nx > rest_near || fx * fx + fy * fy + fz * fz < r * r)
                    continue;
                if (cnt == cap) {
                    cap *= 2;
                    xyz = realloc(xyz, cap * sizeof *xyz);
                    attr = realloc(attr, cap * sizeof *attr);
                    if (!xyz || !attr)
                        return NULL;
                }
                double nv[3] = {x + 0.5 - c, y + 0.5 - c, z + 0.5 - c};
                xyz[cnt][0] = x;
                xyz[cnt][1] = y;
                xyz[cnt][2] = z;
                attr[cnt] = oct_voxel_pack(nv, 0.0);
                cnt++;
            }
        }
    const double origin[3] = {0, 0, 0};
    oct_tree *t = tree_util_build(levels, origin, 1.0, (const uint32_t(*)[3])xyz, cnt, attr,
                                  NULL, 1, NULL);
    free(xyz);
    free(attr);
    return t;
}

int main(int argc, char **argv)
{
    unsigned levels = argc > 1 ? (unsigned)atoi(argv[1]) : 10;
    unsigned size = argc > 2 ? (unsigned)atoi(argv[2]) : 1024;
    long th = argc > 3 ? atol(argv[3]) : sysconf(_SC_NPROCESSORS_ONLN);
    unsigned kmin = argc > 4 ? (unsigned)atoi(argv[4]) : 0;
    unsigned kmax = argc > 5 ? (unsigned)atoi(argv[5]) : levels;
    if (levels < 1 || levels > 12 || size < 1 || size > 8192 || th < 1 || kmax > levels) {
        fprintf(stderr, "usage: tracebench [LEVELS 1..12] [SIZE] [THREADS] [K_MIN] [K_MAX]\n");
        return 2;
    }
    double t0 = now_ms();
    oct_tree *tree = sphere_shell(levels);
    if (!tree) {
        fprintf(stderr, "tracebench: out of memory\n");
        return 1;
    }
    printf("tracebench: sphere shell, levels %u, %llu voxels, built in %.0f ms; %ux%u, %ld threads\n",
           levels, (unsigned long long)tree->voxel_count, now_ms() - t0, size, size, th);
    camera cam;
    const double eye[3] = {2.2, 1.6, 1.9}, target[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1};
    if (camera_init(&cam, eye, target, up, 30.0, size, size) != CAMERA_OK)
        return 1;
    uint8_t *rgb = malloc((size_t)size * size * 3);
    if (!rgb)
        return 1;
    for (unsigned k = kmin; k <= kmax; k++) {
        frame_job job = {0};
        job.tree = tree;
        job.cam = &cam;
        job.opts.split = k;
        job.shade.ambient = 0.15f;
        const double l[3] = {1, 1, 2};
        shade_set_light(&job.shade, l);
        job.rgb = rgb;
        job.threads = (unsigned)th;
        frame_stats st;
        double best = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            double a = now_ms();
            frame_render(&job, &st);
            double ms = now_ms() - a;
            if (ms < best)
                best = ms;
        }
        printf("K=%2u (%u+%u): %8.1f ms  %7.2f Mrays/s  hits %.1f%%  %.1f steps/ray\n", k, k,
               levels - k, best, (double)st.rays / best / 1e3,
               100.0 * (double)st.hits / (double)st.rays, (double)st.steps / (double)st.rays);
        fflush(stdout);
    }
    if (getenv("TRACEBENCH_PNG"))
        image_write_png(getenv("TRACEBENCH_PNG"), rgb, size, size, NULL);
    free(rgb);
    tree_util_free(tree);
    return 0;
}
