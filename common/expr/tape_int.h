/* tape_int.h: helpers shared by the tape's builder and evaluators, private
 * to common/expr/. static inline so each evaluator's loop keeps them inlined. */
#ifndef TAPE_INT_H
#define TAPE_INT_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "common/expr/sincos_kernel.h"
#include "common/expr/tape.h"

/* min and max in double that propagate NaN from either operand. The
 * builder's constant folding and every point evaluator use these, so folded
 * and evaluated values agree bit for bit. */
static inline double point_min(double a, double b) { return (a < b || a != a) ? a : b; }
static inline double point_max(double a, double b) { return (a > b || a != a) ? a : b; }

/* sin(x) and cos(x) for every point evaluator (sincos_kernel.h: one
 * reduction for both). */
static inline void point_sincos(double x, double *s, double *c) { sincos_point(x, s, c); }

/* 0.0, which the compiler cannot see is 0.0: a lane loop storing it becomes
 * vector stores, where one storing the constant became a memset (rep stos,
 * slow to start, and its stores are not forwarded to the vector loads of the
 * next ops: docs/perf-log.md). */
static inline double opaque_zero(void)
{
    double z = 0.0;
#if defined(__GNUC__) && defined(__SSE2__)
    __asm__("" : "+x"(z));
#endif
    return z;
}

/* The sin and cos of the last TRIG_MEMO argument slots of a trigonometric
 * instruction in one evaluation (slots are written once), so that the sin
 * and cos of one argument (gyroid's sin(3 pi x) and cos(3 pi x)) share one
 * evaluation: the same bits as two, and the flags the first one raised are
 * already in the evaluation's. trig_memo_keys is the part every memo (one
 * interval, one lane set) shares: which slots its entries hold. */
#define TRIG_MEMO 4
typedef struct trig_memo_keys {
    uint32_t arg[TRIG_MEMO];
    unsigned next;
} trig_memo_keys;

static inline void trig_memo_keys_init(trig_memo_keys *k)
{
    for (unsigned j = 0; j < TRIG_MEMO; j++)
        k->arg[j] = UINT32_MAX;
    k->next = 0;
}

/* The entry holding slot a; on a miss (*miss = 1) the oldest, given to a. */
static inline unsigned trig_memo_find(trig_memo_keys *k, uint32_t a, int *miss)
{
    *miss = 0;
    for (unsigned j = 0; j < TRIG_MEMO; j++)
        if (k->arg[j] == a)
            return j;
    unsigned j = k->next++ % TRIG_MEMO;
    k->arg[j] = a;
    *miss = 1;
    return j;
}

/* The scalar interval evaluators' memo. */
typedef struct trig_memo {
    trig_memo_keys k;
    interval s[TRIG_MEMO], c[TRIG_MEMO];
} trig_memo;

static inline void trig_memo_init(trig_memo *m) { trig_memo_keys_init(&m->k); }

/* The memo's entry for argument slot a (value x), made on a miss. */
static inline unsigned trig_memo_entry(trig_memo *m, uint32_t a, interval x, unsigned *flags)
{
    int miss;
    const unsigned j = trig_memo_find(&m->k, a, &miss);
    if (miss)
        interval_sincos(x, &m->s[j], &m->c[j], flags);
    return j;
}

/* The point lanes' memo; its arrays are the widest lane count's. */
typedef struct trig_memo_lanes {
    trig_memo_keys k;
    double s[TRIG_MEMO][TAPE_LANES], c[TRIG_MEMO][TAPE_LANES];
} trig_memo_lanes;

static inline void trig_memo_lanes_init(trig_memo_lanes *m) { trig_memo_keys_init(&m->k); }

/* The memo's entry for argument slot a (values x[0..n-1]), made on a miss,
 * every lane at once (vector code); lanes n.. of the entry take lane 0's. */
static inline unsigned trig_memo_lanes_entry(trig_memo_lanes *m, uint32_t a, const double *x,
                                             unsigned n)
{
    int miss;
    const unsigned j = trig_memo_find(&m->k, a, &miss);
    if (miss)
        sincos_point_lanes(TAPE_LANES, n, x, m->s[j], m->c[j]);
    return j;
}

/* The default of a switch over a tape's op codes: a tape holds none but
 * tape_op's (the builder makes none else, and the reader refuses unknown
 * codes: format/oct_function.c), so the compiler may drop its range test. */
#if defined(__GNUC__)
#define TAPE_OP_NONE() __builtin_unreachable()
#else
#define TAPE_OP_NONE() ((void)0)
#endif

/* The dispatch of a loop over a tape's instructions: OP(NAME) labels an
 * op's code, which ends with continue. With GCC, a table of label addresses
 * indexed by op code (one indirect jump from each op, not the switch's
 * bounds test and shared jump); -DTAPE_NO_COMPUTED_GOTO or another compiler:
 * the switch. */
#if defined(__GNUC__) && !defined(TAPE_NO_COMPUTED_GOTO)
#define TAPE_OPL(o) tape_l_##o
#define TAPE_DISPATCH(op)                                                                      \
    static const void *const tape_lbl_[] = {                                                   \
        [TAPE_CONST] = &&tape_l_CONST, [TAPE_X] = &&tape_l_X,       [TAPE_Y] = &&tape_l_Y,     \
        [TAPE_Z] = &&tape_l_Z,         [TAPE_NEG] = &&tape_l_NEG,   [TAPE_SQUARE] = &&tape_l_SQUARE, \
        [TAPE_SQRT] = &&tape_l_SQRT,   [TAPE_EXP] = &&tape_l_EXP,   [TAPE_LOG] = &&tape_l_LOG, \
        [TAPE_ABS] = &&tape_l_ABS,     [TAPE_SIN] = &&tape_l_SIN,   [TAPE_COS] = &&tape_l_COS, \
        [TAPE_TAN] = &&tape_l_TAN,     [TAPE_ADD] = &&tape_l_ADD,   [TAPE_SUB] = &&tape_l_SUB, \
        [TAPE_MUL] = &&tape_l_MUL,     [TAPE_DIV] = &&tape_l_DIV,   [TAPE_MIN] = &&tape_l_MIN, \
        [TAPE_MAX] = &&tape_l_MAX,     [TAPE_POWC] = &&tape_l_POWC, [TAPE_NOPS] = &&tape_l_NOPS, \
    };                                                                                         \
    _Static_assert(sizeof tape_lbl_ / sizeof tape_lbl_[0] == TAPE_NOPS + 1, "one label an op"); \
    goto *tape_lbl_[(op)];
#define TAPE_DISPATCH_DEFAULT() ((void)0)
#else
#define TAPE_OPL(o) case TAPE_##o
#define TAPE_DISPATCH(op) switch ((tape_op)(op))
#define TAPE_DISPATCH_DEFAULT() default: TAPE_OP_NONE()
#endif

/* Operand slots of an instruction, 0 where the field is not a slot (a
 * constant-pool index, or unused), so that no pointer is formed outside
 * the caller's slot array. */
static inline uint32_t slot_a(const tape_insn *in) { return in->op > TAPE_Z ? in->a : 0; }
static inline uint32_t slot_b(const tape_insn *in)
{
    return in->op >= TAPE_ADD && in->op != TAPE_POWC ? in->b : 0;
}

#endif
