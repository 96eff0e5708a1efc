/* diag: the one place programs print diagnostics, in the forms users and
 * scripts rely on:
 *     prog: message
 *     prog: path: message
 *     FILE:LINE:COLUMN: message      (scene and views files; docs/INTERFACE.md)
 * Library code returns error codes; only a program's main() calls these. */
#ifndef DIAG_H
#define DIAG_H

#include <stdarg.h>

/* Sets the program name used as prefix (basename of argv[0] is typical). */
void diag_set_progname(const char *name);
const char *diag_progname(void);

/* "prog: <fmt>\n" on stderr. */
void diag_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* "prog: path: <fmt>\n" on stderr. */
void diag_path_error(const char *path, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* "file:line:col: <fmt>\n" on stderr (no program prefix). */
void diag_at(const char *file, unsigned line, unsigned col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* "prog: <fmt>\n" and then `usage` on stderr; returns EXIT_USAGE (2), for
 * `return diag_usage_error(...)` from main's option parsing. */
int diag_usage_error(const char *usage, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* True when stderr is a terminal (progress bars are drawn only then). */
int diag_stderr_is_tty(void);

/* Exit codes (docs/INTERFACE.md). */
enum { EXIT_OK = 0, EXIT_RUNTIME = 1, EXIT_USAGE = 2 };

#endif
