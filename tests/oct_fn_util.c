/* oct_fn_util: the test tapes and 1.1 files (see the header). */
#include "tests/oct_fn_util.h"

#include <math.h>
#include <stdlib.h>

#include "common/expr/tape_io.h"

static int32_t ok(int32_t slot)
{
    if (slot < 0)
        abort();
    return slot;
}

void test_fn_every_op(tape *out)
{
    tape_builder *b = tape_builder_new();
    if (!b)
        abort();
    int32_t x = ok(tape_emit_var(b, 0)), y = ok(tape_emit_var(b, 1)), z = ok(tape_emit_var(b, 2));
    int32_t tenth = ok(tape_emit_const(b, 0.1, nextafter(0.1, 0.0), nextafter(0.1, 1.0)));
    int32_t half = ok(tape_emit_const(b, 0.5, 0.5, 0.5));
    int32_t v[18], n = 0;
    v[n++] = ok(tape_emit_unary(b, TAPE_NEG, x));
    v[n++] = ok(tape_emit_unary(b, TAPE_SQUARE, y));
    v[n++] = ok(tape_emit_unary(b, TAPE_SQRT, z));
    v[n++] = ok(tape_emit_unary(b, TAPE_EXP, x));
    v[n++] = ok(tape_emit_unary(b, TAPE_LOG, y));
    v[n++] = ok(tape_emit_unary(b, TAPE_ABS, z));
    v[n++] = ok(tape_emit_unary(b, TAPE_SIN, x));
    v[n++] = ok(tape_emit_unary(b, TAPE_COS, y));
    v[n++] = ok(tape_emit_unary(b, TAPE_TAN, z));
    v[n++] = ok(tape_emit_binary(b, TAPE_SUB, x, tenth));
    v[n++] = ok(tape_emit_binary(b, TAPE_MUL, y, half));
    v[n++] = ok(tape_emit_binary(b, TAPE_DIV, z, x));
    v[n++] = ok(tape_emit_binary(b, TAPE_MIN, x, y));
    v[n++] = ok(tape_emit_binary(b, TAPE_MAX, y, z));
    v[n++] = ok(tape_emit_pow(b, x, ok(tape_emit_const(b, 1.5, 1.5, 1.5)))); /* POWC */
    int32_t sum = v[0];
    for (int32_t i = 1; i < n; i++)
        sum = ok(tape_emit_binary(b, TAPE_ADD, sum, v[i]));
    if (tape_builder_finish(b, sum, out) != TAPE_OK)
        abort();
    tape_builder_free(b);
}

void test_fn_sphere(tape *out)
{
    tape_builder *b = tape_builder_new();
    if (!b)
        abort();
    int32_t s = ok(tape_emit_unary(b, TAPE_SQUARE, ok(tape_emit_var(b, 0))));
    s = ok(tape_emit_binary(b, TAPE_ADD, s, ok(tape_emit_unary(b, TAPE_SQUARE, ok(tape_emit_var(b, 1))))));
    s = ok(tape_emit_binary(b, TAPE_ADD, s, ok(tape_emit_unary(b, TAPE_SQUARE, ok(tape_emit_var(b, 2))))));
    s = ok(tape_emit_binary(b, TAPE_SUB, ok(tape_emit_const(b, 0.25, 0.25, 0.25)), s));
    s = ok(tape_emit_unary(b, TAPE_NEG, s)); /* 11 instructions */
    if (tape_builder_finish(b, s, out) != TAPE_OK || out->n % 2 == 0)
        abort();
    tape_builder_free(b);
}

unsigned char *test_fn_section(unsigned count, size_t *size)
{
    tape every, sphere;
    test_fn_every_op(&every);
    test_fn_sphere(&sphere);
    const tape *list[OCT_MAX_SURFACES];
    for (unsigned s = 0; s < count; s++)
        list[s] = s % 2 ? &sphere : &every;
    unsigned char *p;
    if (tape_io_encode(list, count, &p, size) != TAPE_OK)
        abort();
    tape_free(&every);
    tape_free(&sphere);
    return p;
}

void test_fn_small_file(unsigned char **buf, size_t *len, test_tree *t, uint32_t flags)
{
    test_tree_random(t, 3, 40, 2, 7, 1);
    oct_writer_params p = {0};
    size_t fsize;
    unsigned char *fn = test_fn_section(2, &fsize);
    p.flags = flags;
    p.function = fn;
    p.function_size = fsize;
    if (test_tree_write_1_1(t, &p, buf, len) != OCT_OK)
        abort();
    free(fn);
}
