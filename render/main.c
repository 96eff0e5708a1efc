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
#include "common/close_stdout.h"
#include "common/diag.h"
#include "common/limits.h"
#include "common/view/image.h"
#include "common/parse_num.h"
#include "common/test_hooks.h"
#include "common/version.h"
#include "format/oct.h"
#include "render/aa.h"
#include "render/ao.h"
#include "render/exact_load.h"
#include "render/frame.h"
#include "render/framing.h"
#include "render/map_guard.h"
#include "render/outputs.h"
#include "render/shade.h"
#include "render/trace.h"
#include "render/view_light.h"
#include "render/view_report.h"
#include "render/views.h"

_Static_assert(VIEWS_AA_MAX == AA_MAX && VIEWS_AO_MAX == AO_MAX_RAYS, "views limits");
#define RENDER_MAX_PARTS 100000 /* --part I/N: N at most the largest --orbit */

static const char usage_text[] =
    "usage: render FILE.oct -o OUT.png [--size WxH] [--eye X,Y,Z] [--target X,Y,Z]\n"
    "              [--up X,Y,Z] [--fov DEG] [--depth OUT.pfm] [--normals OUT.png]\n"
    "              [--split K] [--refine] [--exact] [--light X,Y,Z] [--background R,G,B]\n"
    "              [--aa N] [--alpha] [--shadows] [--ao N] [--ao-distance F]\n"
    "              [--beam N] [--threads N] [--trust] [--info] [-q] [-v]\n"
    "       render FILE.oct --views VIEWS_FILE [--part I/N] [options]\n"
    "       render FILE.oct -o 'frame_%04d.png' --orbit N [--part I/N] [options]\n"
    "       render --info FILE.oct\n";

static const char help_text[] =
    "\n"
    "Ray traces the voxels of FILE.oct (two-step discrete ray tracing).\n"
    "  -o OUT.png          colour image (8-bit sRGB PNG; '-': standard output)\n"
    "  --size WxH          image size in pixels (default 512x512, each 1.." LIMIT_STR(CAMERA_MAX_SIZE) ")\n"
    "  --eye, --target     camera position and aim (default: a view framing the occupied voxels)\n"
    "  --up X,Y,Z          up direction (default 0,0,1)\n"
    "  --fov DEG           vertical field of view, in (0, 180) (default 30)\n"
    "  --depth OUT.pfm     distance along each pixel's unit ray (PFM, +inf on miss)\n"
    "  --normals OUT.png   surface normals as colour, (n + 1) / 2 per channel;\n"
    "                      a name ending in .pfm gets float normals (3-channel PFM)\n"
    "  --split K           octree depth where the empty-space skipping stops (default: levels)\n"
    "  --refine            intersect the voxels' stored planes for sub-voxel depth\n"
    "  --exact             place each hit at the first root of the file's stored\n"
    "                      functions in the occupied voxels the ray crosses: exact\n"
    "                      depth, normals (the gradient) and colour (format 1.1)\n"
    "  --beam N            walk N x N pixel blocks (and their 4 x 4 sub-blocks) as\n"
    "                      pyramids first, to skip what no ray of them can hit\n"
    "                      (default 32; 0: off; same image)\n"
    "  --aa N              up to N x N samples for a pixel whose centre ray differs from\n"
    "                      a neighbour's, 1.." LIMIT_STR(VIEWS_AA_MAX) " (default 1: one ray a pixel)\n"
    "  --alpha             RGBA PNG, alpha = the fraction of the pixel's samples that hit\n"
    "  --shadows           one shadow ray per lit hit towards --light\n"
    "  --ao N              ambient occlusion: N rays over each hit's hemisphere,\n"
    "                      0.." LIMIT_STR(VIEWS_AO_MAX) " (default 0: off)\n"
    "  --ao-distance F     the AO rays' length in cube edges, (0, " LIMIT_STR(VIEWS_AO_DISTANCE_MAX) "] (default " LIMIT_STR(VIEWS_AO_DISTANCE) ")\n"
    "  --light X,Y,Z       direction towards the light (default over the viewer's shoulder)\n"
    "  --background R,G,B  linear colour of rays that miss, 0..1 each (default 0,0,0)\n"
    "  --threads N         worker threads, 1.." LIMIT_STR(THREADS_MAX) " (default: online CPUs, at most "
    LIMIT_STR(THREADS_DEFAULT_MAX) ")\n"
    "  --views FILE        one view a line, same options as above ('#' comments)\n"
    "  --orbit N           N views on a circle around the target; -o is a pattern\n"
    "                      with one integer conversion, e.g. frame_%04d.png\n"
    "  --part I/N          render only views I, I+N, I+2N, ... of --views or --orbit\n"
    "                      (0 <= I < N <= " LIMIT_STR(RENDER_MAX_PARTS) "): N parts write the frames of one run\n"
    "  --trust             skip the file's CRC-32 checks (a fixed cost per file); the\n"
    "                      structure is still validated in full\n"
    "  --info              print a summary of FILE.oct (format version, flags,\n"
    "                      tree, stored function, shard fields)\n"
    "  -q                  no per-view timing lines\n"
    "  -v                  per-view line with Mrays/s of each kind of ray\n"
    "  --version           print the version and exit\n"
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

