/* scene_limits: what a parsed scene must also satisfy to become an .oct file
 * at a given --levels (the cube rule of format/FORMAT.md §6, at most
 * OCT_MAX_SURFACES surfaces), reported as FILE:LINE:COL scene errors. */
#ifndef SCENE_LIMITS_H
#define SCENE_LIMITS_H

#include "common/expr/scene.h"

/* Returns 0 when the scene fits; else fills *err (the line and column of the
 * offending `bounds` value or `surface` statement) and returns -1. */
int scene_limits_check(const scene *sc, unsigned levels, scene_error *err);

#endif
