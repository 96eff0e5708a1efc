/* tape: an implicit function compiled to a flat SSA instruction array, and
 * its evaluators (point, gradient, interval, interval gradient) and pruner.
 * Built in tape_build.c, pruned in tape_prune.c, evaluated in tape_eval.c
 * (point, gradient), tape_lanes.c (gradient over several points) and
 * tape_eval_interval.c (interval, interval gradient). */
#ifndef TAPE_H
#define TAPE_H

#include <stdint.h>

#include "common/expr/interval.h"

/* Instruction i writes slot i; operands name earlier slots, so a tape is
 * evaluated by one forward loop. */
typedef enum tape_op {
    TAPE_CONST,  /* a = index into the constant pool */
    TAPE_X, TAPE_Y, TAPE_Z,
    TAPE_NEG, TAPE_SQUARE, TAPE_SQRT, TAPE_EXP, TAPE_LOG, TAPE_ABS,
    TAPE_SIN, TAPE_COS, TAPE_TAN,
    TAPE_ADD, TAPE_SUB, TAPE_MUL, TAPE_DIV, TAPE_MIN, TAPE_MAX,
    TAPE_POWC,   /* slot a ^ pool[b].v, the exponent exact and not an integer */
    TAPE_NOPS
} tape_op;

typedef struct tape_insn {
    uint32_t op; /* tape_op */
    uint32_t a, b;
} tape_insn;

/* A constant: v is the double the point evaluators use; [lo, hi] encloses
 * the real number written in the scene (lo == hi == v when v is exact). */
typedef struct tape_const {
    double v, lo, hi;
} tape_const;

/* A tape. Evaluators only read it, so one tape may be shared by threads.
 * The output is slot `root`. A pruned tape (tape_prune) borrows the
 * constant pool of the tape it came from and its instructions live in the
 * caller's buffer. */
typedef struct tape {
    const tape_insn *insn;
    uint32_t n, root;
    const tape_const *konst;
    uint32_t nconst;
    int owned; /* insn and konst were allocated by tape_builder_finish */
    uint32_t ntree; /* instructions requested while building, before sharing,
                       folding and dead-code removal (for statistics) */
} tape;

/* Forward-mode dual numbers for the gradient evaluators. */
typedef struct tape_dual {
    double v, d[3];
} tape_dual;
typedef struct tape_idual {
    interval v, d[3];
} tape_idual;

/* ---- Building ---------------------------------------------------------- */

enum tape_err {
    TAPE_OK = 0,
    TAPE_ENOMEM = -1,
    TAPE_ETOOBIG = -2,   /* more than TAPE_MAX_INSNS instructions */
    TAPE_EDOMAIN = -3,   /* a constant sub-expression is undefined or not finite */
    TAPE_EEXPONENT = -4, /* integer exponent beyond TAPE_MAX_POWI */
};
#define TAPE_MAX_INSNS (1u << 22)
#define TAPE_MAX_POWI 1024

const char *tape_strerror(int err);

typedef struct tape_builder tape_builder;

/* New empty builder; NULL when out of memory. Free with tape_builder_free. */
tape_builder *tape_builder_new(void);
void tape_builder_free(tape_builder *b); /* accepts NULL */

/* Each emitter returns the slot of the value (>= 0) or a negative tape_err.
 * Equal instructions are shared (hash-consing; + * min max are commutative),
 * operations on constants are folded, and a folded constant that is not
 * finite or undefined (exp(1000), 1/0, sqrt(-1)) is TAPE_EDOMAIN. */
int32_t tape_emit_const(tape_builder *b, double v, double lo, double hi);
/* axis 0, 1, 2 for x, y, z. */
int32_t tape_emit_var(tape_builder *b, int axis);
/* op is one of the unary ops NEG..TAN. */
int32_t tape_emit_unary(tape_builder *b, tape_op op, int32_t a);
/* op is one of ADD..MAX. */
int32_t tape_emit_binary(tape_builder *b, tape_op op, int32_t a, int32_t c);
/* base ^ exponent, also pow(base, exponent). An exact integer exponent
 * becomes squarings and multiplications (x^4 = square(square(x)), negative
 * ones a division of 1 by that); another exact constant becomes POWC (base
 * >= 0); e^u becomes exp(u); anything else is exp(exponent * log(base)),
 * defined for base > 0 only. */
