/* tape_io: tape -> FUNCTION section -> file -> tape, bit for bit, for every
 * op and for scene-compiled tapes; the op code table against FORMAT.md's
 * numbers; the decoder's own checks; render's stored_tapes loader. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "common/expr/tape_io.h"
#include "format/oct.h"
#include "render/stored_tapes.h"
#include "tests/oct_check.h"
#include "tests/oct_fn_util.h"

static void assert_same_tape(const tape *a, const tape *b)
{
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->root, b->root);
    assert_int_equal(a->nconst, b->nconst);
    for (uint32_t i = 0; i < a->n; i++) {
        assert_int_equal(a->insn[i].op, b->insn[i].op);
        assert_int_equal(a->insn[i].a, b->insn[i].a);
        assert_int_equal(a->insn[i].b, b->insn[i].b);
    }
    assert_memory_equal(a->konst, b->konst, a->nconst * sizeof *a->konst); /* bits, -0 and all */
    double *s1 = malloc(a->n * sizeof *s1), *s2 = malloc(a->n * sizeof *s2);
    static const double pts[][3] = {{0.3, 0.7, 0.2}, {-0.5, 2.0, 0.9}, {1e-3, 0.25, 4.0}};
    for (int p = 0; p < 3; p++) {
        double fa = tape_eval(a, pts[p][0], pts[p][1], pts[p][2], s1);
        double fb = tape_eval(b, pts[p][0], pts[p][1], pts[p][2], s2);
        assert_memory_equal(&fa, &fb, sizeof fa);
    }
    free(s1);
    free(s2);
}

/* Through a whole file: encode, write, open (validate), decode. */
static void round_trip(const tape *const *tapes, unsigned count)
{
    unsigned char *fn;
    size_t fsize;
    assert_int_equal(tape_io_encode(tapes, count, &fn, &fsize), TAPE_OK);
    test_tree t;
    test_tree_random(&t, 3, 40, count, 11, 1);
    oct_writer_params p = {0};
    p.function = fn;
    p.function_size = fsize;
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write_1_1(&t, &p, &buf, &len), OCT_OK);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    const oct_function_tape *ft = oct_get_function(f);
    assert_non_null(ft);
    for (unsigned s = 0; s < count; s++) {
        tape back;
        assert_int_equal(tape_io_decode(ft[s].insn, ft[s].insn_count, ft[s].konst, ft[s].const_count,
                                        ft[s].root, &back),
                         TAPE_OK);
        assert_same_tape(tapes[s], &back);
        tape_free(&back);
    }
    stored_tapes st;
    assert_int_equal(stored_tapes_load(f, &st), STORED_TAPES_OK);
    assert_int_equal(st.count, count);
    for (unsigned s = 0; s < count; s++)
        assert_same_tape(tapes[s], &st.tapes[s]);
    stored_tapes_free(&st);
    oct_close(f);
    free(buf);
    free(fn);
    test_tree_free(&t);
}

static void test_every_op_round_trip(void **state)
{
    (void)state;
    tape every, sphere;
    test_fn_every_op(&every);
    test_fn_sphere(&sphere);
    int seen[TAPE_NOPS] = {0};
    for (uint32_t i = 0; i < every.n; i++)
        seen[every.insn[i].op] = 1;
    for (int op = 0; op < TAPE_NOPS; op++)
        if (!seen[op])
            fail_msg("the every-op tape lacks %s", tape_op_name((tape_op)op));
    const tape *list[3] = {&every, &sphere, &every};
    round_trip(list, 1);
    round_trip(list, 3);
    tape_free(&every);
    tape_free(&sphere);
}

/* Tapes as the scene compiler makes them: the example scenes' kind. */
static void test_scene_round_trip(void **state)
{
    (void)state;
    static const char text[] =
        "bounds -1 -1 -1 1 1 1\n"
        "surface x^2 + y^2 + z^2 - 0.3^2\ncolor 1 0 0\n"
        "surface min(max(abs(x) - 0.5, abs(y) - 0.5), sqrt(x^2 + z^2) - 0.2) + 0.1*sin(7*x)\n"
        "surface exp(-4*(x^2 + y^2)) + exp(-4*((x-0.3)^2 + z^2)) - 0.5 + y^1.5 * 0 - log(2 + cos(z)) / 3\n";
    scene *sc = NULL;
    scene_error err;
    assert_int_equal(scene_parse(text, sizeof text - 1, &sc, &err), 0);
    const tape *list[3];
    for (size_t s = 0; s < sc->nsurfaces; s++)
        list[s] = &sc->surfaces[s].tape;
    round_trip(list, (unsigned)sc->nsurfaces);
    scene_free(sc);
}

