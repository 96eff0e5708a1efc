/* shard: the partition of a sharded rasterization (shard.h). */
#include "rasterize/shard.h"

#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "common/parse_num.h"
#include "rasterize/build_internal.h"

/* How many levels below depth k the coarse pass counts surviving cells:
 * their number follows the surface area inside the cell, which is what the
 * work below it grows with. Two levels keep the pass to a few per cent of a
 * shard's time at 12 levels (docs/perf-log.md, shard). */
#define ESTIMATE_DEPTH 2u
#define SHARD_MIN_DEPTH 4u

int shard_parse(const char *s, uint32_t *index, uint32_t *count)
{
    long i, n;
    if (parse_index_of(s, SHARD_MAX_COUNT, &i, &n) != PARSE_OK)
        return -1;
    *index = (uint32_t)i;
    *count = (uint32_t)n;
    return 0;
}

unsigned shard_depth(unsigned levels, unsigned mv_levels, uint32_t count)
{
    unsigned k = SHARD_MIN_DEPTH;
    while ((UINT64_C(1) << (3 * k)) < 64 * (uint64_t)count)
        k++;
    unsigned top = levels > mv_levels ? levels - mv_levels : 0;
    return k < top ? k : top;
}

/* Surviving descendants, `stop` deep, of a cell already kept at depth. */
static uint64_t count_below(worker *wk, unsigned depth, const uint64_t cell[3], unsigned stop)
{
    if (depth == stop)
        return 1;
    uint64_t n = 0;
    for (unsigned i = 0; i < 8; i++) {
        uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1), 2 * cell[2] + (i >> 2)};
        interval box[3];
        double centre[3];
        if (cell_test_surviving(wk, depth + 1, depth + 1, cc, box, centre))
            n += count_below(wk, depth + 1, cc, stop);
    }
    return n;
}

/* Down from a kept cell (Morton code m) to the cells of depth k. */
static void estimate_below(worker *wk, unsigned depth, const uint64_t cell[3], uint64_t m, unsigned k,
                           unsigned stop, uint64_t *weight)
{
    if (depth == k) {
        weight[m] = 1 + count_below(wk, depth, cell, stop);
        return;
    }
    for (unsigned i = 0; i < 8; i++) {
        uint64_t cc[3] = {2 * cell[0] + (i & 1), 2 * cell[1] + ((i >> 1) & 1), 2 * cell[2] + (i >> 2)};
        interval box[3];
        double centre[3];
        if (cell_test_surviving(wk, depth + 1, depth + 1, cc, box, centre))
            estimate_below(wk, depth + 1, cc, 8 * m + i, k, stop, weight);
    }
}

int shard_estimate(const scene *sc, const build_params *p, unsigned depth, uint64_t *weight)
{
    memset(weight, 0, ((size_t)1 << (3 * depth)) * sizeof *weight);
    build_params whole = *p;
    whole.shard = NULL;
    build_ctx c;
    worker wk;
    int rc = -1;
    memset(&wk, 0, sizeof wk);
    if (build_ctx_init(&c, sc, &whole) != 0 || worker_init(&wk, &c) != 0)
        goto done;
#if defined(__SSE2__)
    unsigned csr = _mm_getcsr(); /* the build's workers flush subnormals; so does this pass */
    _mm_setcsr(csr | 0x8040u);
#endif
    unsigned stop = depth + ESTIMATE_DEPTH < p->levels ? depth + ESTIMATE_DEPTH : p->levels - 1;
    if (stop < depth)
        stop = depth;
    const uint64_t root[3] = {0, 0, 0};
    interval box[3];
    double centre[3];
    if (cell_test_surviving(&wk, 0, 0, root, box, centre))
        estimate_below(&wk, 0, root, 0, depth, stop, weight);
#if defined(__SSE2__)
    _mm_setcsr(csr);
#endif
    rc = 0;
done:
    worker_free(&wk);
    build_ctx_free(&c);
    return rc;
}

void shard_cut(const uint64_t *weight, uint64_t ncells, uint32_t count, uint64_t *bounds)
{
    uint64_t total = 0;
    for (uint64_t c = 0; c < ncells; c++)
        total += weight[c]; /* at most 2^21 cells of 1 + 8^2 each */
    uint64_t c = 0, sum = 0;
    bounds[0] = 0;
    for (uint32_t i = 1; i < count; i++) {
        uint64_t target = (total * i + count - 1) / count; /* ceil(i W / N), i W < 2^40 */
        while (c < ncells && sum < target)
            sum += weight[c++];
        bounds[i] = c;
    }
    bounds[count] = ncells;
}

uint32_t shard_partition_crc(const uint64_t *bounds, uint32_t count)
{
    uLong crc = crc32_z(0, NULL, 0);
    for (uint32_t i = 0; i <= count; i++) {
        unsigned char b[8];
        for (int k = 0; k < 8; k++)
            b[k] = (unsigned char)(bounds[i] >> (8 * k));
        crc = crc32_z(crc, b, 8);
    }
    return (uint32_t)crc;
}

int shard_plan(const scene *sc, const build_params *p, uint32_t index, uint32_t count,
               build_shard *out, double *share)
{
    unsigned k = shard_depth(p->levels, build_mean_value_levels(sc, p->method), count);
    uint64_t ncells = UINT64_C(1) << (3 * k);
    uint64_t *weight = malloc(ncells * sizeof *weight);
    uint64_t *bounds = malloc(((size_t)count + 1) * sizeof *bounds);
    int rc = -1;
    if (!weight || !bounds || shard_estimate(sc, p, k, weight) != 0)
        goto done;
    shard_cut(weight, ncells, count, bounds);
    memset(out, 0, sizeof *out);
    out->count = count;
    out->index = index;
    out->depth = k;
    out->crc = shard_partition_crc(bounds, count);
    out->lo = bounds[index];
    out->hi = bounds[index + 1];
    if (share) {
        uint64_t total = 0, mine = 0;
        for (uint64_t c = 0; c < ncells; c++) {
            total += weight[c];
            if (c >= out->lo && c < out->hi)
                mine += weight[c];
        }
        *share = total ? (double)mine / (double)total : (index == count - 1);
    }
    rc = 0;
done:
    free(weight);
    free(bounds);
    return rc;
}