int32_t tape_emit_pow(tape_builder *b, int32_t base, int32_t exponent);
/* True when slot s is a constant; *v receives its double. */
int tape_slot_is_const(const tape_builder *b, int32_t s, double *v);

/* Moves the instructions reachable from `root` into a new tape (dead code
 * dropped) and resets nothing else: free the builder afterwards. Returns
 * TAPE_OK or TAPE_ENOMEM. The caller frees *out with tape_free. */
int tape_builder_finish(tape_builder *b, int32_t root, tape *out);
/* Frees an owned tape's arrays; a borrowed (pruned) tape is left alone. */
void tape_free(tape *t);

/* ---- Evaluating -------------------------------------------------------- */
/* All evaluators are reentrant: `slots` is the caller's scratch of at least
 * t->n elements; nothing is allocated and no global state is touched. */

/* f(x, y, z) in double. NaN where f is undefined (sqrt(-1), 0/0); min/max
 * propagate NaN. */
double tape_eval(const tape *t, double x, double y, double z, double *slots);

/* f and its gradient at p by forward-mode AD; grad[3] receives df/dx,
 * df/dy, df/dz. abs/min/max use the derivative of the branch taken. */
double tape_eval_grad(const tape *t, const double p[3], double grad[3], tape_dual *slots);

/* tape_eval_grad at up to TAPE_LANES points at once, in structure-of-arrays
 * form: lane l of f and g is, bit for bit, tape_eval_grad at (x[l], y[l],
 * z[l]) for l < n (1 <= n <= TAPE_LANES). The arithmetic runs on every lane
 * (the compiler vectorises it), so one pass over the tape serves n points;
 * lanes from n on repeat lane 0. `slots` is the caller's scratch of t->n
 * elements (common/expr/tape_lanes.c). */
#define TAPE_LANES 8
typedef struct tape_dual_lanes {
    double v[TAPE_LANES], d[3][TAPE_LANES];
} tape_dual_lanes;
void tape_eval_grad_lanes(const tape *t, unsigned n, const double x[TAPE_LANES],
                          const double y[TAPE_LANES], const double z[TAPE_LANES],
                          double f[TAPE_LANES], double g[3][TAPE_LANES], tape_dual_lanes *slots);
/* tape_eval at up to TAPE_LANES points at once: lane l of f is, bit for bit,
 * tape_eval at (x[l], y[l], z[l]) (and tape_eval_grad_lanes's f) for l < n,
 * without the gradient's cost. `slots` as for tape_eval_grad_lanes (only
 * their values are written). */
void tape_eval_lanes(const tape *t, unsigned n, const double x[TAPE_LANES],
                     const double y[TAPE_LANES], const double z[TAPE_LANES], double f[TAPE_LANES],
                     tape_dual_lanes *slots);

/* Sound enclosure of f over the box box[0] x box[1] x box[2]; *flags
 * receives INTERVAL_MAYBE_NAN when f may be undefined somewhere in the box
 * (see interval.h: then the result encloses f only where it is defined,
 * and a NaN interval means defined nowhere). Slot i of `slots` receives the
 * enclosure of instruction i, for tape_prune. */
interval tape_eval_interval(const tape *t, const interval box[3], interval *slots, unsigned *flags);

/* tape_eval_interval on up to TAPE_LANES boxes at once: out[l] and flags[l]
 * are, bit for bit, tape_eval_interval's result and flags on box[l], for
 * l < n (1 <= n <= TAPE_LANES), and lane l of slots[i] its slot i (for
 * tape_prune). The cheap operations run on all lanes in one pass (vector
 * code), the libm ones lane by lane. `slots` is the caller's scratch of t->n
 * elements (common/expr/tape_ilanes.c). */
