/* tape_err_cell: tape_eval_dir's rounding error bounded once over a box
 * (see tape_err_cell.h; the argument is in render/RENDER.md, "The a-priori
 * bound").
 *
 * The interval evaluation with gradients over the box (outward rounding)
 * gives every slot's exact value a and gradient within magnitudes A =
 * max |a| and G_k = max |da/dx_k| at every point of the box. Per slot the
 * pass below carries E >= |â - a| (â: tape_eval_dir's value at the point)
 * and F_k with |â' - a'| <= sum_k |dir_k| F_k (â': its derivative along
 * dir): every formula of tape_eval_err.c with the computed operands' sizes
 * bounded by A + E and |a'| by sum_k |dir_k| G_k. Each formula is linear in
 * the derivatives and their errors with coefficients that depend on the
 * values alone, so the derivative's bound splits into the three lanes F_k.
 * The op's own rounding is u of the size of its exact result on the
 * computed operands (at most the result's magnitude plus the propagated
 * error), 2^-51 (1 + 2^-50) of it for exp log sin cos (two ulps of the
 * computed result). The bounds are computed from non-negative terms with
 * fewer than 40 roundings each (a divisor's lower bound rounded down), so
 * times C = 1 + 2^-44 they are at least the exact formulas; TINY = 2^-300
 * covers underflow (an absolute 2^-1075 per rounding, amplified by at
 * most five factors below 2^102 and two divisions by at least 2^-100). */
#include "common/expr/tape_err_cell.h"

#include "common/expr/tape_int.h"

#define U 0x1p-53
#define LIB (0x1p-51 * (1.0 + 0x1p-50)) /* two ulps of the computed result */
#define C (1.0 + 0x1p-44)
#define TINY 0x1p-300
#define BIG 0x1p100
#define SMALL 0x1p-100
#define TRIG_MAX 1e8 /* as interval.c */

static inline double fin(double x) { return x * C + TINY; }
static inline double mag(interval a) { return fmax(fabs(a.lo), fabs(a.hi)); }
/* a lower bound of x - y for x > y >= 0 (rounded down) */
static inline double low(double x, double y) { return (x - y) * (1.0 - 0x1p-51); }

/* The derivative lanes of r = phi(a), computed as â' * ŝ with |ŝ - s| <= es
 * and |s| <= sm (s = phi'(a) over the box). */
static inline void scaled(tape_cerr *r, const tape_cerr *a, const tape_idual *ga, double sm,
                          double es)
{
    const double sh = sm + es; /* |ŝ| */
    for (int k = 0; k < 3; k++) {
        const double g = mag(ga->d[k]);
        r->f[k] = fin(a->f[k] * sh + g * es + U * (g + a->f[k]) * sh);
    }
}

