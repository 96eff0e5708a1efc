/* scene_util: scene files for the test suites (cmocka). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "tests/scene_util.h"

scene *test_scene_load(const char *path)
{
    scene *sc = NULL;
    scene_error err;
    if (scene_load(path, &sc, &err) != 0)
        fail_msg("%s:%u:%u: %s", path, err.line, err.col, err.message);
    return sc;
}
