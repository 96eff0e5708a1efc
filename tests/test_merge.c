/* Tests for format/oct_merge: the N shards of a split merge into the whole
 * run's file byte for byte, whatever N, the order of the parts and the
 * threads; parts that do not belong together, a missing or repeated shard
 * and damaged parts are refused, naming the file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "common/expr/scene.h"
#include "common/expr/tape_io.h"
#include "format/oct.h"
#include "format/oct_layout.h"
#include "format/oct_merge.h"
#include "rasterize/build.h"
#include "rasterize/shard.h"
#include "tests/scene_util.h"

static char dir[] = "/tmp/test_merge.XXXXXX";
static int with_function; /* files store the surfaces' tapes (format 1.1), as rasterize's do */

static int setup(void **state)
{
    (void)state;
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[64];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Rasterizes shard index/count (count 0: the whole grid) into path. */
static void rasterize_to(const scene *sc, unsigned levels, unsigned threads, uint32_t index,
                         uint32_t count, const char *path)
{
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, levels, palette, &wp);
    unsigned char *function = NULL;
    if (with_function) {
        const tape *tapes[OCT_MAX_SURFACES];
        for (size_t s = 0; s < sc->nsurfaces; s++)
            tapes[s] = &sc->surfaces[s].tape;
        assert_int_equal(tape_io_encode(tapes, (unsigned)sc->nsurfaces, &function, &wp.function_size),
                         TAPE_OK);
        wp.function = function;
    }
    build_params bp = {.levels = levels, .method = BUILD_INTERVAL, .threads = threads};
    build_shard sh;
    if (count) {
        assert_int_equal(shard_plan(sc, &bp, index, count, &sh, NULL), 0);
        bp.shard = &sh;
        wp.shard_count = sh.count;
        wp.shard_index = sh.index;
        wp.shard_depth = sh.depth;
        wp.partition_crc = sh.crc;
        wp.morton_lo = sh.lo;
        wp.morton_hi = sh.hi;
    }
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    build_stats st;
    assert_int_equal(build_octree(sc, &bp, w, &st), OCT_OK);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_OK);
    assert_int_equal(fclose(f), 0);
    oct_writer_free(w);
    free(function);
}

static unsigned char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fseek(f, 0, SEEK_END), 0);
    long n = ftell(f);
    assert_true(n >= 0);
    rewind(f);
    unsigned char *b = malloc((size_t)n + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *size = (size_t)n;
    return b;
}

/* Merges the parts (in the given order) into path; returns the error. */
static oct_err merge_to(const char *const *parts, size_t n, const char *path, oct_merge_error *e)
{
    FILE *f = fopen(path, "w+b");
    assert_non_null(f);
    uint64_t bytes = 0;
    oct_err r = oct_merge(parts, n, f, &bytes, e);
    long end = ftell(f);
    assert_int_equal(fclose(f), 0);
    if (r == OCT_OK)
        assert_int_equal((long)bytes, end);
    return r;
}

typedef struct split {
    char (*path)[256];
    const char **order;
    uint32_t n;
} split;

static void make_split(const scene *sc, unsigned levels, uint32_t n, const char *tag, split *s)
{
    s->n = n;
    s->path = calloc(n, sizeof *s->path);
    s->order = calloc(n, sizeof *s->order);
    assert_non_null(s->path);
    assert_non_null(s->order);
    for (uint32_t i = 0; i < n; i++) {
        snprintf(s->path[i], sizeof s->path[i], "%s/%s-%u-%u.oct", dir, tag, (unsigned)i, (unsigned)n);
        rasterize_to(sc, levels, 1 + (i & 1), i, n, s->path[i]);
        s->order[i] = s->path[i];
    }
}

static void split_free(split *s)
{
    for (uint32_t i = 0; i < s->n; i++)
        unlink(s->path[i]);
    free(s->path);
    free(s->order);
}

