/* tape_io: encode tapes as an .oct FUNCTION section, decode a stored tape
 * (format/FORMAT.md §8 is the byte layout; its numbers are restated here). */
#include "common/expr/tape_io.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* FORMAT.md §8's op codes, by tape_op: the file's numbers are fixed, the
 * enum's may change, so the two are tied by this table, not by equality. */
static const uint32_t file_code[TAPE_NOPS] = {
    [TAPE_CONST] = 0, [TAPE_X] = 1, [TAPE_Y] = 2, [TAPE_Z] = 3,
    [TAPE_NEG] = 4, [TAPE_SQUARE] = 5, [TAPE_SQRT] = 6, [TAPE_EXP] = 7, [TAPE_LOG] = 8,
    [TAPE_ABS] = 9, [TAPE_SIN] = 10, [TAPE_COS] = 11, [TAPE_TAN] = 12,
    [TAPE_ADD] = 13, [TAPE_SUB] = 14, [TAPE_MUL] = 15, [TAPE_DIV] = 16, [TAPE_MIN] = 17,
    [TAPE_MAX] = 18, [TAPE_POWC] = 19,
};

enum { HEAD = 8, TAPE_HEAD = 16, CONST_SIZE = 24, INSN_SIZE = 12 };

uint32_t tape_io_file_op(tape_op op) { return file_code[op]; }

int tape_io_tape_op(uint32_t code)
{
    for (int op = 0; op < TAPE_NOPS; op++)
        if (file_code[op] == code)
            return op;
    return -1;
}

static void put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); } /* little-endian host */
static void put_f64(unsigned char *p, double v) { memcpy(p, &v, 8); }

static int unary(tape_op op) { return op >= TAPE_NEG && op <= TAPE_TAN; }
static int binary(tape_op op) { return op >= TAPE_ADD && op <= TAPE_MAX; }

static size_t tape_bytes(const tape *t)
{
    size_t end = TAPE_HEAD + (size_t)CONST_SIZE * t->nconst + (size_t)INSN_SIZE * t->n;
    return (end + 7) & ~(size_t)7;
}

/* One tape at p (tape_bytes(t) bytes, zeroed): the head, the constants, the
 * instructions with their unused operands 0. */
static void put_tape(const tape *t, unsigned char *p)
{
    put_u32(p, t->n);
    put_u32(p + 4, t->nconst);
    put_u32(p + 8, t->root);
    unsigned char *k = p + TAPE_HEAD;
    for (uint32_t j = 0; j < t->nconst; j++, k += CONST_SIZE) {
        put_f64(k, t->konst[j].v);
        put_f64(k + 8, t->konst[j].lo);
        put_f64(k + 16, t->konst[j].hi);
    }
    for (uint32_t i = 0; i < t->n; i++, k += INSN_SIZE) {
        const tape_op op = (tape_op)t->insn[i].op;
        int has_a = op == TAPE_CONST || unary(op) || binary(op) || op == TAPE_POWC;
        int has_b = binary(op) || op == TAPE_POWC;
        put_u32(k, file_code[op]);
        put_u32(k + 4, has_a ? t->insn[i].a : 0);
        put_u32(k + 8, has_b ? t->insn[i].b : 0);
    }
}

int tape_io_encode(const tape *const *tapes, unsigned count, unsigned char **out, size_t *size)
{
    *out = NULL;
    *size = 0;
    size_t total = HEAD;
    for (unsigned s = 0; s < count; s++) {
        if (tapes[s]->n < 1 || tapes[s]->n > TAPE_MAX_INSNS || tapes[s]->nconst > TAPE_MAX_INSNS)
            return TAPE_ETOOBIG;
        total += tape_bytes(tapes[s]); /* < 2^28 each: no overflow for 255 tapes */
    }
    unsigned char *p = calloc(1, total);
    if (!p)
        return TAPE_ENOMEM;
    put_u32(p, count);
    size_t at = HEAD;
    for (unsigned s = 0; s < count; s++) {
        put_tape(tapes[s], p + at);
        at += tape_bytes(tapes[s]);
    }
    *out = p;
    *size = total;
    return TAPE_OK;
}

/* The rules of FORMAT.md §8 for one instruction i, in tape_op terms. */
static int insn_ok(int op, uint32_t i, uint32_t a, uint32_t b, const double *konst, uint32_t m)
{
    if (op < 0)
        return 0;
    if (op == TAPE_CONST)
        return a < m && b == 0;
    if (op <= TAPE_Z)
        return a == 0 && b == 0;
    if (unary((tape_op)op))
        return a < i && b == 0;
    if (binary((tape_op)op))
        return a < i && b < i;
    /* POWC: the exponent an exact non-integer constant */
    return a < i && b < m && konst[3 * (size_t)b + 1] == konst[3 * (size_t)b] &&
           konst[3 * (size_t)b] == konst[3 * (size_t)b + 2] && konst[3 * (size_t)b] != floor(konst[3 * (size_t)b]);
}

int tape_io_decode(const uint32_t *insn, uint32_t n, const double *konst, uint32_t m, uint32_t root,
                   tape *out)
{
    memset(out, 0, sizeof *out);
    if (n < 1 || n > TAPE_MAX_INSNS || m > TAPE_MAX_INSNS || root >= n)
        return TAPE_IO_EINVALID;
    for (uint32_t j = 0; j < m; j++) {
        double v = konst[3 * (size_t)j], lo = konst[3 * (size_t)j + 1], hi = konst[3 * (size_t)j + 2];
        if (!isfinite(v) || !isfinite(lo) || !isfinite(hi) || !(lo <= v && v <= hi))
            return TAPE_IO_EINVALID;
    }
    for (uint32_t i = 0; i < n; i++)
        if (!insn_ok(tape_io_tape_op(insn[3 * (size_t)i]), i, insn[3 * (size_t)i + 1],
                     insn[3 * (size_t)i + 2], konst, m))
            return TAPE_IO_EINVALID;
    tape_insn *ti = malloc((size_t)n * sizeof *ti);
    tape_const *tk = malloc((m ? m : 1) * sizeof *tk);
    if (!ti || !tk) {
        free(ti);
        free(tk);
        return TAPE_ENOMEM;
    }
    for (uint32_t i = 0; i < n; i++) {
        ti[i].op = (uint32_t)tape_io_tape_op(insn[3 * (size_t)i]);
        ti[i].a = insn[3 * (size_t)i + 1];
        ti[i].b = insn[3 * (size_t)i + 2];
    }
    for (uint32_t j = 0; j < m; j++) {
        tk[j].v = konst[3 * (size_t)j];
        tk[j].lo = konst[3 * (size_t)j + 1];
        tk[j].hi = konst[3 * (size_t)j + 2];
    }
    out->insn = ti;
    out->n = n;
    out->root = root;
    out->konst = tk;
    out->nconst = m;
    out->owned = 1;
    out->ntree = n;
    return TAPE_OK;
}
