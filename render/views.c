/* views: per-view options, views files, orbits. */
#include "render/views.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "common/view/camera.h"
#include "common/limits.h"
#include "common/parse_num.h"

void views_defaults(views_view *v)
{
    memset(v, 0, sizeof *v);
    v->up[2] = 1.0;
    v->fov = 30.0;
    v->width = 512;
    v->height = 512;
    v->aa = 1;
    v->ao_distance = VIEWS_AO_DISTANCE;
}

static const char *const value_opts[] = {"-o", "--eye", "--target", "--up", "--fov",
                                         "--size", "--depth", "--normals", "--aa", "--ao",
                                         "--ao-distance"};

int views_is_option(const char *name)
{
    for (size_t i = 0; i < sizeof value_opts / sizeof value_opts[0]; i++)
        if (strcmp(name, value_opts[i]) == 0)
            return 1;
    return 0;
}

int views_flag(views_view *v, const char *name)
{
    int *f = NULL, dummy = 0;
    if (strcmp(name, "--alpha") == 0)
        f = v ? &v->alpha : &dummy;
    else if (strcmp(name, "--shadows") == 0)
        f = v ? &v->shadows : &dummy;
    else if (strcmp(name, "--exact") == 0)
        f = v ? &v->exact : &dummy;
    if (!f)
        return 0;
    *f = 1;
    return 1;
}

int views_check(const views_view *v, char *msg, size_t n)
{
    size_t len = v->out ? strlen(v->out) : 0;
    if (v->alpha && !(len >= 4 && strcasecmp(v->out + len - 4, ".png") == 0)) {
        snprintf(msg, n, "--alpha: '%s': the output must be a PNG (name ending in .png)",
                 v->out ? v->out : "");
        return -1;
    }
    return 0;
}

int views_apply(views_view *v, const char *name, const char *value, char *msg, size_t n)
{
    parse_err e = PARSE_OK;
    if (strcmp(name, "-o") == 0) {
        v->out = value;
    } else if (strcmp(name, "--depth") == 0) {
        v->depth = value;
    } else if (strcmp(name, "--normals") == 0) {
        v->normals = value;
    } else if (strcmp(name, "--eye") == 0) {
        e = parse_vec3(value, v->eye);
        v->has_eye = 1;
    } else if (strcmp(name, "--target") == 0) {
        e = parse_vec3(value, v->target);
        v->has_target = 1;
    } else if (strcmp(name, "--up") == 0) {
        e = parse_vec3(value, v->up);
    } else if (strcmp(name, "--fov") == 0) {
        e = parse_double(value, &v->fov);
        if (e == PARSE_OK && !(v->fov > 0.0 && v->fov < 180.0)) {
            snprintf(msg, n, "--fov: %s: must be in (0, 180) degrees", value);
            return -1;
        }
    } else if (strcmp(name, "--size") == 0) {
        e = parse_size(value, CAMERA_MAX_SIZE, &v->width, &v->height);
    } else if (strcmp(name, "--aa") == 0) {
        e = parse_long(value, 1, VIEWS_AA_MAX, &v->aa);
    } else if (strcmp(name, "--ao") == 0) {
        e = parse_long(value, 0, VIEWS_AO_MAX, &v->ao);
    } else if (strcmp(name, "--ao-distance") == 0) {
        e = parse_double(value, &v->ao_distance);
        if (e == PARSE_OK && !(v->ao_distance > 0.0 && v->ao_distance <= VIEWS_AO_DISTANCE_MAX)) {
            snprintf(msg, n, "--ao-distance: %s: must be in (0, " LIMIT_STR(VIEWS_AO_DISTANCE_MAX)
                             "] cube edges", value);
            return -1;
        }
    } else {
        snprintf(msg, n, "unknown option '%s'", name);
        return -1;
    }
    if (e == PARSE_OK && (strcmp(name, "-o") == 0 || strcmp(name, "--depth") == 0 ||
                          strcmp(name, "--normals") == 0) && value[0] == '\0') {
        snprintf(msg, n, "%s: empty path", name);
        return -1;
    }
    if (e != PARSE_OK) {
        snprintf(msg, n, "%s: '%s': %s%s", name, value, parse_strerror(e),
                 strcmp(name, "--size") == 0  ? " (WxH, 1.." LIMIT_STR(CAMERA_MAX_SIZE) " each)"
                 : strcmp(name, "--aa") == 0 ? " (1.." LIMIT_STR(VIEWS_AA_MAX) ")"
                 : strcmp(name, "--ao") == 0 ? " (0.." LIMIT_STR(VIEWS_AO_MAX) ")"
                                             : "");
        return -1;
    }
    return 0;
}

