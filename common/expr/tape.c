/* tape: builder (hash-consing, constant folding, integer powers), the four
 * evaluators and the pruner. */
#include "common/expr/tape.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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

static double point_min(double a, double b) { return (a < b || a != a) ? a : b; }
static double point_max(double a, double b) { return (a > b || a != a) ? a : b; }

/* One operation in double and in intervals, for constant folding. */
static double point_op(tape_op op, double a, double c, double p)
{
    switch (op) {
    case TAPE_NEG: return -a;
    case TAPE_SQUARE: return a * a;
    case TAPE_SQRT: return sqrt(a);
    case TAPE_EXP: return exp(a);
    case TAPE_LOG: return log(a);
    case TAPE_ABS: return fabs(a);
    case TAPE_SIN: return sin(a);
    case TAPE_COS: return cos(a);
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

/* ---- Dead code and pruning ------------------------------------------- */

/* Marks in `m` (n entries): EMPTY for dead instructions, i for a live one
 * kept as is, j < i when instruction i is replaced by slot j. */
/* Marks in m the instructions the value of `root` depends on: m[i] = i when
 * live, EMPTY when dead, w when instruction i is replaced by instruction w (a
 * decided min/max), CONSTANT when it is replaced by its enclosure s[i] (an
 * interval narrower than `tiny`: see tape_prune_const). s may be NULL: then
 * only dead code goes. */
#define CONSTANT (EMPTY - 1)
static void mark(const tape_insn *in, uint32_t n, uint32_t root, const interval *s, double tiny,
                 uint32_t *m)
{
    for (uint32_t i = 0; i < n; i++)
        m[i] = EMPTY;
    m[root] = root;
    for (uint32_t i = root + 1; i-- > 0;) {
        if (m[i] == EMPTY)
            continue;
        uint32_t op = in[i].op, a = in[i].a, c = in[i].b;
        if (op == TAPE_CONST || op <= TAPE_Z)
            continue;
        if (s && i != root && s[i].hi - s[i].lo <= tiny) { /* NaN or inf: the test fails */
            m[i] = CONSTANT;
            continue;
        }
        if (s && (op == TAPE_MIN || op == TAPE_MAX)) {
            /* Strict comparisons: equal values could differ in the sign of 0. */
            int a_lower = s[a].hi < s[c].lo, c_lower = s[c].hi < s[a].lo;
            uint32_t w = EMPTY;
            if (op == TAPE_MIN)
                w = a_lower ? a : c_lower ? c : EMPTY;
            else
                w = a_lower ? c : c_lower ? a : EMPTY;
            if (w != EMPTY) {
                m[i] = w;
                if (m[w] == EMPTY)
                    m[w] = w;
                continue;
            }
        }
        if (m[a] == EMPTY)
            m[a] = a;
        if (op >= TAPE_ADD && op != TAPE_POWC && m[c] == EMPTY)
            m[c] = c;
    }
}

/* Emits the live instructions renumbered; returns the count and sets *root.
 * An instruction marked CONSTANT becomes a constant whose enclosure is s[i],
 * appended to `konst` at *nconst. */
static uint32_t compact(const tape_insn *in, uint32_t n, uint32_t *root, uint32_t *m, tape_insn *out,
                        const interval *s, tape_const *konst, uint32_t *nconst)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (m[i] == EMPTY)
            continue;
        if (m[i] == CONSTANT) {
            tape_const c = {0.5 * s[i].lo + 0.5 * s[i].hi, s[i].lo, s[i].hi};
            konst[*nconst] = c;
            out[k].op = TAPE_CONST;
            out[k].a = (*nconst)++;
            out[k].b = 0;
            m[i] = k++;
            continue;
        }
        if (m[i] != i) {
            m[i] = m[m[i]]; /* already renumbered, as m[i] < i */
            continue;
        }
        tape_insn t = in[i];
        if (t.op != TAPE_CONST && t.op > TAPE_Z) {
            t.a = m[t.a];
            if (t.op >= TAPE_ADD && t.op != TAPE_POWC)
                t.b = m[t.b];
        }
        out[k] = t;
        m[i] = k++;
    }
    *root = m[*root];
    return k;
}

