/* povexpr: recursive printer from the tape's SSA slots. */
#include "bench/povexpr.h"

#include <stdarg.h>
#include <stdio.h>

typedef struct out {
    char *buf;
    size_t cap, len;
    int full;
} out;

static void put(out *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(out *o, const char *fmt, ...)
{
    if (o->full)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf + o->len, o->cap - o->len, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= o->cap - o->len)
        o->full = 1;
    else
        o->len += (size_t)n;
}

static void emit(const tape *t, uint32_t s, out *o)
{
    static const char *const unary[TAPE_NOPS] = {
        [TAPE_SQRT] = "sqrt", [TAPE_EXP] = "exp", [TAPE_LOG] = "ln", [TAPE_ABS] = "abs",
        [TAPE_SIN] = "sin",   [TAPE_COS] = "cos", [TAPE_TAN] = "tan",
    };
    static const char infix[TAPE_NOPS] = {
        [TAPE_ADD] = '+', [TAPE_SUB] = '-', [TAPE_MUL] = '*', [TAPE_DIV] = '/',
    };
    if (o->full)
        return;
    const tape_insn *in = &t->insn[s];
    switch ((tape_op)in->op) {
    case TAPE_CONST:
        put(o, "(%.17g)", t->konst[in->a].v);
        return;
    case TAPE_X:
    case TAPE_Y:
    case TAPE_Z:
        put(o, "%c", "xyz"[in->op - TAPE_X]);
        return;
    case TAPE_NEG:
        put(o, "(-");
        emit(t, in->a, o);
        put(o, ")");
        return;
    case TAPE_SQUARE:
        put(o, "pow(");
        emit(t, in->a, o);
        put(o, ",2)");
        return;
    case TAPE_POWC:
        put(o, "pow(");
        emit(t, in->a, o);
        put(o, ",%.17g)", t->konst[in->b].v);
        return;
    case TAPE_MIN:
    case TAPE_MAX:
        put(o, in->op == TAPE_MIN ? "min(" : "max(");
        emit(t, in->a, o);
        put(o, ",");
        emit(t, in->b, o);
        put(o, ")");
        return;
    case TAPE_ADD:
    case TAPE_SUB:
    case TAPE_MUL:
    case TAPE_DIV:
        put(o, "(");
        emit(t, in->a, o);
        put(o, "%c", infix[in->op]);
        emit(t, in->b, o);
        put(o, ")");
        return;
    default:
        if (in->op < TAPE_NOPS && unary[in->op]) {
            put(o, "%s(", unary[in->op]);
            emit(t, in->a, o);
            put(o, ")");
            return;
        }
        o->full = 1; /* an op this printer does not know */
    }
}

long povexpr_write(const tape *t, char *buf, size_t cap)
{
    if (cap == 0)
        return -1;
    out o = {buf, cap, 0, 0};
    buf[0] = '\0';
    emit(t, t->root, &o);
    return o.full ? -1 : (long)o.len;
}
