/* tape_ilanes_body.h: the body of the lane interval evaluator, included by
 * tape_ilanes.c (the portable build) and tape_ilanes_avx2.c (the same code
 * compiled for AVX2) once per lane count W (4 or 8), with FN its name.
 *
 * Each lane gives, bit for bit, what tape_eval_interval gives on its box.
 * The cheap operations (+ - * square abs min max neg) and exp run a fast path over
 * all lanes at once: the result of the scalar operation's own fast path,
 * taken where that path applies (finite operands, results normal numbers),
 * with the tests made on the bit patterns (integer tests raise no
 * floating-point exception, and vectorise). A lane where it does not apply
 * is done again by the scalar operation. The libm operations run the scalar
 * operation lane by lane. Lanes n..W-1 repeat lane 0: every lane is
 * computed, so none holds a value lane 0 would not. */
#define LANES for (unsigned l = 0; l < W; l++)
#define A ((const tape_ilanes *restrict)(s + in[i].a))
#define C ((const tape_ilanes *restrict)(s + in[i].b))

#define ADD_FN CAT(FN, _add)
#define MUL_FN CAT(FN, _mul)
#define SQR_FN CAT(FN, _sqr)
#define ABS_FN CAT(FN, _abs)
#define MINMAX_FN CAT(FN, _minmax)
#define EXP_FN CAT(FN, _exp)
#define LIBM_FN CAT(FN, _libm)
#define TRIG_FN CAT(FN, _trig)
#define TRIG_MEMO_T CAT(FN, _trig_memo)

/* a + c, or a - c (sub), as interval_add and interval_sub. */
static void ADD_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                   const tape_ilanes *restrict c, int sub, unsigned *fl)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        double bl = sub ? -c->hi[l] : c->lo[l], bh = sub ? -c->lo[l] : c->hi[l];
        double flo = a->lo[l] + bl, fhi = a->hi[l] + bh;
        uint64_t g = il_normal(flo) & il_normal(fhi);
        bad[l] = g ^ 1;
        ok &= g;
        r->lo[l] = il_step_down(flo);
        r->hi[l] = il_step_up(fhi);
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, sub ? interval_sub(il_get(a, l), il_get(c, l), &fl[l])
                             : interval_add(il_get(a, l), il_get(c, l), &fl[l]));
}

/* a * c, as interval_mul. */
static void MUL_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                   const tape_ilanes *restrict c, unsigned *fl)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        uint64_t f = il_finite(a->lo[l]) & il_finite(a->hi[l]) & il_finite(c->lo[l]) &
                     il_finite(c->hi[l]);
        double al = il_sel(f, a->lo[l], 1.0), ah = il_sel(f, a->hi[l], 1.0);
        double cl = il_sel(f, c->lo[l], 1.0), ch = il_sel(f, c->hi[l], 1.0);
        double p1 = al * cl, p2 = al * ch, p3 = ah * cl, p4 = ah * ch;
        double lo = il_min(il_min(p1, p2), il_min(p3, p4));
        double hi = il_max(il_max(p1, p2), il_max(p3, p4));
        uint64_t g = f & il_normal(lo) & il_normal(hi);
        bad[l] = g ^ 1;
        ok &= g;
        r->lo[l] = il_step_down(lo);
        r->hi[l] = il_step_up(hi);
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, interval_mul(il_get(a, l), il_get(c, l), &fl[l]));
}

/* a * a, as interval_sqr. */
static void SQR_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a, unsigned *fl)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        uint64_t g = 1;
        il_sqr_ends(a->lo[l], a->hi[l], &r->lo[l], &r->hi[l], &g);
        bad[l] = g ^ 1;
        ok &= g;
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, interval_sqr(il_get(a, l), &fl[l]));
}

/* |a|, as interval_abs. */
static void ABS_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        uint64_t f = il_finite(a->lo[l]) & il_finite(a->hi[l]);
        double x = il_sel(f, a->lo[l], 0.0), y = il_sel(f, a->hi[l], 0.0);
        uint64_t pos = x >= 0.0, neg = y <= 0.0;
        r->lo[l] = il_sel(pos, x, il_sel(neg, -y, 0.0));
        r->hi[l] = il_sel(pos, y, il_sel(neg, -x, il_max(-x, y)));
        bad[l] = f ^ 1;
        ok &= f;
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, interval_abs(il_get(a, l)));
}

