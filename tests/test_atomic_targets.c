/* common/atomic_file.c and common/output_path.c on the targets that are not
 * a plain regular file: devices, FIFOs, symlinks, names near NAME_MAX; the
 * commit of several files together; every terminating signal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/atomic_file.h"
#include "common/output_path.h"

static char dir[] = "/tmp/test_af_targets_XXXXXX";

static int setup(void **state)
{
    (void)state;
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    DIR *d = opendir(dir);
    struct dirent *e;
    char p[PATH_MAX];
    while (d && (e = readdir(d))) {
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            unlink(p);
        }
    }
    if (d)
        closedir(d);
    return rmdir(dir);
}

static int count_tmp_files(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        n += strstr(e->d_name, ".tmp.") != NULL;
    closedir(d);
    return n;
}

static void path_in(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", dir, name);
}

static int write_file(const char *target, const char *text, const char **op)
{
    atomic_file *af = atomic_file_open(target);
    if (!af) {
        *op = "open";
        return -1;
    }
    if (atomic_file_write(af, text, strlen(text)) != 0) {
        int e = errno;
        atomic_file_abort(af);
        errno = e;
        *op = "write";
        return -1;
    }
    return atomic_file_commit(af, op);
}

static void expect_text(const char *path, const char *text)
{
    char buf[256] = {0};
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    assert_int_equal(n, strlen(text));
    assert_string_equal(buf, text);
}

/* A device is written in place: /dev/null stays the character device it
 * was (as root a rename would have replaced it), /dev/full says ENOSPC. */
static void test_devices_written_directly(void **state)
{
    (void)state;
    const char *op = NULL;
    assert_int_equal(write_file("/dev/null", "discarded", &op), 0);
    struct stat st;
    assert_int_equal(stat("/dev/null", &st), 0);
    assert_true(S_ISCHR(st.st_mode));
    assert_int_equal(write_file("/dev/full", "no room", &op), -1);
    assert_int_equal(errno, ENOSPC);
    assert_string_equal(op, "write");
    assert_int_equal(stat("/dev/full", &st), 0);
    assert_true(S_ISCHR(st.st_mode));
}

/* A FIFO is written into, not replaced by a regular file. */
static void test_fifo_written_directly(void **state)
{
    (void)state;
    char fifo[PATH_MAX];
    path_in(fifo, sizeof fifo, "fifo");
    assert_int_equal(mkfifo(fifo, 0600), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        const char *op;
        _exit(write_file(fifo, "through the pipe", &op) == 0 ? 0 : 1);
    }
    char buf[64] = {0};
    int fd = open(fifo, O_RDONLY);
    assert_true(fd >= 0);
    size_t n = 0;
    for (ssize_t r; (r = read(fd, buf + n, sizeof buf - 1 - n)) > 0;)
        n += (size_t)r;
    close(fd);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    assert_string_equal(buf, "through the pipe");
    struct stat st;
    assert_int_equal(lstat(fifo, &st), 0);
    assert_true(S_ISFIFO(st.st_mode));
    assert_int_equal(count_tmp_files(), 0);
    unlink(fifo);
}

/* A symlink (a chain of two, relative) keeps being a link: the file at its
 * end is replaced, and a dangling link creates the file it names. */
