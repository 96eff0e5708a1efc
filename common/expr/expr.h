/* expr: the EXPR parser (INTERFACE.md) shared with the statement reader in
 * scene.c, private to common/expr/. It reads one line of scene text and
 * reports the first error, with its column, into a scene_error. */
#ifndef EXPR_H
#define EXPR_H

#include <stddef.h>
#include <stdint.h>

#include "common/expr/scene.h"
#include "common/expr/tape.h"

typedef struct expr_parser {
    const char *s;  /* current line, NUL-terminated, comment cut off */
    size_t pos;     /* byte offset in s */
    unsigned line;
    int depth;      /* nesting so far, against SCENE_MAX_DEPTH */
    int failed;     /* an error is in *err; later ones are dropped */
    tape_builder *b;
    scene_error *err;
} expr_parser;

static inline int expr_is_alpha(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
static inline int expr_is_digit(int c) { return c >= '0' && c <= '9'; }
static inline int expr_is_alnum(int c) { return expr_is_alpha(c) || expr_is_digit(c); }

/* Parses a sum (a whole EXPR) at p->pos into p->b and leaves p->pos after
 * it. Returns the slot of its value, or -1 after an error (p->failed). */
int32_t expr_parse(expr_parser *p);

/* Records the error "message" at byte pos of the line (column pos + 1),
 * unless one is recorded already: the first error is the one reported. */
void expr_fail_at(expr_parser *p, size_t pos, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Skips blanks: space, tab and carriage return. */
void expr_skip_ws(expr_parser *p);

/* Describes the byte at pos for "unexpected ..." messages: "end of line",
 * "'c'" for a printable byte, else "byte 0xNN". */
void expr_describe(const expr_parser *p, size_t pos, char *buf, size_t n);

/* Reads an unsigned decimal literal at p->pos: 1 and the value (*exact set
 * when the literal is exactly that double), or 0 with an error (or without
 * one if there is no digit at all: *none is set). */
int expr_read_number(expr_parser *p, double *v, int *exact, int *none);

#endif
