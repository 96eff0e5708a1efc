/* tape_int.h: helpers shared by the tape's builder and evaluators, private
 * to common/expr/. static inline so each evaluator's loop keeps them inlined. */
#ifndef TAPE_INT_H
#define TAPE_INT_H

#include "common/expr/tape.h"

/* min and max in double that propagate NaN from either operand. The
 * builder's constant folding and every point evaluator use these, so folded
 * and evaluated values agree bit for bit. */
static inline double point_min(double a, double b) { return (a < b || a != a) ? a : b; }
static inline double point_max(double a, double b) { return (a > b || a != a) ? a : b; }

/* Operand slots of an instruction, 0 where the field is not a slot (a
 * constant-pool index, or unused), so that no pointer is formed outside
 * the caller's slot array. */
static inline uint32_t slot_a(const tape_insn *in) { return in->op > TAPE_Z ? in->a : 0; }
static inline uint32_t slot_b(const tape_insn *in)
{
    return in->op >= TAPE_ADD && in->op != TAPE_POWC ? in->b : 0;
}

#endif
