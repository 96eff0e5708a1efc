/* tape_eval_interval: the interval evaluators, an enclosure of f and one of
 * f with its gradient (forward-mode AD in interval arithmetic), over a box. */
#include "common/expr/tape.h"

#include "common/expr/tape_int.h"

#define A s[in[i].a]
#define C s[in[i].b]

interval tape_eval_interval(const tape *t, const interval box[3], interval *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    trig_memo tm;
    trig_memo_init(&tm);
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: s[i].lo = k[in[i].a].lo; s[i].hi = k[in[i].a].hi; break;
        case TAPE_X: s[i] = box[0]; break;
        case TAPE_Y: s[i] = box[1]; break;
        case TAPE_Z: s[i] = box[2]; break;
        case TAPE_NEG: s[i] = interval_neg(A); break;
        case TAPE_SQUARE: s[i] = interval_sqr(A, &f); break;
        case TAPE_SQRT: s[i] = interval_sqrt(A, &f); break;
        case TAPE_EXP: s[i] = interval_exp(A, &f); break;
        case TAPE_LOG: s[i] = interval_log(A, &f); break;
        case TAPE_ABS: s[i] = interval_abs(A); break;
        case TAPE_SIN: { unsigned j = trig_memo_entry(&tm, in[i].a, A, &f); s[i] = tm.s[j]; break; }
        case TAPE_COS: { unsigned j = trig_memo_entry(&tm, in[i].a, A, &f); s[i] = tm.c[j]; break; }
        case TAPE_TAN: s[i] = interval_tan(A, &f); break;
        case TAPE_ADD: s[i] = interval_add(A, C, &f); break;
        case TAPE_SUB: s[i] = interval_sub(A, C, &f); break;
        case TAPE_MUL: s[i] = interval_mul(A, C, &f); break;
        case TAPE_DIV: s[i] = interval_div(A, C, &f); break;
        case TAPE_MIN: s[i] = interval_min(A, C); break;
        case TAPE_MAX: s[i] = interval_max(A, C); break;
        case TAPE_POWC: s[i] = interval_powc(A, k[in[i].b].v, &f); break;
        case TAPE_NOPS: s[i] = interval_nan(); f |= INTERVAL_MAYBE_NAN; break;
        }
    }
    *flags = f;
    return s[t->root];
}

static int is_zero(interval a) { return a.lo == 0.0 && a.hi == 0.0; }
static int is_finite(interval a) { return isfinite(a.lo) && isfinite(a.hi); } /* quiet: no trap */

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
static void iscale(tape_idual *r, const tape_idual *a, interval v, interval m, unsigned *f)
{
    for (int j = 0; j < 3; j++)
        r->d[j] = dmul(a->d[j], m, f);
    r->v = v;
}

static interval ipt(double x) { interval r = {x, x}; return r; }

interval tape_eval_interval_grad(const tape *t, const interval box[3], interval grad[3],
                                 tape_idual *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    trig_memo tm;
    trig_memo_init(&tm);
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_idual *r = &s[i];
        const tape_idual *a = s + slot_a(&in[i]), *c = s + slot_b(&in[i]);
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
            iscale(r, a, interval_sqr(a->v, &f), interval_mul(ipt(2.0), a->v, &f), &f);
            break;
        case TAPE_SQRT: {
            interval v = interval_sqrt(a->v, &f);
            iscale(r, a, v, interval_div(ipt(0.5), v, &f), &f);
            break;
        }
        case TAPE_EXP: { interval v = interval_exp(a->v, &f); iscale(r, a, v, v, &f); break; }
        case TAPE_LOG:
            iscale(r, a, interval_log(a->v, &f), interval_div(ipt(1.0), a->v, &f), &f);
            break;
        case TAPE_ABS: {
            interval v = interval_abs(a->v);
            interval m = a->v.lo >= 0.0 ? ipt(1.0) : a->v.hi <= 0.0 ? ipt(-1.0) : (interval){-1.0, 1.0};
            iscale(r, a, v, m, &f);
            break;
        }
        case TAPE_SIN:
        case TAPE_COS: {
            unsigned j = trig_memo_entry(&tm, in[i].a, a->v, &f);
            interval sv = tm.s[j], cv = tm.c[j];
            if (in[i].op == TAPE_SIN)
                iscale(r, a, sv, cv, &f);
            else
                iscale(r, a, cv, interval_neg(sv), &f);
            break;
        }
        case TAPE_TAN: {
            interval v = interval_tan(a->v, &f);
            iscale(r, a, v, interval_add(ipt(1.0), interval_sqr(v, &f), &f), &f);
            break;
        }
        case TAPE_ADD:
        case TAPE_SUB: {
            int add = in[i].op == TAPE_ADD;
            interval v = add ? interval_add(a->v, c->v, &f) : interval_sub(a->v, c->v, &f);
            /* A constant operand has a zero derivative: skip the arithmetic. */
            if (in[in[i].b].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    r->d[j] = a->d[j];
            } else if (in[in[i].a].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    r->d[j] = add ? c->d[j] : interval_neg(c->d[j]);
            } else {
                for (int j = 0; j < 3; j++)
                    r->d[j] = add ? interval_add(a->d[j], c->d[j], &f)
                                  : interval_sub(a->d[j], c->d[j], &f);
            }
            r->v = v;
            break;
        }
        case TAPE_MUL:
            if (in[in[i].a].op == TAPE_CONST) {
                iscale(r, c, interval_mul(a->v, c->v, &f), a->v, &f);
                break;
            }
            if (in[in[i].b].op == TAPE_CONST) {
                iscale(r, a, interval_mul(a->v, c->v, &f), c->v, &f);
                break;
            }
            for (int j = 0; j < 3; j++)
                r->d[j] = interval_add(dmul(a->d[j], c->v, &f), dmul(a->v, c->d[j], &f), &f);
            r->v = interval_mul(a->v, c->v, &f);
            break;
        case TAPE_DIV: {
            interval v = interval_div(a->v, c->v, &f);
            for (int j = 0; j < 3; j++)
                r->d[j] = interval_div(interval_sub(a->d[j], dmul(v, c->d[j], &f), &f),
                                       c->v, &f);
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
            interval v = interval_powc(a->v, e, &f);
            interval m = interval_mul(ipt(e), interval_powc(a->v, e - 1.0, &f), &f);
            iscale(r, a, v, m, &f);
            break;
        }
        case TAPE_NOPS:
            r->v = interval_nan();
            f |= INTERVAL_MAYBE_NAN;
            break;
        }
    }
    *flags = f;
    const tape_idual *r = &s[t->root];
    grad[0] = r->d[0];
    grad[1] = r->d[1];
    grad[2] = r->d[2];
    return r->v;
}
