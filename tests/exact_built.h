/* exact_built: a scene rasterized in memory into a format 1.1 file, opened
 * with its stored tapes and prepared for --exact (render/exact_scene.h), as
 * render does it; for the --exact suites. */
#ifndef TESTS_EXACT_BUILT_H
#define TESTS_EXACT_BUILT_H

#include <stddef.h>

#include "common/expr/scene.h"
#include "format/oct.h"
#include "render/exact_scene.h"
#include "render/stored_tapes.h"

typedef struct exact_built {
    scene *sc;
    char *bytes;
    size_t size;
    oct_file *file;
    const oct_tree *tree;
    stored_tapes st; /* the file's own tapes, as render loads them */
    exact_scene es;
} exact_built;

/* The scene `text` at `levels`, coarse cells of depth `depth`; a failure
 * fails the running test. */
void exact_built_make(const char *text, unsigned levels, unsigned depth, exact_built *b);
void exact_built_free(exact_built *b);

#endif
