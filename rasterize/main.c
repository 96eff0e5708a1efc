/* rasterize: scene file -> sparse voxel octree (.oct), written atomically. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "common/atomic_file.h"
#include "common/close_stdout.h"
#include "common/diag.h"
#include "common/limits.h"
#include "common/output_path.h"
#include "common/output_set.h"
#include "common/parse_num.h"
#include "common/test_hooks.h"
#include "common/version.h"
#include "common/expr/scene.h"
#include "format/oct.h"
#include "rasterize/build.h"

#define DEFAULT_LEVELS 10

static const char usage_text[] =
    "usage: rasterize SCENE -o OUT.oct [--levels N] [--method interval|lipschitz]\n"
    "                 [--threads N] [-q]\n";

static const char help_text[] =
    "Subdivide space once around the implicit surfaces of SCENE and write the\n"
    "voxels they pass through (normal, plane offset, surface) as a sparse octree.\n"
    "\n"
    "  -o, --output OUT.oct   output file (written atomically: all or nothing;\n"
    "                         '-': standard output, the summary then on stderr)\n"
    "  --levels N             octree levels: a 2^N grid over the cube enclosing the\n"
    "                         scene's bounds (1.." LIMIT_STR(OCT_MAX_LEVELS) ", default 10)\n"
    "  --method M             interval (default): drop a cell when the interval of f\n"
    "                         over it excludes 0 (Duff), with a first-order Taylor\n"
    "                         test at the finest levels; lipschitz: drop it when\n"
    "                         |f(centre)| exceeds the gradient bound (Kalra-Barr)\n"
    "  --threads N            worker threads, 1.." LIMIT_STR(THREADS_MAX) " (default: the number of\n"
    "                         cores, at most " LIMIT_STR(THREADS_DEFAULT_MAX) ")\n"
    "  -q, --quiet            no progress bar and no summary\n"
    "  -h, --help             this text\n"
    "  --version              print the version and exit\n"
    "\n"
    "Exit status: 0 success, 1 run-time failure, 2 bad usage.\n";

typedef struct progress {
    int enabled;
    int last;
} progress;

static void show_progress(void *ctx, double fraction)
{
    progress *pr = ctx;
    int pct = (int)(fraction * 100.0);
    if (!pr->enabled || pct == pr->last)
        return;
    pr->last = pct;
    int bar = pct * 40 / 100;
    fprintf(stderr, "\rrasterize [%-40.*s] %3d%%", bar, "########################################", pct);
    if (pct == 100)
        fputs("\r\033[K", stderr);
    fflush(stderr);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static long peak_rss_kib(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss : 0;
}

static void print_summary(FILE *to, const char *out, unsigned levels, const build_stats *st,
                          uint64_t bytes, double seconds)
{
    fprintf(to, "rasterize: %s: levels %u (%u^3), %llu voxels, %llu nodes, %llu bytes (%.2f bytes/voxel)\n",
           out, levels, 1u << levels, (unsigned long long)st->voxels, (unsigned long long)st->nodes,
           (unsigned long long)bytes, st->voxels ? (double)bytes / (double)st->voxels : 0.0);
    fprintf(to, "rasterize: evaluations: %llu interval, %llu interval-gradient, %llu point; "
           "pruning ran %.1f%% of the instructions; %llu voxels dropped by the Taylor test\n",
           (unsigned long long)st->interval_evals, (unsigned long long)st->gradient_evals,
           (unsigned long long)st->point_evals,
           st->insns_full ? 100.0 * (double)st->insns_evaluated / (double)st->insns_full : 100.0,
           (unsigned long long)st->taylor_drops);
    fprintf(to, "rasterize: %llu cells where f may be undefined, %llu normal fallbacks; "
           "%.3f s, peak memory %.1f MiB\n",
           (unsigned long long)st->nan_cells, (unsigned long long)st->normal_fallbacks, seconds,
           (double)peak_rss_kib() / 1024.0);
}

/* Writes the finished tree to out_path, all or nothing (atomic_file.h).
 * Returns 0, or -1 after the message. */
static int write_output(oct_writer *w, const char *out_path, uint64_t *bytes)
{
    atomic_file *af = atomic_file_open(out_path);
    if (!af) {
        diag_path_error(out_path, "%s", strerror(errno));
        return -1;
    }
    oct_err err = oct_writer_finish(w, atomic_file_stream(af), bytes);
    if (err != OCT_OK) {
        diag_path_error(out_path, "write: %s", err == OCT_EIO ? strerror(errno) : oct_strerror(err));
        atomic_file_abort(af);
        return -1;
    }
    const char *op = NULL;
    if (atomic_file_commit(af, &op) != 0) {
        diag_path_error(out_path, "%s: %s", op, strerror(errno));
        return -1;
    }
    return 0;
}

