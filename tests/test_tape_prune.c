/* Tests for common/expr/tape on random expression trees and for the
 * pruner: interval enclosures of random trees and agreement of their
 * pruned tapes, tape_prune on a known min/max and abs, tape_prune_const's
 * soundness and what it drops, tape_prune_kinks against tape_hess_kinks of
 * the pruned tape. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "common/expr/tape.h"
#include "common/expr/tape_hess.h"
#include "tests/test_tape_util.h"

static void test_random_trees(void **state)
{
    (void)state;
    static char text[16384];
    static interval slots[MAXSLOTS];
    static tape_insn pruned_insn[MAXSLOTS];
    static uint32_t scratch[MAXSLOTS];
    double d1[MAXSLOTS], d2[MAXSLOTS];
    long points = 0, pruned_shorter = 0;
    for (int n = 0; n < 3000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        const tape *t = &s->surfaces[0].tape;
        for (int b = 0; b < 30; b++) {
            interval box[3];
            rand_tree_box(box);
            unsigned f;
            interval r = tape_eval_interval(t, box, slots, &f);
            tape pt;
            uint32_t len = tape_prune(t, slots, f, pruned_insn, scratch, &pt);
            assert_true(len <= t->n && len >= 1);
            pruned_shorter += len < t->n;
            for (int w = 0; w < 10; w++) {
                double p[3] = {in_box(box[0]), in_box(box[1]), in_box(box[2])};
                double v = tape_eval(t, p[0], p[1], p[2], d1);
                points++;
                if (!encloses(r, f, v))
                    fail_msg("%s box [%a,%a]x[%a,%a]x[%a,%a]: f(%a,%a,%a) = %a outside [%a, %a] "
                             "(flags %u)", text, box[0].lo, box[0].hi, box[1].lo, box[1].hi,
                             box[2].lo, box[2].hi, p[0], p[1], p[2], v, r.lo, r.hi, f);
                double pv = tape_eval(&pt, p[0], p[1], p[2], d2);
                if (!(pv == v || (isnan(pv) && isnan(v))))
                    fail_msg("%s: pruned %.17g, full %.17g", text, pv, v);
            }
        }
        scene_free(s);
    }
    assert_true(points > 0);
    assert_true(pruned_shorter > 0);
}

/* tape_prune_const on random trees with an aggressive tolerance: on random
 * sub-boxes, the pruned tape's interval and mean-value enclosures must still
 * hold the full tape's values. */
static void test_prune_const_stays_sound(void **state)
{
    (void)state;
    static char text[16384];
    static interval slots[MAXSLOTS];
    static tape_insn pruned_insn[MAXSLOTS];
    static tape_const pruned_konst[2 * MAXSLOTS];
    static uint32_t scratch[MAXSLOTS];
    static tape_idual islots[MAXSLOTS];
    double d1[MAXSLOTS];
    long checked = 0, replaced = 0;
    for (int n = 0; n < 2000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        const tape *t = &s->surfaces[0].tape;
        assert_true(t->nconst + t->n <= 2 * MAXSLOTS);
        for (int b = 0; b < 20; b++) {
            interval box[3];
            rand_tree_box(box);
            unsigned f;
            interval r = tape_eval_interval(t, box, slots, &f);
            tape pt;
            double tiny = 0.05 * (r.hi - r.lo);
            tape_prune_const(t, slots, f, isfinite(tiny) ? tiny : -1.0, pruned_insn, pruned_konst,
                             scratch, &pt);
            replaced += pt.nconst > t->nconst;
            for (int sb = 0; sb < 4; sb++) {
                interval sub[3];
                double c[3];
                for (int a = 0; a < 3; a++) {
                    double u = in_box(box[a]), v = in_box(box[a]);
                    sub[a].lo = u < v ? u : v;
                    sub[a].hi = u < v ? v : u;
                    c[a] = 0.5 * (sub[a].lo + sub[a].hi);
                }
                unsigned pf = 0, gf = 0, cf = 0;
                interval pr = tape_eval_interval(&pt, sub, slots, &pf);
                interval g[3], cb[3] = {{c[0], c[0]}, {c[1], c[1]}, {c[2], c[2]}};
                tape_eval_interval_grad(&pt, sub, g, islots, &gf);
                interval fc = tape_eval_interval(&pt, cb, slots, &cf);
                for (int w = 0; w < 5; w++) {
                    double p[3] = {in_box(sub[0]), in_box(sub[1]), in_box(sub[2])};
                    double v = tape_eval(t, p[0], p[1], p[2], d1);
                    if (isnan(v) || isinf(v))
                        continue;
                    checked++;
                    if (!encloses(pr, pf, v))
                        fail_msg("%s: pruned interval [%a, %a] misses f = %a", text, pr.lo, pr.hi, v);
                    if (gf || cf || interval_is_nan(fc))
                        continue;
                    unsigned mf = 0;
                    interval mv = fc;
                    for (int a = 0; a < 3; a++) {
                        interval off = {interval_next_down(p[a] - c[a]), interval_next_up(p[a] - c[a])};
                        mv = interval_add(mv, interval_mul(g[a], off, &mf), &mf);
                    }
                    if (!mf && !(mv.lo <= v && v <= mv.hi))
                        fail_msg("%s: pruned mean-value form [%a, %a] misses f = %a", text, mv.lo,
                                 mv.hi, v);
                }
            }
        }
        scene_free(s);
    }
    assert_true(checked > 1000);
    assert_true(replaced > 0);
}

