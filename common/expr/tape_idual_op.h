/* tape_idual_op.h: one instruction of the interval gradient evaluator
 * (forward-mode AD in interval arithmetic), shared by tape_eval_interval_grad
 * and the lanes of tape_eval_interval_grad_lanes, which redo a lane with it
 * where their fast paths do not apply (private to common/expr/). */
#ifndef TAPE_IDUAL_OP_H
#define TAPE_IDUAL_OP_H

#include "common/expr/tape_int.h"

static inline int is_zero(interval a) { return a.lo == 0.0 && a.hi == 0.0; }
static inline int is_finite(interval a) { return isfinite(a.lo) && isfinite(a.hi); } /* quiet: no trap */

/* interval_mul for the partials: those of a term without that variable are
 * [0, 0], and [0, 0] times a finite interval is [+0, +0] in interval_mul
 * (its all-finite path, no flag), here without the products. */
INTERVAL_INLINE interval dmul(interval a, interval b, unsigned *f)
{
    if ((is_zero(a) && is_finite(b)) || (is_zero(b) && is_finite(a))) {
        interval z = {0.0, 0.0};
        return z;
    }
    return interval_mul(a, b, f);
}

/* r->d[j] = a->d[j] * m for an interval multiplier m. */
INTERVAL_INLINE void iscale(tape_idual *r, const tape_idual *a, interval v, interval m,
                            unsigned *f)
{
    for (int j = 0; j < 3; j++)
        r->d[j] = dmul(a->d[j], m, f);
    r->v = v;
}

static inline interval ipt(double x) { interval r = {x, x}; return r; }

/* Instruction i of t into r from its operands' slots a and c; sv and cv
 * are sin and cos of a's value for TAPE_SIN and TAPE_COS (the evaluation's
 * memo), unused otherwise. Flags go into *f. */
INTERVAL_INLINE void idual_op(const tape *t, uint32_t i, const interval box[3],
                              const tape_idual *a, const tape_idual *c, interval sv, interval cv,
                              tape_idual *r, unsigned *f)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    switch ((tape_op)in[i].op) {
    case TAPE_CONST:
        r->v.lo = k[in[i].a].lo;
        r->v.hi = k[in[i].a].hi;
        r->d[0] = r->d[1] = r->d[2] = ipt(0.0);
        break;
    case TAPE_X: case TAPE_Y: case TAPE_Z: {
        int ax = (int)in[i].op - TAPE_X;
        r->v = box[ax];
        r->d[0] = r->d[1] = r->d[2] = ipt(0.0);
        r->d[ax] = ipt(1.0);
        break;
    }
    case TAPE_NEG:
        r->v = interval_neg(a->v);
        for (int j = 0; j < 3; j++)
            r->d[j] = interval_neg(a->d[j]);
        break;
    case TAPE_SQUARE:
        iscale(r, a, interval_sqr(a->v, f), interval_mul(ipt(2.0), a->v, f), f);
        break;
    case TAPE_SQRT: {
        interval v = interval_sqrt(a->v, f);
        iscale(r, a, v, interval_div(ipt(0.5), v, f), f);
        break;
    }
    case TAPE_EXP: { interval v = interval_exp(a->v, f); iscale(r, a, v, v, f); break; }
    case TAPE_LOG:
        iscale(r, a, interval_log(a->v, f), interval_div(ipt(1.0), a->v, f), f);
        break;
    case TAPE_ABS: {
        interval v = interval_abs(a->v);
        interval m = a->v.lo >= 0.0 ? ipt(1.0) : a->v.hi <= 0.0 ? ipt(-1.0) : (interval){-1.0, 1.0};
        iscale(r, a, v, m, f);
        break;
    }
    case TAPE_SIN:
    case TAPE_COS: {
        if (in[i].op == TAPE_SIN)
            iscale(r, a, sv, cv, f);
        else
            iscale(r, a, cv, interval_neg(sv), f);
        break;
    }
    case TAPE_TAN: {
        interval v = interval_tan(a->v, f);
        iscale(r, a, v, interval_add(ipt(1.0), interval_sqr(v, f), f), f);
        break;
    }
    case TAPE_ADD:
    case TAPE_SUB: {
        int add = in[i].op == TAPE_ADD;
        interval v = add ? interval_add(a->v, c->v, f) : interval_sub(a->v, c->v, f);
        /* A constant operand has a zero derivative: skip the arithmetic. */
        if (in[in[i].b].op == TAPE_CONST) {
            for (int j = 0; j < 3; j++)
                r->d[j] = a->d[j];
        } else if (in[in[i].a].op == TAPE_CONST) {
            for (int j = 0; j < 3; j++)
                r->d[j] = add ? c->d[j] : interval_neg(c->d[j]);
        } else {
            for (int j = 0; j < 3; j++)
                r->d[j] = add ? interval_add(a->d[j], c->d[j], f)
                              : interval_sub(a->d[j], c->d[j], f);
        }
        r->v = v;
        break;
    }
    case TAPE_MUL:
        if (in[in[i].a].op == TAPE_CONST) {
            iscale(r, c, interval_mul(a->v, c->v, f), a->v, f);
            break;
        }
        if (in[in[i].b].op == TAPE_CONST) {
            iscale(r, a, interval_mul(a->v, c->v, f), c->v, f);
            break;
        }
        for (int j = 0; j < 3; j++)
            r->d[j] = interval_add(dmul(a->d[j], c->v, f), dmul(a->v, c->d[j], f), f);
        r->v = interval_mul(a->v, c->v, f);
        break;
    case TAPE_DIV: {
        interval v = interval_div(a->v, c->v, f);
        for (int j = 0; j < 3; j++)
            r->d[j] = interval_div(interval_sub(a->d[j], dmul(v, c->d[j], f), f),
                                   c->v, f);
        r->v = v;
        break;
    }
    case TAPE_MIN:
    case TAPE_MAX: {
        int is_min = in[i].op == TAPE_MIN;
        interval v = is_min ? interval_min(a->v, c->v) : interval_max(a->v, c->v);
        const tape_idual *w = NULL;
        if (a->v.hi < c->v.lo)
            w = is_min ? a : c;
        else if (c->v.hi < a->v.lo)
            w = is_min ? c : a;
        for (int j = 0; j < 3; j++)
            r->d[j] = w ? w->d[j] : interval_hull(a->d[j], c->d[j]);
        r->v = v;
        break;
    }
    case TAPE_POWC: {
        double e = k[in[i].b].v;
        interval v = interval_powc(a->v, e, f);
        interval m = interval_mul(ipt(e), interval_powc(a->v, e - 1.0, f), f);
        iscale(r, a, v, m, f);
        break;
    }
    case TAPE_NOPS:
        r->v = interval_nan();
        *f |= INTERVAL_MAYBE_NAN;
        break;
    }
}

#endif
