/* tape_build: the tape builder (hash-consing, constant folding, integer
 * powers), finishing a tape and freeing it. */
#include "common/expr/tape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/tape_int.h"

struct tape_builder {
    tape_insn *insn;
    uint32_t n, cap;
    tape_const *konst;
    uint32_t nconst, kcap;
    uint32_t *hash; /* open addressing over insn indices; UINT32_MAX = empty */
    uint32_t hcap;
    uint32_t nreq; /* emit calls, for tape.ntree */
};

#define EMPTY UINT32_MAX

const char *tape_strerror(int err)
{
    switch (err) {
    case TAPE_OK: return "ok";
    case TAPE_ENOMEM: return "out of memory";
    case TAPE_ETOOBIG: return "expression too large";
    case TAPE_EDOMAIN: return "constant expression is undefined or not finite";
    case TAPE_EEXPONENT: return "integer exponent too large";
    }
    return "unknown error";
}

const char *tape_op_name(tape_op op)
{
    static const char *names[TAPE_NOPS] = {
        "const", "x", "y", "z", "neg", "square", "sqrt", "exp", "log", "abs", "sin", "cos",
        "tan", "add", "sub", "mul", "div", "min", "max", "powc"};
    return (unsigned)op < TAPE_NOPS ? names[op] : "?";
}

tape_builder *tape_builder_new(void)
{
    tape_builder *b = calloc(1, sizeof *b);
    if (!b)
        return NULL;
    b->hcap = 256;
    b->hash = malloc(b->hcap * sizeof *b->hash);
    if (!b->hash) {
        free(b);
        return NULL;
    }
    memset(b->hash, 0xff, b->hcap * sizeof *b->hash);
    return b;
}

void tape_builder_free(tape_builder *b)
{
    if (!b)
        return;
    free(b->insn);
    free(b->konst);
    free(b->hash);
    free(b);
}

static uint64_t bits(double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
}

static uint32_t hash_insn(const tape_builder *b, const tape_insn *in)
{
    uint64_t h = in->op * 0x9e3779b97f4a7c15ull;
    if (in->op == TAPE_CONST) {
        const tape_const *k = &b->konst[in->a];
        h ^= bits(k->v) * 0xff51afd7ed558ccdull;
        h ^= bits(k->lo) * 0xc4ceb9fe1a85ec53ull + (h >> 29);
        h ^= bits(k->hi) * 0x94d049bb133111ebull + (h >> 31);
    } else {
        h ^= (uint64_t)in->a * 0xff51afd7ed558ccdull;
        h ^= ((uint64_t)in->b + 1) * 0xc4ceb9fe1a85ec53ull + (h >> 29);
        if (in->op == TAPE_POWC)
            h ^= bits(b->konst[in->b].v) * 0x94d049bb133111ebull;
    }
    h ^= h >> 33;
    return (uint32_t)h;
}

static int same_const(const tape_const *p, const tape_const *q)
{
    return bits(p->v) == bits(q->v) && bits(p->lo) == bits(q->lo) && bits(p->hi) == bits(q->hi);
}

static int same_insn(const tape_builder *b, const tape_insn *p, const tape_insn *q)
{
    if (p->op != q->op)
        return 0;
    if (p->op == TAPE_CONST)
        return same_const(&b->konst[p->a], &b->konst[q->a]);
    if (p->op == TAPE_POWC)
        return p->a == q->a && same_const(&b->konst[p->b], &b->konst[q->b]);
    return p->a == q->a && p->b == q->b;
}

static int grow_hash(tape_builder *b)
{
    uint32_t cap = b->hcap * 2;
    uint32_t *h = malloc(cap * sizeof *h);
    if (!h)
        return TAPE_ENOMEM;
    memset(h, 0xff, cap * sizeof *h);
    for (uint32_t i = 0; i < b->n; i++) {
        uint32_t j = hash_insn(b, &b->insn[i]) & (cap - 1);
        while (h[j] != EMPTY)
            j = (j + 1) & (cap - 1);
        h[j] = i;
    }
    free(b->hash);
    b->hash = h;
    b->hcap = cap;
    return TAPE_OK;
}

