/* tape_eval_dir: f with its derivative along one direction, at a point
 * (double, also with the gradient) and over a box (intervals); see
 * tape_dir.h. The rules are those of tape_eval_grad and
 * tape_eval_interval_grad with one tangent (four) instead of three. */
#include "common/expr/tape_dir.h"

#include "common/expr/exp_kernel.h"
#include "common/expr/tape_int.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* A leaf's slot (a variable's, a constant's) written whole, in the shape
 * in which GCC's code for the ops loads slots: (v, d[0]) as one 16-byte
 * vector with one tangent, v alone and the tangents in pairs with four. A
 * slot written in parts and read by a wider load cannot be forwarded from
 * the store buffer: the load waits for the stores to retire, and each
 * variable's first use paid that (docs/perf-log.md). */
static inline void leaf_dir1(tape_dir1 *r, double v, const double d[1])
{
#if defined(__SSE2__)
    _mm_storeu_pd(&r->v, _mm_set_pd(d[0], v));
#else
    r->v = v;
    r->d[0] = d[0];
#endif
}

static inline void leaf_dir4(tape_dir4 *r, double v, const double d[4])
{
#if defined(__SSE2__)
    _mm_store_sd(&r->v, _mm_set_sd(v));
    _mm_storeu_pd(&r->d[0], _mm_loadu_pd(d));
    _mm_storeu_pd(&r->d[2], _mm_loadu_pd(d + 2));
#else
    r->v = v;
    for (int j = 0; j < 4; j++)
        r->d[j] = d[j];
#endif
}

#define N 1
#define LEAF leaf_dir1
#define FN eval_dir1
#define SLOT tape_dir1
#include "common/expr/tape_dir_body.h"
#undef N
#undef LEAF
#undef FN
#undef SLOT

#define N 4
#define LEAF leaf_dir4
#define FN eval_dir4
#define SLOT tape_dir4
#include "common/expr/tape_dir_body.h"
#undef N
#undef LEAF
#undef FN
#undef SLOT

double tape_eval_dir(const tape *t, const double p[3], const double d[3], double *deriv,
                     tape_dir1 *s)
{
    const double seed[3][1] = {{d[0]}, {d[1]}, {d[2]}};
    const double v = eval_dir1(t, p, seed, s);
    *deriv = s[t->root].d[0];
    return v;
}

double tape_eval_dir_grad(const tape *t, const double p[3], const double d[3], double *deriv,
                          double grad[3], tape_dir4 *s)
{
    /* tangent 0 along d (tape_eval_dir's), 1 to 3 along the axes */
    const double seed[3][4] = {{d[0], 1.0, 0.0, 0.0}, {d[1], 0.0, 1.0, 0.0}, {d[2], 0.0, 0.0, 1.0}};
    const double v = eval_dir4(t, p, seed, s);
    *deriv = s[t->root].d[0];
    for (int k = 0; k < 3; k++)
        grad[k] = s[t->root].d[1 + k];
    return v;
}

static int is_zero(interval a) { return a.lo == 0.0 && a.hi == 0.0; }
static int is_finite(interval a) { return isfinite(a.lo) && isfinite(a.hi); } /* quiet: no trap */
static interval ipt(double x) { interval r = {x, x}; return r; }

/* interval_mul where an exact zero factor times a finite one is [0, 0] (as
 * tape_eval_interval_grad's dmul): the derivative of a constant. */
INTERVAL_INLINE interval dmul(interval a, interval b, unsigned *f)
{
    if ((is_zero(a) && is_finite(b)) || (is_zero(b) && is_finite(a)))
        return ipt(0.0);
    return interval_mul(a, b, f);
}

