/* Tests for rasterize/shard: the I/N parser, the partition depth, the cut
 * of the work estimate, and the central property: the N shards of any
 * split hold disjoint voxels whose union is the whole run's tree, record
 * for record, whatever N and the thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "format/oct.h"
#include "rasterize/build.h"
#include "rasterize/shard.h"
#include "tests/scene_util.h"

static void test_parse(void **state)
{
    (void)state;
    uint32_t i = 99, n = 99;
    assert_int_equal(shard_parse("0/1", &i, &n), 0);
    assert_int_equal(i, 0);
    assert_int_equal(n, 1);
    assert_int_equal(shard_parse("63/64", &i, &n), 0);
    assert_int_equal(i, 63);
    assert_int_equal(n, 64);
    assert_int_equal(shard_parse("4095/4096", &i, &n), 0);
    static const char *const bad[] = {"3/3", "-1/4", "0/0", "x/y", "1", "/4", "1/", "1/4/5", "01x/4",
                                      "1 /4", "0/4097", "0/-1", "", "0/1e1", "2/2", "999999999999999999/4"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        i = n = 7;
        if (shard_parse(bad[k], &i, &n) == 0)
            fail_msg("'%s' accepted", bad[k]);
        assert_int_equal(i, 7); /* untouched on failure */
        assert_int_equal(n, 7);
    }
}

static void test_depth(void **state)
{
    (void)state;
    assert_int_equal(shard_depth(12, 3, 1), 4);
    assert_int_equal(shard_depth(12, 3, 64), 4);   /* 8^4 = 4096 = 64 * 64 */
    assert_int_equal(shard_depth(12, 3, 65), 5);
    assert_int_equal(shard_depth(12, 3, 4096), 6);
    assert_int_equal(shard_depth(7, 3, 64), 4);    /* levels - 3 */
    assert_int_equal(shard_depth(6, 3, 64), 3);
    assert_int_equal(shard_depth(3, 3, 2), 0);
    assert_int_equal(shard_depth(1, 3, 2), 0);
    assert_int_equal(shard_depth(20, 3, 4096), 6);
    /* five mean-value levels (a smooth scene): the partition stays above them */
    assert_int_equal(shard_depth(12, 5, 4096), 6);
    assert_int_equal(shard_depth(10, 5, 4096), 5);
    assert_int_equal(shard_depth(7, 5, 64), 2);
    assert_int_equal(shard_depth(5, 5, 2), 0);
}

/* Five mean-value levels for one kink-free surface under the interval
 * method, three otherwise. */
static void test_mean_value_levels(void **state)
{
    (void)state;
    static const struct {
        const char *path;
        unsigned want;
    } cases[] = {{"scenes/blobs_a.scene", 5}, {"scenes/sphere.scene", 5},
                 {"scenes/csg.scene", 3},     {"scenes/gyroid.scene", 3},
                 {"scenes/multi.scene", 3}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        scene *sc = test_scene_load(cases[i].path);
        assert_int_equal(build_mean_value_levels(sc, BUILD_INTERVAL), cases[i].want);
        assert_int_equal(build_mean_value_levels(sc, BUILD_LIPSCHITZ), 3);
        scene_free(sc);
    }
}

static void test_cut(void **state)
{
    (void)state;
    uint64_t w[10] = {5, 0, 0, 5, 5, 5, 0, 0, 0, 0}, b[5];
    shard_cut(w, 10, 4, b);
    /* W = 20: targets 5, 10, 15; first cell whose prefix sum reaches them */
    uint64_t want[5] = {0, 1, 4, 5, 10};
    for (int i = 0; i < 5; i++)
        assert_int_equal(b[i], want[i]);
    shard_cut(w, 10, 1, b);
    assert_int_equal(b[0], 0);
    assert_int_equal(b[1], 10);
    uint64_t z[4] = {0, 0, 0, 0}, bz[4];
    shard_cut(z, 4, 3, bz); /* nothing to share: the last shard takes the grid */
    assert_int_equal(bz[0], 0);
    assert_int_equal(bz[1], 0);
    assert_int_equal(bz[2], 0);
    assert_int_equal(bz[3], 4);
    /* More shards than weighted cells: monotone, some empty. */
    uint64_t one[3] = {0, 7, 0}, bo[6];
    shard_cut(one, 3, 5, bo);
    for (int i = 0; i < 5; i++)
        assert_true(bo[i] <= bo[i + 1]);
    assert_int_equal(bo[5], 3);
    /* The checksum covers every boundary. */
    uint32_t c0 = shard_partition_crc(b, 1);
    b[1] = 9;
    assert_int_not_equal(shard_partition_crc(b, 1), c0);
}

/* The voxels of a tree: Morton code, record and surface of each. */
typedef struct voxels {
    uint64_t n, *code;
    uint32_t *rec;
    uint8_t *surf;
} voxels;

