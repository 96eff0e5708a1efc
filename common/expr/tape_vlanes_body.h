/* tape_vlanes_body.h: the body of the lane value evaluator (f alone, no
 * gradient), included by tape_lanes_inst.h once per lane count W with FN its
 * name. Each lane performs the operations of tape_eval (the value part of
 * tape_lanes_body.h, the same bits); lanes n..W-1 repeat lane 0. Only the
 * v field of the scratch slots is used. */
#define LANES for (unsigned l = 0; l < W; l++)
#define A (s[in[i].a].v)
#define C (s[in[i].b].v)

static void FN(const tape *t, unsigned n, const double x[L], const double y[L], const double z[L],
               double f[L], tape_dual_lanes *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    trig_memo_lanes tm;
    trig_memo_lanes_init(&tm);
    for (uint32_t i = 0, len = t->n; i < len; i++) {
        double *restrict r = s[i].v;
        uint32_t op = in[i].op;
        switch ((tape_op)op) {
        case TAPE_CONST: {
            double v = k[in[i].a].v;
            LANES r[l] = v;
            break;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            const double *p = op == TAPE_X ? x : op == TAPE_Y ? y : z;
            LANES r[l] = p[l < n ? l : 0];
            break;
        }
        case TAPE_NEG: LANES r[l] = -A[l]; break;
        case TAPE_SQUARE: LANES r[l] = A[l] * A[l]; break;
        case TAPE_SQRT:
            for (unsigned l = 0; l < n; l++)
                r[l] = sqrt(A[l]);
            fill(r, n);
            break;
        case TAPE_EXP:
            for (unsigned l = 0; l < n; l++)
                r[l] = exp(A[l]);
            fill(r, n);
            break;
        case TAPE_LOG:
            for (unsigned l = 0; l < n; l++)
                r[l] = log(A[l]);
            fill(r, n);
            break;
        case TAPE_ABS: LANES r[l] = fabs(A[l]); break;
        case TAPE_SIN:
        case TAPE_COS: {
            /* sincos's bits are sin's and cos's (point_sincos) */
            const unsigned j = trig_memo_lanes_entry(&tm, in[i].a, A, n);
            memcpy(r, op == TAPE_SIN ? tm.s[j] : tm.c[j], n * sizeof r[0]);
            fill(r, n);
            break;
        }
        case TAPE_TAN:
            for (unsigned l = 0; l < n; l++)
                r[l] = tan(A[l]);
            fill(r, n);
            break;
        case TAPE_ADD: LANES r[l] = A[l] + C[l]; break;
        case TAPE_SUB: LANES r[l] = A[l] - C[l]; break;
        case TAPE_MUL: LANES r[l] = A[l] * C[l]; break;
        case TAPE_DIV: LANES r[l] = A[l] / C[l]; break;
        case TAPE_MIN: LANES r[l] = point_min(A[l], C[l]); break;
        case TAPE_MAX: LANES r[l] = point_max(A[l], C[l]); break;
        case TAPE_POWC: {
            double e = k[in[i].b].v;
            for (unsigned l = 0; l < n; l++)
                r[l] = pow(A[l], e);
            fill(r, n);
            break;
        }
        case TAPE_NOPS: LANES r[l] = NAN; break;
        }
    }
    memcpy(f, s[t->root].v, sizeof s[t->root].v);
}

#undef LANES
#undef A
#undef C
