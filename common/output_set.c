/* output_set: one file in two roles, and outputs that cannot be written;
 * see output_set.h. */
#include "common/output_set.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/diag.h"
#include "common/output_path.h"

typedef struct key {
    char *canon;    /* resolved directory + last component of the link chain */
    dev_t dev;
    ino_t ino;
    int has_ino;    /* the file exists */
    int shareable;  /* a character device: any number of uses may share it */
    unsigned line;  /* the use's view (its views-file line), for the tie order */
    size_t use;
} key;

/* The last resolved directory, for runs that write hundreds of frames into
 * one directory. */
typedef struct dir_cache {
    char *dir, *real;
} dir_cache;

static void describe(const output_use *u, char *out, size_t n)
{
    if (u->line)
        snprintf(out, n, "%s (views line %u)", u->role, u->line);
    else
        snprintf(out, n, "%s", u->role);
}

static char *join(const char *dir, const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t n = strlen(dir) + 1 + strlen(base) + 1;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/%s", strcmp(dir, "/") == 0 ? "" : dir, base);
    return s;
}

/* An output's canonical name, after checking that it can be written.
 * Returns 0, EXIT_RUNTIME with msg, or -1 (no memory). */
static int output_key(const output_use *u, key *k, dir_cache *dc, char *msg, size_t n)
{
    char who[96];
    describe(u, who, sizeof who);
    output_kind kind;
    char *resolved = NULL;
    if (output_path_check_length(u->path) != 0) {
        snprintf(msg, n, "%s: name too long: at most %d bytes a component, %d in all (%s)",
                 u->path, NAME_MAX, PATH_MAX - 1, who);
        return EXIT_RUNTIME;
    }
    if (output_path_classify(u->path, &kind, &resolved) != 0) {
        if (errno == ENOMEM)
            return -1;
        snprintf(msg, n, "%s: %s (%s)", u->path, strerror(errno), who);
        return EXIT_RUNTIME;
    }
    if (kind == OUTPUT_STDOUT) {
        k->canon = strdup("-");
        return k->canon ? 0 : -1;
    }
    if (kind == OUTPUT_DIRECT) {
        if (access(u->path, W_OK) != 0) {
            snprintf(msg, n, "%s: %s (%s)", u->path, strerror(errno), who);
            return EXIT_RUNTIME;
        }
        k->canon = realpath(u->path, NULL);
        if (!k->canon)
            k->canon = strdup(u->path);
        return k->canon ? 0 : -1;
    }
    char *dir = output_path_dir(resolved);
    int rc = dir ? 0 : -1;
    if (rc == 0 && (!dc->dir || strcmp(dc->dir, dir) != 0)) {
        free(dc->dir);
        free(dc->real);
        dc->dir = dir;
        dc->real = realpath(dir, NULL);
        dir = NULL;
        if (!dc->real || access(dc->real, W_OK | X_OK) != 0) {
            int e = errno;
            snprintf(msg, n, "%s: %s (%s: directory %s)", u->path, strerror(e), who, dc->dir);
            errno = e;
            free(dc->dir);
            dc->dir = NULL;
            rc = errno == ENOMEM ? -1 : EXIT_RUNTIME;
        }
    }
    if (rc == 0) {
        k->canon = join(dc->real, resolved);
        rc = k->canon ? 0 : -1;
    }
    free(dir);
    free(resolved);
    return rc;
}

/* Ties (one file) in view order, so that the uses of one view sit side by
 * side and the inputs (line 0) next to the first view. */
static int by_view(const key *x, const key *y)
{
    if (x->line != y->line)
        return x->line < y->line ? -1 : 1;
    return x->use < y->use ? -1 : x->use > y->use;
}

static int by_canon(const void *a, const void *b)
{
    const key *x = a, *y = b;
    int c = strcmp(x->canon, y->canon);
    return c ? c : by_view(x, y);
}

static int by_inode(const void *a, const void *b)
{
    const key *x = a, *y = b;
    if (x->has_ino != y->has_ino)
        return x->has_ino < y->has_ino ? -1 : 1;
    if (x->dev != y->dev)
        return x->dev < y->dev ? -1 : 1;
    if (x->ino != y->ino)
        return x->ino < y->ino ? -1 : 1;
    return by_view(x, y);
}

/* Two neighbours after sorting that name one file in two roles. */
static int clash(const key *a, const key *b, const output_use *uses, int same_inode)
{
    if (a->shareable && b->shareable)
        return 0;
    if (uses[a->use].is_input && uses[b->use].is_input)
        return 0;
    if (!uses[a->use].is_input && !uses[b->use].is_input && uses[a->use].line != uses[b->use].line)
        return 0; /* two views writing one file in turn: the later one's stays */
    return same_inode ? a->has_ino && b->has_ino && a->dev == b->dev && a->ino == b->ino
                      : strcmp(a->canon, b->canon) == 0;
}

static int report_clashes(key *keys, size_t n, const output_use *uses, char *msg, size_t msg_size)
{
    for (int pass = 0; pass < 2; pass++) {
        qsort(keys, n, sizeof *keys, pass ? by_inode : by_canon);
        for (size_t i = 1; i < n; i++) {
            if (!clash(&keys[i - 1], &keys[i], uses, pass))
                continue;
            size_t a = keys[i - 1].use, b = keys[i].use;
            if (a > b) {
                size_t t = a;
                a = b;
                b = t;
            }
            char wa[96], wb[96];
            describe(&uses[a], wa, sizeof wa);
            describe(&uses[b], wb, sizeof wb);
            snprintf(msg, msg_size, "%s: %s and %s name the same file", uses[b].path, wa, wb);
            return EXIT_USAGE;
        }
    }
    return 0;
}

int output_set_check(const output_use *uses, size_t n, char *msg, size_t msg_size)
{
    key *keys = calloc(n ? n : 1, sizeof *keys);
    if (!keys)
        return -1;
    dir_cache dc = {NULL, NULL};
    int rc = 0;
    size_t made = 0;
    for (; made < n && rc == 0; made++) {
        const output_use *u = &uses[made];
        key *k = &keys[made];
        k->use = made;
        k->line = u->line;
        struct stat st;
        int is_stdout = !u->is_input && output_path_is_stdout(u->path);
        if (is_stdout ? fstat(STDOUT_FILENO, &st) == 0 : stat(u->path, &st) == 0) {
            k->has_ino = 1;
            k->dev = st.st_dev;
            k->ino = st.st_ino;
            k->shareable = S_ISCHR(st.st_mode) && !is_stdout;
        }
        if (u->is_input) {
            k->canon = realpath(u->path, NULL);
            if (!k->canon)
                k->canon = strdup(u->path);
            rc = k->canon ? 0 : -1;
        } else {
            rc = output_key(u, k, &dc, msg, msg_size);
        }
    }
    if (rc == 0)
        rc = report_clashes(keys, n, uses, msg, msg_size);
    for (size_t i = 0; i < made; i++)
        free(keys[i].canon);
    free(keys);
    free(dc.dir);
    free(dc.real);
    return rc;
}
