/* The seed corpus generator of the fuzz_oct target (tests/fuzz/README.md):
 * writes its files when OCT_CORPUS_DIR is set, and is skipped otherwise. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>

#include "format/oct.h"
#include "format/oct_layout.h"
#include "bench/oct_synth.h"

static void test_make_fuzz_corpus(void **state)
{
    (void)state;
    const char *dir = getenv("OCT_CORPUS_DIR");
    if (!dir)
        skip();
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
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_make_fuzz_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