uint32_t tape_prune(const tape *t, const interval *slots, unsigned flags, tape_insn *out_insn,
                    uint32_t *scratch, tape *out)
{
    uint32_t root = t->root;
    mark(t->insn, t->n, root, flags ? NULL : slots, -1.0, scratch);
    uint32_t n = compact(t->insn, t->n, &root, scratch, out_insn, NULL, NULL, NULL);
    out->insn = out_insn;
    out->n = n;
    out->root = root;
    out->konst = t->konst;
    out->nconst = t->nconst;
    out->owned = 0;
    return n;
}

uint32_t tape_prune_const(const tape *t, const interval *slots, unsigned flags, double tiny,
                          tape_insn *out_insn, tape_const *out_konst, uint32_t *scratch, tape *out)
{
    uint32_t root = t->root, nconst = t->nconst;
    mark(t->insn, t->n, root, flags ? NULL : slots, flags ? -1.0 : tiny, scratch);
    memcpy(out_konst, t->konst, t->nconst * sizeof *out_konst);
    uint32_t n = compact(t->insn, t->n, &root, scratch, out_insn, slots, out_konst, &nconst);
    out->insn = out_insn;
    out->n = n;
    out->root = root;
    out->konst = out_konst;
    out->nconst = nconst;
    out->owned = 0;
    return n;
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
    uint32_t r = (uint32_t)root;
    mark(b->insn, b->n, r, NULL, -1.0, m);
    out->n = compact(b->insn, b->n, &r, m, insn, NULL, NULL, NULL);
    out->root = r;
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

/* ---- Evaluators -------------------------------------------------------- */

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
        case TAPE_EXP: s[i] = exp(A); break;
        case TAPE_LOG: s[i] = log(A); break;
        case TAPE_ABS: s[i] = fabs(A); break;
        case TAPE_SIN: s[i] = sin(A); break;
        case TAPE_COS: s[i] = cos(A); break;
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

/* Operand slots of an instruction, 0 where the field is not a slot (a
 * constant-pool index, or unused), so that no pointer is formed outside
 * the caller's slot array. */
static inline uint32_t slot_a(const tape_insn *in) { return in->op > TAPE_Z ? in->a : 0; }
static inline uint32_t slot_b(const tape_insn *in)
{
    return in->op >= TAPE_ADD && in->op != TAPE_POWC ? in->b : 0;
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
        case TAPE_EXP: { double v = exp(a->v); dscale(r, a, v, v); break; }
        case TAPE_LOG: dscale(r, a, log(a->v), 1.0 / a->v); break;
        case TAPE_ABS: dscale(r, a, fabs(a->v), a->v < 0.0 ? -1.0 : 1.0); break;
        case TAPE_SIN: dscale(r, a, sin(a->v), cos(a->v)); break;
        case TAPE_COS: dscale(r, a, cos(a->v), -sin(a->v)); break;
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

interval tape_eval_interval(const tape *t, const interval box[3], interval *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        switch ((tape_op)in[i].op) {
        case TAPE_CONST: s[i].lo = k[in[i].a].lo; s[i].hi = k[in[i].a].hi; break;
        case TAPE_X: s[i] = box[0]; break;
        case TAPE_Y: s[i] = box[1]; break;
        case TAPE_Z: s[i] = box[2]; break;
        case TAPE_NEG: s[i] = interval_neg(A); break;
        case TAPE_SQUARE: s[i] = interval_sqr(A, &f); break;
        case TAPE_SQRT: s[i] = interval_sqrt(A, &f); break;
        case TAPE_EXP: s[i] = interval_exp(A, &f); break;
        case TAPE_LOG: s[i] = interval_log(A, &f); break;
        case TAPE_ABS: s[i] = interval_abs(A); break;
        case TAPE_SIN: s[i] = interval_sin(A, &f); break;
        case TAPE_COS: s[i] = interval_cos(A, &f); break;
        case TAPE_TAN: s[i] = interval_tan(A, &f); break;
        case TAPE_ADD: s[i] = interval_add(A, C, &f); break;
        case TAPE_SUB: s[i] = interval_sub(A, C, &f); break;
        case TAPE_MUL: s[i] = interval_mul(A, C, &f); break;
        case TAPE_DIV: s[i] = interval_div(A, C, &f); break;
        case TAPE_MIN: s[i] = interval_min(A, C); break;
        case TAPE_MAX: s[i] = interval_max(A, C); break;
        case TAPE_POWC: s[i] = interval_powc(A, k[in[i].b].v, &f); break;
        case TAPE_NOPS: s[i] = interval_nan(); f |= INTERVAL_MAYBE_NAN; break;
        }
    }
    *flags = f;
    return s[t->root];
}

static int is_zero(interval a) { return a.lo == 0.0 && a.hi == 0.0; }
static int is_finite(interval a) { return (a.lo - a.lo) + (a.hi - a.hi) == 0.0; }

/* interval_mul for the partials: those of a term without that variable are
 * [0, 0], and [0, 0] times a finite interval is [+0, +0] in interval_mul
 * (its all-finite path, no flag), here without the products. */
INTERVAL_INLINE interval dmul(interval a, interval b, unsigned *f)
{
    if ((is_zero(a) && is_finite(b)) || (is_zero(b) && is_finite(a))) {
        interval z = {0.0, 0.0};
        return z;
    }
    return interval_mul(a, b, f);
}

/* r->d[j] = a->d[j] * m for an interval multiplier m. */
static void iscale(tape_idual *r, const tape_idual *a, interval v, interval m, unsigned *f)
{
    for (int j = 0; j < 3; j++)
        r->d[j] = dmul(a->d[j], m, f);
    r->v = v;
}

static interval ipt(double x) { interval r = {x, x}; return r; }

interval tape_eval_interval_grad(const tape *t, const interval box[3], interval grad[3],
                                 tape_idual *s, unsigned *flags)
{
    const tape_insn *in = t->insn;
    const tape_const *k = t->konst;
    unsigned f = 0;
    for (uint32_t i = 0, n = t->n; i < n; i++) {
        tape_idual *r = &s[i];
        const tape_idual *a = s + slot_a(&in[i]), *c = s + slot_b(&in[i]);
        switch ((tape_op)in[i].op) {
        case TAPE_CONST:
            r->v.lo = k[in[i].a].lo;
            r->v.hi = k[in[i].a].hi;
            r->d[0] = r->d[1] = r->d[2] = ipt(0.0);
            break;
        case TAPE_X: case TAPE_Y: case TAPE_Z: {
            int ax = (int)in[i].op - TAPE_X;
            r->v = box[ax];
            r->d[0] = r->d[1] = r->d[2] = ipt(0.0);
            r->d[ax] = ipt(1.0);
            break;
        }
        case TAPE_NEG:
            r->v = interval_neg(a->v);
            for (int j = 0; j < 3; j++)
                r->d[j] = interval_neg(a->d[j]);
            break;
        case TAPE_SQUARE:
            iscale(r, a, interval_sqr(a->v, &f), interval_mul(ipt(2.0), a->v, &f), &f);
            break;
        case TAPE_SQRT: {
            interval v = interval_sqrt(a->v, &f);
            iscale(r, a, v, interval_div(ipt(0.5), v, &f), &f);
            break;
        }
        case TAPE_EXP: { interval v = interval_exp(a->v, &f); iscale(r, a, v, v, &f); break; }
        case TAPE_LOG:
            iscale(r, a, interval_log(a->v, &f), interval_div(ipt(1.0), a->v, &f), &f);
            break;
        case TAPE_ABS: {
            interval v = interval_abs(a->v);
            interval m = a->v.lo >= 0.0 ? ipt(1.0) : a->v.hi <= 0.0 ? ipt(-1.0) : (interval){-1.0, 1.0};
            iscale(r, a, v, m, &f);
            break;
        }
        case TAPE_SIN: iscale(r, a, interval_sin(a->v, &f), interval_cos(a->v, &f), &f); break;
        case TAPE_COS:
            iscale(r, a, interval_cos(a->v, &f), interval_neg(interval_sin(a->v, &f)), &f);
            break;
        case TAPE_TAN: {
            interval v = interval_tan(a->v, &f);
            iscale(r, a, v, interval_add(ipt(1.0), interval_sqr(v, &f), &f), &f);
            break;
        }
        case TAPE_ADD:
        case TAPE_SUB: {
            int add = in[i].op == TAPE_ADD;
            interval v = add ? interval_add(a->v, c->v, &f) : interval_sub(a->v, c->v, &f);
            /* A constant operand has a zero derivative: skip the arithmetic. */
            if (in[in[i].b].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    r->d[j] = a->d[j];
            } else if (in[in[i].a].op == TAPE_CONST) {
                for (int j = 0; j < 3; j++)
                    r->d[j] = add ? c->d[j] : interval_neg(c->d[j]);
            } else {
                for (int j = 0; j < 3; j++)
                    r->d[j] = add ? interval_add(a->d[j], c->d[j], &f)
                                  : interval_sub(a->d[j], c->d[j], &f);
            }
            r->v = v;
            break;
        }
        case TAPE_MUL:
            if (in[in[i].a].op == TAPE_CONST) {
                iscale(r, c, interval_mul(a->v, c->v, &f), a->v, &f);
                break;
            }
            if (in[in[i].b].op == TAPE_CONST) {
                iscale(r, a, interval_mul(a->v, c->v, &f), c->v, &f);
                break;
            }
            for (int j = 0; j < 3; j++)
                r->d[j] = interval_add(dmul(a->d[j], c->v, &f), dmul(a->v, c->d[j], &f), &f);
            r->v = interval_mul(a->v, c->v, &f);
            break;
        case TAPE_DIV: {
            interval v = interval_div(a->v, c->v, &f);
            for (int j = 0; j < 3; j++)
                r->d[j] = interval_div(interval_sub(a->d[j], dmul(v, c->d[j], &f), &f),
                                       c->v, &f);
            r->v = v;
            break;
        }
        case TAPE_MIN:
        case TAPE_MAX: {
            int is_min = in[i].op == TAPE_MIN;
            interval v = is_min ? interval_min(a->v, c->v) : interval_max(a->v, c->v);
            const tape_idual *w = NULL;
            if (a->v.hi < c->v.lo)
                w = is_min ? a : c;
            else if (c->v.hi < a->v.lo)
                w = is_min ? c : a;
            for (int j = 0; j < 3; j++)
                r->d[j] = w ? w->d[j] : interval_hull(a->d[j], c->d[j]);
            r->v = v;
            break;
        }
        case TAPE_POWC: {
            double e = k[in[i].b].v;
            interval v = interval_powc(a->v, e, &f);
            interval m = interval_mul(ipt(e), interval_powc(a->v, e - 1.0, &f), &f);
            iscale(r, a, v, m, &f);
            break;
        }
        case TAPE_NOPS:
            r->v = interval_nan();
            f |= INTERVAL_MAYBE_NAN;
            break;
        }
    }
    *flags = f;
    const tape_idual *r = &s[t->root];
    grad[0] = r->d[0];
    grad[1] = r->d[1];
    grad[2] = r->d[2];
    return r->v;
}
