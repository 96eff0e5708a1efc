/* octvalidate: the .oct reader's validation throughput on a synthetic
 * ~50 MB file (12 levels, ~8.1 M clustered voxels, 3 surfaces), with and
 * without the CRCs; best of 20 opens each.
 *   build/rel/bin/octvalidate */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "format/oct.h"
#include "bench/oct_synth.h"

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int main(void)
{
    test_tree t;
    test_tree_random(&t, 12, 8100000, 3, 1, 1);
    unsigned char *buf;
    size_t len;
    oct_err rc = test_tree_write(&t, &buf, &len);
    if (rc != OCT_OK) {
        fprintf(stderr, "octvalidate: write: %s\n", oct_strerror(rc));
        return 1;
    }
    printf("synthetic file: %.1f MB, %zu voxels, %.2f bytes/voxel\n", (double)len / 1e6, t.voxel_count,
           (double)len / (double)t.voxel_count);
    for (int trust = 0; trust <= 1; trust++) {
        double best = 1e9;
        for (int r = 0; r < 20; r++) {
            oct_file *f;
            double a = seconds_now();
            rc = oct_open_memory(buf, len, trust ? OCT_OPEN_TRUST : 0, &f, NULL);
            double b = seconds_now() - a;
            if (rc != OCT_OK) {
                fprintf(stderr, "octvalidate: open: %s\n", oct_strerror(rc));
                return 1;
            }
            oct_close(f);
            if (b < best)
                best = b;
        }
        printf("validation %s: %.1f ms, %.0f MB/s\n", trust ? "without CRC" : "with CRC   ", best * 1e3,
               (double)len / 1e6 / best);
    }
    free(buf);
    test_tree_free(&t);
    return 0;
}
