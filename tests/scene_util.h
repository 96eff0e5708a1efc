/* scene_util: scene files for the test suites. */
#ifndef TESTS_SCENE_UTIL_H
#define TESTS_SCENE_UTIL_H

#include "common/expr/scene.h"

/* The scene at path; a load error fails the running test with the
 * scene's FILE:LINE:COL message. */
scene *test_scene_load(const char *path);

#endif
