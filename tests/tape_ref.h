/* tape_ref.h: a long-double reference evaluation of a tape (value and
 * derivative along d) for the error-bound tests (test_tape_err.c,
 * test_tape_err_cell.c). Include after cmocka.h and test_tape_util.h. */
#ifndef TAPE_REF_H
#define TAPE_REF_H

#include <math.h>

#include "common/expr/tape_int.h"

typedef struct ldual {
    long double v, d;
} ldual;

/* The reference: f and its derivative along d at the exact point P, in
 * long double (11 more bits than double), constants at v (end 0), lo (1)
 * or hi (2). */
static inline ldual ref_eval(const tape *t, const long double P[3], const double d[3], int end,
                             ldual *s)
{
    for (uint32_t i = 0; i < t->n; i++) {
        const tape_insn *in = &t->insn[i];
        const ldual a = s[slot_a(in)], c = s[slot_b(in)];
        ldual *r = &s[i];
        switch ((tape_op)in->op) {
        case TAPE_CONST: {
            const tape_const *k = &t->konst[in->a];
            r->v = end == 0 ? k->v : end == 1 ? k->lo : k->hi;
            r->d = 0.0L;
            break;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z:
            r->v = P[in->op - TAPE_X];
            r->d = d[in->op - TAPE_X];
            break;
        case TAPE_NEG: r->v = -a.v; r->d = -a.d; break;
        case TAPE_SQUARE: r->v = a.v * a.v; r->d = 2.0L * a.v * a.d; break;
        case TAPE_SQRT: r->v = sqrtl(a.v); r->d = a.d * 0.5L / r->v; break;
        case TAPE_EXP: r->v = expl(a.v); r->d = a.d * r->v; break;
        case TAPE_LOG: r->v = logl(a.v); r->d = a.d / a.v; break;
        case TAPE_ABS: r->v = fabsl(a.v); r->d = a.v < 0 ? -a.d : a.d; break;
        case TAPE_SIN: r->v = sinl(a.v); r->d = a.d * cosl(a.v); break;
        case TAPE_COS: r->v = cosl(a.v); r->d = -a.d * sinl(a.v); break;
        case TAPE_TAN: r->v = tanl(a.v); r->d = a.d * (1.0L + r->v * r->v); break;
        case TAPE_ADD: r->v = a.v + c.v; r->d = a.d + c.d; break;
        case TAPE_SUB: r->v = a.v - c.v; r->d = a.d - c.d; break;
        case TAPE_MUL: r->v = a.v * c.v; r->d = a.d * c.v + a.v * c.d; break;
        case TAPE_DIV: r->v = a.v / c.v; r->d = (a.d - r->v * c.d) / c.v; break;
        case TAPE_MIN: *r = a.v <= c.v ? a : c; break;
        case TAPE_MAX: *r = a.v >= c.v ? a : c; break;
        case TAPE_POWC: {
            const long double e = t->konst[in->b].v;
            r->v = powl(a.v, e);
            r->d = a.d * e * powl(a.v, e - 1.0L);
            break;
        }
        case TAPE_NOPS: r->v = r->d = NAN; break;
        }
    }
    return s[t->root];
}

#endif
