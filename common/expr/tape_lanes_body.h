/* tape_lanes_body.h: the body of the lane evaluator, included by
 * tape_lanes.c once per lane count W (2, 4, 6 or 8) with FN its name and SCALE
 * its helper, so that every lane loop has a constant trip count and becomes
 * vector code without an epilogue. Lanes n..W-1 repeat lane 0. */
#define LANES for (unsigned l = 0; l < W; l++)
/* The operand slots, formed only where the fields are slots. */
#define A ((const tape_dual_lanes *restrict)(s + in[i].a))
#define C ((const tape_dual_lanes *restrict)(s + in[i].b))

/* The three partials in one lane loop, here and in every operation: one
 * loop's overhead instead of three, the same arithmetic lane by lane. */
static void SCALE(tape_dual_lanes *restrict r, const tape_dual_lanes *restrict a,
                  const double *restrict m)
{
    LANES {
        r->d[0][l] = a->d[0][l] * m[l];
        r->d[1][l] = a->d[1][l] * m[l];
        r->d[2][l] = a->d[2][l] * m[l];
    }
}

static void FN(const tape *t, unsigned n, const double x[L], const double y[L], const double z[L],
               double f[L], double g[3][L], tape_dual_lanes *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    double pt[3][W]; /* the points, lanes from n on repeating lane 0, made once a pass */
    trig_memo_lanes tm;
    trig_memo_lanes_init(&tm);
    LANES {
        pt[0][l] = x[l < n ? l : 0];
        pt[1][l] = y[l < n ? l : 0];
        pt[2][l] = z[l < n ? l : 0];
    }
/* A variable: its coordinate, and the unit vector along its axis (AX, a
 * constant in each case, so the stores are of constants; the zeros
 * opaque_zero's). */
#define AXIS(AX)                                                                                   \
    LANES {                                                                                        \
        r->v[l] = pt[AX][l];                                                                       \
        r->d[0][l] = (AX) == 0 ? 1.0 : zero;                                                       \
        r->d[1][l] = (AX) == 1 ? 1.0 : zero;                                                       \
        r->d[2][l] = (AX) == 2 ? 1.0 : zero;                                                       \
    }
    const double zero = opaque_zero();
    for (uint32_t i = 0, len = t->n; i < len; i++) {
        tape_dual_lanes *restrict r = &s[i];
        uint32_t op = in[i].op;
        double m[L];
        switch ((tape_op)op) {
        case TAPE_CONST: {
            const double v = k[in[i].a].v;
            LANES {
                r->v[l] = v;
                r->d[0][l] = r->d[1][l] = r->d[2][l] = zero;
            }
            break;
        }
        case TAPE_X: AXIS(0); break;
        case TAPE_Y: AXIS(1); break;
        case TAPE_Z: AXIS(2); break;
        case TAPE_NEG:
            LANES { r->v[l] = -A->v[l]; m[l] = -1.0; }
            SCALE(r, A, m);
            break;
        case TAPE_SQUARE:
            LANES { r->v[l] = A->v[l] * A->v[l]; m[l] = 2.0 * A->v[l]; }
            SCALE(r, A, m);
            break;
        case TAPE_SQRT:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = sqrt(A->v[l]);
            fill(r->v, n);
            LANES m[l] = 0.5 / r->v[l];
            SCALE(r, A, m);
            break;
        case TAPE_EXP:
            LANES r->v[l] = exp_kernel(A->v[l]); /* lanes from n on: lane 0's */
            SCALE(r, A, r->v);
            break;
        case TAPE_LOG:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = log(A->v[l]);
            fill(r->v, n);
            LANES m[l] = 1.0 / A->v[l];
            SCALE(r, A, m);
            break;
        case TAPE_ABS:
            LANES { r->v[l] = fabs(A->v[l]); m[l] = A->v[l] < 0.0 ? -1.0 : 1.0; }
            SCALE(r, A, m);
            break;
        case TAPE_SIN:
        case TAPE_COS: {
            const unsigned j = trig_memo_lanes_entry(&tm, in[i].a, A->v, n);
            const double *sv = tm.s[j], *cv = tm.c[j];
            for (unsigned l = 0; l < n; l++) {
                r->v[l] = op == TAPE_SIN ? sv[l] : cv[l];
                m[l] = op == TAPE_SIN ? cv[l] : -sv[l];
            }
            fill(r->v, n);
            fill(m, n);
            SCALE(r, A, m);
            break;
        }
        case TAPE_TAN:
            for (unsigned l = 0; l < n; l++)
                r->v[l] = tan(A->v[l]);
            fill(r->v, n);
            LANES m[l] = 1.0 + r->v[l] * r->v[l];
            SCALE(r, A, m);
            break;
        case TAPE_ADD:
            LANES {
                r->v[l] = A->v[l] + 1.0 * C->v[l];
                r->d[0][l] = A->d[0][l] + 1.0 * C->d[0][l];
                r->d[1][l] = A->d[1][l] + 1.0 * C->d[1][l];
                r->d[2][l] = A->d[2][l] + 1.0 * C->d[2][l];
            }
            break;
        case TAPE_SUB:
            LANES {
                r->v[l] = A->v[l] + -1.0 * C->v[l];
                r->d[0][l] = A->d[0][l] + -1.0 * C->d[0][l];
                r->d[1][l] = A->d[1][l] + -1.0 * C->d[1][l];
                r->d[2][l] = A->d[2][l] + -1.0 * C->d[2][l];
            }
            break;
        case TAPE_MUL:
            LANES {
                r->d[0][l] = A->d[0][l] * C->v[l] + A->v[l] * C->d[0][l];
                r->d[1][l] = A->d[1][l] * C->v[l] + A->v[l] * C->d[1][l];
                r->d[2][l] = A->d[2][l] * C->v[l] + A->v[l] * C->d[2][l];
                r->v[l] = A->v[l] * C->v[l];
            }
            break;
        case TAPE_DIV:
            LANES {
                double v = A->v[l] / C->v[l];
                r->v[l] = v;
                r->d[0][l] = (A->d[0][l] - v * C->d[0][l]) / C->v[l];
                r->d[1][l] = (A->d[1][l] - v * C->d[1][l]) / C->v[l];
                r->d[2][l] = (A->d[2][l] - v * C->d[2][l]) / C->v[l];
            }
            break;
        case TAPE_MIN:
        case TAPE_MAX:
            LANES {
                double v = op == TAPE_MIN ? point_min(A->v[l], C->v[l]) : point_max(A->v[l], C->v[l]);
                const tape_dual_lanes *w = (v == A->v[l] || v != v) ? A : C;
                for (int j = 0; j < 3; j++)
                    r->d[j][l] = w->d[j][l];
                r->v[l] = v;
            }
            break;
        case TAPE_POWC: {
            double e = k[in[i].b].v;
            for (unsigned l = 0; l < n; l++) {
                r->v[l] = pow(A->v[l], e);
                m[l] = e * pow(A->v[l], e - 1.0);
            }
            fill(r->v, n);
            fill(m, n);
            SCALE(r, A, m);
            break;
        }
        case TAPE_NOPS:
            LANES r->v[l] = NAN;
            break;
        }
    }
    const tape_dual_lanes *r = &s[t->root];
    memcpy(f, r->v, sizeof r->v);
    memcpy(g, r->d, sizeof r->d);
}

#undef AXIS
#undef LANES
#undef A
#undef C
