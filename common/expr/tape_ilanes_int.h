/* tape_ilanes_int.h: what the two builds of the lane evaluators (interval:
 * tape_ilanes.c, gradient: tape_lanes.c) share (private to common/expr/): bit-pattern tests and steps that
 * vectorise, and the entry each build defines. */
#ifndef TAPE_ILANES_INT_H
#define TAPE_ILANES_INT_H

#include <stdint.h>
#include <string.h>

#include "common/expr/interval_lanes.h"
#include "common/expr/tape_int.h"
#include "common/expr/tape.h"

#define IL_CAT2(a, b) a##b
#define CAT(a, b) IL_CAT2(a, b)

/* The AVX2 build exists on x86-64 with a GCC-compatible compiler. */
#if defined(__x86_64__) && defined(__GNUC__)
#define TAPE_ILANES_AVX2 1
#else
#define TAPE_ILANES_AVX2 0
#endif

static inline interval il_get(const tape_ilanes *v, unsigned l)
{
    interval r = {v->lo[l], v->hi[l]};
    return r;
}
static inline void il_set(tape_ilanes *v, unsigned l, interval x)
{
    v->lo[l] = x.lo;
    v->hi[l] = x.hi;
}

/* The first of v's lanes 0..l whose ends have the bits of lane l's (l
 * itself when no earlier one does). */
static inline unsigned il_first_same(const tape_ilanes *v, unsigned l)
{
    uint64_t lo, hi;
    memcpy(&lo, &v->lo[l], sizeof lo);
    memcpy(&hi, &v->hi[l], sizeof hi);
    for (unsigned j = 0; j < l; j++) {
        uint64_t a, b;
        memcpy(&a, &v->lo[j], sizeof a);
        memcpy(&b, &v->hi[j], sizeof b);
        if (a == lo && b == hi)
            return j;
    }
    return l;
}

static inline tape_idual igl_get(const tape_idual_lanes *v, unsigned l)
{
    tape_idual r = {il_get(&v->v, l), {il_get(&v->d[0], l), il_get(&v->d[1], l), il_get(&v->d[2], l)}};
    return r;
}
static inline void igl_set(tape_idual_lanes *v, unsigned l, const tape_idual *x)
{
    il_set(&v->v, l, x->v);
    for (int j = 0; j < 3; j++)
        il_set(&v->d[j], l, x->d[j]);
}

/* The boxes in lanes for one pass: lanes n.. repeat lane 0 up to the pass's
 * width (4 or TAPE_LANES), so every lane of the pass computes a real box. */
static inline void il_boxes_in_lanes(unsigned n, const interval box[][3], tape_ilanes b[3])
{
    const unsigned w = n <= 4 ? 4 : TAPE_LANES;
    for (unsigned k = 0; k < 3; k++)
        for (unsigned l = 0; l < w; l++) {
            const interval *src = &box[l < n ? l : 0][k];
            b[k].lo[l] = src->lo;
            b[k].hi[l] = src->hi;
        }
}

/* One build's evaluator: tape_eval_interval_lanes with the boxes already in
 * lanes (lanes n.. repeating lane 0) and fl[] cleared. */
void tape_ilanes_portable(const tape *t, unsigned n, const tape_ilanes box[3],
                          unsigned fl[TAPE_LANES], tape_ilanes *slots);
#if TAPE_ILANES_AVX2
void tape_ilanes_avx2(const tape *t, unsigned n, const tape_ilanes box[3],
                      unsigned fl[TAPE_LANES], tape_ilanes *slots);
#endif

/* The lane gradient evaluator's builds (tape_lanes.c, tape_lanes_avx2.c):
 * tape_eval_grad_lanes on one of them. */
void tape_grad_lanes_portable(const tape *t, unsigned n, const double x[TAPE_LANES],
                              const double y[TAPE_LANES], const double z[TAPE_LANES],
                              double f[TAPE_LANES], double g[3][TAPE_LANES], tape_dual_lanes *s);
#if TAPE_ILANES_AVX2
void tape_grad_lanes_avx2(const tape *t, unsigned n, const double x[TAPE_LANES],
                          const double y[TAPE_LANES], const double z[TAPE_LANES],
                          double f[TAPE_LANES], double g[3][TAPE_LANES], tape_dual_lanes *s);
#endif
/* The lane value evaluator's builds: tape_eval_lanes on one of them. */
void tape_grad_lanes_portable_value(const tape *t, unsigned n, const double x[TAPE_LANES],
                                    const double y[TAPE_LANES], const double z[TAPE_LANES],
                                    double f[TAPE_LANES], tape_dual_lanes *s);
#if TAPE_ILANES_AVX2
void tape_grad_lanes_avx2_value(const tape *t, unsigned n, const double x[TAPE_LANES],
                                const double y[TAPE_LANES], const double z[TAPE_LANES],
                                double f[TAPE_LANES], tape_dual_lanes *s);
#endif

/* The lane interval gradient evaluator's builds (tape_iglanes.c,
 * tape_iglanes_avx2.c), with the boxes in lanes as above. */
void tape_iglanes_portable(const tape *t, unsigned n, const tape_ilanes box[3],
                           unsigned fl[TAPE_LANES], tape_idual_lanes *slots);
#if TAPE_ILANES_AVX2
void tape_iglanes_avx2(const tape *t, unsigned n, const tape_ilanes box[3],
                       unsigned fl[TAPE_LANES], tape_idual_lanes *slots);
#endif

/* The definitions of one build (NAME its entry), from tape_ilanes_body.h
 * or tape_iglanes_body.h (SLOT the slot type). */
#define TAPE_ILANES_DEFINE(NAME, SLOT)                                                        \
    void NAME(const tape *t, unsigned n, const tape_ilanes box[3], unsigned fl[TAPE_LANES],    \
              SLOT *slots)                                                                    \
    {                                                                                         \
        if (n <= 4)                                                                           \
            CAT(NAME, _4)(t, n, box, fl, slots);                                              \
        else                                                                                  \
            CAT(NAME, _8)(t, n, box, fl, slots);                                              \
    }

#endif
