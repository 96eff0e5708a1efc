/* tape_ilanes_inst.h: the lane interval evaluator for 4 and 8 lanes and
 * its entry NAME, included by one build's file with NAME defined. */
#define W 4
#define FN CAT(NAME, _4)
#include "common/expr/tape_ilanes_body.h"
#undef W
#undef FN
#define W 8
#define FN CAT(NAME, _8)
#include "common/expr/tape_ilanes_body.h"
#undef W
#undef FN
TAPE_ILANES_DEFINE(NAME, tape_ilanes)