/* The command line. */
typedef struct render_args {
    views_view base; /* the command line's view options */
    const char *oct_path, *views_path;
    long orbit, split, threads, beam;
    long part_index, part_count; /* --part I/N; count 0: every view */
    int refine, info, quiet, trust, verbose;
    double light[3], bg[3];
    int has_light;
} render_args;

/* One value option (a known name, its value). Returns -1 when it is good,
 * else the exit status. */
static int parse_value_option(render_args *o, const char *a, const char *val)
{
    char msg[512];
    parse_err e = PARSE_OK;
    if (views_is_option(a)) {
        if (views_apply(&o->base, a, val, msg, sizeof msg) != 0)
            return diag_usage_error(usage_text, "%s", msg);
    } else if (strcmp(a, "--views") == 0) {
        o->views_path = val;
    } else if (strcmp(a, "--orbit") == 0) {
        e = parse_long(val, 1, 100000, &o->orbit);
    } else if (strcmp(a, "--part") == 0) {
        e = parse_index_of(val, RENDER_MAX_PARTS, &o->part_index, &o->part_count);
    } else if (strcmp(a, "--split") == 0) {
        e = parse_long(val, 0, OCT_MAX_LEVELS, &o->split);
    } else if (strcmp(a, "--threads") == 0) {
        e = parse_long(val, 1, THREADS_MAX, &o->threads);
    } else if (strcmp(a, "--beam") == 0) {
        e = parse_long(val, 0, FRAME_TILE, &o->beam);
    } else if (strcmp(a, "--light") == 0) {
        e = parse_vec3(val, o->light);
        o->has_light = 1;
        shade_params sp;
        if (e == PARSE_OK && shade_set_light(&sp, o->light) != 0)
            return diag_usage_error(usage_text, "--light: %s: must be a finite, non-zero vector",
                                    val);
    } else if (strcmp(a, "--background") == 0) {
        e = parse_vec3(val, o->bg);
        for (int k = 0; k < 3 && e == PARSE_OK; k++)
            if (!(o->bg[k] >= 0.0 && o->bg[k] <= 1.0))
                e = PARSE_RANGE;
    }
    if (e != PARSE_OK) {
        snprintf(msg, sizeof msg, "%s: '%s': %s", a, val, parse_strerror(e));
        return diag_usage_error(usage_text, "%s", msg);
    }
    return -1;
}

/* The options' combinations that cannot work. Returns -1 when they are
 * good, else the exit status. */
