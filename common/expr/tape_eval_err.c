/* tape_eval_err: tape_eval_dir with a running bound on the error of each
 * value and derivative (see tape_err.h).
 *
 * The argument, per instruction: the operands' computed values â (and ĉ)
 * lie within ea (ec) of the exact ones, their derivatives â' within ea'.
 * The result's bound is the op's own rounding (u = 2^-53 of its result for
 * + - * / sqrt, 2^-51 for the libm functions: two ulps) plus the
 * propagated part, bounded by the mean value theorem over the operands'
 * error ranges (the conditions that fail the evaluation keep those ranges
 * clear of kinks, poles and domain edges). Each bound is itself computed
 * in double from non-negative terms, with fewer than 40 roundings of at
 * most u each: times C = 1 + 2^-44 it is at least the exact formula. The
 * absolute error of an underflow (at most 2^-1075, gradual underflow) is
 * amplified inside one formula by at most three factors of at most 2^153
 * and one of 1 / 2^-100 (the divisor check): TINY = 2^-500 added to every
 * bound covers it, and the libm's two ulps of a subnormal result. The
 * range check is on the bounds (at most 2^100): each result's bound holds
 * u of its value and derivative, so those stay below 2^153; the inputs
 * (coordinates, direction, constants) are checked where they enter. */
#include "common/expr/tape_err.h"

#include "common/expr/exp_kernel.h"
#include "common/expr/tape_int.h"

#define U 0x1p-53   /* + - * / sqrt: half an ulp, at most u of the result */
#define LIB 0x1p-51 /* exp log sin cos tan pow: two ulps of the result */
#define C (1.0 + 0x1p-44)
#define TINY 0x1p-500
#define BIG 0x1p100   /* every bound stays below, every input too */
#define SMALL 0x1p-100 /* every divisor's lower bound stays above */
#define TRIG_MAX 1e8  /* as interval.c */

static inline double fin(double x) { return x * C + TINY; }
/* |x| <= BIG; false for NaN (a quiet comparison) */
static inline int small(double x) { return fabs(x) <= BIG; }
/* e1, e2 >= 0 (or NaN) both at most BIG: their sum is, NaN and inf fail */
static inline int bounded(double e1, double e2) { return e1 + e2 <= BIG; }

double tape_err_point(double o, double m, double d, double *p)
{
    const double q = m * d;
    *p = o + q;
    return fin(U * (fabs(q) + fabs(*p)));
}

/* r->d = a->d * s, where the exact derivative of the op is (exact a') times
 * (exact scale), |s - exact scale| <= es. */
static inline void scaled(tape_edir *r, const tape_edir *a, double s, double es)
{
    r->d = a->d * s;
    r->ed = fin(fabs(a->d) * es + fabs(s) * a->ed + a->ed * es + U * fabs(r->d));
}

#define OP TAPE_OPL

