/* views: the view options shared by the command line and views files, the
 * views-file parser and the --orbit generator.
 *
 * Views file format: one view a line; '#' starts a comment; blank lines are
 * skipped. A line is whitespace-separated options with the same names and
 * value syntax as the command line:
 *     -o OUT.png [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z] [--fov DEG]
 *     [--size WxH] [--depth OUT.pfm] [--normals OUT.png] [--exact]
 * Options a line leaves out take the command line's values (or the
 * defaults). Paths cannot contain whitespace or '#'. Every line needs -o.
 * Relative paths are taken as they are (relative to the working directory). */
#ifndef VIEWS_H
#define VIEWS_H

#include <stddef.h>

typedef struct views_view {
    double eye[3], target[3], up[3];
    double fov;          /* degrees */
    long width, height;  /* pixels */
    int has_eye, has_target;
    const char *out;     /* PNG path (required) */
    const char *depth;   /* PFM path or NULL */
    const char *normals; /* PNG path or NULL */
    int exact;           /* --exact: hits placed by the stored functions */
    unsigned line;       /* views-file line (1-based), 0 for the command line */
} views_view;

/* The built-in defaults: 512x512, up 0,0,1, fov 30; eye and target unset
 * (the caller frames the cube); no outputs. */
void views_defaults(views_view *v);

/* 1 when `name` is a per-view option that takes a value. */
int views_is_option(const char *name);
/* The field of a per-view flag (no value: --exact) in v, or NULL. */
int *views_flag(views_view *v, const char *name);

/* Applies option `name` with `value` to v. `value` must outlive v (paths
 * are not copied). Returns 0, or -1 with a message in msg (size n). */
int views_apply(views_view *v, const char *name, const char *value, char *msg, size_t n);

/* Reports one bad line (1-based line number, message). */
typedef void (*views_report_fn)(void *ctx, unsigned line, const char *msg);

/* Parses the views file `text` (NUL-terminated, modified in place: the views
 * point into it). Each view starts as a copy of `base`. On success returns 0
 * with *out a malloc'ed array of *count views (caller frees the array; text
 * must outlive it). When any line is bad, every bad line is reported, *out is
 * NULL and -1 is returned. -2 on allocation failure. An empty file gives 0
 * views (the caller decides whether that is an error). */
int views_parse(char *text, const views_view *base, views_view **out, size_t *count,
                views_report_fn report, void *ctx);

/* 0 when `pattern` holds exactly one integer conversion (%d, %i, %u with
 * optional flags "0-+ " and width, e.g. %04d) and otherwise only "%%";
 * -1 otherwise. */
int views_check_pattern(const char *pattern);

/* n views on a circle around base's target, about its up axis, at the eye's
 * distance from the up axis and its height along it, starting at the eye.
 * Outputs are pattern formatted with the frame number (0..n-1), written into
 * one malloc'ed block owned by the returned array (free the array only).
 * Depth and normals are not written. NULL on allocation failure or when the
 * eye lies on the axis. */
views_view *views_orbit(const views_view *base, unsigned n, const char *pattern);

#endif