static int check_args(const render_args *o)
{
    if (!o->oct_path)
        return diag_usage_error(usage_text, "%s", "no input file");
    if (o->views_path && o->orbit)
        return diag_usage_error(usage_text, "%s", "--views and --orbit cannot be combined");
    if (o->views_path && o->base.out)
        return diag_usage_error(usage_text, "%s", "-o goes into the views file with --views");
    if (o->refine && o->base.exact) /* each places the hits its own way */
        return diag_usage_error(usage_text, "%s", "--refine and --exact cannot be combined");
    if (!o->views_path && !o->base.out && !o->info)
        return diag_usage_error(usage_text, "%s", "no output: give -o OUT.png or --views FILE");
    int pattern = o->orbit ? views_check_pattern(o->base.out) : 0;
    if (pattern != 0)
        return diag_usage_error(usage_text, "--orbit: -o '%s': %s", o->base.out,
                                views_orbit_strerror(pattern == -2 ? VIEWS_ORBIT_WIDTH : VIEWS_ORBIT_PATTERN));
    char msg[512];
    if (!o->views_path && views_check(&o->base, msg, sizeof msg) != 0)
        return diag_usage_error(usage_text, "%s", msg);
    if (o->part_count && !o->views_path && !o->orbit)
        return diag_usage_error(usage_text, "%s", "--part needs --views or --orbit");
    if (o->orbit && (o->base.depth || o->base.normals))
        return diag_usage_error(usage_text, "%s", "--orbit writes colour images only (no --depth or --normals)");
    return -1;
}

/* Parses the command line into o. Returns -1 to go on, else the exit
 * status (--help, bad usage). */
static int parse_args(int argc, char **argv, render_args *o)
{
    memset(o, 0, sizeof *o);
    views_defaults(&o->base);
    o->split = -1;
    o->beam = FRAME_BEAM_DEFAULT;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            fputs(help_text, stdout);
            return EXIT_OK;
        }
        if (strcmp(a, "--version") == 0) {
            version_print("render");
            return EXIT_OK;
        }
        if (a[0] != '-' || a[1] == '\0') {
            if (o->oct_path)
                return diag_usage_error(usage_text, "unexpected argument '%s'", a);
            o->oct_path = a;
            continue;
        }
        int *flag = strcmp(a, "--refine") == 0 ? &o->refine
                    : strcmp(a, "--info") == 0 ? &o->info
                    : strcmp(a, "--trust") == 0 ? &o->trust
                    : strcmp(a, "-q") == 0     ? &o->quiet
                    : strcmp(a, "-v") == 0     ? &o->verbose
                                               : NULL;
        if (flag) {
            *flag = 1;
            continue;
        }
        if (views_flag(&o->base, a))
            continue;
        int known = views_is_option(a) || strcmp(a, "--views") == 0 ||
                    strcmp(a, "--orbit") == 0 || strcmp(a, "--split") == 0 || strcmp(a, "--part") == 0 ||
                    strcmp(a, "--light") == 0 || strcmp(a, "--background") == 0 ||
                    strcmp(a, "--threads") == 0 || strcmp(a, "--beam") == 0;
        if (!known)
            return diag_usage_error(usage_text, "unrecognized option '%s'", a);
        if (!val)
            return diag_usage_error(usage_text, "option '%s' needs a value", a);
        i++;
        int st = parse_value_option(o, a, val);
        if (st >= 0)
            return st;
    }
    return check_args(o);
}

/* Reads and parses the views file into *list. Returns EXIT_OK or the exit
 * status. */
static int load_views_file(const render_args *o, const views_view *base, char **text,
                           views_view **list, size_t *nviews)
{
    unsigned line = 0, col = 0;
    const char *what = NULL;
    int rr = views_read_file(o->views_path, text, &line, &col, &what);
    if (rr == -2) {
        diag_at(o->views_path, line, col, "%s", what);
        return EXIT_USAGE;
    }
    if (rr != 0) {
        diag_path_error(o->views_path, "%s", strerror(errno));
        return EXIT_RUNTIME;
    }
    views_report_ctx rc = {o->views_path};
    int r = views_parse(*text, base, list, nviews, report_line, &rc);
    if (r == -2) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    if (r != 0)
        return EXIT_USAGE;
    if (*nviews == 0) {
        diag_path_error(o->views_path, "no views");
        return EXIT_USAGE;
    }
    int bad = 0;
    for (size_t k = 0; o->refine && k < *nviews; k++)
        if ((*list)[k].exact) {
            report_line(&rc, (*list)[k].line,
                        "--exact and --refine (on the command line) cannot be combined");
            bad = 1;
        }
    return bad ? EXIT_USAGE : EXIT_OK;
}

