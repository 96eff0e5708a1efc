/* Format 1.1 (FORMAT.md §5, §8, §11): what the writer writes when, the 1.1
 * header fields (flags, shard fields) and their checks, shell-only files,
 * and the truncation and bit-flip sweeps over a 1.1 file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_io.h"
#include "format/oct.h"
#include "format/oct_layout.h"
#include "tests/oct_check.h"
#include "tests/oct_fn_util.h"

/* Nothing of 1.1 used: a 1.0 file, header 256; with a function: 1.1,
 * header 320, the same sections shifted by 64 and FUNCTION after PALETTE. */
static void test_writer_versions(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *b10, *b11;
    size_t l10, l11;
    oct_check_small_file(&b10, &l10, &t);
    assert_int_equal(rd_u16le(b10 + OCT_OFF_MINOR), 0);
    assert_int_equal(rd_u32le(b10 + OCT_OFF_HEADER_SIZE), 256);
    test_tree_free(&t);
    test_fn_small_file(&b11, &l11, &t, 0);
    assert_int_equal(rd_u16le(b11 + OCT_OFF_MINOR), 1);
    assert_int_equal(rd_u32le(b11 + OCT_OFF_HEADER_SIZE), 320);
    for (int k = 0; k < OCT_SEC_COUNT_1_0; k++) {
        uint64_t o10 = rd_u64le(b10 + OCT_SEC_OFF(k)), o11 = rd_u64le(b11 + OCT_SEC_OFF(k));
        uint64_t size = rd_u64le(b10 + OCT_SEC_OFF(k) + 8);
        assert_int_equal(rd_u64le(b11 + OCT_SEC_OFF(k) + 8), size);
        assert_int_equal(rd_u32le(b11 + OCT_SEC_OFF(k) + 16), rd_u32le(b10 + OCT_SEC_OFF(k) + 16));
        if (size) {
            assert_int_equal(o11, o10 + 64);
            assert_memory_equal(b11 + o11, b10 + o10, size);
        }
    }
    size_t fsize;
    unsigned char *fn = test_fn_section(2, &fsize);
    uint64_t F = rd_u64le(b11 + OCT_SEC_OFF(OCT_SEC_FUNCTION));
    uint64_t pal_end = rd_u64le(b11 + OCT_SEC_OFF(OCT_SEC_PALETTE)) + 12 * 2;
    assert_int_equal(F, oct_align_up(pal_end));
    assert_int_equal(rd_u64le(b11 + OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8), fsize);
    assert_int_equal(l11, F + fsize);
    assert_memory_equal(b11 + F, fn, fsize);
    oct_file *f;
    assert_int_equal(oct_open_memory(b11, l11, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    const oct_info *in = oct_get_info(f);
    assert_int_equal(in->version_minor, 1);
    assert_int_equal(in->flags, 0);
    assert_int_equal(in->shard_count, 0);
    assert_int_equal(in->function_size, fsize);
    assert_memory_equal(in->function, fn, fsize);
    const oct_function_tape *ft = oct_get_function(f);
    assert_non_null(ft);
    assert_int_equal(ft[0].insn_count, rd_u32le(fn + OCT_FN_HEAD));
    assert_int_equal(ft[0].const_count, rd_u32le(fn + OCT_FN_HEAD + 4));
    assert_int_equal(ft[0].root, rd_u32le(fn + OCT_FN_HEAD + 8));
    assert_ptr_equal(ft[0].konst, (const void *)(b11 + F + OCT_FN_HEAD + OCT_FN_TAPE_HEAD));
    oct_close(f);
    /* the 1.0 file stores no function */
    assert_int_equal(oct_open_memory(b10, l10, 0, &f, NULL), OCT_OK);
    assert_null(oct_get_function(f));
    assert_null(oct_get_info(f)->function);
    oct_close(f);
    free(fn);
    free(b10);
    free(b11);
    test_tree_free(&t);
}

/* Masks and surfaces of the opened file equal t's (the records aside). */
static void check_shell(const oct_file *f, const test_tree *t)
{
    const oct_tree *ft = oct_get_tree(f);
    assert_int_equal(ft->voxel_count, t->voxel_count);
    assert_null(ft->voxels);
    for (uint32_t d = 0; d < t->levels; d++) {
        assert_int_equal(ft->node_count[d], t->count[d]);
        for (size_t i = 0; i < t->count[d]; i++)
            assert_int_equal(oct_node_mask(ft->groups[d], i), t->masks[d][i]);
    }
    assert_memory_equal(ft->surfaces, t->surfaces, t->voxel_count);
}

static void test_shell_only(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *full, *shell;
    size_t lfull, lshell;
    test_fn_small_file(&full, &lfull, &t, 0);
    test_tree_free(&t);
    test_fn_small_file(&shell, &lshell, &t, OCT_FLAG_SHELL_ONLY);
    assert_true(lshell < lfull);
    assert_int_equal(rd_u32le(shell + OCT_OFF_FLAGS), OCT_FLAG_SHELL_ONLY);
    assert_int_equal(rd_u64le(shell + OCT_SEC_OFF(OCT_SEC_VOXELS)), 0);
    assert_int_equal(rd_u64le(shell + OCT_SEC_OFF(OCT_SEC_VOXELS) + 8), 0);
    assert_int_equal(rd_u64le(shell + OCT_OFF_VOXEL_COUNT), t.voxel_count);
    oct_file *f;
    assert_int_equal(oct_open_memory(shell, lshell, 0, &f, NULL), OCT_OK);
    check_shell(f, &t);
    assert_int_equal(oct_get_info(f)->flags, OCT_FLAG_SHELL_ONLY);
    assert_non_null(oct_get_function(f));
    oct_close(f);
    /* shell-only needs the function: without, the writer refuses... */
    oct_writer_params p = {0};
    p.flags = OCT_FLAG_SHELL_ONLY;
    unsigned char *b;
    size_t l;
    assert_int_equal(test_tree_write_1_1(&t, &p, &b, &l), OCT_EUSAGE);
    /* ... and the reader refuses a file that drops it */
    uint64_t end = rd_u64le(shell + OCT_SEC_OFF(OCT_SEC_PALETTE)) + 12 * 2, at;
    memset(shell + OCT_SEC_OFF(OCT_SEC_FUNCTION), 0, 20);
    test_oct_refresh_crcs(shell, (size_t)end);
    assert_int_equal(oct_check_open(shell, (size_t)end, 0, &at), OCT_ESECTION);
    assert_int_equal(at, OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8);
    /* records in a shell-only file: VOXELS has the wrong size */
    wr_u32le(full + OCT_OFF_FLAGS, OCT_FLAG_SHELL_ONLY);
    test_oct_refresh_crcs(full, lfull);
    assert_int_equal(oct_check_open(full, lfull, 0, &at), OCT_ESECTION);
    assert_int_equal(at, OCT_SEC_OFF(OCT_SEC_VOXELS) + 8);
    free(shell);
    free(full);
    test_tree_free(&t);
}

typedef struct hcase {
    const char *what;
    unsigned offset, width; /* 4 or 8 */
    uint64_t value;
    oct_err want;
    unsigned at;
} hcase;

/* 1.1 header fields out of range, each alone (CRCs refreshed). */
static void test_header_fields_1_1(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    const hcase cases[] = {
        {"unknown flag", OCT_OFF_FLAGS, 4, 2, OCT_EHEADER, OCT_OFF_FLAGS},
        {"high flag", OCT_OFF_FLAGS, 4, 1u << 31, OCT_EHEADER, OCT_OFF_FLAGS},
        {"index, no shards", OCT_OFF_SHARD_INDEX, 4, 1, OCT_EHEADER, OCT_OFF_SHARD_INDEX},
        {"depth, no shards", OCT_OFF_SHARD_DEPTH, 4, 1, OCT_EHEADER, OCT_OFF_SHARD_DEPTH},
        {"crc, no shards", OCT_OFF_PARTITION_CRC, 4, 1, OCT_EHEADER, OCT_OFF_PARTITION_CRC},
        {"lo, no shards", OCT_OFF_MORTON_LO, 8, 1, OCT_EHEADER, OCT_OFF_MORTON_LO},
        {"hi, no shards", OCT_OFF_MORTON_HI, 8, 1, OCT_EHEADER, OCT_OFF_MORTON_HI},
        {"reserved2 first", OCT_OFF_RESERVED2, 4, 1, OCT_ERESERVED, OCT_OFF_RESERVED2},
        {"reserved2 last", OCT_OFF_HEADER_CRC_1_1 - 4, 4, 1u << 24, OCT_ERESERVED, OCT_OFF_HEADER_CRC_1_1 - 1},
        {"FUNCTION entry reserved", OCT_SEC_OFF(OCT_SEC_FUNCTION) + 20, 4, 1, OCT_ERESERVED,
         OCT_SEC_OFF(OCT_SEC_FUNCTION) + 20},
        {"FUNCTION misplaced", OCT_SEC_OFF(OCT_SEC_FUNCTION), 8, 64 * 100, OCT_ESECTION,
         OCT_SEC_OFF(OCT_SEC_FUNCTION)},
        {"header size 256", OCT_OFF_HEADER_SIZE, 4, 256, OCT_EHEADER, OCT_OFF_HEADER_SIZE},
        {"header size 384", OCT_OFF_HEADER_SIZE, 4, 384, OCT_EHEADER, OCT_OFF_HEADER_SIZE},
    };
    unsigned char *c = malloc(len);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        memcpy(c, buf, len);
        if (cases[i].width == 4)
            wr_u32le(c + cases[i].offset, (uint32_t)cases[i].value);
        else
            wr_u64le(c + cases[i].offset, cases[i].value);
        test_oct_refresh_crcs(c, len);
        uint64_t at;
        oct_err rc = oct_check_open(c, len, 0, &at);
        if (rc != cases[i].want || at != cases[i].at)
            fail_msg("%s: got %s at %llu", cases[i].what, oct_strerror(rc), (unsigned long long)at);
    }
    /* a 1.0 file knows no flags at all */
    unsigned char *b10;
    size_t l10;
    test_tree t10;
    oct_check_small_file(&b10, &l10, &t10);
    wr_u32le(b10 + OCT_OFF_FLAGS, OCT_FLAG_SHELL_ONLY);
    test_oct_refresh_crcs(b10, l10);
    uint64_t at;
    assert_int_equal(oct_check_open(b10, l10, 0, &at), OCT_EHEADER);
    assert_int_equal(at, OCT_OFF_FLAGS);
    free(b10);
    test_tree_free(&t10);
    free(c);
    free(buf);
    test_tree_free(&t);
}

static oct_writer_params shard(uint32_t n, uint32_t i, uint32_t k, uint64_t lo, uint64_t hi)
{
    oct_writer_params p = {0};
    p.shard_count = n;
    p.shard_index = i;
    p.shard_depth = k;
    p.partition_crc = 0x12345678u;
    p.morton_lo = lo;
    p.morton_hi = hi;
    return p;
}

/* Shard fields: stored, read back, printed; out-of-range ones refused by
 * the writer and, written over a valid file, by the reader. */
static void test_shard_fields(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 3, 40, 2, 7, 1);
    oct_writer_params p = shard(4, 3, 2, 48, 64);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write_1_1(&t, &p, &buf, &len), OCT_OK);
    assert_int_equal(rd_u16le(buf + OCT_OFF_MINOR), 1); /* a shard is 1.1, function or not */
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    const oct_info *in = oct_get_info(f);
    assert_int_equal(in->shard_count, 4);
    assert_int_equal(in->shard_index, 3);
    assert_int_equal(in->shard_depth, 2);
    assert_int_equal(in->partition_crc, 0x12345678u);
    assert_int_equal(in->morton_lo, 48);
    assert_int_equal(in->morton_hi, 64);
    assert_null(oct_get_function(f));
    char *text = NULL;
    size_t tlen = 0;
    FILE *m = open_memstream(&text, &tlen);
    assert_int_equal(oct_print_info(m, f), 0);
    fclose(m);
    assert_non_null(strstr(text, "shard:       3 of 4 (0-based), cells of depth 2, Morton codes [48, 64)"));
    assert_non_null(strstr(text, "function:    none"));
    assert_non_null(strstr(text, "format:      .oct 1.1"));
    free(text);
    oct_close(f);
    const oct_writer_params bad[] = {
        shard(4, 4, 2, 0, 1),  /* index >= count */
        shard(4, 0, 4, 0, 1),  /* depth > levels (3) */
        shard(4, 0, 2, 0, 65), /* hi > 8^k */
        shard(4, 0, 2, 9, 8),  /* lo > hi */
        shard(0, 1, 0, 0, 0),  /* fields without shards */
        shard(0, 0, 0, 0, 1),
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        unsigned char *b;
        size_t l;
        assert_int_equal(test_tree_write_1_1(&t, &bad[i], &b, &l), OCT_EUSAGE);
    }
    const hcase rcases[] = {
        {"index >= count", OCT_OFF_SHARD_INDEX, 4, 4, OCT_EHEADER, OCT_OFF_SHARD_INDEX},
        {"depth > levels", OCT_OFF_SHARD_DEPTH, 4, 4, OCT_EHEADER, OCT_OFF_SHARD_DEPTH},
        {"hi > 8^k", OCT_OFF_MORTON_HI, 8, 65, OCT_EHEADER, OCT_OFF_MORTON_HI},
        {"lo > hi", OCT_OFF_MORTON_LO, 8, 65, OCT_EHEADER, OCT_OFF_MORTON_LO},
        {"a shard below the root", OCT_OFF_ROOT_DEPTH, 4, 1, OCT_EHEADER, OCT_OFF_ROOT_DEPTH},
    };
    unsigned char *c = malloc(len);
    for (size_t i = 0; i < sizeof rcases / sizeof rcases[0]; i++) {
        memcpy(c, buf, len);
        if (rcases[i].width == 4)
            wr_u32le(c + rcases[i].offset, (uint32_t)rcases[i].value);
        else
            wr_u64le(c + rcases[i].offset, rcases[i].value);
        test_oct_refresh_crcs(c, len);
        uint64_t at;
        oct_err rc = oct_check_open(c, len, 0, &at);
        if (rc != rcases[i].want || at != rcases[i].at)
            fail_msg("%s: got %s at %llu", rcases[i].what, oct_strerror(rc), (unsigned long long)at);
    }
    free(c);
    free(buf);
    test_tree_free(&t);
}

