/* The FUNCTION section's invariants (FORMAT.md §8, reader check 13a): each
 * broken once, with the reader's exact phrase and offset, and refused by the
 * writer too (format/oct_function.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "format/oct.h"
#include "format/oct_layout.h"
#include "tests/oct_check.h"
#include "tests/oct_fn_util.h"

/* Where things are in the small 1.1 file: the section, and per tape its
 * head, constants and instructions. */
typedef struct loc {
    uint64_t F, size;           /* the section's offset and size */
    uint64_t T[2], K[2], I[2];  /* tape heads, constants, instructions */
    uint32_t n[2], m[2];
    uint64_t end1;              /* end of tape 1's instructions (before its padding) */
} loc;

static void locate(const unsigned char *b, loc *L)
{
    L->F = rd_u64le(b + OCT_SEC_OFF(OCT_SEC_FUNCTION));
    L->size = rd_u64le(b + OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8);
    uint64_t at = L->F + OCT_FN_HEAD;
    for (int t = 0; t < 2; t++) {
        L->T[t] = at;
        L->n[t] = rd_u32le(b + at);
        L->m[t] = rd_u32le(b + at + 4);
        L->K[t] = at + OCT_FN_TAPE_HEAD;
        L->I[t] = L->K[t] + 24ull * L->m[t];
        uint64_t end = L->I[t] + 12ull * L->n[t];
        if (t == 1)
            L->end1 = end;
        at = (end + 7) & ~7ull;
    }
    assert_int_equal(at, L->F + L->size);
}

/* Offset of the first instruction of tape 0 with file op code `op`. */
static uint64_t insn_at(const unsigned char *b, const loc *L, uint32_t op, uint32_t *index)
{
    for (uint32_t i = 0; i < L->n[0]; i++)
        if (rd_u32le(b + L->I[0] + 12ull * i) == op) {
            *index = i;
            return L->I[0] + 12ull * i;
        }
    fail_msg("op %u not in the every-op tape", op);
    return 0;
}

/* Pool index in tape 0 of the first constant with lo < hi (inexact). */
static uint32_t inexact_const(const unsigned char *b, const loc *L)
{
    for (uint32_t j = 0; j < L->m[0]; j++)
        if (rd_f64le(b + L->K[0] + 24ull * j + 8) < rd_f64le(b + L->K[0] + 24ull * j + 16))
            return j;
    fail_msg("no inexact constant");
    return 0;
}

/* The damaged copy (CRCs refreshed) must be refused with `what` at `at`,
 * with and without the CRC checks, and its section refused by the writer. */
static void expect_fault(unsigned char *copy, size_t len, const char *what, uint64_t at)
{
    test_oct_refresh_crcs(copy, len);
    for (int trust = 0; trust < 2; trust++) {
        oct_file *f = NULL;
        oct_fault fault;
        oct_err rc = oct_open_memory_fault(copy, len, trust ? OCT_OPEN_TRUST : 0u, &f, &fault);
        if (rc != OCT_EFUNCTION || strcmp(fault.what, what) != 0 || fault.offset != at)
            fail_msg("want '%s' at %llu, got %s: '%s' at %llu", what, (unsigned long long)at,
                     oct_strerror(rc), fault.what ? fault.what : "(null)",
                     (unsigned long long)fault.offset);
        assert_null(f);
    }
    uint64_t F = rd_u64le(copy + OCT_SEC_OFF(OCT_SEC_FUNCTION));
    uint64_t size = rd_u64le(copy + OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8);
    oct_writer_params p = {0};
    p.levels = 3;
    p.edge = 1.0;
    p.surface_count = 2;
    p.function = copy + F;
    p.function_size = (size_t)size;
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    assert_null(w);
}

#define EDIT(stmt, what, at)                                                                       \
    do {                                                                                           \
        memcpy(c, buf, len);                                                                       \
        stmt;                                                                                      \
        expect_fault(c, len, what, at);                                                            \
    } while (0)

