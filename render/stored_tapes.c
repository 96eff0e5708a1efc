/* stored_tapes: the file's validated FUNCTION section decoded into tapes. */
#include "render/stored_tapes.h"

#include <stdlib.h>

#include "common/expr/tape_io.h"

int stored_tapes_load(const oct_file *f, stored_tapes *out)
{
    out->count = 0;
    out->tapes = NULL;
    const oct_function_tape *fn = oct_get_function(f);
    if (!fn)
        return STORED_TAPES_NONE;
    const unsigned n = oct_get_tree(f)->surface_count;
    tape *t = calloc(n, sizeof *t);
    if (!t)
        return STORED_TAPES_NOMEM;
    for (unsigned s = 0; s < n; s++) {
        int rc = tape_io_decode(fn[s].insn, fn[s].insn_count, fn[s].konst, fn[s].const_count,
                                fn[s].root, &t[s]);
        if (rc != TAPE_OK) {
            for (unsigned k = 0; k < s; k++)
                tape_free(&t[k]);
            free(t);
            return rc == TAPE_ENOMEM ? STORED_TAPES_NOMEM : STORED_TAPES_INVALID;
        }
    }
    out->count = n;
    out->tapes = t;
    return STORED_TAPES_OK;
}

void stored_tapes_free(stored_tapes *st)
{
    for (unsigned s = 0; s < st->count; s++)
        tape_free(&st->tapes[s]);
    free(st->tapes);
    st->count = 0;
    st->tapes = NULL;
}

const char *stored_tapes_strerror(int err)
{
    switch (err) {
    case STORED_TAPES_OK: return "ok";
    case STORED_TAPES_NONE: return "no stored function (rasterize it again)";
    case STORED_TAPES_NOMEM: return "out of memory";
    default: return "corrupt: invalid function section";
    }
}
