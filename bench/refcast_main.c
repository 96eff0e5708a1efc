/* refcast: the exact reference image of a scene (depth PFM, float normals,
 * shaded PNG), by direct interval ray casting of its functions. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench/refcast.h"
#include "common/view/camera.h"
#include "common/diag.h"
#include "common/view/image.h"
#include "common/parse_num.h"
#include "common/expr/scene.h"

static const char usage_text[] =
    "usage: refcast SCENE [-o OUT.png] [--depth OUT.pfm] [--normals OUT.pfm]\n"
    "               [--size WxH] [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z] [--fov DEG]\n"
    "               [--threads N] [-q]\n"
    "Exact reference: the first root of each pixel ray by interval bisection,\n"
    "refined to 1e-12 relative. Same camera and depth convention as render;\n"
    "--normals writes a 3-channel float PFM (unit gradient facing the viewer,\n"
    "0 on a miss). Default view: render's, framing the cube around the bounds.\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

static int usage_error(const char *msg, const char *arg)
{
    diag_error("%s '%s'", msg, arg);
    fputs(usage_text, stderr);
    return EXIT_USAGE;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* render's default view: the cube enclosing the bounds, seen from (1.7, 1.1, 1.4). */
static void frame_bounds(const scene *s, double fov, long w, long h, int has_eye,
                         int has_target, double eye[3], double target[3])
{
    double edge = 0.0;
    for (int a = 0; a < 3; a++)
        if (s->hi[a] - s->lo[a] > edge)
            edge = s->hi[a] - s->lo[a];
    if (!has_target)
        for (int a = 0; a < 3; a++)
            target[a] = s->lo[a] + 0.5 * edge;
    if (!has_eye) {
        static const double dir[3] = {1.7, 1.1, 1.4};
        double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        double t = tan(fov * M_PI / 360.0);
        if (w < h)
            t = t * (double)w / (double)h;
        double dist = 1.05 * (0.5 * sqrt(3.0) * edge) / sin(atan(t));
        for (int a = 0; a < 3; a++)
            eye[a] = target[a] + dist * dir[a] / n;
    }
}

static void shade(const scene *s, const camera *cam, const float *depth, const float *nrm,
                  const uint8_t *surf, uint8_t *rgb)
{
    double l[3], ln = 0.0;
    for (int a = 0; a < 3; a++) { /* render's default light */
        l[a] = -cam->forward[a] + 0.7 * cam->up[a] - 0.5 * cam->right[a];
        ln += l[a] * l[a];
    }
    ln = sqrt(ln);
    size_t n = (size_t)cam->width * cam->height;
    for (size_t px = 0; px < n; px++) {
        if (isinf(depth[px])) {
            rgb[3 * px] = rgb[3 * px + 1] = rgb[3 * px + 2] = 0;
            continue;
        }
        double lam = (nrm[3 * px] * l[0] + nrm[3 * px + 1] * l[1] + nrm[3 * px + 2] * l[2]) / ln;
        float k = 0.15f + 0.85f * (float)(lam > 0.0 ? lam : 0.0);
        const double *col = s->surfaces[surf[px]].color;
        for (int a = 0; a < 3; a++)
            rgb[3 * px + (size_t)a] = image_srgb8((float)col[a] * k);
    }
}