static void test_heads_and_counts(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    loc L;
    locate(buf, &L);
    unsigned char *c = malloc(len);
    EDIT(wr_u32le(c + L.F, 3), "function: tape count is not the surface count", L.F);
    EDIT(wr_u32le(c + L.F, 1), "function: tape count is not the surface count", L.F);
    EDIT(wr_u32le(c + L.F + 4, 1), "function: reserved field not zero", L.F + 4);
    EDIT(wr_u32le(c + L.T[0], 0), "function: instruction count out of range", L.T[0]);
    EDIT(wr_u32le(c + L.T[0], OCT_FN_MAX_INSNS + 1), "function: instruction count out of range", L.T[0]);
    EDIT(wr_u32le(c + L.T[0] + 4, OCT_FN_MAX_CONSTS + 1), "function: constant count out of range",
         L.T[0] + 4);
    EDIT(wr_u32le(c + L.T[0] + 8, L.n[0]), "function: root is not an instruction", L.T[0] + 8);
    EDIT(wr_u32le(c + L.T[1] + 8, UINT32_MAX), "function: root is not an instruction", L.T[1] + 8);
    EDIT(wr_u32le(c + L.T[1] + 12, 1u << 31), "function: reserved field not zero", L.T[1] + 12);
    /* tape 1 claims more than the section holds */
    EDIT(wr_u32le(c + L.T[1], L.n[1] + 1), "function: tape past the section end", L.T[1]);
    EDIT(wr_u32le(c + L.T[1] + 4, L.m[1] + 1), "function: tape past the section end", L.T[1]);
    /* the padding after tape 1's odd number of instructions */
    assert_int_equal(L.n[1] % 2, 1);
    EDIT(c[L.end1 + 2] = 1, "function: padding not zero", L.end1 + 2);
    free(c);
    free(buf);
    test_tree_free(&t);
}

static void test_constants(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    loc L;
    locate(buf, &L);
    unsigned char *c = malloc(len);
    const uint64_t k = L.K[0] + 24ull * inexact_const(buf, &L);
    EDIT(wr_f64le(c + k, NAN), "function: constant not finite", k);
    EDIT(wr_f64le(c + k, INFINITY), "function: constant not finite", k);
    EDIT(wr_f64le(c + k + 8, -INFINITY), "function: constant bound not finite", k + 8);
    EDIT(wr_f64le(c + k + 16, NAN), "function: constant bound not finite", k + 16);
    EDIT(wr_f64le(c + k + 8, rd_f64le(c + k + 16)), "function: constant below its lower bound", k + 8);
    EDIT(wr_f64le(c + k + 16, rd_f64le(c + k + 8)), "function: constant above its upper bound", k + 16);
    const uint64_t k1 = L.K[1]; /* the sphere's one constant, exact */
    EDIT(wr_f64le(c + k1, 0.3), "function: constant above its upper bound", k1 + 16);
    free(c);
    free(buf);
    test_tree_free(&t);
}

