/* atomic_file: temp file in the target's directory, fsync, rename, fsync dir.
 * Pattern from git's tempfile.c and SQLite's unixSync; see atomic_file.h. */
#include "common/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct atomic_file {
    FILE *fp;  /* a cookie stream over fd, so the fault hook sees every write */
    int fd;
    char *target;
    char *tmp;
    char *dir;
    int registered;
};

/* Temporary files alive right now, for the signal handler. A fixed table:
 * the handler must not allocate or take locks. */
#define MAX_LIVE 16
static char *volatile live[MAX_LIVE];
static int handlers_installed;

static void on_signal(int sig)
{
    for (int i = 0; i < MAX_LIVE; i++)
        if (live[i])
            unlink(live[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_handlers(void)
{
    if (handlers_installed)
        return;
    handlers_installed = 1;
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        struct sigaction old;
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue; /* respect nohup and friends */
        sigaction(sigs[i], &sa, NULL);
    }
}

static void set_live(atomic_file *af, int on)
{
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    for (int i = 0; i < MAX_LIVE; i++) {
        if (on && !live[i]) {
            live[i] = af->tmp;
            af->registered = 1;
            break;
        }
        if (!on && live[i] == af->tmp) {
            live[i] = NULL;
            af->registered = 0;
            break;
        }
    }
    pthread_sigmask(SIG_SETMASK, &old, NULL);
}

/* --- fault injection (test hook) -------------------------------------- */

#ifndef DDA_TEST_HOOKS
static int fault_check(const char *op)
{
    (void)op;
    return 0;
}
#else
static int fault_check(const char *op)
{
    const char *spec = getenv("ATOMIC_FAULT");
    if (!spec || !*spec)
        return 0;
    size_t oplen = strlen(op);
    if (strncmp(spec, op, oplen) != 0 || spec[oplen] != ':')
        return 0;
    char *end;
    long n = strtol(spec + oplen + 1, &end, 10);
    int err = EIO, sticky = 0;
    while (*end == ':') {
        const char *f = end + 1;
        if (strncmp(f, "ENOSPC", 6) == 0) err = ENOSPC;
        else if (strncmp(f, "EIO", 3) == 0) err = EIO;
        else if (strncmp(f, "EDQUOT", 6) == 0) err = EDQUOT;
        else if (strncmp(f, "EACCES", 6) == 0) err = EACCES;
        else if (strncmp(f, "sticky", 6) == 0) sticky = 1;
        end = strchr(f, ':');
        if (!end)
            break;
    }
    static long counts[4];
    static const char *ops[4] = {"write", "fsync", "close", "rename"};
    for (int i = 0; i < 4; i++) {
        if (strcmp(op, ops[i]) == 0) {
            long c = ++counts[i];
            if (c == n || (sticky && c > n)) {
                errno = err;
                return -1;
            }
        }
    }
    return 0;
}
#endif

/* --- public API ------------------------------------------------------- */

static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return strdup(".");
    if (slash == path)
        return strdup("/");
    return strndup(path, (size_t)(slash - path));
}

static ssize_t cookie_write(void *cookie, const char *data, size_t n)
{
    atomic_file *af = cookie;
    size_t done = 0;
    if (fault_check("write") != 0)
        return -1;
    while (done < n) {
        ssize_t w = write(af->fd, data + done, n - done);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            return done ? (ssize_t)done : -1;
        }
        done += (size_t)w;
    }
    return (ssize_t)n;
}

/* Seeking lets a writer fill in a header last (rasterize --merge). */
static int cookie_seek(void *cookie, off64_t *pos, int whence)
{
    atomic_file *af = cookie;
    off_t r = lseek(af->fd, (off_t)*pos, whence);
    if (r < 0)
        return -1;
    *pos = (off64_t)r;
    return 0;
}

static int cookie_close(void *cookie)
{
    atomic_file *af = cookie;
    int fd = af->fd;
    af->fd = -1;
    if (fault_check("close") != 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    return close(fd);
}

atomic_file *atomic_file_open(const char *target_path)
{
    atomic_file *af = calloc(1, sizeof *af);
    if (!af)
        return NULL;
    af->target = strdup(target_path);
    af->dir = dir_of(target_path);
    size_t n = strlen(target_path) + 16;
    af->tmp = malloc(n);
    if (!af->target || !af->dir || !af->tmp) {
        free(af->target); free(af->dir); free(af->tmp); free(af);
        errno = ENOMEM;
        return NULL;
    }
    snprintf(af->tmp, n, "%s.tmp.XXXXXX", target_path);
    install_handlers();
    int fd = mkstemp(af->tmp);
    if (fd < 0) {
        int e = errno;
        free(af->target); free(af->dir); free(af->tmp); free(af);
        errno = e;
        return NULL;
    }
    set_live(af, 1);
    mode_t mask = umask(0); /* mkstemp makes 0600; outputs are ordinary files */
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    af->fd = fd;
    cookie_io_functions_t io = {NULL, cookie_write, cookie_seek, cookie_close};
    af->fp = fopencookie(af, "wb", io);
    if (!af->fp) {
        int e = errno;
        close(fd);
        atomic_file_abort(af);
        errno = e;
        return NULL;
    }
    return af;
}

FILE *atomic_file_stream(atomic_file *af) { return af->fp; }

int atomic_file_write(atomic_file *af, const void *data, size_t n)
{
    if (n && fwrite(data, 1, n, af->fp) != n)
        return -1;
    return 0;
}

static void release(atomic_file *af, int remove_tmp)
{
    if (remove_tmp)
        unlink(af->tmp);
    if (af->registered)
        set_live(af, 0);
    free(af->target);
    free(af->tmp);
    free(af->dir);
    free(af);
}

int atomic_file_commit(atomic_file *af, const char **failed_op)
{
    const char *op = "write";
    if (fflush(af->fp) != 0 || ferror(af->fp))
        goto fail;
    op = "fsync";
    if (fault_check("fsync") != 0 || fsync(af->fd) != 0)
        goto fail;
    op = "close";
    FILE *fp = af->fp;
    af->fp = NULL;
    if (fclose(fp) != 0) /* cookie_close closes the descriptor */
        goto fail;
    op = "rename";
    if (fault_check("rename") != 0 || rename(af->tmp, af->target) != 0)
        goto fail;
    /* The rename is durable only once the directory entry is; a failure here
     * leaves a complete file in place, so it is not reported as an error. */
    int dfd = open(af->dir, O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) {
        fsync(dfd);
        close(dfd);
    }
    release(af, 0);
    return 0;
fail:;
    int e = errno;
    if (af->fp)
        fclose(af->fp);
    af->fp = NULL;
    release(af, 1);
    if (failed_op)
        *failed_op = op;
    errno = e;
    return -1;
}

void atomic_file_abort(atomic_file *af)
{
    if (!af)
        return;
    if (af->fp)
        fclose(af->fp);
    af->fp = NULL;
    release(af, 1);
}
