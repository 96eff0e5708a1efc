/* oct_function: the checks of the FUNCTION section (FORMAT.md §8), shared by
 * the reader (before the first ray) and the writer (before a byte is
 * written). One linear pass; every count is bounded before it is used. */
#include "format/oct.h"
#include "format/oct_layout.h"

#include <math.h>

enum { KIND_CONST, KIND_VAR, KIND_UNARY, KIND_BINARY, KIND_POWC };

/* The operands each op code takes (FORMAT.md §8, "Instructions"). */
static const unsigned char op_kind[OCT_OP_COUNT] = {
    [OCT_OP_CONST] = KIND_CONST,
    [OCT_OP_X] = KIND_VAR, [OCT_OP_Y] = KIND_VAR, [OCT_OP_Z] = KIND_VAR,
    [OCT_OP_NEG] = KIND_UNARY, [OCT_OP_SQUARE] = KIND_UNARY, [OCT_OP_SQRT] = KIND_UNARY,
    [OCT_OP_EXP] = KIND_UNARY, [OCT_OP_LOG] = KIND_UNARY, [OCT_OP_ABS] = KIND_UNARY,
    [OCT_OP_SIN] = KIND_UNARY, [OCT_OP_COS] = KIND_UNARY, [OCT_OP_TAN] = KIND_UNARY,
    [OCT_OP_ADD] = KIND_BINARY, [OCT_OP_SUB] = KIND_BINARY, [OCT_OP_MUL] = KIND_BINARY,
    [OCT_OP_DIV] = KIND_BINARY, [OCT_OP_MIN] = KIND_BINARY, [OCT_OP_MAX] = KIND_BINARY,
    [OCT_OP_POWC] = KIND_POWC,
};

#define FAIL_UNLESS(cond, off, text)                                                               \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            *where = base + (off);                                                                 \
            *what = (text);                                                                        \
            return -1;                                                                             \
        }                                                                                          \
    } while (0)

/* Constants: finite, lo <= v <= hi (each at its own offset). */
static int check_constants(const unsigned char *p, uint64_t base, uint64_t at, uint32_t m,
                           uint64_t *where, const char **what)
{
    for (uint32_t j = 0; j < m; j++, at += OCT_FN_CONST_SIZE) {
        double v = rd_f64le(p + at), lo = rd_f64le(p + at + 8), hi = rd_f64le(p + at + 16);
        FAIL_UNLESS(isfinite(v), at, "function: constant not finite");
        FAIL_UNLESS(isfinite(lo), at + 8, "function: constant bound not finite");
        FAIL_UNLESS(isfinite(hi), at + 16, "function: constant bound not finite");
        FAIL_UNLESS(lo <= v, at + 8, "function: constant below its lower bound");
        FAIL_UNLESS(v <= hi, at + 16, "function: constant above its upper bound");
    }
    return 0;
}

/* True when pool entry b is an exact, non-integer number (a POWC exponent:
 * the evaluators use its double as the real exponent). */
static int exact_fraction(const unsigned char *konst, uint32_t b)
{
    const unsigned char *k = konst + (uint64_t)OCT_FN_CONST_SIZE * b;
    double v = rd_f64le(k), lo = rd_f64le(k + 8), hi = rd_f64le(k + 16);
    return lo == v && v == hi && v != floor(v);
}

/* Instructions: known op codes, operands strictly earlier, pool indices in
 * range, unused operands zero. `konst` is the tape's (checked) pool. */
static int check_insns(const unsigned char *p, uint64_t base, uint64_t at, uint32_t n, uint32_t m,
                       const unsigned char *konst, uint64_t *where, const char **what)
{
    for (uint32_t i = 0; i < n; i++, at += OCT_FN_INSN_SIZE) {
        uint32_t op = rd_u32le(p + at), a = rd_u32le(p + at + 4), b = rd_u32le(p + at + 8);
        FAIL_UNLESS(op < OCT_OP_COUNT, at, "function: unknown op code");
        switch (op_kind[op]) {
        case KIND_CONST:
            FAIL_UNLESS(a < m, at + 4, "function: constant index out of range");
            FAIL_UNLESS(b == 0, at + 8, "function: unused operand not zero");
            break;
        case KIND_VAR:
            FAIL_UNLESS(a == 0, at + 4, "function: unused operand not zero");
            FAIL_UNLESS(b == 0, at + 8, "function: unused operand not zero");
            break;
        case KIND_UNARY:
            FAIL_UNLESS(a < i, at + 4, "function: operand not strictly earlier");
            FAIL_UNLESS(b == 0, at + 8, "function: unused operand not zero");
            break;
        case KIND_BINARY:
            FAIL_UNLESS(a < i, at + 4, "function: operand not strictly earlier");
            FAIL_UNLESS(b < i, at + 8, "function: operand not strictly earlier");
            break;
        default: /* KIND_POWC */
            FAIL_UNLESS(a < i, at + 4, "function: operand not strictly earlier");
            FAIL_UNLESS(b < m, at + 8, "function: constant index out of range");
            FAIL_UNLESS(exact_fraction(konst, b), at + 8,
                        "function: power exponent not an exact non-integer");
            break;
        }
    }
    return 0;
}

int oct__function_check(const unsigned char *p, uint64_t size, uint64_t base, uint32_t count,
                        oct_function_tape *tapes, uint64_t *where, const char **what)
{
    FAIL_UNLESS(size >= OCT_FN_HEAD, 0, "function: section shorter than its head");
    FAIL_UNLESS(rd_u32le(p) == count, 0, "function: tape count is not the surface count");
    FAIL_UNLESS(rd_u32le(p + 4) == 0, 4, "function: reserved field not zero");
    uint64_t at = OCT_FN_HEAD;
    for (uint32_t t = 0; t < count; t++) {
        FAIL_UNLESS(size - at >= OCT_FN_TAPE_HEAD, at, "function: tape past the section end");
        uint32_t n = rd_u32le(p + at), m = rd_u32le(p + at + 4), root = rd_u32le(p + at + 8);
        FAIL_UNLESS(n >= 1 && n <= OCT_FN_MAX_INSNS, at, "function: instruction count out of range");
        FAIL_UNLESS(m <= OCT_FN_MAX_CONSTS, at + 4, "function: constant count out of range");
        FAIL_UNLESS(root < n, at + 8, "function: root is not an instruction");
        FAIL_UNLESS(rd_u32le(p + at + 12) == 0, at + 12, "function: reserved field not zero");
        const uint64_t kon = at + OCT_FN_TAPE_HEAD, ins = kon + (uint64_t)OCT_FN_CONST_SIZE * m;
        const uint64_t end = ins + (uint64_t)OCT_FN_INSN_SIZE * n, padded = (end + 7) & ~(uint64_t)7;
        FAIL_UNLESS(padded <= size, at, "function: tape past the section end"); /* < 2^28: no overflow */
        if (check_constants(p, base, kon, m, where, what) != 0 ||
            check_insns(p, base, ins, n, m, p + kon, where, what) != 0)
            return -1;
        for (uint64_t k = end; k < padded; k++)
            FAIL_UNLESS(p[k] == 0, k, "function: padding not zero");
        if (tapes) {
            tapes[t].insn_count = n;
            tapes[t].const_count = m;
            tapes[t].root = root;
            tapes[t].insn = (const uint32_t *)(const void *)(p + ins);
            tapes[t].konst = m ? (const double *)(const void *)(p + kon) : NULL;
        }
        at = padded;
    }
    FAIL_UNLESS(at == size, at, "function: bytes after the last tape");
    return 0;
}
