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

#include "common/output_path.h"

struct atomic_file {
    FILE *fp;  /* a cookie stream over fd, so the fault hook sees every write */
    int fd;
    char *target;
    char *tmp;
    char *dir;
    int registered; /* in the signal handler's table */
    int made;       /* the temporary exists */
    int direct;     /* a device, FIFO or stdout: written in place, no rename */
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
    raise(sig); /* blocked until the handler returns, then the default kills */
}

/* Every signal whose default action ends the process, except the faults of
 * the program itself (SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGTRAP: their
 * handling belongs to the code that can cause them) and SIGKILL/SIGSTOP,
 * which cannot be caught. SIGXFSZ is here: a file-size limit kills the
 * writer in the middle of a write. */
static const int fatal_signals[] = {
    SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGPIPE, SIGALRM, SIGUSR1, SIGUSR2, SIGABRT,
    SIGXCPU, SIGXFSZ, SIGVTALRM, SIGPROF,
#ifdef SIGIO
    SIGIO,
#endif
#ifdef SIGPWR
    SIGPWR,
#endif
#ifdef SIGSTKFLT
    SIGSTKFLT,
#endif
#ifdef SIGSYS
    SIGSYS,
#endif
};

static void install_one(int sig)
{
    struct sigaction sa, old;
    if (sigaction(sig, NULL, &old) != 0 || old.sa_handler != SIG_DFL)
        return; /* ignored (nohup and friends) or someone else's handler */
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigfillset(&sa.sa_mask); /* one handler at a time */
    sigaction(sig, &sa, NULL);
}

static void install_handlers(void)
{
    if (handlers_installed)
        return;
    handlers_installed = 1;
    for (size_t i = 0; i < sizeof fatal_signals / sizeof fatal_signals[0]; i++)
        install_one(fatal_signals[i]);
#if defined(SIGRTMIN) && defined(SIGRTMAX)
    for (int sig = SIGRTMIN; sig <= SIGRTMAX; sig++)
        install_one(sig);
#endif
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

static void release(atomic_file *af, int remove_tmp);

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

static void free_af(atomic_file *af)
{
    free(af->target);
    free(af->tmp);
    free(af->dir);
    free(af);
}

/* The temporary beside the target (af->target resolved already). */
static int open_temp(atomic_file *af)
{
    af->dir = output_path_dir(af->target);
    af->tmp = output_path_temp_template(af->target);
    if (!af->dir || !af->tmp) {
        errno = ENOMEM;
        return -1;
    }
    install_handlers();
    /* Registered before it exists, so that no signal can leave it behind;
     * unlinking a name not created yet is harmless. */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, &old);
    int fd = mkstemp(af->tmp);
    if (fd >= 0) {
        af->made = 1;
        set_live(af, 1);
    }
    int e = errno;
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (fd < 0) {
        errno = e;
        return -1;
    }
    mode_t mask = umask(0); /* mkstemp makes 0600; outputs are ordinary files */
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    af->fd = fd;
    return 0;
}

atomic_file *atomic_file_open(const char *target_path)
{
    atomic_file *af = calloc(1, sizeof *af);
    if (!af)
        return NULL;
    af->fd = -1;
    output_kind kind;
    if (output_path_classify(target_path, &kind, &af->target) != 0) {
        int e = errno;
        free_af(af);
        errno = e;
        return NULL;
    }
    int rc = 0;
    if (kind == OUTPUT_REPLACE) {
        rc = open_temp(af);
    } else {
        /* Written where it is: replacing a device or a FIFO by a regular
         * file would be wrong, and renaming over stdout impossible. */
        af->direct = 1;
        af->fd = kind == OUTPUT_STDOUT ? dup(STDOUT_FILENO)
                                       : open(target_path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
        rc = af->fd < 0 ? -1 : 0;
    }
    if (rc != 0) {
        int e = errno;
        release(af, 1);
        errno = e;
        return NULL;
    }
    cookie_io_functions_t io = {NULL, cookie_write, cookie_seek, cookie_close};
    af->fp = fopencookie(af, "wb", io);
    if (!af->fp) {
        int e = errno;
        close(af->fd);
        release(af, 1);
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
    if (remove_tmp && af->made)
        unlink(af->tmp);
    if (af->registered)
        set_live(af, 0);
    free_af(af);
}

/* Everything but the rename: flush, fsync, close. Returns 0, or -1 with
 * errno and *op naming the step; the stream is closed either way. */
static int finish(atomic_file *af, const char **op)
{
    *op = "write";
    int rc = fflush(af->fp) != 0 || ferror(af->fp) ? -1 : 0;
    /* Devices and FIFOs have nothing to make durable (fsync would say
     * EINVAL); a regular file must be on disk before it is renamed. */
    if (rc == 0 && !af->direct) {
        *op = "fsync";
        rc = fault_check("fsync") != 0 || fsync(af->fd) != 0 ? -1 : 0;
    }
    int e = errno;
    FILE *fp = af->fp;
    af->fp = NULL;
    int closed = fclose(fp); /* cookie_close closes the descriptor */
    if (rc == 0 && closed != 0) {
        *op = "close";
        return -1;
    }
    errno = e;
    return rc;
}

static void sync_dir(const char *dir)
{
    /* The rename is durable only once the directory entry is; a failure here
     * leaves a complete file in place, so it is not reported as an error. */
    int dfd = open(dir, O_RDONLY | O_DIRECTORY);
    if (dfd >= 0) {
        fsync(dfd);
        close(dfd);
    }
}

int atomic_file_commit_all(atomic_file **afs, size_t n, size_t *failed, const char **failed_op)
{
    const char *op = NULL;
    size_t k = 0;
    int rc = 0;
    for (; k < n && rc == 0; k++)
        rc = finish(afs[k], &op);
    if (rc == 0) {
        op = "rename";
        for (k = 0; k < n && rc == 0; k++)
            if (!afs[k]->direct &&
                (fault_check("rename") != 0 || rename(afs[k]->tmp, afs[k]->target) != 0))
                rc = -1;
        for (size_t i = 0; i < n && rc == 0; i++)
            if (!afs[i]->direct)
                sync_dir(afs[i]->dir);
    }
    int e = errno;
    /* k is one past the file that failed; the ones renamed before it stay */
    for (size_t i = 0; i < n; i++) {
        if (afs[i]->fp)
            fclose(afs[i]->fp);
        afs[i]->fp = NULL;
        release(afs[i], rc != 0 && (op != NULL && strcmp(op, "rename") == 0 ? i + 1 >= k : 1));
    }
    if (rc != 0) {
        if (failed)
            *failed = k - 1;
        if (failed_op)
            *failed_op = op;
        errno = e;
    }
    return rc;
}

int atomic_file_commit(atomic_file *af, const char **failed_op)
{
    return atomic_file_commit_all(&af, 1, NULL, failed_op);
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
