/* The seed corpus generator of the fuzz_oct target (tests/fuzz/README.md):
 * writes its files to OCT_CORPUS_DIR when that is set, else to a temporary
 * directory; either way every seed is then opened: an ok-* seed must open,
 * a bad-* seed must be refused (so the corpus holds what its names say). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "format/oct.h"
#include "format/oct_layout.h"
#include "bench/oct_synth.h"
#include "tests/oct_fn_util.h"

static void write_file(const char *dir, const char *name, const unsigned char *buf, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(buf, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
}

/* Format 1.1 seeds: a function, shell-only, a shard, and a function with an
 * unknown op code (CRCs fixed, so it reaches check 13a). */
static void make_1_1_seeds(const char *dir)
{
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    write_file(dir, "ok-v11-function.oct", buf, len);
    uint64_t F = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_FUNCTION));
    uint64_t ins = F + OCT_FN_HEAD + OCT_FN_TAPE_HEAD + 24ull * rd_u32le(buf + F + OCT_FN_HEAD + 4);
    wr_u32le(buf + ins, OCT_OP_COUNT);
    test_oct_refresh_crcs(buf, len);
    write_file(dir, "bad-v11-op.oct", buf, len);
    free(buf);
    test_tree_free(&t);
    test_fn_small_file(&buf, &len, &t, OCT_FLAG_SHELL_ONLY);
    write_file(dir, "ok-v11-shell.oct", buf, len);
    free(buf);
    test_tree_free(&t);
    test_tree_random(&t, 4, 100, 1, 5, 1);
    oct_writer_params p = {0};
    p.shard_count = 8;
    p.shard_index = 2;
    p.shard_depth = 2;
    p.partition_crc = 0xdeadbeefu;
    p.morton_lo = 16;
    p.morton_hi = 24;
    assert_int_equal(test_tree_write_1_1(&t, &p, &buf, &len), OCT_OK);
    write_file(dir, "ok-v11-shard.oct", buf, len);
    free(buf);
    test_tree_free(&t);
}

/* Every seed in dir opens (ok-*) or is refused (bad-*); own: remove them. */
static void check_seeds(const char *dir, int own)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    unsigned ok = 0, bad = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const int is_ok = !strncmp(e->d_name, "ok-", 3), is_bad = !strncmp(e->d_name, "bad-", 4);
        if (!is_ok && !is_bad)
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        oct_file *f = NULL;
        const oct_err rc = oct_open(path, 0, &f, NULL);
        if (is_ok && rc != OCT_OK)
            fail_msg("%s: %s", e->d_name, oct_strerror(rc));
        if (is_bad && rc == OCT_OK)
            fail_msg("%s: opened", e->d_name);
        oct_close(f);
        is_ok ? ok++ : bad++;
        if (own)
            assert_int_equal(unlink(path), 0);
    }
    closedir(d);
    if (own)
        assert_int_equal(rmdir(dir), 0);
    assert_int_equal(ok, 21); /* levels 1..6 x 3 variants, three 1.1 seeds */
    assert_int_equal(bad, 6);
}

static void test_make_fuzz_corpus(void **state)
{
    (void)state;
    char tmp[] = "/tmp/oct-corpus-XXXXXX";
    const char *dir = getenv("OCT_CORPUS_DIR");
    const int own = !dir || !*dir;
    if (own) {
        dir = mkdtemp(tmp);
        assert_non_null(dir);
    }
    for (uint32_t levels = 1; levels <= 6; levels++) {
        for (int variant = 0; variant < 3; variant++) {
            test_tree t;
            size_t target = variant == 0 ? 1 : (size_t)(variant == 1 ? 12 : 60) * levels;
            test_tree_random(&t, levels, target, variant == 2 ? 3 : 1, levels * 10 + (uint64_t)variant,
                             variant != 1);
            unsigned char *buf;
            size_t len;
            assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
            for (int corrupt = 0; corrupt < (variant == 2 && levels % 2 ? 2 : 1); corrupt++) {
                char path[512];
                snprintf(path, sizeof path, "%s/%s-l%u-v%d.oct", dir, corrupt ? "bad" : "ok", levels, variant);
                if (corrupt) /* a bad base, CRCs fixed: reaches the tree check */
                    wr_u64le(buf + rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES)), 5), test_oct_refresh_crcs(buf, len);
                FILE *f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len, f), len);
                assert_int_equal(fclose(f), 0);
            }
            if (levels == 4 && variant == 2) { /* a truncated file and a bad checksum */
                char path[512];
                snprintf(path, sizeof path, "%s/bad-trunc-l4.oct", dir);
                FILE *f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len / 2, f), len / 2);
                assert_int_equal(fclose(f), 0);
                buf[len - 1] ^= 0x10; /* a palette bit */
                snprintf(path, sizeof path, "%s/bad-crc-l4.oct", dir);
                f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len, f), len);
                assert_int_equal(fclose(f), 0);
            }
            free(buf);
            test_tree_free(&t);
        }
    }
    make_1_1_seeds(dir);
    check_seeds(dir, own);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_make_fuzz_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
