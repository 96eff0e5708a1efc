/* tape_vlanes_body.h: the body of the lane value evaluator (f alone, no
 * gradient), included by tape_lanes_inst.h once per lane count W with FN its
 * name. Each lane performs the operations of tape_eval (the value part of
 * tape_lanes_body.h, the same bits); lanes n..W-1 repeat lane 0. Only the
 * v field of the scratch slots is used. */
#define LANES for (unsigned l = 0; l < W; l++)
#define A (((const tape_dual_lanes *restrict)(s + in[i].a))->v)
#define C (((const tape_dual_lanes *restrict)(s + in[i].b))->v)

static void FN(const tape *t, unsigned n, const double x[L], const double y[L], const double z[L],
               double f[L], tape_dual_lanes *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    trig_memo_lanes tm;
    trig_memo_lanes_init(&tm);
    for (uint32_t i = 0, len = t->n; i < len; i++) {
        /* a restrict pointer to the slot, as in tape_lanes_body.h: GCC
         * vectorizes the lane loops through it, not through a restrict
         * pointer to its doubles (measured: this body's loops were scalar) */
        tape_dual_lanes *restrict r = &s[i];
        uint32_t op = in[i].op;
        switch ((tape_op)op) {
        case TAPE_CONST: {
            double v = k[in[i].a].v;
            LANES r->v[l] = v;
            break;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            const double *p = op == TAPE_X ? x : op == TAPE_Y ? y : z;
            LANES r->v[l] = p[l < n ? l : 0];
            break;
        }
        case TAPE_NEG: LANES r->v[l] = -A[l]; break;
        case TAPE_SQUARE: LANES r->v[l] = A[l] * A[l]; break;
        case TAPE_SQRT:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = sqrt(A[l]);
            fill(r->v, n);
            break;
        case TAPE_EXP:
            LANES r->v[l] = exp_kernel(A[l]); /* lanes from n on: lane 0's */
            break;
        case TAPE_LOG:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = log(A[l]);
            fill(r->v, n);
            break;
        case TAPE_ABS: LANES r->v[l] = fabs(A[l]); break;
        case TAPE_SIN:
        case TAPE_COS: {
            /* sin and cos from one point_sincos, in lanes */
            const unsigned j = trig_memo_lanes_entry(&tm, in[i].a, A, n);
            memcpy(r->v, op == TAPE_SIN ? tm.s[j] : tm.c[j], n * sizeof r->v[0]);
            fill(r->v, n);
            break;
        }
        case TAPE_TAN:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = tan(A[l]);
            fill(r->v, n);
            break;
        case TAPE_ADD: LANES r->v[l] = A[l] + C[l]; break;
        case TAPE_SUB: LANES r->v[l] = A[l] - C[l]; break;
        case TAPE_MUL: LANES r->v[l] = A[l] * C[l]; break;
        case TAPE_DIV: LANES r->v[l] = A[l] / C[l]; break;
        case TAPE_MIN: LANES r->v[l] = point_min(A[l], C[l]); break;
        case TAPE_MAX: LANES r->v[l] = point_max(A[l], C[l]); break;
        case TAPE_POWC: {
            double e = k[in[i].b].v;
            for (unsigned l = 0; l < n; l++)
                r->v[l] = pow(A[l], e);
            fill(r->v, n);
            break;
        }
        case TAPE_NOPS: LANES r->v[l] = NAN; break;
        }
    }
    memcpy(f, s[t->root].v, sizeof s[t->root].v);
}

#undef LANES
#undef A
#undef C