/* min(a, c) or max(a, c), as interval_min and interval_max. */
static void MINMAX_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                      const tape_ilanes *restrict c, int is_min)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        uint64_t f = il_finite(a->lo[l]) & il_finite(a->hi[l]) & il_finite(c->lo[l]) &
                     il_finite(c->hi[l]);
        double al = il_sel(f, a->lo[l], 0.0), ah = il_sel(f, a->hi[l], 0.0);
        double cl = il_sel(f, c->lo[l], 0.0), ch = il_sel(f, c->hi[l], 0.0);
        r->lo[l] = is_min ? il_min(al, cl) : il_max(al, cl);
        r->hi[l] = is_min ? il_min(ah, ch) : il_max(ah, ch);
        bad[l] = f ^ 1;
        ok &= f;
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, is_min ? interval_min(il_get(a, l), il_get(c, l))
                                : interval_max(il_get(a, l), il_get(c, l)));
}

/* exp(a), as interval_exp. */
static void EXP_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a, unsigned *fl)
{
    uint64_t ok = ~(uint64_t)0, bad[W];
    LANES {
        uint64_t g = il_exp_ends(a->lo[l], a->hi[l], &r->lo[l], &r->hi[l]);
        bad[l] = g ^ 1;
        ok &= g;
    }
    if (ok)
        return;
    LANES
        if (bad[l])
            il_set(r, l, interval_exp(il_get(a, l), &fl[l]));
}

/* The operations of interval.c, one lane at a time on lanes 0..n-1; the
 * others take lane 0's result. */
static void LIBM_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a,
                    const tape_ilanes *restrict c, uint32_t op, double e, unsigned n, unsigned *fl)
{
    for (unsigned l = 0; l < n; l++) {
        interval x = il_get(a, l), v;
        switch ((tape_op)op) {
        case TAPE_SQRT: v = interval_sqrt(x, &fl[l]); break;
        case TAPE_EXP: v = interval_exp(x, &fl[l]); break;
        case TAPE_LOG: v = interval_log(x, &fl[l]); break;
        case TAPE_TAN: v = interval_tan(x, &fl[l]); break;
        case TAPE_DIV: v = interval_div(x, il_get(c, l), &fl[l]); break;
        case TAPE_POWC: v = interval_powc(x, e, &fl[l]); break;
        default: v = interval_nan(); fl[l] |= INTERVAL_MAYBE_NAN; break;
        }
        il_set(r, l, v);
    }
    for (unsigned l = n; l < W; l++) {
        r->lo[l] = r->lo[0];
        r->hi[l] = r->hi[0];
        fl[l] = fl[0];
    }
}

/* sin or cos of slot a, lane by lane as LIBM_FN, through a memo of the last
 * TRIG_MEMO arguments' sin and cos (tape_int.h's trig_memo, in lanes). */
typedef struct TRIG_MEMO_T {
    trig_memo_keys k;
    tape_ilanes s[TRIG_MEMO], c[TRIG_MEMO];
} TRIG_MEMO_T;