/* Finds or appends `in`; returns its slot. */
static int32_t intern(tape_builder *b, tape_insn in)
{
    uint32_t j = hash_insn(b, &in) & (b->hcap - 1);
    while (b->hash[j] != EMPTY) {
        if (same_insn(b, &b->insn[b->hash[j]], &in))
            return (int32_t)b->hash[j];
        j = (j + 1) & (b->hcap - 1);
    }
    if (b->n >= TAPE_MAX_INSNS)
        return TAPE_ETOOBIG;
    if (b->n == b->cap) {
        uint32_t cap = b->cap ? b->cap * 2 : 64;
        tape_insn *p = realloc(b->insn, cap * sizeof *p);
        if (!p)
            return TAPE_ENOMEM;
        b->insn = p;
        b->cap = cap;
    }
    b->insn[b->n] = in;
    b->hash[j] = b->n;
    b->n++;
    if (2 * b->n > b->hcap && grow_hash(b) != TAPE_OK)
        return TAPE_ENOMEM;
    return (int32_t)(b->n - 1);
}

static int32_t add_pool(tape_builder *b, double v, double lo, double hi)
{
    if (b->nconst == b->kcap) {
        uint32_t cap = b->kcap ? b->kcap * 2 : 16;
        tape_const *p = realloc(b->konst, cap * sizeof *p);
        if (!p)
            return TAPE_ENOMEM;
        b->konst = p;
        b->kcap = cap;
    }
    tape_const k = {v, lo, hi};
    for (uint32_t i = 0; i < b->nconst; i++) /* pools are small */
        if (same_const(&b->konst[i], &k))
            return (int32_t)i;
    b->konst[b->nconst] = k;
    return (int32_t)b->nconst++;
}

int32_t tape_emit_const(tape_builder *b, double v, double lo, double hi)
{
    b->nreq++;
    if (!isfinite(v) || !(lo <= v && v <= hi))
        return TAPE_EDOMAIN;
    int32_t k = add_pool(b, v, lo, hi);
    if (k < 0)
        return k;
    tape_insn in = {TAPE_CONST, (uint32_t)k, 0};
    return intern(b, in);
}

int32_t tape_emit_var(tape_builder *b, int axis)
{
    b->nreq++;
    tape_insn in = {(uint32_t)(TAPE_X + axis), 0, 0};
    return intern(b, in);
}

int tape_slot_is_const(const tape_builder *b, int32_t s, double *v)
{
    if (s < 0 || (uint32_t)s >= b->n || b->insn[s].op != TAPE_CONST)
        return 0;
    if (v)
        *v = b->konst[b->insn[s].a].v;
    return 1;
}

/* One operation in double and in intervals, for constant folding. */
static double point_op(tape_op op, double a, double c, double p)
{
    switch (op) {
    case TAPE_NEG: return -a;
    case TAPE_SQUARE: return a * a;
    case TAPE_SQRT: return sqrt(a);
    case TAPE_EXP: return exp_kernel(a); /* as the point evaluators */
    case TAPE_LOG: return log(a);
    case TAPE_ABS: return fabs(a);
    case TAPE_SIN: { double s, co; point_sincos(a, &s, &co); return s; } /* as the evaluators */
    case TAPE_COS: { double s, co; point_sincos(a, &s, &co); return co; }
    case TAPE_TAN: return tan(a);
    case TAPE_ADD: return a + c;
    case TAPE_SUB: return a - c;
    case TAPE_MUL: return a * c;
    case TAPE_DIV: return a / c;
    case TAPE_MIN: return point_min(a, c);
    case TAPE_MAX: return point_max(a, c);
    case TAPE_POWC: return pow(a, p);
    default: return NAN;
    }
}