/* tape_prune_kinks (the pruned tape's kinks from the slots it was pruned
 * with) equals tape_hess_kinks of the pruned tape (its own evaluation), for
 * tape_prune, tape_prune_const and the tape itself, on random trees and
 * boxes (the flagged ones are not its case). */
static void test_prune_kinks(void **state)
{
    (void)state;
    static char text[16384];
    static interval slots[MAXSLOTS], slots2[MAXSLOTS];
    static tape_insn pruned_insn[MAXSLOTS];
    static tape_const pruned_konst[2 * MAXSLOTS];
    static uint32_t scratch[MAXSLOTS];
    long checked = 0, kinked = 0, differ = 0;
    for (int n = 0; n < 3000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        const tape *t = &s->surfaces[0].tape;
        for (int b = 0; b < 20; b++) {
            interval box[3];
            rand_tree_box(box);
            unsigned f;
            const interval r = tape_eval_interval(t, box, slots, &f);
            if (f)
                continue;
            assert_int_equal(tape_prune_kinks(t, slots, NULL, t), tape_hess_kinks(t, box, slots2));
            tape pt;
            tape_prune(t, slots, f, pruned_insn, scratch, &pt);
            const unsigned k1 = tape_prune_kinks(t, slots, scratch, &pt);
            assert_int_equal(k1, tape_hess_kinks(&pt, box, slots2));
            const double tiny = 0.05 * (r.hi - r.lo);
            tape_prune_const(t, slots, f, isfinite(tiny) ? tiny : -1.0, pruned_insn, pruned_konst,
                             scratch, &pt);
            const unsigned k2 = tape_prune_kinks(t, slots, scratch, &pt);
            assert_int_equal(k2, tape_hess_kinks(&pt, box, slots2));
            checked++;
            kinked += k1 != 0;
            differ += k1 != k2;
        }
        scene_free(s);
    }
    if (getenv("TAPE_VERBOSE"))
        printf("prune kinks: %ld boxes, %ld kinked, %ld where the constants took one\n", checked,
               kinked, differ);
    assert_true(checked > 1000);
    assert_true(kinked > 100 / SCALE);
}

/* A far blob over the unit box is a constant to within 1e-40: it goes. */
static void test_prune_const_drops_far_terms(void **state)
{
    (void)state;
    static const char text[] = "bounds 0 0 0 1 1 1\nsurface exp(-((x-20)^2 + y^2)) + x^2 + y - 0.5\n";
    scene *s = NULL;
    scene_error e;
    assert_int_equal(scene_parse(text, sizeof text - 1, &s, &e), 0);
    const tape *t = &s->surfaces[0].tape;
    interval slots[64], box[3] = {{0, 1}, {0, 1}, {0, 1}};
    tape_insn out[64];
    tape_const konst[128];
    uint32_t scratch[64];
    unsigned f;
    tape_eval_interval(t, box, slots, &f);
    tape pt;
    uint32_t n = tape_prune_const(t, slots, f, 1e-30, out, konst, scratch, &pt);
    assert_true(n + 5 <= t->n); /* the exp and its argument's arithmetic are gone */
    double d[64];
    assert_true(fabs(tape_eval(&pt, 0.5, 0.25, 0.0, d) - (0.25 + 0.25 - 0.5)) < 1e-30);
    /* With no tolerance nothing but dead code goes. */
    assert_int_equal(tape_prune_const(t, slots, f, -1.0, out, konst, scratch, &pt), t->n);
    scene_free(s);
}

