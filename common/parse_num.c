/* parse_num: strict decimal parsing on top of strtod/strtol. */
#include "common/parse_num.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const char *parse_strerror(parse_err e)
{
    switch (e) {
    case PARSE_OK: return "ok";
    case PARSE_EMPTY: return "empty value";
    case PARSE_SYNTAX: return "not a number";
    case PARSE_RANGE: return "number out of range";
    }
    return "unknown error";
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

size_t parse_float_prefix(const char *s, int *bad_exponent)
{
    size_t i = 0, digits = 0;
    if (bad_exponent)
        *bad_exponent = 0;
    while (is_digit(s[i])) { i++; digits++; }
    if (s[i] == '.') {
        i++;
        while (is_digit(s[i])) { i++; digits++; }
    }
    if (digits == 0)
        return 0;
    if (s[i] == 'e' || s[i] == 'E') {
        size_t j = i + 1;
        if (s[j] == '+' || s[j] == '-')
            j++;
        if (!is_digit(s[j])) {
            if (bad_exponent)
                *bad_exponent = 1;
            return i;
        }
        while (is_digit(s[j]))
            j++;
        i = j;
    }
    return i;
}

parse_err parse_double(const char *s, double *out)
{
    if (!s || !*s)
        return PARSE_EMPTY;
    size_t sign = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    int bad_exp;
    size_t n = parse_float_prefix(s + sign, &bad_exp);
    if (n == 0 || bad_exp || s[sign + n] != '\0')
        return PARSE_SYNTAX;
    errno = 0;
    double v = strtod(s, NULL);
    if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        return PARSE_RANGE; /* overflow; underflow to 0 or a subnormal is fine */
    *out = v;
    return PARSE_OK;
}

parse_err parse_long(const char *s, long min, long max, long *out)
{
    if (!s || !*s)
        return PARSE_EMPTY;
    size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (!is_digit(s[i]))
        return PARSE_SYNTAX;
    while (is_digit(s[i]))
        i++;
    if (s[i] != '\0')
        return PARSE_SYNTAX;
    errno = 0;
    long v = strtol(s, NULL, 10);
    if (errno == ERANGE || v < min || v > max)
        return PARSE_RANGE;
    *out = v;
    return PARSE_OK;
}

parse_err parse_vec3(const char *s, double out[3])
{
    if (!s || !*s)
        return PARSE_EMPTY;
    char buf[256];
    size_t len = strlen(s);
    if (len >= sizeof buf)
        return PARSE_SYNTAX;
    memcpy(buf, s, len + 1);
    char *p = buf;
    for (int k = 0; k < 3; k++) {
        char *comma = strchr(p, ',');
        if ((k < 2) != (comma != NULL))
            return PARSE_SYNTAX;
        if (comma)
            *comma = '\0';
        parse_err e = parse_double(p, &out[k]);
        if (e != PARSE_OK)
            return e == PARSE_EMPTY ? PARSE_SYNTAX : e;
        p = comma ? comma + 1 : p;
    }
    return PARSE_OK;
}

parse_err parse_size(const char *s, long max, long *w, long *h)
{
    if (!s || !*s)
        return PARSE_EMPTY;
    const char *x = strchr(s, 'x');
    if (!x || x == s || x[1] == '\0')
        return PARSE_SYNTAX;
    char buf[64];
    size_t n = (size_t)(x - s);
    if (n >= sizeof buf)
        return PARSE_SYNTAX;
    memcpy(buf, s, n);
    buf[n] = '\0';
    if (buf[0] == '-' || buf[0] == '+' || x[1] == '-' || x[1] == '+')
        return buf[0] == '-' || x[1] == '-' ? PARSE_RANGE : PARSE_SYNTAX;
    parse_err e = parse_long(buf, 1, max, w);
    if (e != PARSE_OK)
        return e;
    return parse_long(x + 1, 1, max, h);
}

parse_err parse_index_of(const char *s, long max, long *index, long *count)
{
    if (!s || !*s)
        return PARSE_EMPTY;
    const char *slash = strchr(s, '/');
    if (!slash || slash == s || slash[1] == '\0')
        return PARSE_SYNTAX;
    char buf[64];
    size_t n = (size_t)(slash - s);
    if (n >= sizeof buf)
        return PARSE_SYNTAX;
    memcpy(buf, s, n);
    buf[n] = '\0';
    long i, c;
    parse_err e = parse_long(slash + 1, 1, max, &c);
    if (e == PARSE_OK)
        e = parse_long(buf, 0, c - 1, &i);
    if (e != PARSE_OK)
        return e;
    *index = i;
    *count = c;
    return PARSE_OK;
}
