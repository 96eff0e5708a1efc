/* Round trips through format/oct_write.c and format/oct_read.c: random,
 * empty, deepest and subtree files, in memory and through a file, the spec
 * example, and the writer's determinism. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "format/oct.h"
#include "format/oct_layout.h"
#include "format/oct_normal.h"
#include "tests/oct_check.h"

static void test_round_trip_random_trees(void **state)
{
    (void)state;
    for (uint32_t levels = 1; levels <= 12; levels++) {
        for (uint64_t seed = 1; seed <= 6; seed++) {
            test_tree t;
            uint32_t surfaces = seed % 3 == 0 ? 1 : (uint32_t)(seed % 5 + 1);
            size_t target = seed == 1 ? 1 : (size_t)(seed * 700);
            test_tree_random(&t, levels, target, surfaces, seed * 100 + levels, (int)(seed & 1));
            if (seed == 5) { /* a subtree of a bigger grid */
                t.root_depth = 3;
                t.root_cell[0] = 5; t.root_cell[1] = 0; t.root_cell[2] = 7;
                t.edge = 0.25;
                t.origin[0] = -1.0 + 5 * 0.25; t.origin[1] = -1.0; t.origin[2] = -1.0 + 7 * 0.25;
            }
            unsigned char *buf;
            size_t len;
            assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
            assert_int_equal(len % 4, 0);
            oct_file *f = NULL;
            uint64_t at = 99;
            assert_int_equal(oct_open_memory(buf, len, 0, &f, &at), OCT_OK);
            assert_int_equal(at, 0);
            oct_check_tree(f, &t);
            assert_int_equal(oct_get_info(f)->file_size, len);
            oct_close(f);
            assert_int_equal(oct_open_memory(buf, len, OCT_OPEN_TRUST, &f, NULL), OCT_OK);
            oct_close(f);
            free(buf);
            test_tree_free(&t);
        }
    }
}

static void test_round_trip_through_file(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 5000, 3, 42, 1);
    char path[] = "/tmp/test_oct_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *fp = fdopen(fd, "wb");
    oct_writer_params p = {.levels = 8, .edge = t.edge, .surface_count = 3, .palette = t.palette};
    memcpy(p.origin, t.origin, sizeof p.origin);
    oct_writer *w;
    assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
    for (uint32_t d = 0; d < 8; d++)
        assert_int_equal(oct_writer_add_masks(w, d, t.masks[d], t.count[d]), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, t.voxels, t.surfaces, t.voxel_count), OCT_OK);
    uint64_t n = 0;
    assert_int_equal(oct_writer_finish(w, fp, &n), OCT_OK);
    oct_writer_free(w);
    assert_int_equal(fclose(fp), 0);
    oct_file *f;
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_OK);
    assert_int_equal(oct_get_info(f)->file_size, n);
    oct_check_tree(f, &t);
    char *text = NULL;
    size_t tlen = 0;
    FILE *mf = open_memstream(&text, &tlen);
    assert_int_equal(oct_print_info(mf, f), 0);
    fclose(mf);
    assert_non_null(strstr(text, "levels:      8"));
    assert_non_null(strstr(text, "bytes/voxel:"));
    free(text);
    oct_close(f);
    unlink(path);
    test_tree_free(&t);
}

static void test_empty_trees(void **state)
{
    (void)state;
    for (uint32_t levels = 1; levels <= OCT_MAX_LEVELS; levels += 19) {
        test_tree t;
        test_tree_random(&t, levels, 0, 1, 1, 0);
        unsigned char *buf;
        size_t len;
        assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
        oct_file *f;
        assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
        const oct_tree *ft = oct_get_tree(f);
        assert_int_equal(ft->node_count[0], 0);
        assert_int_equal(ft->voxel_count, 0);
        assert_null(ft->voxels);
        oct_close(f);
        free(buf);
        test_tree_free(&t);
    }
}