static void collect(const oct_tree *t, voxels *v)
{
    memset(v, 0, sizeof *v);
    v->n = t->voxel_count;
    v->code = calloc(v->n + 1, sizeof *v->code);
    v->rec = calloc(v->n + 1, sizeof *v->rec);
    v->surf = calloc(v->n + 1, 1);
    uint64_t *cur = calloc(1, sizeof *cur), count = t->node_count[0];
    assert_non_null(cur);
    for (unsigned d = 0; d < t->levels; d++) {
        uint64_t next_n = d + 1 < t->levels ? t->node_count[d + 1] : t->voxel_count, j = 0;
        uint64_t *next = calloc(next_n + 1, sizeof *next);
        assert_non_null(next);
        for (uint64_t i = 0; i < count; i++)
            for (unsigned c = 0; c < 8; c++)
                if (oct_node_mask(t->groups[d], i) & (1u << c))
                    next[j++] = 8 * cur[i] + c;
        assert_int_equal(j, next_n);
        free(cur);
        cur = next;
        count = next_n;
    }
    memcpy(v->code, cur, v->n * sizeof *cur);
    free(cur);
    for (uint64_t i = 0; i < v->n; i++) {
        v->rec[i] = t->voxels[i];
        v->surf[i] = t->surfaces ? t->surfaces[i] : 0;
    }
}

static void voxels_free(voxels *v)
{
    free(v->code);
    free(v->rec);
    free(v->surf);
}

/* Builds shard `index` of `count` (count 0: the whole grid) in memory. */
static void build_part(const scene *sc, unsigned levels, unsigned threads, uint32_t index, uint32_t count,
                       voxels *out, build_shard *sh)
{
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, levels, palette, &wp);
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    build_params bp = {.levels = levels, .method = BUILD_INTERVAL, .threads = threads};
    if (count) {
        double share = -1.0;
        assert_int_equal(shard_plan(sc, &bp, index, count, sh, &share), 0);
        assert_true(share >= 0.0 && share <= 1.0);
        bp.shard = sh;
    }
    build_stats st;
    assert_int_equal(build_octree(sc, &bp, w, &st), OCT_OK);
    char *bytes = NULL;
    size_t size = 0;
    FILE *mem = open_memstream(&bytes, &size);
    assert_non_null(mem);
    assert_int_equal(oct_writer_finish(w, mem, NULL), OCT_OK);
    assert_int_equal(fclose(mem), 0);
    oct_writer_free(w);
    oct_file *f = NULL;
    assert_int_equal(oct_open_memory(bytes, size, 0, &f, NULL), OCT_OK);
    collect(oct_get_tree(f), out);
    oct_close(f);
    free(bytes);
}

/* The shards of an N-way split, in shard order, are the whole tree's
 * voxels cut into consecutive runs, each inside its range, with the same
 * records and surfaces, and every shard computes the same partition. */
static void check_union(const char *path, unsigned levels, uint32_t count, unsigned threads)
{
    scene *sc = test_scene_load(path);
    voxels whole;
    build_part(sc, levels, 2, 0, 0, &whole, NULL);
    uint64_t at = 0, next_lo = 0;
    uint32_t crc = 0;
    for (uint32_t i = 0; i < count; i++) {
        voxels v;
        build_shard sh;
        build_part(sc, levels, threads, i, count, &v, &sh);
        assert_int_equal(sh.index, i);
        assert_int_equal(sh.count, count);
        assert_int_equal(sh.depth, shard_depth(levels, build_mean_value_levels(sc, BUILD_INTERVAL), count));
        assert_int_equal(sh.lo, next_lo); /* contiguous ranges */
        next_lo = sh.hi;
        if (i == 0)
            crc = sh.crc;
        assert_int_equal(sh.crc, crc);
        unsigned shift = 3 * (levels - sh.depth);
        for (uint64_t j = 0; j < v.n; j++, at++) {
            assert_true(at < whole.n);
            assert_int_equal(v.code[j], whole.code[at]);
            assert_int_equal(v.rec[j], whole.rec[at]);
            assert_int_equal(v.surf[j], whole.surf[at]);
            assert_true((v.code[j] >> shift) >= sh.lo && (v.code[j] >> shift) < sh.hi);
        }
        voxels_free(&v);
    }
    assert_int_equal(next_lo, UINT64_C(1) << (3 * shard_depth(levels, build_mean_value_levels(sc, BUILD_INTERVAL), count)));
    assert_int_equal(at, whole.n);
    voxels_free(&whole);
    scene_free(sc);
}

static void test_union_sphere(void **state)
{
    (void)state;
    static const uint32_t counts[] = {1, 2, 3, 7, 64};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++)
        check_union("scenes/sphere.scene", 7, counts[k], 1 + (unsigned)(k & 1));
}

static void test_union_scenes(void **state)
{
    (void)state;
    check_union("scenes/multi.scene", 8, 7, 2);   /* several surfaces */
    check_union("scenes/csg.scene", 8, 3, 1);
    check_union("scenes/blobs_a.scene", 8, 64, 2);
    check_union("scenes/torus.scene", 6, 5, 1);   /* partition depth 1 (five mean-value levels) */
    check_union("scenes/csg.scene", 4, 5, 1);     /* partition depth 1 (three) */
    check_union("scenes/sphere.scene", 3, 2, 1);  /* depth 0: one cell */
    check_union("scenes/sphere.scene", 1, 3, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_depth),
        cmocka_unit_test(test_mean_value_levels),
        cmocka_unit_test(test_cut),
        cmocka_unit_test(test_union_sphere),
        cmocka_unit_test(test_union_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
