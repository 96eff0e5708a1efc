/* tape_dir_body.h: forward-mode AD in double with N tangents, the rules of
 * tape_eval_grad (abs, min, max: the branch taken), included by
 * tape_eval_dir.c once per N with FN its name, SLOT its slot type (v,
 * d[N]) and LEAF(slot, v, d) the store of a leaf's whole slot. seed[k] is
 * the tangent of coordinate k; every tangent follows the same operations,
 * so one tangent seeded with a direction is, bit for bit, the same whatever
 * the others are. */
#define OP TAPE_OPL
#define TANGENTS for (unsigned j = 0; j < N; j++)

static inline double FN(const tape *t, const double p[3], const double seed[3][N], SLOT *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    static const double zero[N] = {0.0};
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        SLOT *r = &s[i];
        /* operands: only the ops that have them name them (as tape_eval) */
#define OA s[in[i].a]
#define OC s[in[i].b]
        TAPE_DISPATCH(in[i].op) {
        OP(CONST): LEAF(r, k[in[i].a].v, zero); continue;
        OP(X): OP(Y): OP(Z): {
            const uint32_t ax = in[i].op - TAPE_X;
            LEAF(r, p[ax], seed[ax]);
            continue;
        }
        OP(NEG): r->v = -OA.v; TANGENTS r->d[j] = -OA.d[j]; continue;
        OP(SQUARE): {
            const double a = OA.v, m = 2.0 * a;
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = a * a;
            continue;
        }
        OP(SQRT): {
            const double v = sqrt(OA.v), m = 0.5 / v;
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = v;
            continue;
        }
        OP(EXP): {
            const double v = exp_kernel(OA.v);
            TANGENTS r->d[j] = OA.d[j] * v;
            r->v = v;
            continue;
        }
        OP(LOG): {
            const double a = OA.v, m = 1.0 / a;
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = log(a);
            continue;
        }
        OP(ABS): {
            const double a = OA.v;
            if (a < 0.0)
                TANGENTS r->d[j] = -OA.d[j];
            else
                TANGENTS r->d[j] = OA.d[j];
            r->v = fabs(a);
            continue;
        }
        OP(SIN): {
            double sv, cv;
            point_sincos(OA.v, &sv, &cv);
            TANGENTS r->d[j] = OA.d[j] * cv;
            r->v = sv;
            continue;
        }
        OP(COS): {
            double sv, cv;
            point_sincos(OA.v, &sv, &cv);
            const double m = -sv;
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = cv;
            continue;
        }
        OP(TAN): {
            const double v = tan(OA.v), m = 1.0 + v * v;
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = v;
            continue;
        }
        OP(ADD): {
            const double v = OA.v + OC.v;
            TANGENTS r->d[j] = OA.d[j] + OC.d[j];
            r->v = v;
            continue;
        }
        OP(SUB): {
            const double v = OA.v - OC.v;
            TANGENTS r->d[j] = OA.d[j] - OC.d[j];
            r->v = v;
            continue;
        }
        OP(MUL): {
            const double a = OA.v, c = OC.v;
            TANGENTS r->d[j] = OA.d[j] * c + a * OC.d[j];
            r->v = a * c;
            continue;
        }
        OP(DIV): {
            const double c = OC.v, v = OA.v / c;
            TANGENTS r->d[j] = (OA.d[j] - v * OC.d[j]) / c;
            r->v = v;
            continue;
        }
        OP(MIN):
        OP(MAX): {
            const double a = OA.v;
            const double v = in[i].op == TAPE_MIN ? point_min(a, OC.v) : point_max(a, OC.v);
            const SLOT *w = (v == a || v != v) ? &OA : &OC;
            TANGENTS r->d[j] = w->d[j];
            r->v = v;
            continue;
        }
        OP(POWC): {
            const double e = k[in[i].b].v, a = OA.v;
            const double m = e * pow(a, e - 1.0);
            TANGENTS r->d[j] = OA.d[j] * m;
            r->v = pow(a, e);
            continue;
        }
        OP(NOPS): r->v = NAN; TANGENTS r->d[j] = NAN; continue;
        TAPE_DISPATCH_DEFAULT();
        }
#undef OA
#undef OC
    }
    return s[t->root].v;
}

#undef TANGENTS
#undef OP
