/* common/atomic_file.c around the .oct writer, as rasterize uses it: faults
 * injected at every write, fsync, close and rename, and SIGTERM during a
 * large write; the target is always the old file or the complete new one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/atomic_file.h"
#include "format/oct.h"
#include "tests/oct_check.h"

static int count_tmp_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        n += strstr(e->d_name, ".tmp.") != NULL;
    closedir(d);
    return n;
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n + 1);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *len = (size_t)n;
    return b;
}

/* The caller's sequence (rasterize): atomic_file + oct_writer_finish +
 * commit; run in a child process, so that the fault hook's counters start at
 * zero. Exit status: 0 success, 1 clean failure. */
_Noreturn static void write_and_exit(const char *target, const test_tree *t, const char *fault)
{
    setenv("ATOMIC_FAULT", fault, 1);
    atomic_file *af = atomic_file_open(target);
    if (!af)
        _exit(1);
    oct_writer_params p = {.levels = t->levels, .edge = t->edge, .surface_count = t->surface_count,
                           .palette = t->palette};
    memcpy(p.origin, t->origin, sizeof p.origin);
    oct_writer *w;
    if (oct_writer_create(&p, &w) != OCT_OK)
        _exit(3);
    for (uint32_t d = 0; d < t->levels; d++)
        oct_writer_add_masks(w, d, t->masks[d], t->count[d]);
    oct_writer_add_voxels(w, t->voxels, t->surfaces, t->voxel_count);
    uint64_t n;
    oct_err rc = oct_writer_finish(w, atomic_file_stream(af), &n);
    oct_writer_free(w);
    if (rc != OCT_OK) {
        atomic_file_abort(af);
        _exit(1);
    }
    /* Route one write through the hook too, as a producer appending
     * through atomic_file_write would (zero bytes: the file is complete). */
    if (atomic_file_write(af, "", 0) != 0) {
        atomic_file_abort(af);
        _exit(1);
    }
    const char *op;
    _exit(atomic_file_commit(af, &op) == 0 ? 0 : 1);
}

static int write_in_child(const char *target, const test_tree *t, const char *fault)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        write_and_exit(target, t, fault);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

static void test_atomic_write_fault_loop(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_oct_af_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char target[600];
    snprintf(target, sizeof target, "%s/out.oct", dir);
    test_tree old, t;
    test_tree_random(&old, 3, 20, 1, 1, 0);
    test_tree_random(&t, 7, 3000, 2, 2, 1);
    assert_int_equal(write_in_child(target, &old, ""), 0);
    size_t old_len;
    unsigned char *old_bytes = slurp(target, &old_len);
    static const char *ops[] = {"write", "fsync", "close", "rename"};
    static const char *errs[] = {"ENOSPC", "EIO"};
    for (int o = 0; o < 4; o++) {
        for (int sticky = 0; sticky <= 1; sticky++) {
            for (int n = 1;; n++) {
                char spec[64];
                snprintf(spec, sizeof spec, "%s:%d:%s%s", ops[o], n, errs[n % 2], sticky ? ":sticky" : "");
                int rc = write_in_child(target, &t, spec);
                assert_true(rc == 0 || rc == 1);
                assert_int_equal(count_tmp_files(dir), 0);
                if (rc == 0) {
                    assert_true(n > 1); /* the first call of each op fails */
                    break;
                }
                size_t l;
                unsigned char *now = slurp(target, &l);
                assert_int_equal(l, old_len);
                assert_memory_equal(now, old_bytes, l);
                free(now);
                assert_true(n < 100);
            }
            /* Success replaced the target: put the old one back for the next op. */
            assert_int_equal(write_in_child(target, &old, ""), 0);
        }
    }
    oct_file *f;
    assert_int_equal(write_in_child(target, &t, ""), 0);
    assert_int_equal(oct_open(target, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    oct_close(f);
    unlink(target);
    rmdir(dir);
    free(old_bytes);
    test_tree_free(&old);
    test_tree_free(&t);
}

/* SIGTERM at random moments of a large atomic write: the target is the old
 * file or the complete new one, and no temporary file is left. */
static void test_signal_during_write(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_oct_sig_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char target[600];
    snprintf(target, sizeof target, "%s/out.oct", dir);
    test_tree old, t;
    test_tree_random(&old, 3, 20, 1, 1, 0);
    test_tree_random(&t, 10, 400000, 2, 3, 0);
    unsigned char *nb;
    size_t nlen;
    assert_int_equal(test_tree_write(&t, &nb, &nlen), OCT_OK);
    assert_int_equal(write_in_child(target, &old, ""), 0);
    size_t old_len;
    unsigned char *old_bytes = slurp(target, &old_len);
    uint64_t rs = 99;
    int interrupted = 0;
    for (int run = 0; run < 10; run++) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            signal(SIGTERM, SIG_DFL);
            write_and_exit(target, &t, "");
        }
        usleep((useconds_t)(test_rand(&rs) % 30000));
        kill(pid, SIGTERM);
        int status;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        assert_true(WIFSIGNALED(status) ? WTERMSIG(status) == SIGTERM : WEXITSTATUS(status) == 0);
        assert_int_equal(count_tmp_files(dir), 0);
        size_t l;
        unsigned char *now = slurp(target, &l);
        if (l == old_len) {
            assert_memory_equal(now, old_bytes, l);
            interrupted++;
        } else {
            assert_int_equal(l, nlen);
            assert_memory_equal(now, nb, l);
            free(old_bytes);
            old_bytes = now;
            old_len = l;
            now = NULL;
        }
        free(now);
    }
    print_message("signal during write: %d of 10 runs interrupted before the rename\n", interrupted);
    unlink(target);
    rmdir(dir);
    free(old_bytes);
    free(nb);
    test_tree_free(&old);
    test_tree_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_atomic_write_fault_loop),
        cmocka_unit_test(test_signal_during_write),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
