/* tape_iglanes_body.h: the body of the lane interval gradient evaluator,
 * included by tape_iglanes.c (the portable build) and tape_iglanes_avx2.c
 * (the same code compiled for AVX2) once per lane count W (4 or 8), with FN
 * its name.
 *
 * Each lane gives, bit for bit, what tape_eval_interval_grad gives on its
 * box. + - * square neg and exp (il_exp_ends) run a fast path over all
 * lanes: the scalar operations' results where their own fast paths apply
 * (finite operands, normal results, exact zero sums and zero factors),
 * tested on the bit patterns as in tape_ilanes_body.h. A lane
 * where one does not apply is redone by the scalar instruction
 * (tape_idual_op.h), as are all the other operations, lane by lane on
 * lanes 0..n-1. Lanes n..W-1 repeat lane 0. */
#define LANES for (unsigned l = 0; l < W; l++)

#define REDO_FN CAT(FN, _redo)
#define SUM_FN CAT(FN, _sum)
#define PROD_FN CAT(FN, _prod)

/* Instruction i redone by the scalar code on lanes l < n where bad[l]
 * (all lanes: slow), the lanes from n on then taking lane 0's result. */
static void REDO_FN(const tape *t, uint32_t i, const tape_ilanes box[3], tape_idual_lanes *s,
                    const uint64_t *bad, trig_memo *tm, unsigned n, unsigned *fl)
{
    const tape_insn *in = &t->insn[i];
    const tape_idual_lanes *a = s + slot_a(in), *c = s + slot_b(in);
    tape_idual_lanes *r = &s[i];
    for (unsigned l = 0; l < n; l++) {
        if (bad && !bad[l])
            continue;
        tape_idual x = igl_get(a, l), y = igl_get(c, l), v;
        interval b[3] = {il_get(&box[0], l), il_get(&box[1], l), il_get(&box[2], l)};
        interval sv = x.v, cv = x.v;
        if (in->op == TAPE_SIN || in->op == TAPE_COS) {
            unsigned j = trig_memo_entry(&tm[l], in->a, x.v, &fl[l]);
            sv = tm[l].s[j];
            cv = tm[l].c[j];
        }
        idual_op(t, i, b, &x, &y, sv, cv, &v, &fl[l]);
        igl_set(r, l, &v);
    }
    if (!bad || bad[0])
        for (unsigned l = n; l < W; l++) {
            tape_idual v = igl_get(r, 0);
            igl_set(r, l, &v);
            fl[l] = fl[0];
        }
}

/* a + c (c negated for sub) as interval_add's finite path: an end's
 * one-step rounding where the sum is normal, the sum itself where it is an
 * exact zero of opposite operands. g[l] &= whether that held. */
static inline void SUM_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                          const tape_ilanes *restrict c, int sub, uint64_t *g)
{
    LANES {
        double bl = sub ? -c->hi[l] : c->lo[l], bh = sub ? -c->lo[l] : c->hi[l];
        double flo = a->lo[l] + bl, fhi = a->hi[l] + bh;
        uint64_t nlo = il_normal(flo), nhi = il_normal(fhi);
        g[l] &= (nlo | (il_zero(flo) & (uint64_t)(a->lo[l] == -bl))) &
                (nhi | (il_zero(fhi) & (uint64_t)(a->hi[l] == -bh)));
        r->lo[l] = il_sel(nlo, il_step_down(flo), flo);
        r->hi[l] = il_sel(nhi, il_step_up(fhi), fhi);
    }
}

/* a * c as dmul (il_mul, lane by lane). */
static inline void PROD_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                           const tape_ilanes *restrict c, uint64_t *g)
{
    LANES
        il_mul_ends(a->lo[l], a->hi[l], c->lo[l], c->hi[l], &r->lo[l], &r->hi[l], &g[l]);
}