/* Merged in order, reversed and shuffled: always the whole file. */
static void check_merge(const char *scene_path, unsigned levels, uint32_t n)
{
    scene *sc = test_scene_load(scene_path);
    char whole[256], out[256];
    snprintf(whole, sizeof whole, "%s/whole.oct", dir);
    snprintf(out, sizeof out, "%s/merged.oct", dir);
    rasterize_to(sc, levels, 2, 0, 0, whole);
    size_t wn, mn;
    unsigned char *want = slurp(whole, &wn);
    split s;
    make_split(sc, levels, n, "p", &s);
    uint64_t seed = 0x9e3779b97f4a7c15u ^ n;
    for (int pass = 0; pass < 3; pass++) {
        if (pass == 1)
            for (uint32_t i = 0; i < n / 2; i++) {
                const char *t = s.order[i];
                s.order[i] = s.order[n - 1 - i];
                s.order[n - 1 - i] = t;
            }
        if (pass == 2)
            for (uint32_t i = n; i > 1; i--) {
                seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
                uint32_t j = (uint32_t)(seed % i);
                const char *t = s.order[i - 1];
                s.order[i - 1] = s.order[j];
                s.order[j] = t;
            }
        oct_merge_error e;
        oct_err r = merge_to(s.order, n, out, &e);
        if (r != OCT_OK)
            fail_msg("%s levels %u, %u shards: %s: %s", scene_path, levels, (unsigned)n,
                     e.path ? e.path : "-", e.msg);
        unsigned char *got = slurp(out, &mn);
        assert_int_equal(mn, wn);
        assert_memory_equal(got, want, wn);
        assert_int_equal(rd_u16le(got + OCT_OFF_MINOR), with_function); /* 1.0 unless 1.1 is used */
        free(got);
    }
    split_free(&s);
    free(want);
    scene_free(sc);
}

static void test_merge_counts(void **state)
{
    (void)state;
    static const uint32_t counts[] = {1, 2, 3, 7, 64};
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        with_function = k != 1; /* one 1.0 run: the merge writes 1.0 then */
        check_merge("scenes/blobs_a.scene", 8, counts[k]);
    }
}

static void test_merge_scenes(void **state)
{
    (void)state;
    with_function = 1;
    check_merge("scenes/multi.scene", 7, 7);  /* several surfaces: SURFACES too */
    check_merge("scenes/gyroid.scene", 6, 64);
    with_function = 0;
    check_merge("scenes/csg.scene", 8, 3);
    check_merge("scenes/torus.scene", 6, 5);  /* partition depth 1 (five mean-value levels) */
    check_merge("scenes/csg.scene", 4, 5);    /* partition depth 1 (three) */
    check_merge("scenes/sphere.scene", 3, 2); /* depth 0: one shard holds everything */
    check_merge("scenes/sphere.scene", 1, 2);
}

/* The merge fails with err, naming `who` (NULL: no file) with a message
 * holding `phrase`. */
static void expect_fail(const char *const *parts, size_t n, oct_err err, const char *who, const char *phrase)
{
    char out[256];
    snprintf(out, sizeof out, "%s/bad.oct", dir);
    oct_merge_error e;
    oct_err r = merge_to(parts, n, out, &e);
    if (r != err)
        fail_msg("error %d, want %d (%s: %s)", (int)r, (int)err, e.path ? e.path : "-", e.msg);
    if (who)
        assert_string_equal(e.path, who);
    else
        assert_null(e.path);
    if (!strstr(e.msg, phrase))
        fail_msg("message '%s' lacks '%s'", e.msg, phrase);
}

static void copy_file(const char *from, const char *to, size_t keep, long flip)
{
    size_t n;
    unsigned char *b = slurp(from, &n);
    if (flip >= 0)
        b[flip] ^= 0x10;
    FILE *f = fopen(to, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, keep < n ? keep : n, f), keep < n ? keep : n);
    fclose(f);
    free(b);
}