static void TRIG_FN(tape_ilanes *restrict r, const tape_ilanes *restrict a, uint32_t slot,
                    int is_cos, TRIG_MEMO_T *m, unsigned n, unsigned *fl)
{
    int miss;
    const unsigned j = trig_memo_find(&m->k, slot, &miss);
    if (miss) {
        /* interval_sincos in lanes: the narrow lanes' midpoints' sin and
         * cos (all lanes at once), then their forms; a lane whose
         * argument has an earlier lane's bits (a cell's children share
         * each coordinate in halves) takes that lane's results and flags. */
        double mid[W] = {0}, sm[W], cm[W];
        unsigned narrow = 0, same[W], lf[W];
        for (unsigned l = 0; l < n; l++) {
            same[l] = il_first_same(a, l);
            lf[l] = 0;
            if (same[l] < l)
                continue;
            interval x = il_get(a, l);
            if (interval__sincos_narrow(x)) {
                narrow |= 1u << l;
                mid[l] = interval__sincos_mid(x);
            } else {
                interval sv, cv;
                interval_sincos(x, &sv, &cv, &lf[l]);
                fl[l] |= lf[l];
                il_set(&m->s[j], l, sv);
                il_set(&m->c[j], l, cv);
            }
        }
        if (narrow)
            sincos_point_lanes(W, W, mid, sm, cm); /* every lane: vector code */
        for (unsigned l = 0; l < n; l++)
            if (narrow >> l & 1) {
                interval x = il_get(a, l);
                double h = interval__sincos_half(x, mid[l]), q = 0.5 * h * h;
                il_set(&m->s[j], l, interval__sincos_form(sm[l], cm[l], h, q));
                il_set(&m->c[j], l, interval__sincos_form(cm[l], sm[l], h, q));
            }
        for (unsigned l = 0; l < n; l++)
            if (same[l] < l) {
                const unsigned e = same[l];
                il_set(&m->s[j], l, il_get(&m->s[j], e));
                il_set(&m->c[j], l, il_get(&m->c[j], e));
                fl[l] |= lf[e];
            }
        for (unsigned l = n; l < W; l++) {
            m->s[j].lo[l] = m->s[j].lo[0];
            m->s[j].hi[l] = m->s[j].hi[0];
            m->c[j].lo[l] = m->c[j].lo[0];
            m->c[j].hi[l] = m->c[j].hi[0];
            fl[l] = fl[0];
        }
    }
    *r = is_cos ? m->c[j] : m->s[j];
}

static void FN(const tape *t, unsigned n, const tape_ilanes box[3], unsigned fl[W],
               tape_ilanes *s)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    TRIG_MEMO_T tm; /* entries are written before they are read */
    trig_memo_keys_init(&tm.k);
    for (uint32_t i = 0, len = t->n; i < len; i++) {
        tape_ilanes *restrict r = &s[i];
        uint32_t op = in[i].op;
        switch ((tape_op)op) {
        case TAPE_CONST: {
            double lo = k[in[i].a].lo, hi = k[in[i].a].hi;
            LANES {
                r->lo[l] = lo;
                r->hi[l] = hi;
            }
            break;
        }
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            const tape_ilanes *b = &box[op - TAPE_X];
            LANES {
                r->lo[l] = b->lo[l];
                r->hi[l] = b->hi[l];
            }
            break;
        }
        case TAPE_NEG:
            LANES {
                r->lo[l] = -A->hi[l];
                r->hi[l] = -A->lo[l];
            }
            break;
        case TAPE_SQUARE: SQR_FN(r, A, fl); break;
        case TAPE_ABS: ABS_FN(r, A); break;
        case TAPE_EXP: EXP_FN(r, A, fl); break;
        case TAPE_ADD: ADD_FN(r, A, C, 0, fl); break;
        case TAPE_SUB: ADD_FN(r, A, C, 1, fl); break;
        case TAPE_MUL: MUL_FN(r, A, C, fl); break;
        case TAPE_MIN: MINMAX_FN(r, A, C, 1); break;
        case TAPE_MAX: MINMAX_FN(r, A, C, 0); break;
        case TAPE_SIN: TRIG_FN(r, A, in[i].a, 0, &tm, n, fl); break;
        case TAPE_COS: TRIG_FN(r, A, in[i].a, 1, &tm, n, fl); break;
        case TAPE_DIV: LIBM_FN(r, A, C, op, 0.0, n, fl); break;
        case TAPE_POWC: LIBM_FN(r, A, A, op, k[in[i].b].v, n, fl); break;
        case TAPE_NOPS: LIBM_FN(r, s, s, op, 0.0, n, fl); break;
        default: LIBM_FN(r, A, A, op, 0.0, n, fl); break;
        }
    }
}

#undef LANES
#undef A
#undef C
#undef ADD_FN
#undef MUL_FN
#undef SQR_FN
#undef ABS_FN
#undef MINMAX_FN
#undef EXP_FN
#undef LIBM_FN
#undef TRIG_FN
#undef TRIG_MEMO_T