static void FN(const tape *t, unsigned n, const tape_ilanes box[3], unsigned fl[W],
               tape_idual_lanes *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    trig_memo tm[W];
    for (unsigned l = 0; l < W; l++)
        trig_memo_init(&tm[l]);
    for (uint32_t i = 0, len = t->n; i < len; i++) {
        tape_idual_lanes *restrict r = &s[i];
        const tape_idual_lanes *a = s + slot_a(&in[i]), *c = s + slot_b(&in[i]);
        uint64_t g[W], all = 1;
        LANES g[l] = 1;
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: {
            const double lo = k[in[i].a].lo, hi = k[in[i].a].hi, zero = opaque_zero();
            LANES {
                r->v.lo[l] = lo;
                r->v.hi[l] = hi;
                for (int j = 0; j < 3; j++)
                    r->d[j].lo[l] = r->d[j].hi[l] = zero;
            }
            continue;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            int ax = (int)in[i].op - TAPE_X;
            LANES {
                r->v.lo[l] = box[ax].lo[l];
                r->v.hi[l] = box[ax].hi[l];
                for (int j = 0; j < 3; j++)
                    r->d[j].lo[l] = r->d[j].hi[l] = j == ax ? 1.0 : 0.0;
            }
            continue;
        }
        case TAPE_NEG:
            LANES {
                r->v.lo[l] = -a->v.hi[l];
                r->v.hi[l] = -a->v.lo[l];
                for (int j = 0; j < 3; j++) {
                    r->d[j].lo[l] = -a->d[j].hi[l];
                    r->d[j].hi[l] = -a->d[j].lo[l];
                }
            }
            continue;
        case TAPE_ADD:
        case TAPE_SUB: {
            int sub = in[i].op == TAPE_SUB;
            SUM_FN(&r->v, &a->v, &c->v, sub, g);
            if (in[in[i].b].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    r->d[j] = a->d[j];
            } else if (in[in[i].a].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    LANES {
                        r->d[j].lo[l] = sub ? -c->d[j].hi[l] : c->d[j].lo[l];
                        r->d[j].hi[l] = sub ? -c->d[j].lo[l] : c->d[j].hi[l];
                    }
            } else {
                for (int j = 0; j < 3; j++)
                    SUM_FN(&r->d[j], &a->d[j], &c->d[j], sub, g);
            }
            break;
        }
        case TAPE_MUL:
            if (in[in[i].a].op == TAPE_CONST || in[in[i].b].op == TAPE_CONST) {
                int ca = in[in[i].a].op == TAPE_CONST;
                const tape_idual_lanes *v = ca ? c : a; /* the varying factor */
                const tape_ilanes m = ca ? a->v : c->v;
                for (int j = 0; j < 3; j++)
                    PROD_FN(&r->d[j], &v->d[j], &m, g);
                PROD_FN(&r->v, &a->v, &c->v, g);
            } else {
                tape_ilanes p, q;
                for (int j = 0; j < 3; j++) {
                    PROD_FN(&p, &a->d[j], &c->v, g);
                    PROD_FN(&q, &a->v, &c->d[j], g);
                    SUM_FN(&r->d[j], &p, &q, 0, g);
                }
                PROD_FN(&r->v, &a->v, &c->v, g);
            }
            break;
        case TAPE_SQUARE: {
            tape_ilanes two, m;
            LANES {
                two.lo[l] = two.hi[l] = 2.0;
                il_sqr_ends(a->v.lo[l], a->v.hi[l], &r->v.lo[l], &r->v.hi[l], &g[l]);
            }
            PROD_FN(&m, &two, &a->v, g);
            for (int j = 0; j < 3; j++)
                PROD_FN(&r->d[j], &a->d[j], &m, g);
            break;
        }
        case TAPE_EXP: {
            tape_ilanes v;
            uint64_t ok = ~(uint64_t)0, bad[W];
            LANES {
                uint64_t e = il_exp_ends(a->v.lo[l], a->v.hi[l], &v.lo[l], &v.hi[l]);
                bad[l] = e ^ 1;
                ok &= e;
            }
            if (!ok)
                LANES
                    if (bad[l])
                        il_set(&v, l, interval_exp(il_get(&a->v, l), &fl[l]));
            for (int j = 0; j < 3; j++)
                PROD_FN(&r->d[j], &a->d[j], &v, g);
            r->v = v;
            break;
        }
        default:
            REDO_FN(t, i, box, s, NULL, tm, n, fl);
            continue;
        }
        LANES all &= g[l];
        if (!all) {
            uint64_t bad[W];
            LANES bad[l] = g[l] ^ 1;
            REDO_FN(t, i, box, s, bad, tm, n, fl);
        }
    }
}

#undef LANES
#undef REDO_FN
#undef SUM_FN
#undef PROD_FN
