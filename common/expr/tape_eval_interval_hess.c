/* tape_eval_interval_hess: value, gradient and Hessian enclosures over a
 * box by second-order forward mode in interval arithmetic (tape_hess.h).
 * A unary phi(a) takes phi' and phi'' enclosures over a's value:
 *   g_i = phi' a.g_i,   h_ij = phi'' a.g_i a.g_j + phi' a.h_ij;
 * a product: h_ij = a.h_ij c.v + a.g_i c.g_j + a.g_j c.g_i + a.v c.h_ij;
 * a quotient is a times the reciprocal of c (phi' = -1/c^2, phi'' = 2/c^3). */
#include "common/expr/tape_hess.h"

#include "common/expr/tape_int.h"

static const int hrow[TAPE_HN] = {0, 0, 0, 1, 1, 2}, hcol[TAPE_HN] = {0, 1, 2, 1, 2, 2};

static interval ipt(double x) { interval r = {x, x}; return r; }
static int is_zero(interval a) { return a.lo == 0.0 && a.hi == 0.0; }
static int is_finite(interval a) { return isfinite(a.lo) && isfinite(a.hi); } /* quiet */

/* interval_mul with [0, 0] times a finite interval kept [0, 0] (no
 * rounding): most derivative entries are zero. */
INTERVAL_INLINE interval zmul(interval a, interval b, unsigned *f)
{
    if ((is_zero(a) && is_finite(b)) || (is_zero(b) && is_finite(a)))
        return ipt(0.0);
    return interval_mul(a, b, f);
}

INTERVAL_INLINE interval zadd(interval a, interval b, unsigned *f)
{
    if (is_zero(a))
        return b;
    if (is_zero(b))
        return a;
    return interval_add(a, b, f);
}

/* r = phi(a) with r.v = v and the enclosures d1 of phi', d2 of phi''. */
INTERVAL_INLINE void chain(tape_ihess *r, const tape_ihess *a, interval v, interval d1, interval d2,
                  unsigned *f)
{
    tape_ihess o;
    o.v = v;
    for (int j = 0; j < 3; j++)
        o.g[j] = zmul(d1, a->g[j], f);
    for (int e = 0; e < TAPE_HN; e++) {
        const interval gg = zmul(a->g[hrow[e]], a->g[hcol[e]], f);
        o.h[e] = zadd(zmul(d2, gg, f), zmul(d1, a->h[e], f), f);
    }
    *r = o;
}

INTERVAL_INLINE void mul(tape_ihess *r, const tape_ihess *a, const tape_ihess *c, interval v, unsigned *f)
{
    tape_ihess o;
    o.v = v;
    for (int j = 0; j < 3; j++)
        o.g[j] = zadd(zmul(a->g[j], c->v, f), zmul(a->v, c->g[j], f), f);
    for (int e = 0; e < TAPE_HN; e++) {
        const int i = hrow[e], j = hcol[e];
        interval s = zadd(zmul(a->h[e], c->v, f), zmul(a->v, c->h[e], f), f);
        s = zadd(s, zmul(a->g[i], c->g[j], f), f);
        o.h[e] = zadd(s, zmul(a->g[j], c->g[i], f), f);
    }
    *r = o;
}

INTERVAL_INLINE void addsub(tape_ihess *r, const tape_ihess *a, const tape_ihess *c, int sub, unsigned *f)
{
    tape_ihess o;
    o.v = sub ? interval_sub(a->v, c->v, f) : interval_add(a->v, c->v, f);
    for (int j = 0; j < 3; j++)
        o.g[j] = zadd(a->g[j], sub ? interval_neg(c->g[j]) : c->g[j], f);
    for (int e = 0; e < TAPE_HN; e++)
        o.h[e] = zadd(a->h[e], sub ? interval_neg(c->h[e]) : c->h[e], f);
    *r = o;
}

