/* exact_load: stored tapes -> exact_scene. */
#include "render/exact_load.h"

#include <string.h>

int exact_load(const oct_file *f, exact_loaded *out, const char **why)
{
    memset(out, 0, sizeof *out);
    const int rc = stored_tapes_load(f, &out->st);
    if (rc != STORED_TAPES_OK) {
        *why = stored_tapes_strerror(rc);
        return -1;
    }
    if (exact_scene_init(&out->es, oct_get_tree(f), out->st.tapes, EXACT_CELL_DEPTH) != 0) {
        stored_tapes_free(&out->st);
        *why = "out of memory";
        return -1;
    }
    return 0;
}

void exact_loaded_free(exact_loaded *x)
{
    exact_scene_free(&x->es);
    stored_tapes_free(&x->st);
}
