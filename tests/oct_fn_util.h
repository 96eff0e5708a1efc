/* oct_fn_util: tapes and format 1.1 files for the FUNCTION section tests and
 * the fuzz corpus: a tape with every op, a sphere, their section bytes. */
#ifndef OCT_FN_UTIL_H
#define OCT_FN_UTIL_H

#include <stddef.h>
#include <stdint.h>

#include "common/expr/tape.h"
#include "format/oct.h"
#include "bench/oct_synth.h"

/* A tape holding every tape_op at least once (an inexact constant, an exact
 * fractional power), all of them live. Free with tape_free. Aborts on
 * failure. */
void test_fn_every_op(tape *out);
/* -(0.25 - (x^2 + y^2 + z^2)): an odd instruction count, so its record
 * ends in 4 bytes of padding. */
void test_fn_sphere(tape *out);

/* The FUNCTION section of `count` tapes: every-op, sphere, every-op, ...
 * (malloc'd; *size bytes). */
unsigned char *test_fn_section(unsigned count, size_t *size);

/* The small tree of oct_check_small_file (3 levels, 2 surfaces) written as a
 * 1.1 file with test_fn_section(2) and `flags`. */
void test_fn_small_file(unsigned char **buf, size_t *len, test_tree *t, uint32_t flags);

#endif
