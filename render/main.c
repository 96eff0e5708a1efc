/* render: map an .oct file once and ray trace every view asked for into PNG
 * (and PFM depth / normal) images. */
#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "common/view/camera.h"
#include "common/diag.h"
#include "common/view/image.h"
#include "common/parse_num.h"
#include "format/oct.h"
#include "render/frame.h"
#include "render/shade.h"
#include "render/trace.h"
#include "render/views.h"

/* The reader lands from another branch; until then the program builds and
 * reports that it cannot open files. */
static const char usage_text[] =
    "usage: render FILE.oct -o OUT.png [--size WxH] [--eye X,Y,Z] [--target X,Y,Z]\n"
    "              [--up X,Y,Z] [--fov DEG] [--depth OUT.pfm] [--normals OUT.png]\n"
    "              [--split K] [--refine] [--light X,Y,Z] [--background R,G,B]\n"
    "              [--beam N] [--threads N] [--trust] [--info] [-q]\n"
    "       render FILE.oct --views VIEWS_FILE [options]\n"
    "       render FILE.oct -o 'frame_%04d.png' --orbit N [options]\n"
    "       render --info FILE.oct\n";

static const char help_text[] =
    "\n"
    "Ray traces the voxels of FILE.oct (two-step discrete ray tracing).\n"
    "  -o OUT.png          colour image (8-bit sRGB PNG)\n"
    "  --size WxH          image size in pixels (default 512x512, each 1..32768)\n"
    "  --eye, --target     camera position and aim (default: a view framing the cube)\n"
    "  --up X,Y,Z          up direction (default 0,0,1)\n"
    "  --fov DEG           vertical field of view, in (0, 180) (default 30)\n"
    "  --depth OUT.pfm     distance along each pixel's unit ray (PFM, +inf on miss)\n"
    "  --normals OUT.png   surface normals as colour, (n + 1) / 2 per channel;\n"
    "                      a name ending in .pfm gets float normals (3-channel PFM)\n"
    "  --split K           octree depth where the empty-space skipping stops (default: levels)\n"
    "  --refine            intersect the voxels' stored planes for sub-voxel depth\n"
    "  --beam N            walk N x N pixel blocks (and their 4 x 4 sub-blocks) as\n"
    "                      pyramids first, to skip what no ray of them can hit\n"
    "                      (default 32; 0: off; same image)\n"
    "  --light X,Y,Z       direction towards the light (default over the viewer's shoulder)\n"
    "  --background R,G,B  linear colour of rays that miss, 0..1 each (default 0,0,0)\n"
    "  --threads N         worker threads (default: online CPUs)\n"
    "  --views FILE        one view a line, same options as above ('#' comments)\n"
    "  --orbit N           N views on a circle around the target; -o is a pattern\n"
    "                      with one integer conversion, e.g. frame_%04d.png\n"
    "  --trust             skip the file's CRC-32 checks (a fixed cost per file); the\n"
    "                      structure is still validated in full\n"
    "  --info              print a summary of FILE.oct (format version, flags,\n"
    "                      tree, stored function, shard fields)\n"
    "  -q                  no per-view timing lines\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static void progress_bar(void *ctx, uint64_t done, uint64_t total)
{
    (void)ctx;
    int width = 40, fill = (int)(done * (uint64_t)width / total);
    fprintf(stderr, "\r[%.*s%*s] %3d%%", fill, "########################################",
            width - fill, "", (int)(done * 100 / total));
    if (done == total)
        fputs("\r\033[K", stderr);
}

typedef struct views_report_ctx {
    const char *path;
} views_report_ctx;

static void report_line(void *ctx, unsigned line, const char *msg)
{
    const views_report_ctx *c = ctx;
    fprintf(stderr, "%s:%u: %s\n", c->path, line, msg);
}

/* Reads a whole text file into a malloc'ed NUL-terminated buffer. */
static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (n + 1 < cap) {
            if (ferror(f)) {
                free(buf);
                buf = NULL;
            }
            break;
        }
        char *nb = realloc(buf, cap * 2);
        if (!nb) {
            free(buf);
            buf = NULL;
        }
        buf = nb;
        cap *= 2;
    }
    int e = errno;
    fclose(f);
    if (buf)
        buf[n] = '\0';
    errno = e;
    return buf;
}

/* True when path ends in ".pfm": --normals then writes float normals. */
static int is_pfm(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcmp(path + n - 4, ".pfm") == 0;
}

