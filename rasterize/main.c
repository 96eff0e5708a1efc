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
#include "common/expr/tape_io.h"
#include "format/oct.h"
#include "rasterize/build.h"
#include "rasterize/merge.h"
#include "rasterize/scene_limits.h"
#include "rasterize/shard.h"

#define DEFAULT_LEVELS 10

static const char usage_text[] =
    "usage: rasterize SCENE -o OUT.oct [--levels N] [--method interval|lipschitz]\n"
    "                 [--threads N] [--shell-only] [--shard I/N] [-q]\n"
    "       rasterize --merge -o OUT.oct PART.oct...\n";

static const char help_text[] =
    "Subdivide space once around the implicit surfaces of SCENE and write the\n"
    "voxels they pass through (normal, plane offset, surface) as a sparse octree,\n"
    "with each surface's compiled function (for render --exact).\n"
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
    "  --shell-only           store only the tree and the surface functions, no\n"
    "                         per-voxel normals and planes (much smaller; the file\n"
    "                         renders with render --exact only)\n"
    "  --shard I/N            write only shard I (0..N-1) of an N-way split of the\n"
    "                         grid (N <= " LIMIT_STR(SHARD_MAX_COUNT) "): a valid .oct of its part; the N\n"
    "                         shards merge into exactly the whole file\n"
    "  --merge PART.oct...    merge the N shards of one split into OUT.oct, byte for\n"
    "                         byte the file a whole run writes\n"
    "  -q, --quiet            no progress bar and no summary\n"
    "  -h, --help             this text\n"
    "  --version              print the version and exit\n"
    "\n"
    "Until the end the voxel records (and with several surfaces their surface\n"
    "indices) wait in unlinked scratch files in $TMPDIR (default /tmp; at most half\n"
    "its free space), or in memory where none can be made; the output is the same.\n"
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

typedef struct options {
    const char *scene_path, *out_path;
    long levels, threads;
    build_method method;
    int quiet, shell_only, sharded, merge;
    uint32_t shard_index, shard_count;
    const char **parts; /* the positional arguments: SCENE, or --merge's parts */
    size_t nparts;
} options;

/* Parses the command line into *o. Returns -1 to go on, else the exit
 * status (help, version, usage errors). */
static int parse_options(int argc, char **argv, options *o)
{
    memset(o, 0, sizeof *o);
    o->levels = DEFAULT_LEVELS;
    o->threads = sysconf(_SC_NPROCESSORS_ONLN);
    o->method = BUILD_INTERVAL;
    if (o->threads < 1)
        o->threads = 1;
    if (o->threads > THREADS_DEFAULT_MAX)
        o->threads = THREADS_DEFAULT_MAX;
    /* Positional arguments are gathered at the front of argv (slot 1 + n is
     * never past the argument being read). */
    o->parts = (const char **)argv + 1;
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
            o->quiet = 1;
        } else if (!strcmp(a, "--shell-only")) {
            o->shell_only = 1;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a file name", a);
            o->out_path = argv[++i];
        } else if (!strcmp(a, "--levels")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            if (parse_long(argv[++i], 1, OCT_MAX_LEVELS, &o->levels) != PARSE_OK)
                return diag_usage_error(usage_text, "--levels: '%s' is not an integer from 1 to %d", argv[i],
                                        OCT_MAX_LEVELS);
        } else if (!strcmp(a, "--threads")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            if (parse_long(argv[++i], 1, THREADS_MAX, &o->threads) != PARSE_OK)
                return diag_usage_error(usage_text, "--threads: '%s' is not an integer from 1 to %d", argv[i],
                                        THREADS_MAX);
        } else if (!strcmp(a, "--method")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            const char *m = argv[++i];
            if (!strcmp(m, "interval"))
                o->method = BUILD_INTERVAL;
            else if (!strcmp(m, "lipschitz"))
                o->method = BUILD_LIPSCHITZ;
            else
                return diag_usage_error(usage_text, "--method: '%s' is not 'interval' or 'lipschitz'", m);
        } else if (!strcmp(a, "--shard")) {
            if (!has_value)
                return diag_usage_error(usage_text, "option '%s' needs a value", a);
            if (shard_parse(argv[++i], &o->shard_index, &o->shard_count) != 0)
                return diag_usage_error(usage_text, "--shard: '%s' is not I/N with 0 <= I < N <= %d",
                                        argv[i], SHARD_MAX_COUNT);
            o->sharded = 1;
        } else if (!strcmp(a, "--merge")) {
            o->merge = 1;
        } else if (a[0] == '-' && a[1] != '\0') {
            return diag_usage_error(usage_text, "unrecognized option '%s'", a);
        } else {
            o->parts[o->nparts++] = a;
        }
    }
    if (o->merge) {
        if (o->sharded)
            return diag_usage_error(usage_text, "%s", "--merge and --shard do not go together");
        if (!o->out_path)
            return diag_usage_error(usage_text, "%s", "missing -o OUT.oct");
        if (!o->nparts)
            return diag_usage_error(usage_text, "%s", "--merge needs the parts to merge");
        return -1;
    }
    if (o->nparts > 1)
        return diag_usage_error(usage_text, "unexpected argument '%s'", o->parts[1]);
    o->scene_path = o->nparts ? o->parts[0] : NULL;
    if (!o->scene_path)
        return diag_usage_error(usage_text, "%s", "missing SCENE");
    if (!o->out_path)
        return diag_usage_error(usage_text, "%s", "missing -o OUT.oct");
    return -1;
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

