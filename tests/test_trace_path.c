/* Tests for render/trace_path: the table of the children a ray visits in a
 * cell (the any-hit walk's lookahead), derived here from the children's time
 * intervals, entry by entry. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "render/trace_impl.h"

/* trace_path_children against the children's time intervals: the ray
 * enters the cell at 0 in child c0 and leaves it at 10; a crossed axis'
 * mid plane is crossed at its rank (1, 2 or 3) in the order, the others
 * not at all. Child k is visited when the times at which the ray is in k's
 * half on every axis meet in [0, 10). The two impossible orders give every
 * child. */
static void test_path_children(void **state)
{
    (void)state;
    unsigned checked = 0;
    for (unsigned idx = 0; idx < 512; idx++) {
        const unsigned c0 = idx & 7u, crossed = idx >> 3 & 7u, order = idx >> 6 & 7u;
        const int lt[3] = {(int)(order & 1u), (int)(order >> 1 & 1u), (int)(order >> 2 & 1u)};
        if (crossed == 7 && lt[0] == lt[1] && lt[2] != lt[0]) {
            /* x < y < z but not x < z, or its converse */
            assert_int_equal(trace_path_children[idx], 0xff);
            continue;
        }
        /* a crossed axis' rank among the crossed ones, from the comparisons
         * x<y, y<z, x<z (before[a][b]: a's mid plane first) */
        const int before[3][3] = {{0, lt[0], lt[2]}, {!lt[0], 0, lt[1]}, {!lt[2], !lt[1], 0}};
        double tm[3];
        for (int a = 0; a < 3; a++) {
            tm[a] = 1.0;
            for (int b = 0; b < 3; b++)
                tm[a] += (double)(b != a && (crossed >> b & 1u) && before[b][a]);
        }
        unsigned want = 0;
        for (unsigned k = 0; k < 8; k++) {
            double lo = 0.0, hi = 10.0;
            int ok = 1;
            for (int a = 0; a < 3; a++) {
                const int same = (k >> a & 1u) == (c0 >> a & 1u);
                if (!(crossed >> a & 1u))
                    ok &= same;
                else if (same)
                    hi = tm[a] < hi ? tm[a] : hi;
                else
                    lo = tm[a] > lo ? tm[a] : lo;
            }
            want |= (unsigned)(ok && lo < hi) << k;
        }
        assert_int_equal(trace_path_children[idx], want);
        checked++;
    }
    assert_int_equal(checked, 512 - 16);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_path_children),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