/* Maps the .oct file (and prints its summary with --info). Returns EXIT_OK
 * or the exit status. */
static int open_tree(const render_args *o, oct_file **file)
{
    oct_fault fault;
    oct_err err = oct_open_fault(o->oct_path, o->trust ? OCT_OPEN_TRUST : 0u, file, &fault);
    if (err != OCT_OK) {
        if (err == OCT_EIO)
            diag_path_error(o->oct_path, "%s", strerror(errno));
        else if (fault.offset) /* what: the broken rule, without "corrupt: " */
            diag_path_error(o->oct_path, "corrupt: %s at offset %llu", fault.what,
                            (unsigned long long)fault.offset);
        else
            diag_path_error(o->oct_path, "%s", oct_strerror(err));
        return EXIT_RUNTIME;
    }
    if (o->info && oct_print_info(stdout, *file) != 0) {
        diag_path_error(o->oct_path, "cannot print the summary");
        return EXIT_RUNTIME;
    }
    return EXIT_OK;
}

/* The views of the command line alone: one, or --orbit's circle. Returns
 * EXIT_OK or the exit status. */
static int command_line_views(const oct_tree *tree, const render_args *o, views_view *base,
                              views_view **list, size_t *nviews)
{
    framing_default_view(tree, base);
    if (o->orbit) {
        views_orbit_err e = views_orbit(base, (unsigned)o->orbit, base->out, list);
        if (e == VIEWS_ORBIT_NOMEM) {
            diag_error("--orbit: out of memory for %ld views", o->orbit);
            return EXIT_RUNTIME;
        }
        if (e != VIEWS_ORBIT_OK)
            return diag_usage_error(usage_text, "--orbit: %s", views_orbit_strerror(e));
        *nviews = (size_t)o->orbit;
        return EXIT_OK;
    }
    *list = malloc(sizeof **list);
    if (!*list) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    (*list)[0] = *base;
    *nviews = 1;
    return EXIT_OK;
}

/* The image buffers, each as large as the largest view needs. */
typedef struct render_buffers {
    uint8_t *rgb, *nrm, *alpha;
    float *depth, *nrm_f;
} render_buffers;

/* Checks every view before rendering any (its camera, its size), sets up
 * the cameras and allocates the buffers. Returns EXIT_OK or the exit status. */