/* The table agrees with format/oct.h's OCT_OP_* (FORMAT.md §8's numbers). */
static void test_op_codes(void **state)
{
    (void)state;
    static const struct { tape_op op; uint32_t code; } want[] = {
        {TAPE_CONST, OCT_OP_CONST}, {TAPE_X, OCT_OP_X}, {TAPE_Y, OCT_OP_Y}, {TAPE_Z, OCT_OP_Z},
        {TAPE_NEG, OCT_OP_NEG}, {TAPE_SQUARE, OCT_OP_SQUARE}, {TAPE_SQRT, OCT_OP_SQRT},
        {TAPE_EXP, OCT_OP_EXP}, {TAPE_LOG, OCT_OP_LOG}, {TAPE_ABS, OCT_OP_ABS},
        {TAPE_SIN, OCT_OP_SIN}, {TAPE_COS, OCT_OP_COS}, {TAPE_TAN, OCT_OP_TAN},
        {TAPE_ADD, OCT_OP_ADD}, {TAPE_SUB, OCT_OP_SUB}, {TAPE_MUL, OCT_OP_MUL},
        {TAPE_DIV, OCT_OP_DIV}, {TAPE_MIN, OCT_OP_MIN}, {TAPE_MAX, OCT_OP_MAX},
        {TAPE_POWC, OCT_OP_POWC},
    };
    assert_int_equal(sizeof want / sizeof want[0], TAPE_NOPS);
    assert_int_equal(OCT_OP_COUNT, TAPE_NOPS);
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        assert_int_equal(tape_io_file_op(want[i].op), want[i].code);
        assert_int_equal(tape_io_tape_op(want[i].code), want[i].op);
    }
    assert_int_equal(tape_io_tape_op(OCT_OP_COUNT), -1);
    assert_int_equal(tape_io_tape_op(UINT32_MAX), -1);
    assert_int_equal(OCT_FN_MAX_INSNS, TAPE_MAX_INSNS);
}

/* The sphere's bytes, field by field. */
static void test_layout(void **state)
{
    (void)state;
    tape sphere;
    test_fn_sphere(&sphere);
    const tape *list[1] = {&sphere};
    unsigned char *p;
    size_t size;
    assert_int_equal(tape_io_encode(list, 1, &p, &size), TAPE_OK);
    const size_t body = 16 + 24 * (size_t)sphere.nconst + 12 * (size_t)sphere.n;
    assert_int_equal(size, 8 + ((body + 7) & ~(size_t)7));
    uint32_t u[4];
    memcpy(u, p, 8);
    assert_int_equal(u[0], 1);
    assert_int_equal(u[1], 0);
    memcpy(u, p + 8, 16);
    assert_int_equal(u[0], sphere.n);
    assert_int_equal(u[1], sphere.nconst);
    assert_int_equal(u[2], sphere.root);
    assert_int_equal(u[3], 0);
    for (uint32_t j = 0; j < sphere.nconst; j++)
        assert_memory_equal(p + 24 + 24 * j, &sphere.konst[j], 24); /* v, lo, hi */
    const unsigned char *ins = p + 24 + 24 * (size_t)sphere.nconst;
    for (uint32_t i = 0; i < sphere.n; i++) {
        memcpy(u, ins + 12 * i, 12);
        assert_int_equal(u[0], tape_io_file_op((tape_op)sphere.insn[i].op));
        if (sphere.insn[i].op <= TAPE_Z && sphere.insn[i].op != TAPE_CONST)
            assert_true(u[1] == 0 && u[2] == 0);
    }
    for (size_t k = 8 + body; k < size; k++)
        assert_int_equal(p[k], 0);
    free(p);
    tape_free(&sphere);
}

/* The decoder refuses on its own what the reader would. */
static void test_decode_refuses(void **state)
{
    (void)state;
    const double k[6] = {1.0, 1.0, 1.0, 0.1, 0.2, 0.3};
    uint32_t ins[9] = {OCT_OP_X, 0, 0, OCT_OP_CONST, 0, 0, OCT_OP_ADD, 0, 1};
    tape t;
    assert_int_equal(tape_io_decode(ins, 3, k, 1, 2, &t), TAPE_OK);
    assert_int_equal(t.n, 3);
    tape_free(&t);
    const struct { uint32_t at, value; } bad[] = {
        {6, 99}, {6, OCT_OP_COUNT}, {8, 2}, {7, 5}, {4, 1}, {1, 1}, {2, 3}, {0, OCT_OP_NEG},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint32_t c[9];
        memcpy(c, ins, sizeof c);
        c[bad[i].at] = bad[i].value;
        assert_int_equal(tape_io_decode(c, 3, k, 1, 2, &t), TAPE_IO_EINVALID);
        assert_null(t.insn);
    }
    assert_int_equal(tape_io_decode(ins, 3, k, 1, 3, &t), TAPE_IO_EINVALID); /* root */
    assert_int_equal(tape_io_decode(ins, 0, k, 1, 0, &t), TAPE_IO_EINVALID); /* empty */
    assert_int_equal(tape_io_decode(ins, 3, k + 3, 1, 2, &t), TAPE_IO_EINVALID); /* 0.1 not in [0.2, 0.3] */
    const double nan3[3] = {NAN, 0.0, 1.0};
    assert_int_equal(tape_io_decode(ins, 3, nan3, 1, 2, &t), TAPE_IO_EINVALID);
}

/* A 1.0 file has no function for the renderer. */
static void test_stored_tapes_none(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    stored_tapes st;
    assert_int_equal(stored_tapes_load(f, &st), STORED_TAPES_NONE);
    assert_int_equal(st.count, 0);
    assert_null(st.tapes);
    assert_string_equal(stored_tapes_strerror(STORED_TAPES_NONE), "no stored function (rasterize it again)");
    stored_tapes_free(&st);
    oct_close(f);
    free(buf);
    test_tree_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_op_round_trip),
        cmocka_unit_test(test_scene_round_trip),
        cmocka_unit_test(test_op_codes),
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_decode_refuses),
        cmocka_unit_test(test_stored_tapes_none),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
