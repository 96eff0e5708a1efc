/* map_guard: see map_guard.h. Signal-handler rules: the handler only calls
 * fstat (async-signal-safe), reads what map_guard_open wrote before any
 * thread started, and leaves with siglongjmp to the thread's own
 * map_guard_run, which is where the interrupted traversal was entered (it
 * holds no lock: tiles are taken through atomics). */
#include "render/map_guard.h"

#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <signal.h>
#include <stddef.h>
#include <sys/stat.h>
#include <unistd.h>

static int guard_fd = -1;
static struct stat guard_st;
static _Thread_local sigjmp_buf *guard_jmp; /* set while this thread runs guarded work */

static int same_identity(const struct stat *a, const struct stat *b)
{
    return a->st_dev == b->st_dev && a->st_ino == b->st_ino && a->st_size == b->st_size &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

int map_guard_changed(void)
{
    if (guard_fd < 0)
        return 0;
    struct stat now;
    return fstat(guard_fd, &now) != 0 || !same_identity(&now, &guard_st);
}

static void on_fault(int sig, siginfo_t *si, void *ctx)
{
    (void)si;
    (void)ctx;
    if (guard_jmp && map_guard_changed())
        siglongjmp(*guard_jmp, 1);
    /* not ours: the default action, as if no handler had been installed */
    struct sigaction dfl;
    dfl.sa_handler = SIG_DFL;
    dfl.sa_flags = 0;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    raise(sig);
}

static void set_handlers(int on)
{
    struct sigaction sa;
    sigemptyset(&sa.sa_mask);
    if (on) {
        sa.sa_sigaction = on_fault;
        sa.sa_flags = SA_SIGINFO;
    } else {
        sa.sa_handler = SIG_DFL;
        sa.sa_flags = 0;
    }
    sigaction(SIGBUS, &sa, NULL);
    sigaction(SIGSEGV, &sa, NULL);
}

int map_guard_open(const char *path, uint64_t mapped_size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    if (fd < 0)
        return -1;
    if (fstat(fd, &guard_st) != 0) {
        int e = errno;
        close(fd);
        errno = e;
        return -1;
    }
    if (!S_ISREG(guard_st.st_mode) || (uint64_t)guard_st.st_size != mapped_size) {
        close(fd); /* replaced or resized since it was mapped */
        errno = 0;
        return -1;
    }
    guard_fd = fd;
    set_handlers(1);
    return 0;
}

int map_guard_run(void (*fn)(void *), void *arg)
{
    sigjmp_buf env;
    if (sigsetjmp(env, 1) != 0) { /* from on_fault: the signal mask is restored */
        guard_jmp = NULL;
        return -1;
    }
    guard_jmp = &env;
    fn(arg);
    guard_jmp = NULL;
    return 0;
}

void map_guard_close(void)
{
    if (guard_fd < 0)
        return;
    set_handlers(0);
    close(guard_fd);
    guard_fd = -1;
}
