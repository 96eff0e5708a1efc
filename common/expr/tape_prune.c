/* tape_prune: dead-code removal and pruning of a tape for a box, from the
 * interval enclosures of its slots over that box. */
#include "common/expr/tape.h"
#include "common/expr/tape_hess.h"

#include <string.h>

#define EMPTY UINT32_MAX

/* Marks in m the instructions the value of `root` depends on: m[i] = i when
 * live, EMPTY when dead, w when instruction i is replaced by instruction w (a
 * decided min/max, or an abs whose operand is positive), NEGATE when it
 * becomes the negation of its operand (an abs whose operand is negative),
 * CONSTANT when it is replaced by its enclosure s[i] (an interval narrower
 * than `tiny`: see tape_prune_const). s may be NULL: then only dead code
 * goes. Returns how many instructions stay as they are (n: the tape is
 * unchanged).
 *
 * The decisions give the full tape's bits at every point of the box: a
 * point's computed operands lie in their enclosures (each operation's
 * rounded result stays between its enclosure's ends, which are doubles), so
 * a min/max whose operands' enclosures are apart picks the same operand,
 * and |a| is a or -a, exactly, when a's enclosure is clear of 0. */
#define CONSTANT (EMPTY - 1)
#define NEGATE (EMPTY - 2)
static uint32_t mark(const tape_insn *in, uint32_t n, uint32_t root, const interval *s, double tiny,
                 uint32_t *m)
{
    for (uint32_t i = 0; i < n; i++)
        m[i] = EMPTY;
    m[root] = root;
    uint32_t kept = 0;
    for (uint32_t i = root + 1; i-- > 0;) {
        if (m[i] == EMPTY)
            continue;
        uint32_t op = in[i].op, a = in[i].a, c = in[i].b;
        if (op == TAPE_CONST || op <= TAPE_Z) {
            kept++;
            continue;
        }
        if (s && i != root && s[i].hi - s[i].lo <= tiny) { /* NaN or inf: the test fails */
            m[i] = CONSTANT;
            continue;
        }
        if (s && op == TAPE_ABS && (s[a].lo > 0.0 || s[a].hi < 0.0)) {
            /* Strict, as below: abs(-0) is +0. */
            m[i] = s[a].lo > 0.0 ? a : NEGATE;
            if (m[a] == EMPTY)
                m[a] = a;
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
        kept++;
        if (m[a] == EMPTY)
            m[a] = a;
        if (op >= TAPE_ADD && op != TAPE_POWC && m[c] == EMPTY)
            m[c] = c;
    }
    return kept;
}

/* Emits the live instructions renumbered; returns the count and sets *root.
 * An instruction marked CONSTANT becomes a constant whose enclosure is s[i],
 * appended to `konst` at *nconst. */
static uint32_t compact(const tape_insn *in, uint32_t n, uint32_t kept, uint32_t *root, uint32_t *m,
                        tape_insn *out, const interval *s, tape_const *konst, uint32_t *nconst)
{
    if (kept == n) { /* nothing pruned: m is already the identity */
        memcpy(out, in, n * sizeof *out);
        return n;
    }
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
        if (m[i] == NEGATE) {
            tape_insn t = {.op = TAPE_NEG, .a = m[in[i].a], .b = 0};
            out[k] = t;
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
    uint32_t kept = mark(t->insn, t->n, root, flags ? NULL : slots, -1.0, scratch);
    uint32_t n = compact(t->insn, t->n, kept, &root, scratch, out_insn, NULL, NULL, NULL);
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
    uint32_t kept = mark(t->insn, t->n, root, flags ? NULL : slots, flags ? -1.0 : tiny, scratch);
    memcpy(out_konst, t->konst, t->nconst * sizeof *out_konst);
    uint32_t n =
        compact(t->insn, t->n, kept, &root, scratch, out_insn, slots, out_konst, &nconst);
    out->insn = out_insn;
    out->n = n;
    out->root = root;
    out->konst = out_konst;
    out->nconst = nconst;
    out->owned = 0;
    return n;
}

/* After compact, scratch[i] is the output index of t's instruction i when
 * it was kept, became a constant, or (a decided min/max) was replaced by
 * its winner, and EMPTY when dead. Only kept instructions give an output
 * instruction of their own op: a constant's is TAPE_CONST (never a kept
 * op), and a replaced min/max whose winner is a min/max too has operands
 * that separate strictly, which is no kink. */
unsigned tape_prune_kinks(const tape *t, const interval *slots, const uint32_t *scratch,
                          const tape *pruned)
{
    unsigned kinks = 0;
    for (uint32_t i = 0; i < t->n; i++) {
        const tape_insn *in = &t->insn[i];
        if (in->op != TAPE_ABS && in->op != TAPE_MIN && in->op != TAPE_MAX)
            continue;
        if (scratch && (scratch[i] == EMPTY || pruned->insn[scratch[i]].op != in->op))
            continue;
        const interval a = slots[in->a];
        if (in->op == TAPE_ABS) {
            if (!(a.lo >= 0.0 || a.hi <= 0.0)) /* (tape_hess_kinks' rule) */
                kinks |= TAPE_KINK_ABS;
        } else {
            const interval c = slots[in->b];
            if (!(a.hi < c.lo || c.hi < a.lo))
                kinks |= TAPE_KINK_MINMAX;
        }
    }
    return kinks;
}
