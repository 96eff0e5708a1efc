/* tape_eval_interval: the interval evaluators, an enclosure of f and one of
 * f with its gradient (forward-mode AD in interval arithmetic), over a box. */
#include "common/expr/tape.h"

#include "common/expr/tape_idual_op.h"

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

interval tape_eval_interval_grad(const tape *t, const interval box[3], interval grad[3],
                                 tape_idual *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    unsigned f = 0;
    trig_memo tm;
    trig_memo_init(&tm);
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        const tape_idual *a = s + slot_a(&in[i]);
        interval sv = a->v, cv = a->v;
        if (in[i].op == TAPE_SIN || in[i].op == TAPE_COS) {
            unsigned j = trig_memo_entry(&tm, in[i].a, a->v, &f);
            sv = tm.s[j];
            cv = tm.c[j];
        }
        idual_op(t, i, box, a, s + slot_b(&in[i]), sv, cv, &s[i], &f);
    }
    *flags = f;
    const tape_idual *r = &s[t->root];
    grad[0] = r->d[0];
    grad[1] = r->d[1];
    grad[2] = r->d[2];
    return r->v;
}