static void test_symlink_target_kept(void **state)
{
    (void)state;
    char real[PATH_MAX], mid[PATH_MAX], link[PATH_MAX];
    path_in(real, sizeof real, "real.txt");
    path_in(mid, sizeof mid, "mid.txt");
    path_in(link, sizeof link, "link.txt");
    assert_int_equal(symlink("real.txt", mid), 0);
    assert_int_equal(symlink("mid.txt", link), 0);
    const char *op;
    assert_int_equal(write_file(link, "dangling", &op), 0);
    expect_text(real, "dangling");
    assert_int_equal(write_file(link, "replaced", &op), 0);
    expect_text(real, "replaced");
    struct stat st;
    assert_int_equal(lstat(link, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(lstat(mid, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(count_tmp_files(), 0);
    /* A loop is an error, not a hang. */
    char a[PATH_MAX], b[PATH_MAX];
    path_in(a, sizeof a, "loop_a");
    path_in(b, sizeof b, "loop_b");
    assert_int_equal(symlink("loop_b", a), 0);
    assert_int_equal(symlink("loop_a", b), 0);
    assert_int_equal(write_file(a, "x", &op), -1);
    assert_int_equal(errno, ELOOP);
    unlink(a); unlink(b); unlink(link); unlink(mid); unlink(real);
}

/* A directory is never a target. */
static void test_directory_refused(void **state)
{
    (void)state;
    const char *op;
    assert_int_equal(write_file(dir, "x", &op), -1);
    assert_int_equal(errno, EISDIR);
    output_kind k;
    assert_int_equal(output_path_classify(dir, &k, NULL), -1);
}

/* The temporary of a 254- or 255-byte name fits NAME_MAX. */
static void test_long_names(void **state)
{
    (void)state;
    for (size_t len = NAME_MAX - 12; len <= NAME_MAX; len++) {
        char name[NAME_MAX + 1], target[PATH_MAX];
        memset(name, 'n', len);
        name[len] = '\0';
        path_in(target, sizeof target, name);
        char *tmpl = output_path_temp_template(target);
        assert_non_null(tmpl);
        const char *base = strrchr(tmpl, '/') + 1;
        assert_true(strlen(base) <= NAME_MAX);
        assert_non_null(strstr(base, ".tmp.XXXXXX"));
        free(tmpl);
        const char *op;
        assert_int_equal(write_file(target, "long", &op), 0);
        expect_text(target, "long");
        assert_int_equal(output_path_check_length(target), 0);
        unlink(target);
    }
    char over[NAME_MAX + 8];
    memset(over, 'o', sizeof over - 1);
    over[sizeof over - 1] = '\0';
    assert_int_equal(output_path_check_length(over), -1);
    assert_int_equal(errno, ENAMETOOLONG);
    static char deep[PATH_MAX + 16];
    for (size_t i = 0; i < sizeof deep - 1; i++)
        deep[i] = i % 2 ? '/' : 'd';
    assert_int_equal(output_path_check_length(deep), -1);
}

/* Several files committed together: a failure in any one's fsync leaves
 * every target as it was; success replaces them all. */
static void test_commit_all_or_none(void **state)
{
    (void)state;
    char t[3][PATH_MAX];
    const char *names[3] = {"a.png", "b.pfm", "c.png"};
    const char *op;
    for (int i = 0; i < 3; i++) {
        path_in(t[i], sizeof t[i], names[i]);
        assert_int_equal(write_file(t[i], "old", &op), 0);
    }
    for (int fail_at = 1; fail_at <= 4; fail_at++) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            char spec[32];
            snprintf(spec, sizeof spec, "fsync:%d:EIO", fail_at);
            setenv("ATOMIC_FAULT", spec, 1);
            atomic_file *af[3];
            for (int i = 0; i < 3; i++) {
                af[i] = atomic_file_open(t[i]);
                if (!af[i] || atomic_file_write(af[i], "new", 3) != 0)
                    _exit(3);
            }
            size_t failed = 99;
            int rc = atomic_file_commit_all(af, 3, &failed, &op);
            if (rc == 0)
                _exit(0);
            _exit(failed == (size_t)(fail_at - 1) && strcmp(op, "fsync") == 0 ? 1 : 4);
        }
        int status;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        assert_true(WIFEXITED(status));
        assert_int_equal(WEXITSTATUS(status), fail_at <= 3 ? 1 : 0);
        for (int i = 0; i < 3; i++)
            expect_text(t[i], fail_at <= 3 ? "old" : "new");
        assert_int_equal(count_tmp_files(), 0);
    }
    for (int i = 0; i < 3; i++)
        unlink(t[i]);
}

/* Each terminating signal, arriving while two temporaries exist, removes
 * both and still ends the process by that signal. */
static void test_every_terminating_signal(void **state)
{
    (void)state;
    static const int sigs[] = {SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGPIPE, SIGALRM, SIGUSR1,
                               SIGUSR2, SIGABRT, SIGXCPU, SIGXFSZ, SIGVTALRM, SIGPROF};
    char t1[PATH_MAX], t2[PATH_MAX];
    path_in(t1, sizeof t1, "one.png");
    path_in(t2, sizeof t2, "two.png");
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            struct rlimit no_core = {0, 0};
            setrlimit(RLIMIT_CORE, &no_core);
            struct sigaction old;
            if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
                _exit(5); /* ignored by whoever started us: respected, not tested */
            atomic_file *a = atomic_file_open(t1), *b = atomic_file_open(t2);
            if (!a || !b || atomic_file_write(a, "x", 1) != 0 || fflush(atomic_file_stream(a)))
                _exit(3);
            raise(sigs[i]);
            _exit(4);
        }
        int status;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        if (WIFEXITED(status) && WEXITSTATUS(status) == 5)
            continue;
        assert_true(WIFSIGNALED(status));
        assert_int_equal(WTERMSIG(status), sigs[i]);
        assert_int_equal(count_tmp_files(), 0);
        assert_int_equal(access(t1, F_OK), -1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_devices_written_directly),
        cmocka_unit_test(test_fifo_written_directly),
        cmocka_unit_test(test_symlink_target_kept),
        cmocka_unit_test(test_directory_refused),
        cmocka_unit_test(test_long_names),
        cmocka_unit_test(test_commit_all_or_none),
        cmocka_unit_test(test_every_terminating_signal),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