/* One file in two roles, or an output that cannot be written: refused
 * before the scene is even read. Returns EXIT_OK or the exit status. */
static int check_files(const char *scene_path, const char *out_path)
{
    const output_use uses[2] = {{scene_path, "the scene", 0, 1}, {out_path, "-o", 0, 0}};
    char msg[2 * 4096 + 256];
    int rc = output_set_check(uses, 2, msg, sizeof msg);
    if (rc != EXIT_OK)
        diag_error("%s", rc < 0 ? "out of memory" : msg);
    return rc < 0 ? EXIT_RUNTIME : rc;
}

static int run(int argc, char **argv)
{
    diag_set_progname("rasterize");
    test_hooks_init();
    const char *scene_path = NULL, *out_path = NULL;
    long levels = DEFAULT_LEVELS, threads = sysconf(_SC_NPROCESSORS_ONLN);
    build_method method = BUILD_INTERVAL;
    int quiet = 0;
    if (threads < 1)
        threads = 1;
    if (threads > THREADS_DEFAULT_MAX)
        threads = THREADS_DEFAULT_MAX;

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        int has_value = i + 1 < argc;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage_text, stdout);
            fputs(help_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--version")) {
            version_print("rasterize");
            return EXIT_OK;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a file name", a);
            out_path = argv[++i];
        } else if (!strcmp(a, "--levels")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            if (parse_long(argv[++i], 1, OCT_MAX_LEVELS, &levels) != PARSE_OK)
                return diag_usage_error(usage_text, "--levels: '%s' is not an integer from 1 to %d", argv[i],
                                        OCT_MAX_LEVELS);
        } else if (!strcmp(a, "--threads")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            if (parse_long(argv[++i], 1, THREADS_MAX, &threads) != PARSE_OK)
                return diag_usage_error(usage_text, "--threads: '%s' is not an integer from 1 to %d", argv[i],
                                        THREADS_MAX);
        } else if (!strcmp(a, "--method")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            const char *m = argv[++i];
            if (!strcmp(m, "interval"))
                method = BUILD_INTERVAL;
            else if (!strcmp(m, "lipschitz"))
                method = BUILD_LIPSCHITZ;
            else
                return diag_usage_error(usage_text, "--method: '%s' is not 'interval' or 'lipschitz'", m);
        } else if (a[0] == '-' && a[1] != '\0') {
            return diag_usage_error(usage_text, "unrecognized option '%s'", a);
        } else if (!scene_path) {
            scene_path = a;
        } else {
            return diag_usage_error(usage_text, "unexpected argument '%s'", a);
        }
    }
    if (!scene_path)
        return diag_usage_error(usage_text, "%s", "missing SCENE");
    if (!out_path)
        return diag_usage_error(usage_text, "%s", "missing -o OUT.oct");

    int checked = check_files(scene_path, out_path);
    if (checked != EXIT_OK)
        return checked;

    int status = EXIT_RUNTIME;
    scene *sc = NULL;
    oct_writer *w = NULL;
    double t0 = now_seconds();
    scene_error serr;
    if (scene_load(scene_path, &sc, &serr) != 0) {
        scene_print_error(scene_path, &serr);
        goto done;
    }
    if (sc->nsurfaces > OCT_MAX_SURFACES) {
        diag_path_error(scene_path, "%zu surfaces; at most %d are supported", sc->nsurfaces,
                        OCT_MAX_SURFACES);
        goto done;
    }

    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, (unsigned)levels, palette, &wp);
    oct_err err = oct_writer_create(&wp, &w);
    if (err != OCT_OK) {
        diag_path_error(scene_path, "%s", oct_strerror(err));
        goto done;
    }

    progress pr = {!quiet && diag_stderr_is_tty(), -1};
    build_params bp = {(unsigned)levels, method, (unsigned)threads, show_progress, &pr};
    build_stats st;
    err = build_octree(sc, &bp, w, &st);
    if (err != OCT_OK) {
        diag_error("%s", oct_strerror(err));
        goto done;
    }

    uint64_t bytes = 0;
    if (write_output(w, out_path, &bytes) != 0)
        goto done;
    if (!quiet)
        print_summary(output_path_is_stdout(out_path) ? stderr : stdout, out_path, (unsigned)levels,
                      &st, bytes, now_seconds() - t0);
    status = EXIT_OK;
done:
    oct_writer_free(w);
    scene_free(sc);
    return status;
}

int main(int argc, char **argv) { return close_stdout(run(argc, argv)); }
