/* output_path: classify an output path, resolve its symlinks, name its
 * temporary; see output_path.h. */
#include "common/output_path.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define MAX_LINKS 40 /* as the kernel's own limit on a path's symlinks */
#define TEMP_SUFFIX ".tmp.XXXXXX"

int output_path_is_stdout(const char *path) { return strcmp(path, "-") == 0; }

char *output_path_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return strdup(".");
    if (slash == path)
        return strdup("/");
    return strndup(path, (size_t)(slash - path));
}

/* Follows the symlinks of the last component, as open() would, without
 * requiring that the chain ends at an existing file (a dangling link is
 * written through: the file it names is created). */
static char *resolve_links(const char *path)
{
    char *cur = strdup(path);
    char *link = malloc(PATH_MAX);
    for (int hops = 0; cur && link; hops++) {
        struct stat st;
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) {
            free(link);
            return cur;
        }
        ssize_t n = hops < MAX_LINKS ? readlink(cur, link, PATH_MAX - 1) : -1;
        if (n < 0) {
            if (hops >= MAX_LINKS)
                errno = ELOOP;
            break;
        }
        link[n] = '\0';
        char *next;
        if (link[0] == '/') {
            next = strdup(link);
        } else {
            char *dir = output_path_dir(cur);
            size_t len = dir ? strlen(dir) + 1 + (size_t)n + 1 : 0;
            next = dir ? malloc(len) : NULL;
            if (next)
                snprintf(next, len, "%s/%s", dir, link);
            free(dir);
        }
        free(cur);
        cur = next;
    }
    int e = cur && link ? errno : ENOMEM;
    free(cur);
    free(link);
    errno = e;
    return NULL;
}

int output_path_classify(const char *path, output_kind *kind, char **resolved)
{
    if (resolved)
        *resolved = NULL;
    if (output_path_is_stdout(path)) {
        *kind = OUTPUT_STDOUT;
        return 0;
    }
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            errno = EISDIR;
            return -1;
        }
        if (!S_ISREG(st.st_mode)) {
            *kind = OUTPUT_DIRECT;
            return 0;
        }
    } else if (errno != ENOENT) {
        return -1;
    }
    *kind = OUTPUT_REPLACE;
    if (!resolved)
        return 0;
    *resolved = resolve_links(path);
    return *resolved ? 0 : -1;
}

char *output_path_temp_template(const char *target)
{
    const char *slash = strrchr(target, '/');
    size_t dir_len = slash ? (size_t)(slash - target) + 1 : 0;
    size_t base_len = strlen(target) - dir_len;
    const size_t suffix = sizeof TEMP_SUFFIX - 1;
    if (base_len + suffix > NAME_MAX)
        base_len = NAME_MAX - suffix;
    char *t = malloc(dir_len + base_len + suffix + 1);
    if (!t)
        return NULL;
    memcpy(t, target, dir_len + base_len);
    memcpy(t + dir_len + base_len, TEMP_SUFFIX, suffix + 1);
    return t;
}

int output_path_check_length(const char *path)
{
    size_t total = strlen(path);
    for (const char *p = path; *p;) {
        const char *end = strchr(p, '/');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        if (len > NAME_MAX)
            total = PATH_MAX;
        p += len + (end != NULL);
    }
    if (total >= PATH_MAX) {
        errno = ENAMETOOLONG;
        return -1;
    }
    return 0;
}
