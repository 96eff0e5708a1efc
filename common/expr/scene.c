/* scene: line-oriented reader for .scene files: bounds, surface and color
 * statements; each surface's EXPR goes to the parser in expr.c. */
#include "common/expr/scene.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/diag.h"
#include "common/expr/expr.h"

static void set_err(scene_error *err, unsigned line, unsigned col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void set_err(scene_error *err, unsigned line, unsigned col, const char *fmt, ...)
{
    err->line = line;
    err->col = col;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

/* Reads n signed numbers for bounds/color; positions into cols. */
static int read_numbers(expr_parser *p, const char *stmt, int n, double *v, size_t *cols)
{
    for (int i = 0; i < n; i++) {
        expr_skip_ws(p);
        size_t start = p->pos;
        int neg = 0;
        if (p->s[p->pos] == '-' || p->s[p->pos] == '+')
            neg = p->s[p->pos++] == '-';
        int exact, none;
        if (!expr_read_number(p, &v[i], &exact, &none)) {
            if (none) {
                char what[32];
                expr_describe(p, start, what, sizeof what);
                expr_fail_at(p, start, "%s needs %d numbers, found %s", stmt, n, what);
            }
            return 0;
        }
        if (neg)
            v[i] = -v[i];
        cols[i] = start;
    }
    expr_skip_ws(p);
    if (p->s[p->pos] != '\0') {
        char what[32];
        expr_describe(p, p->pos, what, sizeof what);
        expr_fail_at(p, p->pos, "unexpected %s after the %d numbers of %s", what, n, stmt);
        return 0;
    }
    return 1;
}

void scene_free(scene *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < s->nsurfaces; i++)
        tape_free(&s->surfaces[i].tape);
    free(s->surfaces);
    free(s);
}

/* bounds X0 Y0 Z0 X1 Y1 Z1, at most once; start is the keyword's offset. */
static void read_bounds(expr_parser *p, scene *sc, size_t start, int *have_bounds,
                        unsigned *bounds_line)
{
    if (*have_bounds) {
        expr_fail_at(p, start, "bounds already given on line %u", *bounds_line);
        return;
    }
    double v[6];
    size_t cols[6];
    if (!read_numbers(p, "bounds", 6, v, cols))
        return;
    for (int a = 0; a < 3; a++)
        if (!(v[a + 3] > v[a])) {
            expr_fail_at(p, cols[a + 3], "empty bounds: %c1 (%g) must be greater than %c0 (%g)",
                         'X' + a, v[a + 3], 'X' + a, v[a]);
            return;
        }
    for (int a = 0; a < 3; a++) {
        sc->lo[a] = v[a];
        sc->hi[a] = v[a + 3];
    }
    sc->bounds_line = p->line;
    sc->bounds_col[0] = (unsigned)start + 1;
    for (int i = 0; i < 6; i++)
        sc->bounds_col[i + 1] = (unsigned)cols[i] + 1;
    *have_bounds = 1;
    *bounds_line = p->line;
}

/* surface EXPR: compiles EXPR to a tape and appends the surface, grey
 * until a color follows. *cap is the allocated length of sc->surfaces. */
static void read_surface(expr_parser *p, scene *sc, size_t start, int *has_color, size_t *cap)
{
    if (sc->nsurfaces == *cap) {
        size_t nc = *cap ? *cap * 2 : 4;
        scene_surface *ns = realloc(sc->surfaces, nc * sizeof *ns);
        if (!ns) {
            expr_fail_at(p, start, "out of memory");
            return;
        }
        sc->surfaces = ns;
        *cap = nc;
    }
    p->b = tape_builder_new();
    if (!p->b) {
        expr_fail_at(p, start, "out of memory");
        return;
    }
    if (p->s[p->pos] != ' ' && p->s[p->pos] != '\t' && p->s[p->pos] != '\0') {
        char what[32];
        expr_describe(p, p->pos, what, sizeof what);
        expr_fail_at(p, p->pos, "unexpected %s after 'surface'", what);
        goto done;
    }
    int32_t root = expr_parse(p);
    if (root < 0)
        goto done;
    expr_skip_ws(p);
    if (p->s[p->pos] != '\0') {
        char what[32];
        expr_describe(p, p->pos, what, sizeof what);
        if (p->s[p->pos] == ')')
            expr_fail_at(p, p->pos, "unmatched ')'");
        else
            expr_fail_at(p, p->pos, "unexpected %s after the expression", what);
        goto done;
    }
    scene_surface *sf = &sc->surfaces[sc->nsurfaces];
    if (tape_builder_finish(p->b, root, &sf->tape) != TAPE_OK) {
        expr_fail_at(p, start, "out of memory");
        goto done;
    }
    sf->color[0] = sf->color[1] = sf->color[2] = SCENE_DEFAULT_COLOR;
    sf->line = p->line;
    sf->col = (unsigned)start + 1;
    sc->nsurfaces++;
    *has_color = 0;
done:
    tape_builder_free(p->b);
    p->b = NULL;
}

/* color R G B, for the surface just above, at most once. */
static void read_color(expr_parser *p, scene *sc, size_t start, int *has_color)
{
    if (sc->nsurfaces == 0) {
        expr_fail_at(p, start, "color before any surface");
        return;
    }
    if (*has_color) {
        expr_fail_at(p, start, "the surface on line %u already has a color",
                     sc->surfaces[sc->nsurfaces - 1].line);
        return;
    }
    double v[3];
    size_t cols[3];
    if (!read_numbers(p, "color", 3, v, cols))
        return;
    for (int i = 0; i < 3; i++)
        if (!(v[i] >= 0.0 && v[i] <= 1.0)) {
            expr_fail_at(p, cols[i], "color component %g outside 0..1", v[i]);
            return;
        }
    memcpy(sc->surfaces[sc->nsurfaces - 1].color, v, sizeof v);
    *has_color = 1;
}

/* Parses one statement line (comment already removed) into sc. */
static void parse_line(expr_parser *p, scene *sc, int *have_bounds, unsigned *bounds_line,
                       int *has_color, size_t *cap)
{
    expr_skip_ws(p);
    size_t start = p->pos;
    if (p->s[start] == '\0')
        return;
    size_t n = 0;
    while (expr_is_alnum(p->s[start + n]))
        n++;
    const char *w = p->s + start;
    p->pos = start + n;
    if (n == 6 && memcmp(w, "bounds", 6) == 0) {
        read_bounds(p, sc, start, have_bounds, bounds_line);
    } else if (n == 7 && memcmp(w, "surface", 7) == 0) {
        read_surface(p, sc, start, has_color, cap);
    } else if (n == 5 && memcmp(w, "color", 5) == 0) {
        read_color(p, sc, start, has_color);
    } else if (n > 0) {
        expr_fail_at(p, start, "unknown statement '%.*s' (expected bounds, surface or color)",
                     (int)(n > 64 ? 64 : n), w);
    } else {
        char what[32];
        expr_describe(p, start, what, sizeof what);
        expr_fail_at(p, start, "expected bounds, surface or color, found %s", what);
    }
}

int scene_parse(const char *text, size_t len, scene **out, scene_error *err)
{
    *out = NULL;
    memset(err, 0, sizeof *err);
    char *buf = NULL;
    scene *sc = calloc(1, sizeof *sc);
    expr_parser p = {0};
    p.err = err;
    if (!sc) {
        set_err(err, 1, 1, "out of memory");
        goto fail;
    }
    if (len == 0) {
        set_err(err, 1, 1, "empty file");
        goto fail;
    }
    int have_bounds = 0, has_color = 0;
    unsigned bounds_line = 0;
    size_t cap = 0;
    size_t off = 0;
    for (unsigned line = 1; off < len; line++) {
        const char *nl = memchr(text + off, '\n', len - off);
        size_t n = nl ? (size_t)(nl - (text + off)) : len - off;
        if (n > SCENE_MAX_LINE) {
            set_err(err, line, SCENE_MAX_LINE + 1, "line longer than %u bytes", SCENE_MAX_LINE);
            goto fail;
        }
        const unsigned char *l = (const unsigned char *)text + off;
        size_t stmt = n; /* bytes before a comment */
        for (size_t i = 0; i < n; i++) {
            unsigned char c = l[i];
            int ok = c >= 0x20 ? c != 0x7f : (c == '\t' || (c == '\r' && i + 1 == n));
            if (!ok) {
                set_err(err, line, (unsigned)i + 1, "not a text file: byte 0x%02x", c);
                goto fail;
            }
            if (c == '#' && stmt == n)
                stmt = i;
        }
        free(buf);
        buf = malloc(stmt + 1);
        if (!buf) {
            set_err(err, line, 1, "out of memory");
            goto fail;
        }
        memcpy(buf, l, stmt);
        buf[stmt] = '\0';
        p.s = buf;
        p.pos = 0;
        p.line = line;
        p.depth = 0;
        parse_line(&p, sc, &have_bounds, &bounds_line, &has_color, &cap);
        if (p.failed)
            goto fail;
        off += n + (nl ? 1 : 0);
    }
    if (!have_bounds) {
        set_err(err, 1, 1, "missing 'bounds' statement");
        goto fail;
    }
    if (sc->nsurfaces == 0) {
        set_err(err, 1, 1, "missing 'surface' statement");
        goto fail;
    }
    free(buf);
    *out = sc;
    return 0;
fail:
    free(buf);
    scene_free(sc);
    return -1;
}

int scene_load(const char *path, scene **out, scene_error *err)
{
    *out = NULL;
    memset(err, 0, sizeof *err);
    char *text = NULL;
    int rc = -1;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        set_err(err, 1, 1, "cannot open: %s", strerror(errno));
        goto done;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        set_err(err, 1, 1, "cannot stat: %s", strerror(errno));
        goto done;
    }
    if (S_ISDIR(st.st_mode)) {
        set_err(err, 1, 1, "is a directory, not a scene file");
        goto done;
    }
    size_t cap = 4096, len = 0;
    text = malloc(cap);
    if (!text) {
        set_err(err, 1, 1, "out of memory");
        goto done;
    }
    for (;;) {
        if (len == cap) {
            if (len > SCENE_MAX_FILE) { /* reads stop one byte past the limit */
                set_err(err, 1, 1, "file larger than %u bytes (%u MiB)", SCENE_MAX_FILE,
                        SCENE_MAX_FILE >> 20);
                goto done;
            }
            size_t nc = cap * 2 > (size_t)SCENE_MAX_FILE + 1 ? (size_t)SCENE_MAX_FILE + 1 : cap * 2;
            char *t = realloc(text, nc);
            if (!t) {
                set_err(err, 1, 1, "out of memory");
                goto done;
            }
            text = t;
            cap = nc;
        }
        ssize_t r = read(fd, text + len, cap - len);
        if (r < 0) {
            if (errno == EINTR)
                continue;
            set_err(err, 1, 1, "cannot read: %s", strerror(errno));
            goto done;
        }
        if (r == 0)
            break;
        len += (size_t)r;
    }
    rc = scene_parse(text, len, out, err);
done:
    if (fd >= 0)
        close(fd);
    free(text);
    return rc;
}

void scene_print_error(const char *path, const scene_error *err)
{
    diag_at(path, err->line, err->col, "%s", err->message);
}
