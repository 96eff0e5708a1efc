/* exact_load: what `render --exact` needs of an opened file: its stored
 * tapes (format 1.1) prepared per coarse cell (exact_scene.h). */
#ifndef EXACT_LOAD_H
#define EXACT_LOAD_H

#include "format/oct.h"
#include "render/exact_scene.h"
#include "render/stored_tapes.h"

typedef struct exact_loaded {
    stored_tapes st; /* owned: the scene borrows them */
    exact_scene es;
} exact_loaded;

/* Loads f's stored tapes and prepares them for f's tree. Returns 0, or -1
 * with *why the message for "render: F.oct: <why>" (static text: "no stored
 * function (rasterize it again)" for a file without one, "out of memory");
 * *out then holds nothing. */
int exact_load(const oct_file *f, exact_loaded *out, const char **why);
void exact_loaded_free(exact_loaded *x); /* accepts a zeroed or freed one */

#endif
