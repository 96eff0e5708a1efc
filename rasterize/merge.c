/* merge: rasterize --merge (merge.h). */
#include "rasterize/merge.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "common/atomic_file.h"
#include "common/diag.h"
#include "format/oct_merge.h"

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int merge_main(const char *out_path, const char *const *parts, size_t n, int quiet)
{
    double t0 = now_seconds();
    atomic_file *af = atomic_file_open(out_path);
    if (!af) {
        diag_path_error(out_path, "%s", strerror(errno));
        return EXIT_RUNTIME;
    }
    oct_merge_error e;
    uint64_t bytes = 0;
    if (oct_merge(parts, n, atomic_file_stream(af), &bytes, &e) != OCT_OK) {
        atomic_file_abort(af);
        if (e.path)
            diag_path_error(e.path, "%s", e.msg);
        else if (e.err == OCT_EIO)
            diag_path_error(out_path, "%s", e.msg);
        else
            diag_error("--merge: %s", e.msg);
        return EXIT_RUNTIME;
    }
    const char *op = NULL;
    if (atomic_file_commit(af, &op) != 0) {
        diag_path_error(out_path, "%s: %s", op, strerror(errno));
        return EXIT_RUNTIME;
    }
    if (!quiet) {
        double s = now_seconds() - t0;
        printf("rasterize: %s: merged %zu shards, %llu bytes, %.3f s (%.1f MB/s)\n", out_path, n,
               (unsigned long long)bytes, s, s > 0 ? (double)bytes / s / 1e6 : 0.0);
    }
    return EXIT_OK;
}