static interval iv_op(tape_op op, interval a, interval c, double p, unsigned *f)
{
    switch (op) {
    case TAPE_NEG: return interval_neg(a);
    case TAPE_SQUARE: return interval_sqr(a, f);
    case TAPE_SQRT: return interval_sqrt(a, f);
    case TAPE_EXP: return interval_exp(a, f);
    case TAPE_LOG: return interval_log(a, f);
    case TAPE_ABS: return interval_abs(a);
    case TAPE_SIN: return interval_sin(a, f);
    case TAPE_COS: return interval_cos(a, f);
    case TAPE_TAN: return interval_tan(a, f);
    case TAPE_ADD: return interval_add(a, c, f);
    case TAPE_SUB: return interval_sub(a, c, f);
    case TAPE_MUL: return interval_mul(a, c, f);
    case TAPE_DIV: return interval_div(a, c, f);
    case TAPE_MIN: return interval_min(a, c);
    case TAPE_MAX: return interval_max(a, c);
    case TAPE_POWC: return interval_powc(a, p, f);
    default: *f |= INTERVAL_MAYBE_NAN; return interval_nan();
    }
}

/* Knuth's TwoSum: the exact rounding error of s = fl(x + y), for finite s. */
static double two_sum_err(double x, double y, double s)
{
    double bb = s - x;
    return (x - (s - bb)) + (y - bb);
}

/* Folds op over constant slots a and c (c < 0: unary). */
static int32_t fold(tape_builder *b, tape_op op, int32_t a, int32_t c, double p)
{
    const tape_const *ka = &b->konst[b->insn[a].a];
    const tape_const *kc = c >= 0 ? &b->konst[b->insn[c].a] : ka;
    interval ia = {ka->lo, ka->hi}, ic = {kc->lo, kc->hi};
    unsigned f = 0;
    double v = point_op(op, ka->v, kc->v, p);
    interval r = iv_op(op, ia, ic, p, &f);
    if (f || !isfinite(v) || !isfinite(r.lo) || !isfinite(r.hi))
        return TAPE_EDOMAIN;
    if (r.lo > v) r.lo = v; /* both are enclosures of (nearly) the same real */
    if (r.hi < v) r.hi = v;
    /* Exact results of exact operands stay exact when the double op is exact:
     * keep it simple and only trust negation, abs, min and max. */
    if (ka->lo == ka->hi && kc->lo == kc->hi &&
        (op == TAPE_NEG || op == TAPE_ABS || op == TAPE_MIN || op == TAPE_MAX))
        r.lo = r.hi = v;
    /* For + - * / on exact operands, an exact double result is detected by
     * redoing the operation backwards (error-free when it round-trips). */
    if (ka->lo == ka->hi && kc->lo == kc->hi && c >= 0) {
        double x = ka->v, y = kc->v;
        int exact = 0;
        if (op == TAPE_ADD) exact = two_sum_err(x, y, v) == 0.0;
        else if (op == TAPE_SUB) exact = two_sum_err(x, -y, v) == 0.0;
        /* fma gives the exact residual unless it underflows: stay clear of
         * the subnormal range. */
        else if (op == TAPE_MUL)
            exact = (x == 0.0 || y == 0.0) || (fabs(v) >= 0x1p-900 && fma(x, y, -v) == 0.0);
        else if (op == TAPE_DIV)
            exact = x == 0.0 || (fabs(v) >= 0x1p-900 && fabs(x) >= 0x1p-900 && fma(v, y, -x) == 0.0);
        if (exact)
            r.lo = r.hi = v;
    }
    if (op == TAPE_SQUARE && ka->lo == ka->hi &&
        (ka->v == 0.0 || (fabs(v) >= 0x1p-900 && fma(ka->v, ka->v, -v) == 0.0)))
        r.lo = r.hi = v;
    return tape_emit_const(b, v, r.lo, r.hi);
}

static int is_const(const tape_builder *b, int32_t s) { return b->insn[s].op == TAPE_CONST; }

int32_t tape_emit_unary(tape_builder *b, tape_op op, int32_t a)
{
    b->nreq++;
    if (a < 0)
        return a;
    if (is_const(b, a))
        return fold(b, op, a, -1, 0.0);
    tape_insn in = {op, (uint32_t)a, 0};
    return intern(b, in);
}