int views_parse(char *text, const views_view *base, views_view **out, size_t *count,
                views_report_fn report, void *ctx)
{
    views_view *arr = NULL;
    size_t n = 0, cap = 0;
    int bad = 0;
    unsigned lineno = 0;
    char *line = text;
    *out = NULL;
    *count = 0;
    while (line && *line) {
        char *nl = strchr(line, '\n');
        if (nl)
            *nl = '\0';
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        views_view v = *base;
        v.line = lineno;
        char msg[256];
        int line_bad = 0, any = 0;
        char *save = NULL;
        for (char *tok = strtok_r(line, " \t\r\v\f", &save); tok;
             tok = strtok_r(NULL, " \t\r\v\f", &save)) {
            any = 1;
            if (views_flag(&v, tok))
                continue;
            if (!views_is_option(tok)) {
                snprintf(msg, sizeof msg, "unknown option '%s'", tok);
                line_bad = 1;
                break;
            }
            char *val = strtok_r(NULL, " \t\r\v\f", &save);
            if (!val) {
                snprintf(msg, sizeof msg, "option '%s' needs a value", tok);
                line_bad = 1;
                break;
            }
            if (views_apply(&v, tok, val, msg, sizeof msg) != 0) {
                line_bad = 1;
                break;
            }
        }
        if (any && !line_bad && !v.out) {
            snprintf(msg, sizeof msg, "a view needs -o OUT.png");
            line_bad = 1;
        }
        if (any && !line_bad && views_check(&v, msg, sizeof msg) != 0)
            line_bad = 1;
        if (line_bad) {
            bad = 1;
            if (report)
                report(ctx, lineno, msg);
        } else if (any && !bad) {
            if (n == cap) {
                size_t nc = cap ? 2 * cap : 8;
                views_view *na = realloc(arr, nc * sizeof *na);
                if (!na) {
                    free(arr);
                    return -2;
                }
                arr = na;
                cap = nc;
            }
            arr[n++] = v;
        }
        line = nl ? nl + 1 : NULL;
    }
    if (bad) {
        free(arr);
        return -1;
    }
    *out = arr;
    *count = n;
    return 0;
}

int views_check_pattern(const char *p)
{
    int conv = 0;
    for (; *p; p++) {
        if (*p != '%')
            continue;
        p++;
        if (*p == '%')
            continue;
        while (*p && strchr("0-+ ", *p))
            p++;
        long width = 0;
        for (; *p >= '0' && *p <= '9'; p++) {
            width = width * 10 + (*p - '0');
            if (width > NAME_MAX)
                return -2; /* no file name is that long: refused before snprintf */
        }
        if (*p != 'd' && *p != 'i' && *p != 'u')
            return -1;
        conv++;
    }
    return conv == 1 ? 0 : -1;
}

const char *views_orbit_strerror(views_orbit_err e)
{
    switch (e) {
    case VIEWS_ORBIT_OK: return "no error";
    case VIEWS_ORBIT_PATTERN: return "-o must hold exactly one integer conversion such as %04d";
    case VIEWS_ORBIT_WIDTH: return "the conversion's field width is over " LIMIT_STR(NAME_MAX) " (NAME_MAX)";
    case VIEWS_ORBIT_NAME: return "a frame's name is " LIMIT_STR(PATH_MAX) " bytes (PATH_MAX) or more";
    case VIEWS_ORBIT_AXIS: return "the eye lies on the up axis through the target";
    case VIEWS_ORBIT_NOMEM: return "out of memory";
    }
    return "unknown error";
}

/* The pattern is checked by views_check_pattern: one integer conversion. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
views_orbit_err views_orbit(const views_view *base, unsigned n, const char *pattern,
                            views_view **out)
{
    *out = NULL;
    int pc = views_check_pattern(pattern);
    if (n == 0 || n > INT_MAX || pc != 0)
        return pc == -2 ? VIEWS_ORBIT_WIDTH : VIEWS_ORBIT_PATTERN;
    /* Frame numbers only grow, so the last frame's name is the longest. */
    int longest = snprintf(NULL, 0, pattern, (int)(n - 1));
    if (longest < 0 || longest >= PATH_MAX)
        return VIEWS_ORBIT_NAME;
    double un = sqrt(base->up[0] * base->up[0] + base->up[1] * base->up[1] +
                     base->up[2] * base->up[2]);
    if (!(un > 0.0))
        return VIEWS_ORBIT_AXIS;
    double ax[3], rel[3], h = 0.0;
    for (int a = 0; a < 3; a++) {
        ax[a] = base->up[a] / un;
        rel[a] = base->eye[a] - base->target[a];
        h += rel[a] * ax[a];
    }
    double e1[3], r = 0.0;
    for (int a = 0; a < 3; a++) {
        e1[a] = rel[a] - h * ax[a];
        r += e1[a] * e1[a];
    }
    r = sqrt(r);
    if (!(r > 0.0))
        return VIEWS_ORBIT_AXIS;
    for (int a = 0; a < 3; a++)
        e1[a] /= r;
    double e2[3] = {ax[1] * e1[2] - ax[2] * e1[1], ax[2] * e1[0] - ax[0] * e1[2],
                    ax[0] * e1[1] - ax[1] * e1[0]};
    size_t len = (size_t)longest + 1;
    views_view *arr = malloc(n * (sizeof *arr + len));
    if (!arr)
        return VIEWS_ORBIT_NOMEM;
    char *names = (char *)(arr + n);
    for (unsigned k = 0; k < n; k++) {
        double ang = 2.0 * M_PI * (double)k / (double)n;
        double c = cos(ang), s = sin(ang);
        arr[k] = *base;
        for (int a = 0; a < 3; a++)
            arr[k].eye[a] = base->target[a] + h * ax[a] + r * (c * e1[a] + s * e2[a]);
        arr[k].has_eye = 1;
        char *name = names + (size_t)k * len;
        snprintf(name, len, pattern, (int)k);
        arr[k].out = name;
        arr[k].depth = NULL;
        arr[k].normals = NULL;
    }
    *out = arr;
    return VIEWS_ORBIT_OK;
}
#pragma GCC diagnostic pop