static void test_deepest_tree(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, OCT_MAX_LEVELS, 3000, 2, 5, 1);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    oct_close(f);
    /* A would-be DAG: one group of the deepest depth reuses an earlier
     * group's children. Refused by the flat scan, CRCs fixed or not. */
    uint64_t nodes = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES)), g = 0;
    for (uint32_t d = 0; d + 1 < OCT_MAX_LEVELS; d++)
        g += t.count[d] / 8 + (t.count[d] % 8 != 0);
    assert_true(t.count[OCT_MAX_LEVELS - 1] > 8);
    wr_u64le(buf + nodes + 16 * (g + 1), 0);
    uint64_t at;
    assert_int_equal(oct_check_open(buf, len, OCT_OPEN_TRUST, &at), OCT_ETREE);
    assert_int_equal(at, nodes + 16 * (g + 1));
    test_oct_refresh_crcs(buf, len);
    assert_int_equal(oct_check_open(buf, len, 0, NULL), OCT_ETREE);
    free(buf);
    test_tree_free(&t);
}

/* A subtree at the deepest root_depth, at the far corner of its grid. */
static void test_subtree_at_depth_40(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 500, 1, 8, 1);
    t.root_depth = 40;
    uint64_t last = (UINT64_C(1) << 40) - 1;
    t.root_cell[0] = last; t.root_cell[1] = 0; t.root_cell[2] = last / 3;
    t.edge = 0x1p-40;
    for (int i = 0; i < 3; i++)
        t.origin[i] = (double)t.root_cell[i] * t.edge; /* the grid is the unit cube at 0 */
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    const oct_info *in = oct_get_info(f);
    assert_true(in->grid_edge == 1.0);
    for (int i = 0; i < 3; i++) {
        assert_true(in->grid_origin[i] == 0.0);
        assert_true(oct_get_tree(f)->origin[i] == t.origin[i]); /* exact: dyadic */
        assert_int_equal(in->root_cell[i], t.root_cell[i]);
    }
    char *text = NULL;
    size_t tlen = 0;
    FILE *mf = open_memstream(&text, &tlen);
    assert_int_equal(oct_print_info(mf, f), 0);
    fclose(mf);
    assert_non_null(strstr(text, "subtree:     depth 40, cell (1099511627775, 0, 366503875925)"));
    free(text);
    oct_close(f);
    free(buf);
    /* One level more and the finest voxel is too small next to the grid. */
    t.levels = 9;
    oct_writer_params p = {.levels = 9, .edge = t.edge, .root_depth = 40, .surface_count = 1};
    memcpy(p.origin, t.origin, sizeof p.origin);
    memcpy(p.root_cell, t.root_cell, sizeof p.root_cell);
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    t.levels = 8;
    test_tree_free(&t);
}

/* The mapping outlives a rename over the file; a truncation in place is
 * documented (FORMAT.md §10) to raise SIGBUS on the lost pages. */
static void test_mapped_file_replaced_or_truncated(void **state)
{
    (void)state;
    test_tree a, b;
    test_tree_random(&a, 6, 20000, 2, 11, 0);
    test_tree_random(&b, 3, 10, 1, 12, 0);
    unsigned char *ba, *bb;
    size_t la, lb;
    assert_int_equal(test_tree_write(&a, &ba, &la), OCT_OK);
    assert_int_equal(test_tree_write(&b, &bb, &lb), OCT_OK);
    char dir[] = "/tmp/test_oct_map_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char pa[600], pb[600];
    snprintf(pa, sizeof pa, "%s/a.oct", dir);
    snprintf(pb, sizeof pb, "%s/b.oct", dir);
    FILE *fa = fopen(pa, "wb"), *fb = fopen(pb, "wb");
    assert_int_equal(fwrite(ba, 1, la, fa), la);
    assert_int_equal(fwrite(bb, 1, lb, fb), lb);
    fclose(fa);
    fclose(fb);
    oct_file *f;
    assert_int_equal(oct_open(pa, 0, &f, NULL), OCT_OK);
    assert_int_equal(rename(pb, pa), 0);
    oct_check_tree(f, &a); /* still the old inode */
    oct_close(f);

    fa = fopen(pa, "wb");
    assert_int_equal(fwrite(ba, 1, la, fa), la);
    fclose(fa);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGBUS, SIG_DFL); /* cmocka catches it otherwise */
        if (oct_open(pa, 0, &f, NULL) != OCT_OK)
            _exit(2);
        if (truncate(pa, 0) != 0)
            _exit(3);
        const oct_tree *t = oct_get_tree(f);
        volatile uint32_t x = t->voxels[t->voxel_count - 1]; /* on a lost page */
        (void)x;
        _exit(0);
    }
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status));
    assert_int_equal(WTERMSIG(status), SIGBUS);
    unlink(pa);
    rmdir(dir);
    free(ba);
    free(bb);
    test_tree_free(&a);
    test_tree_free(&b);
}

