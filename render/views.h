/* views: the view options shared by the command line and views files, the
 * views-file parser and the --orbit generator.
 *
 * Views file format: one view a line; '#' starts a comment; blank lines are
 * skipped. A line is whitespace-separated options with the same names and
 * value syntax as the command line:
 *     -o OUT.png [--eye X,Y,Z] [--target X,Y,Z] [--up X,Y,Z] [--fov DEG]
 *     [--size WxH] [--depth OUT.pfm] [--normals OUT.png] [--exact]
 *     [--aa N] [--ao N] [--ao-distance F] [--alpha] [--shadows]
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
    long aa;             /* 1..VIEWS_AA_MAX samples a side where needed */
    long ao;             /* ambient occlusion rays, 0..VIEWS_AO_MAX */
    double ao_distance;  /* their length in cube edges, (0, VIEWS_AO_DISTANCE_MAX] */
    int alpha, shadows;  /* flags */
    int exact;           /* --exact: hits placed by the stored functions */
    unsigned line;       /* views-file line (1-based), 0 for the command line */
} views_view;

#define VIEWS_AA_MAX 16    /* render/aa.h's AA_MAX */
#define VIEWS_AO_MAX 4096  /* render/ao.h's AO_MAX_RAYS */
#define VIEWS_AO_DISTANCE 0.125  /* --ao-distance's default: 1/8 of the cube's edge */
#define VIEWS_AO_DISTANCE_MAX 2 /* past the cube's diagonal (sqrt 3): no limit */

/* The built-in defaults: 512x512, up 0,0,1, fov 30, AO rays 1/8 of the
 * cube's edge long; eye and target unset (the caller frames the cube); no
 * outputs. */
void views_defaults(views_view *v);

/* 1 when `name` is a per-view option that takes a value. */
int views_is_option(const char *name);

/* 1 when `name` is a per-view flag (no value): --alpha, --shadows, --exact; sets it
 * in v when v is not NULL. */
int views_flag(views_view *v, const char *name);

/* A view's outputs that cannot work together (--alpha needs a .png output).
 * Returns 0, or -1 with a message in msg (size n). */
int views_check(const views_view *v, char *msg, size_t n);

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
 * optional flags "0-+ " and a width of at most NAME_MAX, e.g. %04d) and
 * otherwise only "%%"; -2 for a wider width, -1 otherwise. */
int views_check_pattern(const char *pattern);

typedef enum views_orbit_err {
    VIEWS_ORBIT_OK,
    VIEWS_ORBIT_PATTERN, /* not one integer conversion */
    VIEWS_ORBIT_WIDTH,   /* a field width over NAME_MAX */
    VIEWS_ORBIT_NAME,    /* a formatted name of PATH_MAX bytes or more */
    VIEWS_ORBIT_AXIS,    /* the eye lies on the up axis */
    VIEWS_ORBIT_NOMEM,
} views_orbit_err;

const char *views_orbit_strerror(views_orbit_err e);

/* n views on a circle around base's target, about its up axis, at the eye's
 * distance from the up axis and its height along it, starting at the eye.
 * Outputs are pattern formatted with the frame number (0..n-1), written into
 * one malloc'ed block owned by the array stored in *out (free the array
 * only). Depth and normals are not written. Returns VIEWS_ORBIT_OK, or the
 * reason with *out NULL. */
views_orbit_err views_orbit(const views_view *base, unsigned n, const char *pattern,
                            views_view **out);

/* Views-file limits, as the scene reader has its own: a views file is read
 * whole, and a hostile one (or /dev/urandom) must not take the memory. */
#define VIEWS_MAX_FILE 16777216 /* bytes in one views file (16 MiB) */
#define VIEWS_MAX_LINE 65536    /* bytes in one line, comment included */

/* Reads the views file at path (at most VIEWS_MAX_FILE bytes, lines of at
 * most VIEWS_MAX_LINE bytes, no NUL byte) into a malloc'ed NUL-terminated
 * *text. Returns 0; or -1 with errno (I/O; ENOMEM); or -2 for a file over
 * the limits, with *line, *col (1-based) and *msg (static) saying where and
 * what. */
int views_read_file(const char *path, char **text, unsigned *line, unsigned *col,
                    const char **msg);

/* The same checks on text already in memory (n bytes): 0, or -2 as above. */
int views_check_text(const char *text, size_t n, unsigned *line, unsigned *col, const char **msg);

#endif
