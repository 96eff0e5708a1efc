/* fuzz_trace: bytes -> a small tree (tree_util) and a ray whose crossing
 * times are exact doubles (start a multiple of 2^-8, direction components
 * +-0 or +-2^j), traced for every split K and compared with a brute-force
 * slab test of every voxel under trace.h's tie rule. Aborts on a mismatch
 * or a step count over trace_max_steps.
 *
 * Layout: byte 0 levels (1..6), byte 1 voxel count (0..63), then per axis 4
 * bytes of start (int32, grid units * 2^8, folded into [-2N, 3N]) and 1 byte
 * of direction, then 3 bytes a voxel (coordinates mod 2^levels). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/trace.h"
#include "bench/tree_util.h"
#include "tests/trace_oracle.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static double dir_of(uint8_t b)
{
    if ((b & 7) == 0)
        return b & 8 ? -0.0 : 0.0;
    double m = ldexp(1.0, (int)((b >> 4) % 7) - 3);
    return b & 8 ? -m : m;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 17)
        return 0;
    const unsigned levels = 1 + data[0] % 6;
    const uint32_t lim = UINT32_C(1) << levels;
    size_t n = data[1] % 64;
    if (size < 17 + 3 * n)
        n = (size - 17) / 3;
    double o[3], d[3];
    for (int a = 0; a < 3; a++) {
        int32_t v;
        memcpy(&v, data + 2 + 5 * a, 4);
        double span = 5.0 * lim * 256.0;
        double f = fmod((double)v, span);
        if (f < 0)
            f += span;
        o[a] = (f - 2.0 * lim * 256.0) / 256.0;
        d[a] = dir_of(data[6 + 5 * a]);
    }
    if (d[0] == 0 && d[1] == 0 && d[2] == 0)
        return 0;
    uint32_t(*vox)[3] = calloc(n + 1, sizeof *vox);
    uint32_t *attrs = calloc(n + 1, sizeof *attrs);
    if (!vox || !attrs)
        abort();
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *p = data + 17 + 3 * i;
        uint32_t v[3] = {p[0] % lim, p[1] % lim, p[2] % lim};
        int dup = 0;
        for (size_t j = 0; j < m && !dup; j++)
            dup = !memcmp(vox[j], v, sizeof v);
        if (dup)
            continue;
        memcpy(vox[m], v, sizeof v);
        attrs[m] = (uint32_t)m + 1;
        m++;
    }
    const double origin[3] = {0, 0, 0};
    oct_tree *t = tree_util_build(levels, origin, (double)lim, (const uint32_t(*)[3])vox, m, attrs,
                                  NULL, 1, NULL);
    if (!t)
        abort();
    /* oracle: exact because every (k - o) / d is an exact double here */
    long best = -1;
    double best_t = INFINITY;
    for (size_t i = 0; i < m; i++) {
        double lo = 0.0, hi = INFINITY;
        int ok = 1;
        for (int a = 0; a < 3 && ok; a++) {
            if (d[a] == 0.0) {
                double f = floor(o[a]);
                ok = o[a] >= 0 && o[a] <= lim && vox[i][a] == (f >= lim ? lim - 1 : (uint32_t)f);
                continue;
            }
            double k = vox[i][a];
            double en = ((d[a] > 0 ? k : k + 1) - o[a]) / d[a];
            double ex = ((d[a] > 0 ? k + 1 : k) - o[a]) / d[a];
            lo = en > lo ? en : lo;
            hi = ex < hi ? ex : hi;
        }
        if (ok && lo < hi && lo < best_t) {
            best_t = lo;
            best = (long)i;
        }
    }
    for (unsigned k = 0; k <= levels; k++) {
        trace_opts opts = {k, 0, NULL};
        trace_hit h;
        trace_cast_all(t, &opts, o, d, &h); /* unit cells: world = grid */
        int good = h.steps <= trace_max_steps(levels);
        if (best < 0)
            good = good && !h.hit;
        else
            good = good && h.hit && t->voxels[h.voxel] == (uint32_t)best + 1 && h.t == best_t;
        if (!good) {
            fprintf(stderr, "fuzz_trace: L=%u K=%u o=(%a %a %a) d=(%a %a %a): hit %d (%u %u %u) t %a, "
                            "oracle %ld t %a\n",
                    levels, k, o[0], o[1], o[2], d[0], d[1], d[2], h.hit, h.xyz[0], h.xyz[1], h.xyz[2],
                    h.t, best, best_t);
            abort();
        }
    }
    tree_util_free(t);
    free(vox);
    free(attrs);
    return 0;
}