static void leaf(tape_ihess *r, interval v, int axis)
{
    r->v = v;
    for (int j = 0; j < 3; j++)
        r->g[j] = ipt(j == axis ? 1.0 : 0.0);
    for (int e = 0; e < TAPE_HN; e++)
        r->h[e] = ipt(0.0);
}

interval tape_eval_interval_hess(const tape *t, const interval box[3], interval grad[3],
                                 interval hess[TAPE_HN], tape_ihess *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_ihess *r = &s[i];
        const tape_ihess *a = s + slot_a(&in[i]), *c = s + slot_b(&in[i]);
        const interval av = a->v;
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: leaf(r, (interval){k[in[i].a].lo, k[in[i].a].hi}, -1); break;
        case TAPE_X: case TAPE_Y: case TAPE_Z:
            leaf(r, box[in[i].op - TAPE_X], (int)in[i].op - TAPE_X);
            break;
        case TAPE_NEG: chain(r, a, interval_neg(av), ipt(-1.0), ipt(0.0), &f); break;
        case TAPE_SQUARE:
            chain(r, a, interval_sqr(av, &f), interval_mul(ipt(2.0), av, &f), ipt(2.0), &f);
            break;
        case TAPE_SQRT: {
            const interval v = interval_sqrt(av, &f);
            const interval d1 = interval_div(ipt(0.5), v, &f);
            /* phi'' = -1 / (4 a sqrt(a)) = -d1 / (2 a) */
            const interval d2 = interval_neg(interval_div(d1, interval_mul(ipt(2.0), av, &f), &f));
            chain(r, a, v, d1, d2, &f);
            break;
        }
        case TAPE_EXP: { const interval v = interval_exp(av, &f); chain(r, a, v, v, v, &f); break; }
        case TAPE_LOG: {
            const interval d1 = interval_div(ipt(1.0), av, &f);
            chain(r, a, interval_log(av, &f), d1, interval_neg(interval_sqr(d1, &f)), &f);
            break;
        }
        case TAPE_ABS:
            if (av.lo >= 0.0 || av.hi <= 0.0) {
                const double sg = av.lo >= 0.0 ? 1.0 : -1.0; /* (a holding only 0: either) */
                chain(r, a, interval_abs(av), ipt(sg), ipt(0.0), &f);
            } else {
                f |= TAPE_HESS_KINK;
                chain(r, a, interval_abs(av), (interval){-1.0, 1.0}, ipt(0.0), &f);
            }
            break;
        case TAPE_SIN: {
            const interval sv = interval_sin(av, &f);
            chain(r, a, sv, interval_cos(av, &f), interval_neg(sv), &f);
            break;
        }
        case TAPE_COS: {
            const interval cv = interval_cos(av, &f);
            chain(r, a, cv, interval_neg(interval_sin(av, &f)), interval_neg(cv), &f);
            break;
        }
        case TAPE_TAN: {
            const interval v = interval_tan(av, &f);
            const interval d1 = interval_add(ipt(1.0), interval_sqr(v, &f), &f);
            chain(r, a, v, d1, interval_mul(interval_mul(ipt(2.0), v, &f), d1, &f), &f);
            break;
        }
        case TAPE_ADD: addsub(r, a, c, 0, &f); break;
        case TAPE_SUB: addsub(r, a, c, 1, &f); break;
        case TAPE_MUL: mul(r, a, c, interval_mul(av, c->v, &f), &f); break;
        case TAPE_DIV: {
            const interval q = interval_div(ipt(1.0), c->v, &f);
            const interval q2 = interval_sqr(q, &f);
            tape_ihess rc;
            chain(&rc, c, q, interval_neg(q2),
                  interval_mul(ipt(2.0), interval_mul(q2, q, &f), &f), &f);
            mul(r, a, &rc, interval_div(av, c->v, &f), &f);
            break;
        }
        case TAPE_MIN:
        case TAPE_MAX: {
            const int is_min = in[i].op == TAPE_MIN;
            const tape_ihess *w = NULL;
            if (av.hi < c->v.lo)
                w = is_min ? a : c;
            else if (c->v.hi < av.lo)
                w = is_min ? c : a;
            if (w) {
                *r = *w;
            } else {
                f |= TAPE_HESS_KINK;
                r->v = is_min ? interval_min(av, c->v) : interval_max(av, c->v);
                for (int j = 0; j < 3; j++)
                    r->g[j] = interval_hull(a->g[j], c->g[j]);
                for (int e = 0; e < TAPE_HN; e++)
                    r->h[e] = interval_hull(a->h[e], c->h[e]);
            }
            break;
        }
        case TAPE_POWC: {
            const double e = k[in[i].b].v;
            const interval v = interval_powc(av, e, &f);
            const interval d1 = interval_mul(ipt(e), interval_powc(av, e - 1.0, &f), &f);
            /* e (e - 1) is exact enough for an enclosure only when rounded out */
            const interval ee = interval_mul(ipt(e), interval_sub(ipt(e), ipt(1.0), &f), &f);
            chain(r, a, v, d1, interval_mul(ee, interval_powc(av, e - 2.0, &f), &f), &f);
            break;
        }
        case TAPE_NOPS:
            leaf(r, interval_nan(), -1);
            f |= INTERVAL_MAYBE_NAN;
            break;
        }
    }
    *flags = f;
    const tape_ihess *r = &s[t->root];
    for (int j = 0; j < 3; j++)
        grad[j] = r->g[j];
    for (int e = 0; e < TAPE_HN; e++)
        hess[e] = r->h[e];
    return r->v;
}