/* A view that frames the root cube: aim at its centre from the direction of
 * the benchmark view, far enough that its bounding sphere fits the fov. */
static void frame_cube(const oct_tree *t, views_view *v)
{
    double c[3];
    for (int a = 0; a < 3; a++)
        c[a] = t->origin[a] + 0.5 * t->edge;
    if (!v->has_target)
        memcpy(v->target, c, sizeof c);
    if (!v->has_eye) {
        static const double dir[3] = {1.7, 1.1, 1.4};
        double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        double h = tan(v->fov * M_PI / 360.0);
        if (v->width < v->height)
            h = h * (double)v->width / (double)v->height;
        double dist = 1.05 * (0.5 * sqrt(3.0) * t->edge) / sin(atan(h));
        for (int a = 0; a < 3; a++)
            v->eye[a] = v->target[a] + dist * dir[a] / n;
    }
}

int main(int argc, char **argv)
{
    diag_set_progname("render");
    diag_fpe_traps_from_env();
    views_view base;
    views_defaults(&base);
    const char *oct_path = NULL, *views_path = NULL;
    long orbit = 0, split = -1, threads = 0, beam = FRAME_BEAM_DEFAULT;
    int refine = 0, info = 0, quiet = 0, trust = 0, status = EXIT_OK;
    double light[3] = {0, 0, 0}, bg[3] = {0, 0, 0};
    int has_light = 0;
    char msg[512];
    char *views_text = NULL;
    views_view *list = NULL;
    size_t nviews = 0;
    uint8_t *rgb = NULL, *nrm = NULL;
    float *depth = NULL, *nrm_f = NULL;
    camera *cams = NULL;
    oct_file *file = NULL;
    const oct_tree *tree = NULL;

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            fputs(help_text, stdout);
            return EXIT_OK;
        }
        if (a[0] != '-' || a[1] == '\0') {
            if (oct_path)
                return diag_usage_error(usage_text, "unexpected argument '%s'", a);
            oct_path = a;
            continue;
        }
        if (strcmp(a, "--refine") == 0) {
            refine = 1;
            continue;
        }
        if (strcmp(a, "--info") == 0) {
            info = 1;
            continue;
        }
        if (strcmp(a, "--trust") == 0) {
            trust = 1;
            continue;
        }
        if (strcmp(a, "-q") == 0) {
            quiet = 1;
            continue;
        }
        int known = views_is_option(a) || strcmp(a, "--views") == 0 ||
                    strcmp(a, "--orbit") == 0 || strcmp(a, "--split") == 0 ||
                    strcmp(a, "--light") == 0 || strcmp(a, "--background") == 0 ||
                    strcmp(a, "--threads") == 0 || strcmp(a, "--beam") == 0;
        if (!known)
            return diag_usage_error(usage_text, "unrecognized option '%s'", a);
        if (!val)
            return diag_usage_error(usage_text, "option '%s' needs a value", a);
        i++;
        parse_err e = PARSE_OK;
        if (views_is_option(a)) {
            if (views_apply(&base, a, val, msg, sizeof msg) != 0)
                return diag_usage_error(usage_text, "%s", msg);
        } else if (strcmp(a, "--views") == 0) {
            views_path = val;
        } else if (strcmp(a, "--orbit") == 0) {
            e = parse_long(val, 1, 100000, &orbit);
        } else if (strcmp(a, "--split") == 0) {
            e = parse_long(val, 0, OCT_MAX_LEVELS, &split);
        } else if (strcmp(a, "--threads") == 0) {
            e = parse_long(val, 1, 256, &threads);
        } else if (strcmp(a, "--beam") == 0) {
            e = parse_long(val, 0, FRAME_TILE, &beam);
        } else if (strcmp(a, "--light") == 0) {
            e = parse_vec3(val, light);
            has_light = 1;
            if (e == PARSE_OK && light[0] == 0 && light[1] == 0 && light[2] == 0)
                return diag_usage_error(usage_text, "--light: %s: must not be the zero vector", val);
        } else if (strcmp(a, "--background") == 0) {
            e = parse_vec3(val, bg);
            for (int k = 0; k < 3 && e == PARSE_OK; k++)
                if (!(bg[k] >= 0.0 && bg[k] <= 1.0))
                    e = PARSE_RANGE;
        }
        if (e != PARSE_OK) {
            snprintf(msg, sizeof msg, "%s: '%s': %s", a, val, parse_strerror(e));
            return diag_usage_error(usage_text, "%s", msg);
        }
    }
    if (!oct_path)
        return diag_usage_error(usage_text, "%s", "no input file");
    if (views_path && orbit)
        return diag_usage_error(usage_text, "%s", "--views and --orbit cannot be combined");
    if (views_path && base.out)
        return diag_usage_error(usage_text, "%s", "-o goes into the views file with --views");
    if (!views_path && !base.out && !info)
        return diag_usage_error(usage_text, "%s", "no output: give -o OUT.png or --views FILE");
    if (orbit && views_check_pattern(base.out) != 0)
        return diag_usage_error(usage_text, "--orbit: -o '%s' must hold exactly one integer conversion such as %%04d",
                           base.out);
    if (orbit && (base.depth || base.normals))
        return diag_usage_error(usage_text, "%s", "--orbit writes colour images only (no --depth or --normals)");

    if (views_path) {
        views_text = read_text(views_path);
        if (!views_text) {
            diag_path_error(views_path, "%s", strerror(errno));
            status = EXIT_RUNTIME;
            goto done;
        }
        views_report_ctx rc = {views_path};
        int r = views_parse(views_text, &base, &list, &nviews, report_line, &rc);
        if (r == -2) {
            diag_error("out of memory");
            status = EXIT_RUNTIME;
            goto done;
        }
        if (r != 0) {
            status = EXIT_USAGE;
            goto done;
        }
        if (nviews == 0) {
            diag_path_error(views_path, "no views");
            status = EXIT_USAGE;
            goto done;
        }
    }

    {
        oct_fault fault;
        oct_err err = oct_open_fault(oct_path, trust ? OCT_OPEN_TRUST : 0u, &file, &fault);
        if (err != OCT_OK) {
            if (err == OCT_EIO)
                diag_path_error(oct_path, "%s", strerror(errno));
            else if (fault.offset)
                diag_path_error(oct_path, "corrupt: %s at offset %llu", fault.what,
                                (unsigned long long)fault.offset);
            else
                diag_path_error(oct_path, "%s", oct_strerror(err));
            status = EXIT_RUNTIME;
            goto done;
        }
        tree = oct_get_tree(file);
        if (info && oct_print_info(stdout, file) != 0) {
            diag_path_error(oct_path, "cannot print the summary");
            status = EXIT_RUNTIME;
            goto done;
        }
    }
    if (!views_path && !base.out)
        goto done; /* --info only */
    if (oct_get_info(file)->flags & OCT_FLAG_SHELL_ONLY) { /* only the function can place hits */
        diag_path_error(oct_path, "stores no normals (rasterized with --shell-only): use --exact");
        status = EXIT_RUNTIME;
        goto done;
    }
    if (split > (long)tree->levels) {
        snprintf(msg, sizeof msg, "--split %ld: the tree has only %u levels", split,
                 (unsigned)tree->levels);
        status = diag_usage_error(usage_text, "%s", msg);
        goto done;
    }

    if (!views_path) {
        frame_cube(tree, &base);
        if (orbit) {
            list = views_orbit(&base, (unsigned)orbit, base.out);
            if (!list) {
                status = diag_usage_error(usage_text, "%s", "--orbit: the eye lies on the up axis through the target");
                goto done;
            }
            nviews = (size_t)orbit;
        } else {
            list = malloc(sizeof *list);
            if (!list) {
                diag_error("out of memory");
                status = EXIT_RUNTIME;
                goto done;
            }
            list[0] = base;
            nviews = 1;
        }
    }

    /* Check every view before rendering any. */
    cams = calloc(nviews, sizeof *cams);
    if (!cams) {
        diag_error("out of memory");
        status = EXIT_RUNTIME;
        goto done;
    }
    size_t max_px = 0;
    for (size_t k = 0; k < nviews; k++) {
        frame_cube(tree, &list[k]);
        camera_err ce = camera_init(&cams[k], list[k].eye, list[k].target, list[k].up,
                                    list[k].fov, list[k].width, list[k].height);
        if (ce != CAMERA_OK) {
            if (list[k].line)
                fprintf(stderr, "%s:%u: %s\n", views_path, list[k].line, camera_strerror(ce));
            else
                diag_error("%s", camera_strerror(ce));
            status = EXIT_USAGE;
        }
        size_t bytes;
        if (image_rgb_size((uint32_t)list[k].width, (uint32_t)list[k].height, &bytes) != 0) {
            diag_error("image size overflows");
            status = EXIT_USAGE;
        } else if (bytes / 3 > max_px) {
            max_px = bytes / 3;
        }
    }
    if (status != EXIT_OK)
        goto done;
    rgb = malloc(max_px * 3);
    int want_depth = 0, want_nrm = 0, want_nrm_f = 0;
    for (size_t k = 0; k < nviews; k++) {
        want_depth |= list[k].depth != NULL;
        want_nrm |= list[k].normals != NULL && !is_pfm(list[k].normals);
        want_nrm_f |= list[k].normals != NULL && is_pfm(list[k].normals);
    }
    if (want_depth)
        depth = malloc(max_px * sizeof *depth);
    if (want_nrm)
        nrm = malloc(max_px * 3);
    if (want_nrm_f)
        nrm_f = malloc(max_px * 3 * sizeof *nrm_f);
    if (!rgb || (want_depth && !depth) || (want_nrm && !nrm) || (want_nrm_f && !nrm_f)) {
        diag_error("out of memory for a %zu-pixel image", max_px);
        status = EXIT_RUNTIME;
        goto done;
    }
    if (threads == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        threads = n < 1 ? 1 : n > 64 ? 64 : n;
    }

    double total_ms = 0.0;
    uint64_t total_rays = 0;
    for (size_t k = 0; k < nviews; k++) {
        const views_view *v = &list[k];
        frame_job job;
        memset(&job, 0, sizeof job);
        job.tree = tree;
        job.cam = &cams[k];
        job.opts.split = split < 0 ? tree->levels : (unsigned)split;
        job.opts.refine = refine;
        job.shade.ambient = 0.15f;
        for (int a = 0; a < 3; a++)
            job.shade.background[a] = (float)bg[a];
        if (has_light)
            shade_set_light(&job.shade, light);
        else
            shade_default_light(&cams[k], job.shade.light);
        job.rgb = rgb;
        job.depth = v->depth ? depth : NULL;
        job.normals = v->normals && !is_pfm(v->normals) ? nrm : NULL;
        job.normals_f = v->normals && is_pfm(v->normals) ? nrm_f : NULL;
        job.threads = (unsigned)threads;
        job.beam_size = (unsigned)beam;
        if (!quiet && diag_stderr_is_tty())
            job.progress = progress_bar;
        frame_stats st;
        double t0 = now_ms();
        frame_render(&job, &st);
        double ms = now_ms() - t0;
        total_ms += ms;
        total_rays += st.rays;
        const char *op = NULL;
        const uint32_t w = (uint32_t)v->width, h = (uint32_t)v->height;
        if (image_write_png(v->out, rgb, w, h, &op) != 0) {
            diag_path_error(v->out, "%s: %s", op ? op : "write", strerror(errno));
            status = EXIT_RUNTIME;
            goto done;
        }
        if (v->depth && image_write_pfm(v->depth, depth, w, h, &op) != 0) {
            diag_path_error(v->depth, "%s: %s", op ? op : "write", strerror(errno));
            status = EXIT_RUNTIME;
            goto done;
        }
        if (v->normals && (is_pfm(v->normals) ? image_write_pfm_rgb(v->normals, nrm_f, w, h, &op)
                                              : image_write_png(v->normals, nrm, w, h, &op)) != 0) {
            diag_path_error(v->normals, "%s: %s", op ? op : "write", strerror(errno));
            status = EXIT_RUNTIME;
            goto done;
        }
        if (!quiet)
            fprintf(stderr, "render: %s: %ux%u, %.1f ms, %.2f Mrays/s, %.1f%% hit\n", v->out,
                    w, h, ms, ms > 0 ? (double)st.rays / ms / 1e3 : 0.0,
                    100.0 * (double)st.hits / (double)st.rays);
    }
    if (!quiet)
        fprintf(stderr, "render: %zu view%s, %.2f Mrays in %.1f ms, %.2f Mrays/s, %ld thread%s\n",
                nviews, nviews == 1 ? "" : "s", (double)total_rays / 1e6, total_ms,
                total_ms > 0 ? (double)total_rays / total_ms / 1e3 : 0.0, threads,
                threads == 1 ? "" : "s");

done:
    free(rgb);
    free(depth);
    free(nrm);
    free(nrm_f);
    free(cams);
    free(list);
    free(views_text);
    oct_close(file);
    return status;
}