static int prepare_views(const oct_tree *tree, const char *views_path, views_view *list,
                         size_t nviews, camera **cams, render_buffers *buf)
{
    int status = EXIT_OK;
    *cams = calloc(nviews, sizeof **cams);
    if (!*cams) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    size_t max_px = 0;
    for (size_t k = 0; k < nviews; k++) {
        framing_default_view(tree, &list[k]);
        camera_err ce = camera_init(&(*cams)[k], list[k].eye, list[k].target, list[k].up,
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
        return status;
    buf->rgb = malloc(max_px * 3);
    int want_depth = 0, want_nrm = 0, want_nrm_f = 0, want_alpha = 0;
    for (size_t k = 0; k < nviews; k++) {
        want_alpha |= list[k].alpha;
        want_depth |= list[k].depth != NULL;
        want_nrm |= list[k].normals != NULL && !outputs_is_pfm(list[k].normals);
        want_nrm_f |= list[k].normals != NULL && outputs_is_pfm(list[k].normals);
    }
    if (want_depth)
        buf->depth = malloc(max_px * sizeof *buf->depth);
    if (want_nrm)
        buf->nrm = malloc(max_px * 3);
    if (want_nrm_f)
        buf->nrm_f = malloc(max_px * 3 * sizeof *buf->nrm_f);
    if (want_alpha)
        buf->alpha = malloc(max_px);
    if (!buf->rgb || (want_depth && !buf->depth) || (want_nrm && !buf->nrm) ||
        (want_nrm_f && !buf->nrm_f) || (want_alpha && !buf->alpha)) {
        diag_error("out of memory for a %zu-pixel image", max_px);
        return EXIT_RUNTIME;
    }
    return EXIT_OK;
}

/* Renders one view and writes its images; adds its time and rays to the
 * totals. Returns EXIT_OK or EXIT_RUNTIME. */
static int render_view(const oct_tree *tree, const render_args *o, const views_view *v,
                       const camera *cam, const render_buffers *buf, const exact_scene *es,
                       frame_keep *keep, uint64_t shadow_pixels, double *total_ms,
                       uint64_t *total_rays)
{
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = tree;
    job.cam = cam;
    job.exact = v->exact ? es : NULL;
    job.opts.split = o->split < 0 ? tree->levels : (unsigned)o->split;
    job.opts.refine = o->refine;
    job.shade.ambient = 0.15f;
    for (int a = 0; a < 3; a++)
        job.shade.background[a] = (float)o->bg[a];
    view_light(o->has_light, o->light, cam, job.shade.light);
    job.shadow_pixels = shadow_pixels;
    job.rgb = buf->rgb;
    job.depth = v->depth ? buf->depth : NULL;
    job.normals = v->normals && !outputs_is_pfm(v->normals) ? buf->nrm : NULL;
    job.normals_f = v->normals && outputs_is_pfm(v->normals) ? buf->nrm_f : NULL;
    job.threads = (unsigned)o->threads;
    job.beam_size = (unsigned)o->beam;
    job.aa = (unsigned)v->aa;
    job.alpha = v->alpha ? buf->alpha : NULL;
    job.shade.shadows = v->shadows;
    job.keep = keep;
    job.shade.ao_rays = (unsigned)v->ao;
    job.shade.ao_distance = v->ao_distance;
    job.timing = o->verbose;
    if (!o->quiet && diag_stderr_is_tty())
        job.progress = progress_bar;
    frame_stats st;
    double t0 = now_ms();
    const int rc = frame_render(&job, &st);
    if (rc < 0) {
        diag_error("out of memory for --exact's scratch");
        return EXIT_RUNTIME;
    }
    if (rc != 0) /* fewer threads, or (out of memory for --aa) one ray a pixel */
        fprintf(stderr, "render: %s: %s: rendered with what could be had\n", v->out, strerror(rc));
    double ms = now_ms() - t0;
    if (st.file_changed || map_guard_changed()) { /* before any output of this view */
        diag_path_error(o->oct_path, "changed while being read");
        return EXIT_RUNTIME;
    }
    *total_ms += ms;
    *total_rays += st.rays;
    const uint32_t w = (uint32_t)v->width, h = (uint32_t)v->height;
    outputs_images img = {.rgb = buf->rgb,
                          .nrm = buf->nrm,
                          .alpha = v->alpha ? buf->alpha : NULL,
                          .depth = buf->depth,
                          .nrm_f = buf->nrm_f,
                          .width = w,
                          .height = h};
    if (outputs_write_view(v, &img) != EXIT_OK)
        return EXIT_RUNTIME;
    if (!o->quiet)
        view_report(v, &st, ms, o->verbose, (unsigned)o->threads);
    return EXIT_OK;
}

/* The view loop: every view in turn (with --part I/N, views I, I+N, ...),
 * then the totals line. */
static int render_views(const oct_tree *tree, const render_args *o, const views_view *list,
                        size_t nviews, const camera *cams, const render_buffers *buf,
                        const exact_scene *es)
{
    double total_ms = 0.0;
    uint64_t total_rays = 0;
    size_t first = o->part_count ? (size_t)o->part_index : 0, step = o->part_count ? (size_t)o->part_count : 1;
    size_t done = 0;
    frame_keep keep = {0}; /* the shadow map and the border probes, view to view */
    uint64_t *ahead = calloc(nviews, sizeof *ahead); /* NULL: each frame's own pixels */
    if (ahead)
        view_shadow_pixels(o->has_light, o->light, list, cams, nviews, first, step, ahead);
    for (size_t k = first; k < nviews; k += step, done++) {
        test_hooks_view((unsigned)k + 1);
        int st = EXIT_RUNTIME;
        if (map_guard_changed())
            diag_path_error(o->oct_path, "changed while being read");
        else
            st = render_view(tree, o, &list[k], &cams[k], buf, es, &keep,
                             ahead ? ahead[k] : 0, &total_ms, &total_rays);
        if (st != EXIT_OK) {
            frame_keep_free(&keep);
            free(ahead);
            return st;
        }
    }
    frame_keep_free(&keep);
    free(ahead);
    if (!o->quiet && o->part_count)
        fprintf(stderr, "render: part %ld/%ld: %zu of %zu views\n", o->part_index, o->part_count, done,
                nviews);
    if (!o->quiet)
        fprintf(stderr, "render: %zu view%s, %.2f Mrays in %.1f ms, %.2f Mrays/s, %ld thread%s\n",
                done, done == 1 ? "" : "s", (double)total_rays / 1e6, total_ms,
                total_ms > 0 ? (double)total_rays / total_ms / 1e3 : 0.0, o->threads,
                o->threads == 1 ? "" : "s");
    return EXIT_OK;
}

static int run(int argc, char **argv)
{
    diag_set_progname("render");
    test_hooks_init();
    render_args o;
    int status = parse_args(argc, argv, &o);
    if (status >= 0)
        return status;
    status = EXIT_OK;
    char *views_text = NULL;
    views_view *list = NULL;
    size_t nviews = 0;
    render_buffers buf = {NULL, NULL, NULL, NULL, NULL};
    camera *cams = NULL;
    oct_file *file = NULL;
    exact_loaded exact;
    memset(&exact, 0, sizeof exact);

    if (o.views_path)
        status = load_views_file(&o, &o.base, &views_text, &list, &nviews);
    if (status == EXIT_OK)
        status = open_tree(&o, &file);
    if (status != EXIT_OK || (!o.views_path && !o.base.out))
        goto done; /* an error, or --info only */
    int any_exact = o.base.exact, all_exact = nviews ? 1 : o.base.exact;
    for (size_t k = 0; k < nviews; k++) {
        any_exact |= list[k].exact;
        all_exact &= list[k].exact;
    }
    if ((oct_get_info(file)->flags & OCT_FLAG_SHELL_ONLY) && !all_exact) {
        /* only the function can place hits */
        diag_path_error(o.oct_path, "stores no normals (rasterized with --shell-only): use --exact");
        status = EXIT_RUNTIME;
        goto done;
    }
    const char *why = NULL;
    if (any_exact && exact_load(file, &exact, &why) != 0) {
        diag_path_error(o.oct_path, "%s", why);
        status = EXIT_RUNTIME;
        goto done;
    }
    const oct_tree *tree = oct_get_tree(file);
    if (o.split > (long)tree->levels) {
        char msg[512];
        snprintf(msg, sizeof msg, "--split %ld: the tree has only %u levels", o.split,
                 (unsigned)tree->levels);
        status = diag_usage_error(usage_text, "%s", msg);
        goto done;
    }
    if (!o.views_path)
        status = command_line_views(tree, &o, &o.base, &list, &nviews);
    if (status == EXIT_OK)
        status = outputs_check(o.oct_path, o.views_path, list, nviews);
    if (status == EXIT_OK)
        status = prepare_views(tree, o.views_path, list, nviews, &cams, &buf);
    if (status != EXIT_OK)
        goto done;
    if (o.threads == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        o.threads = n < 1 ? 1 : n > THREADS_DEFAULT_MAX ? THREADS_DEFAULT_MAX : n;
    }
    if (map_guard_open(o.oct_path, oct_get_info(file)->file_size) != 0) {
        if (errno)
            diag_path_error(o.oct_path, "%s", strerror(errno));
        else
            diag_path_error(o.oct_path, "changed while being read");
        status = EXIT_RUNTIME;
        goto done;
    }
    status = render_views(tree, &o, list, nviews, cams, &buf, any_exact ? &exact.es : NULL);

done:
    map_guard_close();
    exact_loaded_free(&exact);
    free(buf.rgb);
    free(buf.depth);
    free(buf.nrm);
    free(buf.nrm_f);
    free(buf.alpha);
    free(cams);
    free(list);
    free(views_text);
    oct_close(file);
    return status;
}

int main(int argc, char **argv) { return close_stdout(run(argc, argv)); }
