/* scene_oct: see scene_oct.h. */
#include "bench/scene_oct.h"

#include "common/diag.h"

int scene_oct_open(const char *scene_path, const char *oct_path, scene **sc, oct_file **f)
{
    *sc = NULL;
    *f = NULL;
    scene_error se;
    if (scene_load(scene_path, sc, &se) != 0) {
        scene_print_error(scene_path, &se);
        return EXIT_RUNTIME;
    }
    oct_err err = oct_open(oct_path, 0, f, NULL);
    if (err != OCT_OK) {
        diag_error("%s: %s", oct_path, oct_strerror(err));
        scene_free(*sc);
        *sc = NULL;
        return EXIT_RUNTIME;
    }
    return EXIT_OK;
}
