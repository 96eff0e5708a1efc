/* views_file: read a views file within its limits (views.h). */
#include "render/views.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/limits.h"

int views_check_text(const char *text, size_t n, unsigned *line, unsigned *col, const char **msg)
{
    unsigned ln = 1;
    size_t start = 0;
    for (size_t i = 0; i <= n; i++) {
        if (i == n || text[i] == '\n') {
            if (i - start > VIEWS_MAX_LINE) {
                *line = ln;
                *col = VIEWS_MAX_LINE + 1;
                *msg = "line longer than " LIMIT_STR(VIEWS_MAX_LINE) " bytes";
                return -2;
            }
            ln++;
            start = i + 1;
        } else if (text[i] == '\0') {
            *line = ln;
            *col = (unsigned)(i - start + 1);
            *msg = "NUL byte (a views file is text)";
            return -2;
        }
    }
    return 0;
}

int views_read_file(const char *path, char **text, unsigned *line, unsigned *col,
                    const char **msg)
{
    *text = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    int rc = buf ? 0 : -1;
    while (rc == 0) {
        n += fread(buf + n, 1, cap - 1 - n, f);
        if (n + 1 < cap) {
            rc = ferror(f) ? -1 : 0;
            break;
        }
        if (n > VIEWS_MAX_FILE) { /* read one byte past the limit, no more */
            *line = 1;
            *col = 1;
            *msg = "file larger than " LIMIT_STR(VIEWS_MAX_FILE) " bytes";
            rc = -2;
            break;
        }
        size_t nc = cap * 2 > (size_t)VIEWS_MAX_FILE + 2 ? (size_t)VIEWS_MAX_FILE + 2 : cap * 2;
        char *nb = realloc(buf, nc);
        if (!nb) {
            errno = ENOMEM;
            rc = -1;
            break;
        }
        buf = nb;
        cap = nc;
    }
    int e = errno;
    fclose(f);
    if (rc == 0)
        rc = views_check_text(buf, n, line, col, msg);
    if (rc != 0) {
        free(buf);
        errno = e;
        return rc;
    }
    buf[n] = '\0';
    *text = buf;
    return 0;
}