/* Magnitudes of finite entries into mag (1), else +inf everywhere (0). */
static int magnitudes(const interval h[TAPE_HN], int ok, double mag[TAPE_HN])
{
    for (int e = 0; ok && e < TAPE_HN; e++) {
        ok = is_finite(h[e]);
        mag[e] = ok ? fmax(fabs(h[e].lo), fabs(h[e].hi)) : INFINITY;
    }
    if (!ok)
        for (int e = 0; e < TAPE_HN; e++)
            mag[e] = INFINITY;
    return ok;
}

int tape_hess_mag(const tape *t, const interval box[3], tape_ihess *slots, double mag[TAPE_HN])
{
    interval g[3], h[TAPE_HN];
    unsigned flags = 0;
    tape_eval_interval_hess(t, box, g, h, slots, &flags);
    return magnitudes(h, flags == 0, mag);
}

void tape_hess_mags(const tape *t, const interval box[3], tape_ihess *slots, double mag[TAPE_HN],
                    double branch[TAPE_HN])
{
    interval g[3], h[TAPE_HN];
    unsigned flags = 0;
    tape_eval_interval_hess(t, box, g, h, slots, &flags);
    magnitudes(h, flags == 0, mag);
    magnitudes(h, (flags & ~(unsigned)TAPE_HESS_KINK) == 0, branch);
}

unsigned tape_hess_kinks(const tape *t, const interval box[3], interval *slots)
{
    unsigned flags = 0, kinks = 0;
    tape_eval_interval(t, box, slots, &flags);
    if (flags)
        kinks |= TAPE_KINK_FLAG;
    for (uint32_t i = 0; i < t->n; i++) {
        const tape_insn *in = &t->insn[i];
        if (in->op == TAPE_ABS) {
            const interval a = slots[in->a];
            if (!(a.lo >= 0.0 || a.hi <= 0.0))
                kinks |= TAPE_KINK_ABS;
        } else if (in->op == TAPE_MIN || in->op == TAPE_MAX) {
            const interval a = slots[in->a], c = slots[in->b];
            if (!(a.hi < c.lo || c.hi < a.lo))
                kinks |= TAPE_KINK_MINMAX;
        }
    }
    return kinks;
}