interval tape_eval_interval_dir(const tape *t, const interval box[3], const double d[3],
                                interval *deriv, tape_idir1 *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_idir1 *r = &s[i];
        const tape_idir1 a = s[slot_a(&in[i])], c = s[slot_b(&in[i])];
        switch ((tape_op)in[i].op) {
        case TAPE_CONST:
            r->v.lo = k[in[i].a].lo;
            r->v.hi = k[in[i].a].hi;
            r->d = ipt(0.0);
            break;
        case TAPE_X: case TAPE_Y: case TAPE_Z:
            r->v = box[in[i].op - TAPE_X];
            r->d = ipt(d[in[i].op - TAPE_X]);
            break;
        case TAPE_NEG: r->v = interval_neg(a.v); r->d = interval_neg(a.d); break;
        case TAPE_SQUARE:
            r->v = interval_sqr(a.v, &f);
            r->d = dmul(a.d, interval_mul(ipt(2.0), a.v, &f), &f);
            break;
        case TAPE_SQRT:
            r->v = interval_sqrt(a.v, &f);
            r->d = dmul(a.d, interval_div(ipt(0.5), r->v, &f), &f);
            break;
        case TAPE_EXP: r->v = interval_exp(a.v, &f); r->d = dmul(a.d, r->v, &f); break;
        case TAPE_LOG:
            r->v = interval_log(a.v, &f);
            r->d = dmul(a.d, interval_div(ipt(1.0), a.v, &f), &f);
            break;
        case TAPE_ABS: {
            r->v = interval_abs(a.v);
            const interval m = a.v.lo >= 0.0   ? ipt(1.0)
                               : a.v.hi <= 0.0 ? ipt(-1.0)
                                               : (interval){-1.0, 1.0};
            r->d = dmul(a.d, m, &f);
            break;
        }
        /* the value as tape_eval_interval makes it (interval_sincos), bit for bit */
        case TAPE_SIN: {
            interval sv, cv;
            interval_sincos(a.v, &sv, &cv, &f);
            r->v = sv;
            r->d = dmul(a.d, cv, &f);
            break;
        }
        case TAPE_COS: {
            interval sv, cv;
            interval_sincos(a.v, &sv, &cv, &f);
            r->v = cv;
            r->d = dmul(a.d, interval_neg(sv), &f);
            break;
        }
        case TAPE_TAN:
            r->v = interval_tan(a.v, &f);
            r->d = dmul(a.d, interval_add(ipt(1.0), interval_sqr(r->v, &f), &f), &f);
            break;
        case TAPE_ADD: r->v = interval_add(a.v, c.v, &f); r->d = interval_add(a.d, c.d, &f); break;
        case TAPE_SUB: r->v = interval_sub(a.v, c.v, &f); r->d = interval_sub(a.d, c.d, &f); break;
        case TAPE_MUL:
            r->v = interval_mul(a.v, c.v, &f);
            r->d = interval_add(dmul(a.d, c.v, &f), dmul(a.v, c.d, &f), &f);
            break;
        case TAPE_DIV:
            r->v = interval_div(a.v, c.v, &f);
            r->d = interval_div(interval_sub(a.d, dmul(r->v, c.d, &f), &f), c.v, &f);
            break;
        case TAPE_MIN:
        case TAPE_MAX: {
            const int is_min = in[i].op == TAPE_MIN;
            r->v = is_min ? interval_min(a.v, c.v) : interval_max(a.v, c.v);
            if (a.v.hi < c.v.lo)
                r->d = is_min ? a.d : c.d;
            else if (c.v.hi < a.v.lo)
                r->d = is_min ? c.d : a.d;
            else
                r->d = interval_hull(a.d, c.d);
            break;
        }
        case TAPE_POWC: {
            const double e = k[in[i].b].v;
            r->v = interval_powc(a.v, e, &f);
            r->d = dmul(a.d, interval_mul(ipt(e), interval_powc(a.v, e - 1.0, &f), &f), &f);
            break;
        }
        case TAPE_NOPS:
            r->v = interval_nan();
            r->d = interval_nan();
            f |= INTERVAL_MAYBE_NAN;
            break;
        }
    }
    *flags = f;
    *deriv = s[t->root].d;
    return s[t->root].v;
}
