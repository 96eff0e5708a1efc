/* tape_lanes_inst.h: the lane gradient evaluator for 2, 4, 6 and 8 lanes
 * (tape_lanes_body.h) and its entry NAME, which takes the fewest lanes that
 * hold n (the arithmetic runs on every lane); likewise the value evaluator
 * (tape_vlanes_body.h) and its entry NAME_value. Included by one build's file
 * (tape_lanes.c, tape_lanes_avx2.c) with NAME defined. */
#include <math.h>
#include <string.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/tape_int.h"

#define L TAPE_LANES

/* Lanes from n on take lane 0's value (their points repeat lane 0's). */
static void fill(double *v, unsigned n)
{
    for (unsigned l = n; l < L; l++)
        v[l] = v[0];
}

#define W 2
#define FN CAT(NAME, _2)
#define SCALE CAT(NAME, _scale2)
#include "common/expr/tape_lanes_body.h"
#undef FN
#define FN CAT(NAME, _value2)
#include "common/expr/tape_vlanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 4
#define FN CAT(NAME, _4)
#define SCALE CAT(NAME, _scale4)
#include "common/expr/tape_lanes_body.h"
#undef FN
#define FN CAT(NAME, _value4)
#include "common/expr/tape_vlanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 6
#define FN CAT(NAME, _6)
#define SCALE CAT(NAME, _scale6)
#include "common/expr/tape_lanes_body.h"
#undef FN
#define FN CAT(NAME, _value6)
#include "common/expr/tape_vlanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 8
#define FN CAT(NAME, _8)
#define SCALE CAT(NAME, _scale8)
#include "common/expr/tape_lanes_body.h"
#undef FN
#define FN CAT(NAME, _value8)
#include "common/expr/tape_vlanes_body.h"
#undef W
#undef FN
#undef SCALE

void NAME(const tape *t, unsigned n, const double x[L], const double y[L], const double z[L],
          double f[L], double g[3][L], tape_dual_lanes *s)
{
    if (n <= 2)
        CAT(NAME, _2)(t, n, x, y, z, f, g, s);
    else if (n <= 4)
        CAT(NAME, _4)(t, n, x, y, z, f, g, s);
    else if (n <= 6)
        CAT(NAME, _6)(t, n, x, y, z, f, g, s);
    else
        CAT(NAME, _8)(t, n, x, y, z, f, g, s);
}

void CAT(NAME, _value)(const tape *t, unsigned n, const double x[L], const double y[L],
                      const double z[L], double f[L], tape_dual_lanes *s)
{
    if (n <= 2)
        CAT(NAME, _value2)(t, n, x, y, z, f, s);
    else if (n <= 4)
        CAT(NAME, _value4)(t, n, x, y, z, f, s);
    else if (n <= 6)
        CAT(NAME, _value6)(t, n, x, y, z, f, s);
    else
        CAT(NAME, _value8)(t, n, x, y, z, f, s);
}

#undef L