int tape_err_cell(const tape *t, const interval box[3], tape_cell_err *out, tape_idual *g,
                  tape_cerr *s)
{
    interval grad[3];
    unsigned flags = 0;
    tape_eval_interval_grad(t, box, grad, g, &flags);
    if (flags)
        return 0;
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_cerr *r = &s[i];
        const tape_cerr *a = &s[slot_a(&in[i])], *c = &s[slot_b(&in[i])];
        const tape_idual *gr = &g[i], *ga = &g[slot_a(&in[i])], *gc = &g[slot_b(&in[i])];
        const double Ar = mag(gr->v), Aa = mag(ga->v), Ac = mag(gc->v);
        const double ea = a->e, ec = c->e;
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: {
            const tape_const *kk = &k[in[i].a];
            const double lo = kk->v - kk->lo, hi = kk->hi - kk->v;
            r->e = fin(lo > hi ? lo : hi);
            r->f[0] = r->f[1] = r->f[2] = 0.0;
            break;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z:
            r->e = 0.0; /* the point's coordinates are exact inputs */
            r->f[0] = r->f[1] = r->f[2] = 0.0;
            break;
        case TAPE_NEG: *r = *a; break;
        case TAPE_SQUARE: {
            const double P = ea * (2.0 * Aa + ea);
            r->e = fin(P + U * (Ar + P));
            scaled(r, a, ga, 2.0 * Aa, 2.0 * ea); /* ŝ = 2 â, exact */
            break;
        }
        case TAPE_SQRT: {
            if (!(ga->v.lo > ea))
                return 0;
            const double l = low(ga->v.lo, ea); /* â and a are at least l */
            if (!(l >= SMALL))
                return 0;
            const double sl = sqrt(l) * (1.0 - 0x1p-51); /* r̂ and √a are at least sl */
            const double P = ea / (2.0 * sl);
            r->e = fin(P + U * (Ar + P));
            /* ŝ = fl(0.5 / r̂): |ŝ - 0.5/√a| <= u 0.5/sl + 0.5 |r̂ - √a| / sl² */
            scaled(r, a, ga, 0.5 / sl, fin(0.5 * U / sl + 0.5 * r->e / (sl * sl)));
            break;
        }
        case TAPE_EXP: {
            /* |exp â - exp a| <= exp(a_hi) e^ea ea, e^ea <= 1 + ea (1 + ea) */
            if (!(ea <= 0.0625 && ga->v.hi <= 69.0))
                return 0;
            const double P = gr->v.hi * (1.0 + ea * (1.0 + ea)) * ea;
            r->e = fin(P + LIB * (Ar + P));
            scaled(r, a, ga, Ar, r->e); /* ŝ = r̂ */
            break;
        }
        case TAPE_LOG: {
            if (!(ga->v.lo > ea))
                return 0;
            const double l = low(ga->v.lo, ea);
            if (!(l >= SMALL))
                return 0;
            const double P = ea / l;
            r->e = fin(P + LIB * (Ar + P));
            /* ŝ = fl(1 / â): |ŝ - 1/a| <= u / l + ea / l² */
            scaled(r, a, ga, 1.0 / l, fin(U / l + ea / (l * l)));
            break;
        }
        case TAPE_ABS:
            /* a and â keep one sign over the box: r = ±a exactly */
            if (!(ga->v.lo > ea || -ga->v.hi > ea))
                return 0;
            *r = *a;
            break;
        case TAPE_SIN:
        case TAPE_COS: {
            /* 1-Lipschitz; the scale (cos or -sin of â) within LIB + ea of
             * the exact one, at most 1 */
            if (!(Aa + ea <= TRIG_MAX))
                return 0;
            const double P = ea;
            r->e = fin(P + LIB * (Ar + P));
            scaled(r, a, ga, 1.0, fin(LIB + ea));
            break;
        }
        case TAPE_ADD:
        case TAPE_SUB: {
            const double P = ea + ec;
            r->e = fin(P + U * (Ar + P));
            for (int j = 0; j < 3; j++) {
                const double q = a->f[j] + c->f[j];
                r->f[j] = fin(q + U * (mag(gr->d[j]) + q));
            }
            break;
        }
        case TAPE_MUL: {
            const double ha = Aa + ea, hc = Ac + ec; /* |â|, |ĉ| */
            const double P = ha * ec + Ac * ea;
            r->e = fin(P + U * (Ar + P));
            /* d = fl(fl(â' ĉ) + fl(â ĉ')): three roundings, within 3u of the
             * two products' sizes */
            for (int j = 0; j < 3; j++) {
                const double Ga = mag(ga->d[j]), Gc = mag(gc->d[j]);
                r->f[j] = fin(a->f[j] * hc + Ga * ec + c->f[j] * ha + Gc * ea +
                              3.0 * U * ((Ga + a->f[j]) * hc + (Gc + c->f[j]) * ha));
            }
            break;
        }
        case TAPE_DIV: {
            /* |c| >= lc, |ĉ| >= l; â/ĉ - a/c = (â - a)/ĉ + a (c - ĉ)/(ĉ c) */
            const double lc = gc->v.lo > 0.0 ? gc->v.lo : -gc->v.hi;
            if (!(lc > ec))
                return 0;
            const double l = low(lc, ec);
            if (!(l >= SMALL))
                return 0;
            const double P = ea / l + Aa * ec / (l * lc);
            r->e = fin(P + U * (Ar + P));
            const double hr = Ar + r->e; /* |r̂| */
            /* d = fl(nu / ĉ), nu = fl(â' - q), q = fl(r̂ ĉ'), against
             * r' = n / c, n = a' - r c' (|n| <= N) */
            for (int j = 0; j < 3; j++) {
                const double Ga = mag(ga->d[j]), Gc = mag(gc->d[j]);
                const double N = Ga + Ar * Gc;
                const double e1 = a->f[j] + c->f[j] * hr + Gc * r->e + U * hr * (Gc + c->f[j]);
                const double en = e1 + U * (N + e1);
                r->f[j] = fin(en / l + N * ec / (l * lc) + U * (N + en) / l);
            }
            break;
        }
        case TAPE_MIN:
        case TAPE_MAX: {
            /* one operand below the other over the whole box, by more than
             * their errors: computed and exact take the same one */
            const int a_low = ga->v.hi + ea < gc->v.lo - ec;
            const int c_low = gc->v.hi + ec < ga->v.lo - ea;
            if (!(a_low || c_low))
                return 0;
            *r = (a_low == (in[i].op == TAPE_MIN)) ? *a : *c;
            break;
        }
        case TAPE_TAN:  /* (no a-priori bound: the caller's per-point one) */
        case TAPE_POWC:
        case TAPE_NOPS:
            return 0;
        }
        if (!(Ar <= BIG && r->e <= BIG))
            return 0;
        for (int j = 0; j < 3; j++)
            if (!(r->f[j] <= BIG && mag(gr->d[j]) <= BIG))
                return 0;
    }
    const tape_cerr *r = &s[t->root];
    out->ev = r->e;
    for (int j = 0; j < 3; j++) {
        out->ed[j] = r->f[j];
        out->grad[j] = mag(grad[j]);
    }
    return 1;
}