int32_t tape_emit_binary(tape_builder *b, tape_op op, int32_t a, int32_t c)
{
    b->nreq++;
    if (a < 0)
        return a;
    if (c < 0)
        return c;
    if (is_const(b, a) && is_const(b, c))
        return fold(b, op, a, c, 0.0);
    if (op == TAPE_SUB && a == c) {
        /* a - a is 0 wherever a is finite (NaN where it is not), and so is
         * a * 0; but over a box a - a encloses to [-w, w] and a * 0 to [0, 0],
         * so that 1/(x-x) is nowhere a surface instead of a grid of poles. */
        c = tape_emit_const(b, 0.0, 0.0, 0.0);
        if (c < 0)
            return c;
        op = TAPE_MUL;
    }
    if ((op == TAPE_ADD || op == TAPE_MUL || op == TAPE_MIN || op == TAPE_MAX) && c < a) {
        int32_t t = a;
        a = c;
        c = t;
    }
    tape_insn in = {op, (uint32_t)a, (uint32_t)c};
    return intern(b, in);
}

/* base^n for an integer n >= 1 by repeated squaring; the hash-consing
 * shares the partial powers. */
static int32_t powi(tape_builder *b, int32_t x, unsigned n)
{
    if (n == 1)
        return x;
    if (n % 2 == 0)
        return tape_emit_unary(b, TAPE_SQUARE, powi(b, x, n / 2));
    return tape_emit_binary(b, TAPE_MUL, x, powi(b, x, n - 1));
}

int32_t tape_emit_pow(tape_builder *b, int32_t base, int32_t e)
{
    if (base < 0)
        return base;
    if (e < 0)
        return e;
    if (is_const(b, e)) {
        const tape_const k = b->konst[b->insn[e].a];
        if (k.lo == k.hi && k.v == floor(k.v)) {
            if (fabs(k.v) > TAPE_MAX_POWI)
                return TAPE_EEXPONENT;
            if (k.v == 0.0)
                return tape_emit_const(b, 1.0, 1.0, 1.0);
            int32_t r = powi(b, base, (unsigned)fabs(k.v));
            if (k.v > 0)
                return r;
            return tape_emit_binary(b, TAPE_DIV, tape_emit_const(b, 1.0, 1.0, 1.0), r);
        }
        if (k.lo == k.hi) {
            if (is_const(b, base))
                return fold(b, TAPE_POWC, base, -1, k.v);
            int32_t kp = add_pool(b, k.v, k.v, k.v);
            if (kp < 0)
                return kp;
            tape_insn in = {TAPE_POWC, (uint32_t)base, (uint32_t)kp};
            return intern(b, in);
        }
    }
    if (is_const(b, base)) {
        const tape_const k = b->konst[b->insn[base].a];
        interval ie = interval_around(M_E);
        if (k.v == M_E && k.lo == ie.lo && k.hi == ie.hi)
            return tape_emit_unary(b, TAPE_EXP, e);
    }
    return tape_emit_unary(b, TAPE_EXP,
                           tape_emit_binary(b, TAPE_MUL, e, tape_emit_unary(b, TAPE_LOG, base)));
}

int tape_builder_finish(tape_builder *b, int32_t root, tape *out)
{
    memset(out, 0, sizeof *out);
    if (root < 0 || (uint32_t)root >= b->n)
        return TAPE_ENOMEM;
    tape_insn *insn = malloc(b->n * sizeof *insn);
    uint32_t *m = malloc(b->n * sizeof *m);
    tape_const *k = malloc((b->nconst ? b->nconst : 1) * sizeof *k);
    if (!insn || !m || !k) {
        free(insn);
        free(m);
        free(k);
        return TAPE_ENOMEM;
    }
    /* Dead-code removal is tape_prune without enclosures, run on a view of
     * the builder's arrays. */
    const tape all = {.insn = b->insn, .n = b->n, .root = (uint32_t)root, .konst = b->konst,
                      .nconst = b->nconst};
    tape live;
    tape_prune(&all, NULL, 0, insn, m, &live);
    out->n = live.n;
    out->root = live.root;
    if (b->nconst)
        memcpy(k, b->konst, b->nconst * sizeof *k);
    out->insn = insn;
    out->konst = k;
    out->nconst = b->nconst;
    out->owned = 1;
    out->ntree = b->nreq;
    free(m);
    return TAPE_OK;
}

void tape_free(tape *t)
{
    if (t && t->owned) {
        free((void *)t->insn);
        free((void *)t->konst);
        t->insn = NULL;
        t->konst = NULL;
        t->n = 0;
        t->owned = 0;
    }
}