static void walk_all(const oct_file *f)
{
    const oct_tree *ft = oct_get_tree(f);
    for (uint32_t d = 0; d < ft->levels; d++)
        for (uint64_t i = 0; i < ft->node_count[d]; i++)
            for (unsigned c = 0; c < 8; c++)
                if (oct_node_mask(ft->groups[d], i) & (1u << c)) {
                    uint64_t idx = oct_child_index(ft->groups[d], i, c);
                    assert_true(idx < (d + 1 < ft->levels ? ft->node_count[d + 1] : ft->voxel_count));
                }
    const oct_function_tape *fn = oct_get_function(f);
    for (uint32_t s = 0; fn && s < ft->surface_count; s++) { /* what the reader passed decodes */
        tape tp;
        assert_int_equal(tape_io_decode(fn[s].insn, fn[s].insn_count, fn[s].konst, fn[s].const_count,
                                        fn[s].root, &tp),
                         TAPE_OK);
        tape_free(&tp);
    }
}

/* Every prefix is truncated; every bit flip is refused (the CRCs), and
 * what passes the structure checks alone is walkable and decodable. */
static void test_sweeps_1_1(void **state)
{
    (void)state;
    for (int shell = 0; shell < 2; shell++) {
        test_tree t;
        unsigned char *buf;
        size_t len;
        test_fn_small_file(&buf, &len, &t, shell ? OCT_FLAG_SHELL_ONLY : 0);
        for (size_t n = 0; n < len; n++) {
            unsigned char *copy = malloc(n ? n : 1);
            memcpy(copy, buf, n);
            assert_int_equal(oct_check_open(copy, n, 0, NULL), OCT_ETRUNC);
            assert_int_equal(oct_check_open(copy, n, OCT_OPEN_TRUST, NULL), OCT_ETRUNC);
            free(copy);
        }
        unsigned char *copy = malloc(len);
        size_t opened = 0;
        for (size_t bit = 0; bit < 8 * len; bit++) {
            memcpy(copy, buf, len);
            copy[bit / 8] ^= (unsigned char)(1u << (bit % 8));
            uint64_t at;
            assert_true(oct_check_open(copy, len, 0, &at) != OCT_OK);
            assert_true(at < len);
            oct_file *f;
            if (oct_open_memory(copy, len, OCT_OPEN_TRUST, &f, NULL) == OCT_OK) {
                walk_all(f);
                oct_close(f);
                opened++;
            }
        }
        assert_true(opened > 0); /* e.g. constants moved inside their intervals */
        free(copy);
        free(buf);
        test_tree_free(&t);
    }
}