/* One file in two roles (the output is the scene or one of --merge's
 * parts), or an output that cannot be written: refused before any work.
 * Returns EXIT_OK or the exit status. */
static int check_files(const options *o)
{
    output_use *uses = malloc((o->nparts + 1) * sizeof *uses);
    if (!uses) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    for (size_t i = 0; i < o->nparts; i++)
        uses[i] = (output_use){o->parts[i], o->merge ? "a part" : "the scene", 0, 1};
    uses[o->nparts] = (output_use){o->out_path, "-o", 0, 0};
    char msg[2 * 4096 + 256];
    int rc = output_set_check(uses, o->nparts + 1, msg, sizeof msg);
    free(uses);
    if (rc != EXIT_OK)
        diag_error("%s", rc < 0 ? "out of memory" : msg);
    return rc < 0 ? EXIT_RUNTIME : rc;
}

/* Rasterizes the scene (or one shard of it) into the output file. */
static int rasterize_scene(const options *o)
{
    const char *scene_path = o->scene_path, *out_path = o->out_path;
    const unsigned levels = (unsigned)o->levels;
    int status = EXIT_RUNTIME;
    scene *sc = NULL;
    oct_writer *w = NULL;
    unsigned char *function = NULL;
    double t0 = now_seconds();
    scene_error serr;
    if (scene_load(scene_path, &sc, &serr) != 0) {
        scene_print_error(scene_path, &serr);
        goto done;
    }
    if (scene_limits_check(sc, (unsigned)levels, &serr) != 0) {
        scene_print_error(scene_path, &serr);
        goto done;
    }

    progress pr = {!o->quiet && diag_stderr_is_tty(), -1};
    build_params bp = {.levels = levels,
                       .method = o->method,
                       .threads = (unsigned)o->threads,
                       .progress = show_progress,
                       .progress_ctx = &pr,
                       .shell_only = o->shell_only};
    build_shard shard;
    double share = 1.0;
    if (o->sharded) {
        if (shard_plan(sc, &bp, o->shard_index, o->shard_count, &shard, &share) != 0) {
            diag_error("%s", strerror(ENOMEM));
            goto done;
        }
        bp.shard = &shard;
    }
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, levels, palette, &wp);
    /* every file carries the surfaces' whole tapes (format 1.1), for --exact */
    const tape *tapes[OCT_MAX_SURFACES];
    for (size_t s = 0; s < sc->nsurfaces; s++)
        tapes[s] = &sc->surfaces[s].tape;
    int trc = tape_io_encode(tapes, (unsigned)sc->nsurfaces, &function, &wp.function_size);
    if (trc != TAPE_OK) {
        diag_path_error(scene_path, "%s", tape_strerror(trc));
        goto done;
    }
    wp.function = function;
    wp.flags = o->shell_only ? OCT_FLAG_SHELL_ONLY : 0;
    /* the voxel records and surface indices wait in scratch files, not in
     * memory (README) */
    const char *tmpdir = getenv("TMPDIR");
    wp.spool_dir = tmpdir && *tmpdir ? tmpdir : "/tmp";
    if (bp.shard) { /* the shard's place in its partition, for --merge and --info */
        wp.shard_count = shard.count;
        wp.shard_index = shard.index;
        wp.shard_depth = shard.depth;
        wp.partition_crc = shard.crc;
        wp.morton_lo = shard.lo;
        wp.morton_hi = shard.hi;
    }
    oct_err err = oct_writer_create(&wp, &w);
    if (err != OCT_OK) {
        diag_path_error(scene_path, "%s", oct_strerror(err));
        goto done;
    }
    build_stats st;
    err = build_octree(sc, &bp, w, &st);
    if (err != OCT_OK) {
        diag_error("%s", oct_strerror(err));
        goto done;
    }

    uint64_t bytes = 0;
    if (write_output(w, out_path, &bytes) != 0)
        goto done;
    /* with the tree on stdout, the summary goes to stderr */
    FILE *to = output_path_is_stdout(out_path) ? stderr : stdout;
    if (!o->quiet) {
        if (bp.shard)
            fprintf(to, "rasterize: shard %u/%u: cells [%llu, %llu) of depth %u, %.2f%% of the estimated work "
                   "(partition crc %08x)\n",
                   (unsigned)shard.index, (unsigned)shard.count, (unsigned long long)shard.lo,
                   (unsigned long long)shard.hi, (unsigned)shard.depth, 100.0 * share,
                   (unsigned)shard.crc);
        print_summary(to, out_path, levels, &st, bytes, now_seconds() - t0);
    }
    status = EXIT_OK;
done:
    oct_writer_free(w);
    free(function);
    scene_free(sc);
    return status;
}

static int run(int argc, char **argv)
{
    diag_set_progname("rasterize");
    test_hooks_init();
    options o;
    int rc = parse_options(argc, argv, &o);
    if (rc >= 0)
        return rc;
    rc = check_files(&o);
    if (rc != EXIT_OK)
        return rc;
    if (o.merge)
        return merge_main(o.out_path, o.parts, o.nparts, o.quiet);
    return rasterize_scene(&o);
}

int main(int argc, char **argv) { return close_stdout(run(argc, argv)); }