/* FORMAT.md, Appendix A: the writer makes exactly the example's bytes. */
static void test_spec_example(void **state)
{
    (void)state;
    float pal[3] = {1.0f, 0.5f, 0.25f};
    oct_writer_params p = {.levels = 2, .origin = {-1, -1, -1}, .edge = 2.0, .surface_count = 1, .palette = pal};
    oct_writer *w;
    assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
    const uint8_t root = 0x81, d1[2] = {0x01, 0x80};
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, d1, 2), OCT_OK);
    const double n1[3] = {0, 0, 1}, n2[3] = {1, 1, 1};
    uint32_t v[2] = {oct_voxel_pack(n1, 0.25), oct_voxel_pack(n2, -0.5)};
    assert_int_equal(v[0], 0x20800800u);
    assert_int_equal(v[1], 0xc0aaaaaau);
    assert_int_equal(oct_writer_add_voxels(w, v, NULL, 2), OCT_OK);
    char *mem;
    size_t len;
    FILE *f = open_memstream(&mem, &len);
    uint64_t n;
    assert_int_equal(oct_writer_finish(w, f, &n), OCT_OK);
    oct_writer_free(w);
    fclose(f);
    const unsigned char *b = (const unsigned char *)mem;
    assert_int_equal(len, 460);
    assert_int_equal(rd_u32le(b + OCT_OFF_HEADER_CRC), 0x506ac706u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_LEVELS) + 16), 0x00f6ddb9u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_NODES) + 16), 0x912a2f8cu);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_VOXELS) + 16), 0xb0091dd6u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_PALETTE) + 16), 0xb5cb6adau);
    static const unsigned char nodes[32] = {0, 0, 0, 0, 0, 0, 0, 0, 0x81, 0, 0, 0, 0, 0, 0, 0,
                                            0, 0, 0, 0, 0, 0, 0, 0, 0x01, 0x80, 0, 0, 0, 0, 0, 0};
    assert_memory_equal(b + 320, nodes, 32);
    oct_file *of;
    assert_int_equal(oct_open_memory(mem, len, 0, &of, NULL), OCT_OK);
    const oct_tree *t = oct_get_tree(of);
    assert_int_equal(oct_child_index(t->groups[0], 0, 7), 1);
    assert_int_equal(oct_child_index(t->groups[1], 1, 7), 1);
    oct_close(of);
    free(mem);
}

static void test_writer_is_deterministic(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 6, 2000, 4, 3, 1);
    unsigned char *a, *b;
    size_t la, lb;
    assert_int_equal(test_tree_write(&t, &a, &la), OCT_OK);
    assert_int_equal(test_tree_write(&t, &b, &lb), OCT_OK);
    assert_int_equal(la, lb);
    assert_memory_equal(a, b, la);
    free(a);
    free(b);
    test_tree_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_random_trees),
        cmocka_unit_test(test_round_trip_through_file),
        cmocka_unit_test(test_empty_trees),
        cmocka_unit_test(test_deepest_tree),
        cmocka_unit_test(test_subtree_at_depth_40),
        cmocka_unit_test(test_mapped_file_replaced_or_truncated),
        cmocka_unit_test(test_spec_example),
        cmocka_unit_test(test_writer_is_deterministic),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