int main(int argc, char **argv)
{
    diag_set_progname("refcast");
    const char *scene_path = NULL, *out = NULL, *depth_path = NULL, *nrm_path = NULL;
    double eye[3] = {0, 0, 0}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1}, fov = 30.0;
    int has_eye = 0, has_target = 0, quiet = 0;
    long w = 512, h = 512, threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        }
        if (!strcmp(a, "-q")) {
            quiet = 1;
            continue;
        }
        if (a[0] != '-') {
            if (scene_path)
                return usage_error("unexpected argument", a);
            scene_path = a;
            continue;
        }
        if (!v)
            return usage_error("missing value after", a);
        i++;
        parse_err pe = PARSE_OK;
        if (!strcmp(a, "-o"))
            out = v;
        else if (!strcmp(a, "--depth"))
            depth_path = v;
        else if (!strcmp(a, "--normals"))
            nrm_path = v;
        else if (!strcmp(a, "--size"))
            pe = parse_size(v, CAMERA_MAX_SIZE, &w, &h);
        else if (!strcmp(a, "--eye"))
            pe = parse_vec3(v, eye), has_eye = 1;
        else if (!strcmp(a, "--target"))
            pe = parse_vec3(v, target), has_target = 1;
        else if (!strcmp(a, "--up"))
            pe = parse_vec3(v, up);
        else if (!strcmp(a, "--fov"))
            pe = parse_double(v, &fov);
        else if (!strcmp(a, "--threads"))
            pe = parse_long(v, 1, 256, &threads);
        else
            return usage_error("unknown option", a);
        if (pe != PARSE_OK) {
            diag_error("%s '%s': %s", a, v, parse_strerror(pe));
            return EXIT_USAGE;
        }
    }
    if (!scene_path)
        return usage_error("missing", "SCENE");
    if (!out && !depth_path && !nrm_path)
        return usage_error("nothing to write: give", "-o, --depth or --normals");
    if (!(fov > 0.0 && fov < 180.0)) {
        diag_error("--fov must be in (0, 180)");
        return EXIT_USAGE;
    }
    scene *s = NULL;
    scene_error se;
    if (scene_load(scene_path, &s, &se) != 0) {
        scene_print_error(scene_path, &se);
        return EXIT_RUNTIME;
    }
    frame_bounds(s, fov, w, h, has_eye, has_target, eye, target);
    camera cam;
    camera_err ce = camera_init(&cam, eye, target, up, fov, w, h);
    if (ce != CAMERA_OK) {
        diag_error("%s", camera_strerror(ce));
        scene_free(s);
        return EXIT_USAGE;
    }
    if (threads == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n < 1 ? 1 : n > 64 ? 64 : n;
    }
    size_t npx = (size_t)w * (size_t)h;
    float *depth = malloc(npx * sizeof *depth), *nrm = malloc(npx * 3 * sizeof *nrm);
    uint8_t *surf = malloc(npx), *rgb = malloc(npx * 3);
    int status = EXIT_OK;
    if (!depth || !nrm || !surf || !rgb) {
        diag_error("out of memory for a %zu-pixel image", npx);
        status = EXIT_RUNTIME;
        goto done;
    }
    refcast_stats st;
    double t0 = now_ms();
    if (refcast_image(s, &cam, (unsigned)threads, depth, nrm, surf, &st) != 0) {
        diag_error("out of memory");
        status = EXIT_RUNTIME;
        goto done;
    }
    double ms = now_ms() - t0;
    size_t hits = 0;
    for (size_t px = 0; px < npx; px++)
        hits += !isinf(depth[px]);
    const char *op = NULL;
    if (depth_path && image_write_pfm(depth_path, depth, (uint32_t)w, (uint32_t)h, &op) != 0) {
        diag_path_error(depth_path, "%s: %s", op ? op : "write", strerror(errno));
        status = EXIT_RUNTIME;
        goto done;
    }
    if (nrm_path && image_write_pfm_rgb(nrm_path, nrm, (uint32_t)w, (uint32_t)h, &op) != 0) {
        diag_path_error(nrm_path, "%s: %s", op ? op : "write", strerror(errno));
        status = EXIT_RUNTIME;
        goto done;
    }
    if (out) {
        shade(s, &cam, depth, nrm, surf, rgb);
        if (image_write_png(out, rgb, (uint32_t)w, (uint32_t)h, &op) != 0) {
            diag_path_error(out, "%s: %s", op ? op : "write", strerror(errno));
            status = EXIT_RUNTIME;
            goto done;
        }
    }
    if (!quiet)
        fprintf(stderr,
                "refcast: %s: %ldx%ld, %.1f ms, %.3f Mrays/s, %.1f%% hit, %ld threads; "
                "per ray %.1f interval, %.1f gradient, %.1f point evaluations; %llu touches\n",
                scene_path, w, h, ms, ms > 0 ? (double)npx / ms / 1e3 : 0.0,
                100.0 * (double)hits / (double)npx, threads,
                (double)st.interval_evals / (double)npx, (double)st.grad_evals / (double)npx,
                (double)st.point_evals / (double)npx, (unsigned long long)st.touches);
done:
    free(depth);
    free(nrm);
    free(surf);
    free(rgb);
    scene_free(s);
    return status;
}
