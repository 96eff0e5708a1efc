/* tape_iglanes_avx2: the lane interval gradient evaluator compiled for AVX2
 * (this file alone gets -mavx2; no FMA, and -ffp-contract=off as
 * everywhere, so every lane rounds as the portable build does). Chosen at
 * run time by tape_iglanes.c where the processor has AVX2. */
#include "common/expr/tape_idual_op.h"
#include "common/expr/tape_ilanes_int.h"

#if TAPE_ILANES_AVX2
#if !defined(__AVX2__) || defined(__FMA__)
#error "tape_iglanes_avx2.c is compiled with -mavx2 (and without -mfma)"
#endif
#define NAME tape_iglanes_avx2
#include "common/expr/tape_iglanes_inst.h"
#else
typedef int tape_iglanes_avx2_unused; /* not an empty file */
#endif