static void test_prune(void **state)
{
    (void)state;
    static const char text[] = "bounds 0 0 0 1 1 1\nsurface min(x, y + 10, max(z, z^2 - 5)) + sin(x)\n";
    scene *s = NULL;
    scene_error e;
    assert_int_equal(scene_parse(text, sizeof text - 1, &s, &e), 0);
    const tape *t = &s->surfaces[0].tape;
    interval slots[64], box[3] = {{0, 1}, {0, 1}, {0, 1}};
    tape_insn out[64];
    uint32_t scratch[64];
    unsigned f;
    tape_eval_interval(t, box, slots, &f);
    tape pt;
    uint32_t n = tape_prune(t, slots, f, out, scratch, &pt);
    /* min(min(x, y+10), max(z, z^2-5)) becomes min(x, z): x, z, min, sin, add. */
    assert_true(t->n > 9);
    assert_int_equal(n, 5);
    double d[64];
    assert_true(tape_eval(&pt, 0.5, 0.2, 0.3, d) == 0.3 + sin(0.5));
    /* Pruning a pruned tape again is fine, and NULL slots only drop dead code. */
    tape_insn out2[64];
    tape pt2;
    assert_int_equal(tape_prune(&pt, NULL, 0, out2, scratch, &pt2), 5);
    /* On a box where the operands overlap nothing is dropped. */
    interval wide[3] = {{-20, 20}, {-20, 20}, {-20, 20}};
    tape_eval_interval(t, wide, slots, &f);
    assert_int_equal(tape_prune(t, slots, f, out, scratch, &pt), t->n);
    scene_free(s);
}

/* An abs whose operand is clear of 0 over the box goes: abs(x - 2) becomes
 * -(x - 2), abs(y + 2) becomes y + 2, with the full tape's bits for f and
 * its gradient at points of the box; one whose operand straddles 0 stays,
 * and so does one whose operand touches 0 (abs(-0) is +0, not -0). */
static void test_prune_abs(void **state)
{
    (void)state;
    static const char text[] =
        "bounds 0 0 0 1 1 1\nsurface abs(x - 2) * 3 + abs(y + 2) + abs(z - 0.5) + abs(x*y)\n";
    scene *s = NULL;
    scene_error e;
    assert_int_equal(scene_parse(text, sizeof text - 1, &s, &e), 0);
    const tape *t = &s->surfaces[0].tape;
    interval slots[64], box[3] = {{0.25, 1}, {0, 1}, {0, 1}};
    tape_insn out[64];
    uint32_t scratch[64];
    unsigned f;
    tape_eval_interval(t, box, slots, &f);
    assert_int_equal(f, 0);
    tape pt;
    uint32_t n = tape_prune(t, slots, f, out, scratch, &pt);
    unsigned abs_left = 0, neg = 0;
    for (uint32_t i = 0; i < n; i++) {
        abs_left += pt.insn[i].op == TAPE_ABS;
        neg += pt.insn[i].op == TAPE_NEG;
    }
    /* abs(z - 0.5) straddles 0 and x*y touches it at y = 0: two stay. */
    assert_int_equal(abs_left, 2);
    assert_int_equal(neg, 1);
    assert_int_equal(n, t->n - 1); /* abs(y + 2) gone, abs(x - 2) now a negation */
    assert_int_equal(tape_prune_kinks(t, slots, scratch, &pt), TAPE_KINK_ABS);
    double d1[64], d2[64];
    tape_dual u1[64], u2[64];
    for (int i = 0; i <= 16; i++) {
        double p[3] = {0.25 + 0.75 * i / 16.0, i / 16.0, 1.0 - i / 16.0};
        double g1[3], g2[3];
        double v1 = tape_eval_grad(t, p, g1, u1), v2 = tape_eval_grad(&pt, p, g2, u2);
        assert_true(v1 == v2 && tape_eval(t, p[0], p[1], p[2], d1) == tape_eval(&pt, p[0], p[1], p[2], d2));
        assert_memory_equal(g1, g2, sizeof g1);
    }
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_trees),
        cmocka_unit_test(test_prune),
        cmocka_unit_test(test_prune_abs),
        cmocka_unit_test(test_prune_const_stays_sound),
        cmocka_unit_test(test_prune_const_drops_far_terms),
        cmocka_unit_test(test_prune_kinks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
