/* tape_eval: the point evaluators, f and f with its gradient (forward-mode
 * dual numbers), in double. The lane version of the gradient evaluator is
 * tape_lanes.c. */
#include "common/expr/tape.h"

#include <math.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/tape_int.h"

#define A s[in[i].a]
#define C s[in[i].b]

double tape_eval(const tape *t, double x, double y, double z, double *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: s[i] = k[in[i].a].v; break;
        case TAPE_X: s[i] = x; break;
        case TAPE_Y: s[i] = y; break;
        case TAPE_Z: s[i] = z; break;
        case TAPE_NEG: s[i] = -A; break;
        case TAPE_SQUARE: s[i] = A * A; break;
        case TAPE_SQRT: s[i] = sqrt(A); break;
        case TAPE_EXP: s[i] = exp_kernel(A); break;
        case TAPE_LOG: s[i] = log(A); break;
        case TAPE_ABS: s[i] = fabs(A); break;
        case TAPE_SIN: { double c; point_sincos(A, &s[i], &c); break; }
        case TAPE_COS: { double sv; point_sincos(A, &sv, &s[i]); break; }
        case TAPE_TAN: s[i] = tan(A); break;
        case TAPE_ADD: s[i] = A + C; break;
        case TAPE_SUB: s[i] = A - C; break;
        case TAPE_MUL: s[i] = A * C; break;
        case TAPE_DIV: s[i] = A / C; break;
        case TAPE_MIN: s[i] = point_min(A, C); break;
        case TAPE_MAX: s[i] = point_max(A, C); break;
        case TAPE_POWC: s[i] = pow(A, k[in[i].b].v); break;
        case TAPE_NOPS: s[i] = NAN; break;
        }
    }
    return s[t->root];
}

/* r = a * scale, on the three partials. */
static void dscale(tape_dual *r, const tape_dual *a, double v, double scale)
{
    r->v = v;
    for (int j = 0; j < 3; j++)
        r->d[j] = a->d[j] * scale;
}

double tape_eval_grad(const tape *t, const double p[3], double grad[3], tape_dual *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_dual *r = &s[i];
        const tape_dual *a = s + slot_a(&in[i]), *c = s + slot_b(&in[i]);
        switch ((tape_op)in[i].op) {
        case TAPE_CONST:
            r->v = k[in[i].a].v;
            r->d[0] = r->d[1] = r->d[2] = 0.0;
            break;
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            int ax = (int)in[i].op - TAPE_X;
            r->v = p[ax];
            r->d[0] = r->d[1] = r->d[2] = 0.0;
            r->d[ax] = 1.0;
            break;
        }
        case TAPE_NEG: dscale(r, a, -a->v, -1.0); break;
        case TAPE_SQUARE: dscale(r, a, a->v * a->v, 2.0 * a->v); break;
        case TAPE_SQRT: { double v = sqrt(a->v); dscale(r, a, v, 0.5 / v); break; }
        case TAPE_EXP: { double v = exp_kernel(a->v); dscale(r, a, v, v); break; }
        case TAPE_LOG: dscale(r, a, log(a->v), 1.0 / a->v); break;
        case TAPE_ABS: dscale(r, a, fabs(a->v), a->v < 0.0 ? -1.0 : 1.0); break;
        case TAPE_SIN: { double sv, cv; point_sincos(a->v, &sv, &cv); dscale(r, a, sv, cv); break; }
        case TAPE_COS: { double sv, cv; point_sincos(a->v, &sv, &cv); dscale(r, a, cv, -sv); break; }
        case TAPE_TAN: { double v = tan(a->v); dscale(r, a, v, 1.0 + v * v); break; }
        case TAPE_ADD:
        case TAPE_SUB: {
            double sg = in[i].op == TAPE_ADD ? 1.0 : -1.0;
            double v = a->v + sg * c->v;
            for (int j = 0; j < 3; j++)
                r->d[j] = a->d[j] + sg * c->d[j];
            r->v = v;
            break;
        }
        case TAPE_MUL: {
            double v = a->v * c->v;
            for (int j = 0; j < 3; j++)
                r->d[j] = a->d[j] * c->v + a->v * c->d[j];
            r->v = v;
            break;
        }
        case TAPE_DIV: {
            double v = a->v / c->v;
            for (int j = 0; j < 3; j++)
                r->d[j] = (a->d[j] - v * c->d[j]) / c->v;
            r->v = v;
            break;
        }
        case TAPE_MIN:
        case TAPE_MAX: {
            double v = in[i].op == TAPE_MIN ? point_min(a->v, c->v) : point_max(a->v, c->v);
            const tape_dual *w = (v == a->v || v != v) ? a : c;
            *r = *w;
            r->v = v;
            break;
        }
        case TAPE_POWC: {
            double e = k[in[i].b].v;
            double v = pow(a->v, e);
            dscale(r, a, v, e * pow(a->v, e - 1.0));
            break;
        }
        case TAPE_NOPS: r->v = NAN; break;
        }
    }
    const tape_dual *r = &s[t->root];
    grad[0] = r->d[0];
    grad[1] = r->d[1];
    grad[2] = r->d[2];
    return r->v;
}
