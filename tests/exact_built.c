/* exact_built: scenes rasterized in memory for the --exact suites (cmocka). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/tape_io.h"
#include "rasterize/build.h"
#include "tests/exact_built.h"

void exact_built_make(const char *text, unsigned levels, unsigned depth, exact_built *b)
{
    memset(b, 0, sizeof *b);
    scene_error err;
    assert_int_equal(scene_parse(text, strlen(text), &b->sc, &err), 0);
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(b->sc, levels, palette, &wp);
    const tape *tp[OCT_MAX_SURFACES];
    for (size_t s = 0; s < b->sc->nsurfaces; s++)
        tp[s] = &b->sc->surfaces[s].tape;
    unsigned char *fn = NULL;
    assert_int_equal(tape_io_encode(tp, (unsigned)b->sc->nsurfaces, &fn, &wp.function_size), TAPE_OK);
    wp.function = fn;
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    build_params bp = {.levels = levels, .method = BUILD_INTERVAL, .threads = 2};
    build_stats st;
    assert_int_equal(build_octree(b->sc, &bp, w, &st), OCT_OK);
    FILE *mem = open_memstream(&b->bytes, &b->size);
    assert_non_null(mem);
    uint64_t n = 0;
    assert_int_equal(oct_writer_finish(w, mem, &n), OCT_OK);
    assert_int_equal(fclose(mem), 0);
    oct_writer_free(w);
    free(fn);
    uint64_t off = 0;
    assert_int_equal(oct_open_memory(b->bytes, b->size, 0, &b->file, &off), OCT_OK);
    b->tree = oct_get_tree(b->file);
    assert_int_equal(stored_tapes_load(b->file, &b->st), STORED_TAPES_OK);
    assert_int_equal(b->st.count, b->sc->nsurfaces);
    assert_int_equal(exact_scene_init(&b->es, b->tree, b->st.tapes, depth), 0);
}

void exact_built_free(exact_built *b)
{
    exact_scene_free(&b->es);
    stored_tapes_free(&b->st);
    oct_close(b->file);
    free(b->bytes);
    scene_free(b->sc);
}
