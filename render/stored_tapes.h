/* stored_tapes: the surface functions an .oct file carries (format 1.1's
 * FUNCTION section), as tapes the renderer can evaluate (--exact). */
#ifndef STORED_TAPES_H
#define STORED_TAPES_H

#include "common/expr/tape.h"
#include "format/oct.h"

typedef struct stored_tapes {
    unsigned count; /* the file's surface_count: tapes[s] is surface s (palette order) */
    tape *tapes;    /* owned; the whole tape of each surface */
} stored_tapes;

enum {
    STORED_TAPES_OK = 0,
    STORED_TAPES_NONE = 1,   /* the file stores no function (a 1.0 file, or none written) */
    STORED_TAPES_NOMEM = 2,
    STORED_TAPES_INVALID = 3 /* cannot happen on a file oct_open accepted */
};

/* Decodes every stored tape of the opened file `f` into *out. On failure
 * *out is empty (count 0, tapes NULL). */
int stored_tapes_load(const oct_file *f, stored_tapes *out);
void stored_tapes_free(stored_tapes *st); /* accepts an empty one */

/* The message for a failure, e.g. "no stored function (rasterize it again)". */
const char *stored_tapes_strerror(int err);

#endif
