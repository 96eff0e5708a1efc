/* parse_num: strict number parsing for command lines, scenes and views files.
 * Only decimal numbers in C float syntax are accepted: no hex ("0x1p3"), no
 * "inf"/"nan", no leading or trailing junk, no overflow ("1e999"). */
#ifndef PARSE_NUM_H
#define PARSE_NUM_H

#include <stddef.h>

typedef enum parse_err {
    PARSE_OK = 0,
    PARSE_EMPTY,     /* nothing to parse */
    PARSE_SYNTAX,    /* not a number of the accepted form */
    PARSE_RANGE,     /* overflows, or outside the caller's range */
} parse_err;

const char *parse_strerror(parse_err e);

/* Length of the longest prefix of s that is a decimal float literal
 * ([0-9]+(.[0-9]*)?|.[0-9]+)([eE][+-]?[0-9]+)? — 0 if none. A dangling
 * exponent ("1e", "1e+") is not part of the literal: *bad_exponent is set
 * (when not NULL) so callers can report it. */
size_t parse_float_prefix(const char *s, int *bad_exponent);

/* Whole-string parses. */
parse_err parse_double(const char *s, double *out);                 /* finite */
parse_err parse_long(const char *s, long min, long max, long *out); /* decimal integer */
parse_err parse_vec3(const char *s, double out[3]);                 /* "X,Y,Z" */
parse_err parse_size(const char *s, long max, long *w, long *h);    /* "WxH", 1..max each */
/* "I/N" with 1 <= N <= max and 0 <= I < N (a shard or a part of N);
 * *index and *count are set only on success. */
parse_err parse_index_of(const char *s, long max, long *index, long *count);

#endif