int tape_eval_dir_err(const tape *t, const double p[3], const double ep[3], const double d[3],
                      tape_edir *out, tape_edir *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_edir *r = &s[i];
        /* operands: only the ops that have them name them (as tape_eval) */
#define OA (&s[in[i].a])
#define OC (&s[in[i].b])
        int ok = 1;
        /* (tape_int.h's dispatch; an op's code ends at `checked`, the test
           every op's result takes) */
        TAPE_DISPATCH(in[i].op) {
        OP(CONST): {
            const tape_const *kk = &k[in[i].a];
            r->v = kk->v;
            const double lo = kk->v - kk->lo, hi = kk->hi - kk->v;
            r->ev = fin(lo > hi ? lo : hi);
            ok = small(r->v);
            r->d = 0.0;
            r->ed = 0.0;
            goto checked;
        }
        OP(X): OP(Y): OP(Z):
            r->v = p[in[i].op - TAPE_X];
            r->ev = ep[in[i].op - TAPE_X];
            r->d = d[in[i].op - TAPE_X];
            r->ed = 0.0;
            ok = small(r->v) & small(r->d);
            goto checked;
        OP(NEG):
            r->v = -OA->v;
            r->ev = OA->ev;
            r->d = -OA->d;
            r->ed = OA->ed;
            goto checked;
        OP(SQUARE):
            /* |â² - a²| <= ea (2|â| + ea) */
            r->v = OA->v * OA->v;
            r->ev = fin(OA->ev * (2.0 * fabs(OA->v) + OA->ev) + U * r->v);
            scaled(r, OA, 2.0 * OA->v, 2.0 * OA->ev);
            goto checked;
        OP(SQRT): {
            /* a >= â - ea >= SMALL; |√â - √a| <= ea / √â */
            if (!(OA->v - OA->ev >= SMALL))
                return 0;
            r->v = sqrt(OA->v);
            r->ev = fin(U * r->v + OA->ev / r->v);
            /* √a >= v - ev = ls; |0.5/v - 0.5/√a| <= 0.5 ev / (v ls) */
            const double ls = r->v - r->ev, sc = 0.5 / r->v;
            if (!(ls >= SMALL))
                return 0;
            scaled(r, OA, sc, fin(U * sc + 0.5 * r->ev / (r->v * ls)));
            goto checked;
        }
        OP(EXP):
            /* |exp(â) - exp(a)| <= exp(â) (e^ea - 1) <= exp(â) ea (1 + ea) */
            if (!(OA->ev <= 0.0625 && OA->v <= 69.0)) /* (e^69 < BIG: no overflow) */
                return 0;
            r->v = exp_kernel(OA->v);
            r->ev = fin(LIB * r->v + r->v * (1.0 + LIB) * OA->ev * (1.0 + OA->ev));
            scaled(r, OA, r->v, r->ev);
            goto checked;
        OP(LOG): {
            /* a >= l = â - ea >= SMALL: |log â - log a| <= ea / l,
             * |1/â - 1/a| <= ea / (â l) */
            const double l = OA->v - OA->ev;
            if (!(l >= SMALL))
                return 0;
            r->v = log(OA->v);
            r->ev = fin(LIB * fabs(r->v) + OA->ev / l);
            const double sc = 1.0 / OA->v;
            scaled(r, OA, sc, fin(U * sc + OA->ev / (OA->v * l)));
            goto checked;
        }
        OP(ABS):
            ok = fabs(OA->v) > OA->ev; /* a has â's sign: no kink within reach */
            r->v = fabs(OA->v);
            r->ev = OA->ev;
            r->d = OA->v < 0.0 ? -OA->d : OA->d;
            r->ed = OA->ed;
            goto checked;
        OP(SIN):
        OP(COS): {
            /* Taylor, |sin''|, |cos''| <= 1: |sin â - sin a| <= |cos â| ea +
             * ea²/2, |cos â - cos a| <= |sin â| ea + ea²/2 (|cos â| <= |cv|
             * (1 + LIB): cv is libm's) */
            double sv, cv;
            if (!(fabs(OA->v) <= TRIG_MAX))
                return 0;
            point_sincos(OA->v, &sv, &cv);
            const double q = 0.5 * OA->ev * OA->ev, ea = (1.0 + LIB) * OA->ev;
            const double bs = fin(LIB * fabs(sv) + fabs(cv) * ea + q);
            const double bc = fin(LIB * fabs(cv) + fabs(sv) * ea + q);
            if (in[i].op == TAPE_SIN) {
                r->v = sv;
                r->ev = bs;
                scaled(r, OA, cv, bc);
            } else {
                r->v = cv;
                r->ev = bc;
                scaled(r, OA, -sv, bs);
            }
            goto checked;
        }
        OP(TAN): {
            /* With |tan â| <= T, tau = 1.01 ea >= tan ea (ea <= 1/16) and
             * T tau <= 1/4, for |x - â| <= ea: tan x = (tan â + tan δ) /
             * (1 - tan â tan δ), |δ| <= ea, so no pole and |tan x| <= M =
             * (T + tau) / (1 - T tau), |tan' x| <= 1 + M² */
            if (!(fabs(OA->v) <= TRIG_MAX && OA->ev <= 0.0625))
                return 0;
            r->v = tan(OA->v);
            const double T = fabs(r->v) * (1.0 + LIB), tau = 1.01 * OA->ev;
            if (!(T * tau <= 0.25 && small(T)))
                return 0;
            const double M = (T + tau) / (1.0 - T * tau);
            r->ev = fin(LIB * fabs(r->v) + (1.0 + M * M) * OA->ev);
            const double t2 = r->v * r->v, sc = 1.0 + t2;
            const double es = fin(r->ev * (2.0 * fabs(r->v) + r->ev) + U * t2 + U * sc);
            if (!(small(sc) & small(es)))
                return 0;
            scaled(r, OA, sc, es);
            goto checked;
        }
        OP(ADD):
            r->v = OA->v + OC->v;
            r->d = OA->d + OC->d;
            r->ev = fin(OA->ev + OC->ev + U * fabs(r->v));
            r->ed = fin(OA->ed + OC->ed + U * fabs(r->d));
            goto checked;
        OP(SUB):
            r->v = OA->v - OC->v;
            r->d = OA->d - OC->d;
            r->ev = fin(OA->ev + OC->ev + U * fabs(r->v));
            r->ed = fin(OA->ed + OC->ed + U * fabs(r->d));
            goto checked;
        OP(MUL): {
            r->v = OA->v * OC->v;
            r->ev = fin(fabs(OA->v) * OC->ev + fabs(OC->v) * OA->ev + OA->ev * OC->ev + U * fabs(r->v));
            const double p1 = OA->d * OC->v, p2 = OA->v * OC->d;
            r->d = p1 + p2;
            r->ed = fin(fabs(OA->d) * OC->ev + fabs(OC->v) * OA->ed + OA->ed * OC->ev +
                        fabs(OA->v) * OC->ed + fabs(OC->d) * OA->ev + OA->ev * OC->ed +
                        U * (fabs(p1) + fabs(p2) + fabs(r->d)));
            goto checked;
        }
        OP(DIV): {
            /* |c| >= l = |ĉ| - ec >= SMALL; â/ĉ - a/c = (â - a)/c + (â/ĉ)(c - ĉ)/c */
            const double l = fabs(OC->v) - OC->ev;
            if (!(l >= SMALL))
                return 0;
            r->v = OA->v / OC->v;
            r->ev = fin(U * fabs(r->v) + (OA->ev + fabs(r->v) * OC->ev) / l);
            /* d = (a' - v c') / c: the numerator's error en, then as above */
            const double q = r->v * OC->d, nu = OA->d - q;
            r->d = nu / OC->v;
            const double en = OA->ed + fabs(r->v) * OC->ed + fabs(OC->d) * r->ev + r->ev * OC->ed +
                              U * (fabs(q) + fabs(nu));
            r->ed = fin(U * fabs(r->d) + (en + fabs(r->d) * OC->ev) / l);
            goto checked;
        }
        OP(MIN):
        OP(MAX): {
            /* operands further apart than their errors: the exact values
             * take the same branch, and no kink is within reach */
            ok = fabs(OA->v - OC->v) > (OA->ev + OC->ev) * C;
            const double v = in[i].op == TAPE_MIN ? point_min(OA->v, OC->v) : point_max(OA->v, OC->v);
            *r = v == OA->v ? *OA : *OC;
            goto checked;
        }
        OP(POWC): {
            /* a >= â - ea >= SMALL, rho = ea/â <= 1/2: for x between a and â,
             * (x/â)^(p-1) <= exp(2 rho |p-1|) <= 1 + 4 rho |p-1| when
             * 2 rho |p-1| <= 1; so |â^p - a^p| <= |p| (â^p / â)(1 + 4 rho |p-1|) ea */
            if (!(OA->v - OA->ev >= SMALL))
                return 0;
            const double e = k[in[i].b].v, e1 = e - 1.0, rho = OA->ev / OA->v;
            if (!(rho <= 0.5 && 2.0 * rho * fabs(e1) <= 1.0 &&
                  2.0 * rho * fabs(e - 2.0) <= 1.0))
                return 0;
            r->v = pow(OA->v, e);
            const double q = pow(OA->v, e1);
            if (!(small(r->v) & small(q)))
                return 0;
            r->ev = fin(LIB * r->v + fabs(e) * (r->v / OA->v) * (1.0 + 4.0 * rho * fabs(e1)) * OA->ev);
            /* the scale e a^(e-1): e1 is e - 1 + r (r exact by two-sum), worth
             * a factor â^r within 140 |r| of 1 (|log â| <= 70, |r| <= u |e1|) */
            const double bb = e1 - e, r1 = (e - (e1 - bb)) + (-1.0 - bb);
            const double eq = LIB * q + 140.0 * fabs(r1) * q +
                              fabs(e1) * (q / OA->v) * (1.0 + 4.0 * rho * fabs(e - 2.0)) * OA->ev;
            const double sc = e * q;
            const double es = fin(fabs(e) * eq + U * fabs(sc));
            if (!(small(sc) & small(es)))
                return 0;
            scaled(r, OA, sc, es);
            goto checked;
        }
        OP(NOPS): ok = 0; goto checked;
        TAPE_DISPATCH_DEFAULT();
        }
    checked:
#undef OA
#undef OC
        if (!(ok & bounded(r->ev, r->ed)))
            return 0;
    }
    *out = s[t->root];
    return 1;
}
#undef OP