static void test_merge_refuses(void **state)
{
    (void)state;
    with_function = 1;
    scene *a = test_scene_load("scenes/blobs_a.scene"), *b = test_scene_load("scenes/blobs_b.scene");
    split s3, s2, t3, l3;
    /* levels 9: the partition of depth 4 (above the five mean-value levels
     * of these smooth scenes) leaves the last cell empty, as the gapped
     * shard below needs */
    make_split(a, 9, 3, "a", &s3);
    make_split(a, 9, 2, "a", &s2);
    make_split(b, 9, 3, "b", &t3);
    make_split(a, 6, 3, "l", &l3);
    char whole[256], cut[256], flip[256], missing[256];
    snprintf(whole, sizeof whole, "%s/whole9.oct", dir);
    snprintf(cut, sizeof cut, "%s/cut.oct", dir);
    snprintf(flip, sizeof flip, "%s/flip.oct", dir);
    snprintf(missing, sizeof missing, "%s/no-such.oct", dir);
    rasterize_to(a, 9, 2, 0, 0, whole);

    expect_fail(NULL, 0, OCT_EUSAGE, NULL, "no parts");
    const char *one[] = {s3.path[1]};
    expect_fail(one, 1, OCT_EUSAGE, NULL, "shard 0/3 is missing (1 of 3 parts given)");
    const char *gap[] = {s3.path[0], s3.path[2]};
    expect_fail(gap, 2, OCT_EUSAGE, NULL, "shard 1/3 is missing");
    const char *twice[] = {s3.path[0], s3.path[1], s3.path[1]};
    expect_fail(twice, 3, OCT_EUSAGE, s3.path[1], "is shard 1/3, as");
    const char *scenes[] = {s3.path[0], t3.path[1], s3.path[2]};
    expect_fail(scenes, 3, OCT_EUSAGE, t3.path[1], "a different scene");
    const char *levels[] = {s3.path[0], l3.path[1], s3.path[2]};
    expect_fail(levels, 3, OCT_EUSAGE, l3.path[1], "a different grid");
    const char *parts[] = {s3.path[0], s2.path[1]};
    expect_fail(parts, 2, OCT_EUSAGE, s2.path[1], "a different partition");
    const char *whole_part[] = {s3.path[0], whole, s3.path[2]};
    expect_fail(whole_part, 3, OCT_EUSAGE, whole, "is not a shard");
    const char *absent[] = {s3.path[0], missing};
    expect_fail(absent, 2, OCT_EIO, missing, "No such file");

    size_t n;
    unsigned char *p1 = slurp(s3.path[1], &n);
    long voxel = (long)rd_u64le(p1 + OCT_SEC_OFF(OCT_SEC_VOXELS)) + 1; /* a normal's bits: any value is valid */
    free(p1);
    copy_file(s3.path[1], cut, n - 10, -1);
    const char *trunc[] = {s3.path[0], cut, s3.path[2]};
    expect_fail(trunc, 3, OCT_ETRUNC, cut, "truncated");
    copy_file(s3.path[1], flip, n, voxel); /* only the CRC tells */
    const char *bits[] = {s3.path[0], s3.path[2], flip};
    expect_fail(bits, 3, OCT_ECRC, flip, "checksum");
    /* A shard whose header claims a piece that leaves a gap (its CRC fixed,
     * so it passes the reader): the ranges do not tile the cells. */
    char gapped[256];
    snprintf(gapped, sizeof gapped, "%s/gapped.oct", dir);
    unsigned char *h = slurp(s3.path[2], &n);
    wr_u64le(h + OCT_OFF_MORTON_HI, rd_u64le(h + OCT_OFF_MORTON_HI) - 1);
    wr_u32le(h + OCT_OFF_HEADER_CRC_1_1, (uint32_t)crc32(0, h, OCT_OFF_HEADER_CRC_1_1));
    FILE *f = fopen(gapped, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(h, 1, n, f), n);
    fclose(f);
    free(h);
    const char *tiles[] = {s3.path[0], s3.path[1], gapped};
    expect_fail(tiles, 3, OCT_EUSAGE, gapped, "does not continue the other shards'");

    split_free(&s3);
    split_free(&s2);
    split_free(&t3);
    split_free(&l3);
    scene_free(a);
    scene_free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_merge_counts),
        cmocka_unit_test(test_merge_scenes),
        cmocka_unit_test(test_merge_refuses),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