typedef struct tape_ilanes {
    double lo[TAPE_LANES], hi[TAPE_LANES];
} tape_ilanes;
void tape_eval_interval_lanes(const tape *t, unsigned n, const interval box[][3], interval out[],
                              unsigned flags[], tape_ilanes *slots);

/* The builds of the lane evaluators a run may choose from: the portable one
 * (the baseline instruction set) and, on x86-64 processors that have it,
 * AVX2. tape_lanes_path is the one in use (AVX2 where available, unless a
 * test build runs with DDA_SIMD=portable); tape_eval_interval_lanes_on runs
 * a given one (an available one: tape_lanes_path_available), for tests. */
enum { TAPE_PATH_PORTABLE = 0, TAPE_PATH_AVX2 = 1, TAPE_PATHS = 2 };
int tape_lanes_path(void);
int tape_lanes_path_available(int path);
const char *tape_lanes_path_name(int path);
void tape_eval_interval_lanes_on(int path, const tape *t, unsigned n,
                                 const interval box[][3], interval out[],
                                 unsigned flags[], tape_ilanes *slots);

/* Enclosures of f and of each partial derivative over the box (forward-mode
 * AD in interval arithmetic): for every p in the box where f is defined and
 * differentiable, grad f(p) lies in grad[0..2] (unless *flags is set). */
interval tape_eval_interval_grad(const tape *t, const interval box[3], interval grad[3],
                                 tape_idual *slots, unsigned *flags);

/* tape_eval_interval_grad on up to TAPE_LANES boxes at once: out[l],
 * grad[l] and flags[l] are, bit for bit, its results on box[l] for l < n
 * (1 <= n <= TAPE_LANES). `slots` is the caller's scratch of t->n elements
 * (common/expr/tape_iglanes.c); _on runs a given build, as
 * tape_eval_interval_lanes_on. */
typedef struct tape_idual_lanes {
    tape_ilanes v, d[3];
} tape_idual_lanes;
void tape_eval_interval_grad_lanes(const tape *t, unsigned n, const interval box[][3],
                                   interval out[], interval grad[][3], unsigned flags[],
                                   tape_idual_lanes *slots);
void tape_eval_interval_grad_lanes_on(int path, const tape *t, unsigned n,
                                      const interval box[][3], interval out[],
                                      interval grad[][3], unsigned flags[],
                                      tape_idual_lanes *slots);

/* ---- Pruning ----------------------------------------------------------- */

/* Shortens t for the box whose slot enclosures `slots` (from
 * tape_eval_interval over that box, with its `flags`) describe: a min or
 * max whose operands' enclosures do not overlap keeps only the winner, and
 * instructions no longer reachable are dropped. The result agrees with t
 * at every point of that box and its sub-boxes. When flags is nonzero (f
 * may be NaN somewhere) or slots is NULL, only dead code is removed.
 * `out_insn` and `scratch` are caller buffers of t->n elements each. *out
 * borrows t's constant pool and out_insn. Returns out->n. Two linear passes. */
uint32_t tape_prune(const tape *t, const interval *slots, unsigned flags, tape_insn *out_insn,
                    uint32_t *scratch, tape *out);

/* tape_prune, and more: every instruction whose enclosure over the box is
 * narrower than `tiny` (finite) becomes a constant holding that enclosure,
 * and whatever only it used is dropped — a far blob's exp(-50) is then one
 * constant. Sound on the box and its sub-boxes for every evaluator: the
 * pruned tape stands for the family of functions with that term anywhere in
 * its interval, and f is one of them at every point, so interval, gradient
 * and mean-value enclosures still hold f. The point value of such a constant
 * is its midpoint (off by at most tiny / 2). `out_konst` is a caller buffer
 * of t->nconst + t->n entries and becomes the pruned tape's constant pool.
 * With flags set nothing is replaced, as in tape_prune. */
uint32_t tape_prune_const(const tape *t, const interval *slots, unsigned flags, double tiny,
                          tape_insn *out_insn, tape_const *out_konst, uint32_t *scratch, tape *out);

/* Name of an op, for dumps. */
const char *tape_op_name(tape_op op);

#endif
