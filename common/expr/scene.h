/* scene: reader for .scene files (bounds, surface, color; docs/INTERFACE.md),
 * each surface expression compiled to a tape. */
#ifndef SCENE_H
#define SCENE_H

#include <stddef.h>

#include "common/expr/tape.h"

#define SCENE_MAX_LINE (1u << 20)  /* bytes in one line, comment included */
#define SCENE_MAX_FILE (64u << 20) /* bytes in one file */
#define SCENE_MAX_DEPTH 200        /* nesting of parentheses, unary minus, ^ */
#define SCENE_DEFAULT_COLOR 0.8    /* grey, for a surface without `color` */

/* Where and why a scene was rejected. line and col are 1-based (col counts
 * bytes); file-level problems (empty, unreadable, a directory) are at 1:1. */
typedef struct scene_error {
    unsigned line, col;
    char message[256];
} scene_error;

typedef struct scene_surface {
    tape tape;       /* f; the surface is f = 0. Owned by the scene. */
    double color[3]; /* R G B in 0..1 */
    unsigned line;   /* line of its `surface` statement */
} scene_surface;

typedef struct scene {
    double lo[3], hi[3]; /* bounds: lo < hi on each axis, both finite */
    size_t nsurfaces;    /* >= 1 */
    scene_surface *surfaces;
} scene;

/* Parses `len` bytes of scene text (need not be NUL-terminated). On
 * success returns 0 and *out (free with scene_free); on failure returns -1,
 * fills *err and leaves *out NULL. Prints nothing. */
int scene_parse(const char *text, size_t len, scene **out, scene_error *err);

/* Reads and parses the file at `path`; same contract as scene_parse. A
 * directory, an unreadable or empty file is an error too. */
int scene_load(const char *path, scene **out, scene_error *err);

/* Frees a scene and its tapes; accepts NULL. */
void scene_free(scene *s);

/* Prints "PATH:LINE:COL: message" on stderr (diag_at). For main() only. */
void scene_print_error(const char *path, const scene_error *err);

#endif