/* The 1.1 writer (the function's copy, a shell-only file's surfaces without
 * records) fails cleanly at every allocation, and otherwise writes the
 * same bytes. */
static void test_allocation_failures_1_1(void **state)
{
    (void)state;
    for (int shell = 0; shell < 2; shell++) {
        test_tree t;
        unsigned char *good;
        size_t good_len;
        test_fn_small_file(&good, &good_len, &t, shell ? OCT_FLAG_SHELL_ONLY : 0);
        size_t fsize;
        unsigned char *fn = test_fn_section(2, &fsize);
        oct_writer_params p = {0};
        p.flags = shell ? OCT_FLAG_SHELL_ONLY : 0;
        p.function = fn;
        p.function_size = fsize;
        for (long n = 1;; n++) {
            unsigned char *out = NULL;
            size_t len = 0;
            oct__alloc_fail_after(n, 1);
            oct_err rc = test_tree_write_1_1(&t, &p, &out, &len);
            oct__alloc_fail_after(0, 0);
            if (rc == OCT_OK) {
                assert_int_equal(len, good_len);
                assert_memory_equal(out, good, len);
                free(out);
                break;
            }
            free(out);
            assert_int_equal(rc, OCT_ENOMEM);
            assert_true(n < 1000);
        }
        free(fn);
        free(good);
        test_tree_free(&t);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_writer_versions),
        cmocka_unit_test(test_shell_only),
        cmocka_unit_test(test_header_fields_1_1),
        cmocka_unit_test(test_shard_fields),
        cmocka_unit_test(test_sweeps_1_1),
        cmocka_unit_test(test_allocation_failures_1_1),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