static void test_instructions(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    loc L;
    locate(buf, &L);
    unsigned char *c = malloc(len);
    uint32_t i_const = 0, i_x = 0, i_un = 0, i_bin = 0, i_pow = 0; /* set by insn_at (it asserts) */
    const uint64_t ic = insn_at(buf, &L, OCT_OP_CONST, &i_const), ix = insn_at(buf, &L, OCT_OP_Y, &i_x);
    const uint64_t iu = insn_at(buf, &L, OCT_OP_SQRT, &i_un), ib = insn_at(buf, &L, OCT_OP_DIV, &i_bin);
    const uint64_t ip = insn_at(buf, &L, OCT_OP_POWC, &i_pow);
    EDIT(wr_u32le(c + ib, OCT_OP_COUNT), "function: unknown op code", ib);
    EDIT(wr_u32le(c + ic, UINT32_MAX), "function: unknown op code", ic);
    EDIT(wr_u32le(c + ic + 4, L.m[0]), "function: constant index out of range", ic + 4);
    EDIT(wr_u32le(c + ic + 8, 1), "function: unused operand not zero", ic + 8);
    EDIT(wr_u32le(c + ix + 4, 1), "function: unused operand not zero", ix + 4);
    EDIT(wr_u32le(c + ix + 8, 1), "function: unused operand not zero", ix + 8);
    EDIT(wr_u32le(c + iu + 4, i_un), "function: operand not strictly earlier", iu + 4);
    EDIT(wr_u32le(c + iu + 8, 1), "function: unused operand not zero", iu + 8);
    EDIT(wr_u32le(c + ib + 4, i_bin + 5), "function: operand not strictly earlier", ib + 4);
    EDIT(wr_u32le(c + ib + 8, i_bin), "function: operand not strictly earlier", ib + 8);
    EDIT(wr_u32le(c + ip + 4, i_pow), "function: operand not strictly earlier", ip + 4);
    EDIT(wr_u32le(c + ip + 8, L.m[0]), "function: constant index out of range", ip + 8);
    EDIT(wr_u32le(c + ip + 8, inexact_const(buf, &L)), "function: power exponent not an exact non-integer",
         ip + 8);
    const uint64_t e = L.K[0] + 24ull * rd_u32le(buf + ip + 8); /* the exponent 1.5 becomes 2 */
    EDIT((wr_f64le(c + e, 2.0), wr_f64le(c + e + 8, 2.0), wr_f64le(c + e + 16, 2.0)),
         "function: power exponent not an exact non-integer", ip + 8);
    /* an op turned into another of a different arity */
    EDIT(wr_u32le(c + iu, OCT_OP_X), "function: unused operand not zero", iu + 4);
    EDIT(wr_u32le(c + L.I[0], OCT_OP_NEG), "function: operand not strictly earlier", L.I[0] + 4);
    free(c);
    free(buf);
    test_tree_free(&t);
}

/* A copy whose FUNCTION section is `size` bytes (the file ends with it):
 * shorter, cut where `keep` says, or longer with zero bytes. */
static unsigned char *resize_section(const unsigned char *buf, const loc *L, uint64_t size, size_t *len)
{
    *len = (size_t)(L->F + size);
    unsigned char *c = calloc(1, *len);
    memcpy(c, buf, (size_t)(L->F + (size < L->size ? size : L->size)));
    wr_u64le(c + OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8, size);
    return c;
}

static void test_section_sizes(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len, n;
    test_fn_small_file(&buf, &len, &t, 0);
    loc L;
    locate(buf, &L);
    unsigned char *c = resize_section(buf, &L, 4, &n);
    expect_fault(c, n, "function: section shorter than its head", L.F);
    free(c);
    c = resize_section(buf, &L, L.T[1] - L.F, &n); /* tape 1 missing */
    expect_fault(c, n, "function: tape past the section end", L.T[1]);
    free(c);
    c = resize_section(buf, &L, L.T[1] - L.F + 8, &n); /* tape 1's head cut */
    expect_fault(c, n, "function: tape past the section end", L.T[1]);
    free(c);
    c = resize_section(buf, &L, L.T[1] - L.F + 24, &n); /* tape 1's body cut */
    expect_fault(c, n, "function: tape past the section end", L.T[1]);
    free(c);
    c = resize_section(buf, &L, L.size + 8, &n);
    expect_fault(c, n, "function: bytes after the last tape", L.F + L.size);
    free(c);
    free(buf);
    test_tree_free(&t);
}

/* Damage the structure checks cannot see is the section CRC's. */
static void test_section_crc(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    test_fn_small_file(&buf, &len, &t, 0);
    loc L;
    locate(buf, &L);
    const uint64_t k = L.K[0] + 24ull * inexact_const(buf, &L);
    wr_f64le(buf + k, rd_f64le(buf + k + 8)); /* v moved to lo: still valid */
    uint64_t at;
    assert_int_equal(oct_check_open(buf, len, 0, &at), OCT_ECRC);
    assert_int_equal(at, OCT_SEC_OFF(OCT_SEC_FUNCTION) + 16);
    assert_int_equal(oct_check_open(buf, len, OCT_OPEN_TRUST, NULL), OCT_OK);
    free(buf);
    test_tree_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_heads_and_counts),
        cmocka_unit_test(test_constants),
        cmocka_unit_test(test_instructions),
        cmocka_unit_test(test_section_sizes),
        cmocka_unit_test(test_section_crc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
