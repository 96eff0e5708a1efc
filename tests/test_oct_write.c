/* The .oct writer's contract (format/oct_write.c): usage errors, failing
 * writes and allocation failures, and the same bytes wherever the voxel
 * records wait (format/oct_store.c: a scratch file, memory, or both). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "format/oct.h"
#include "format/oct_layout.h" /* oct__alloc_fail_after */
#include "format/oct_store.h"  /* oct__spool_limit, OCT_CHUNK */
#include "bench/oct_synth.h"
#include "tests/oct_check.h"

static void test_writer_usage_errors(void **state)
{
    (void)state;
    float pal[6] = {0.1f, 0.2f, 0.3f, 1, 1, 1};
    oct_writer_params ok = {.levels = 2, .edge = 1.0, .surface_count = 2, .palette = pal};
    oct_writer *w = (oct_writer *)1;
    oct_writer_params p = ok;
    p.levels = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    assert_null(w);
    p = ok; p.levels = 21;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.edge = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.edge = NAN;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.origin[1] = INFINITY;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.surface_count = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.surface_count = 256;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.root_cell[2] = 1; /* root_depth 0 has one cell */
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.root_depth = 41;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    float bad[6] = {0, 0, 0, 0, 2, 0};
    p = ok; p.palette = bad;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);

    char *mem;
    size_t memlen;
    FILE *f = open_memstream(&mem, &memlen);
    const uint8_t root = 0x81, zero = 0, two[2] = {1, 1};
    uint32_t vox[3] = {1, 2, 3};
    uint8_t surf_ok[3] = {0, 1, 1}, surf_bad[3] = {0, 2, 0};
    /* Each case: a fresh writer, fed something inconsistent. */
    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &zero, 1), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_masks(w, 2, &root, 1), OCT_EUSAGE); /* depth >= levels */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_bad, 3), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_voxels(w, vox, NULL, 3), OCT_EUSAGE); /* 2 surfaces: needed */
    uint32_t reserved = 0x80000000u;
    assert_int_equal(oct_writer_add_voxels(w, &reserved, surf_ok, 1), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 2), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 3), OCT_OK);
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE); /* 2 voxels under the masks, 3 given */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 1), OCT_EUSAGE); /* finished */
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 1), OCT_OK); /* mask says 2 nodes */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 1), OCT_OK);
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE);
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, two, 2), OCT_OK); /* two roots */
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE);
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 2), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 2), OCT_OK);
    assert_int_equal(oct_writer_finish(w, NULL, NULL), OCT_EUSAGE);
    oct_writer_free(w);
    oct_writer_free(NULL);
    fclose(f);
    free(mem);
}

/* A stream whose Nth write fails (fopencookie). Buffered with a small buffer,
 * like a file: a failure surfaces inside some later fwrite, through its
 * return value or the error flag. */
typedef struct fail_stream { int calls, fail_at, sticky; size_t bytes; } fail_stream;
static ssize_t fail_write(void *c, const char *b, size_t n)
{
    (void)b;
    fail_stream *s = c;
    s->calls++;
    if (s->calls == s->fail_at || (s->sticky && s->calls > s->fail_at)) {
        errno = ENOSPC;
        return 0; /* not -1: glibc 2.36 adds a -1 from a cookie to the bytes left to write */
    }
    s->bytes += n;
    return (ssize_t)n;
}

static void test_writer_write_failures(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 60000, 2, 77, 0); /* > 32768 nodes at a depth: several node chunks */
    unsigned char *good;
    size_t good_len;
    assert_int_equal(test_tree_write(&t, &good, &good_len), OCT_OK);
    for (int sticky = 0; sticky <= 1; sticky++) {
        for (int n = 1;; n++) {
            fail_stream fs = {0, n, sticky, 0};
            cookie_io_functions_t io = {.write = fail_write};
            FILE *f = fopencookie(&fs, "w", io);
            static char iobuf[4096];
            setvbuf(f, iobuf, _IOFBF, sizeof iobuf);
            oct_writer_params p = {.levels = t.levels, .edge = t.edge, .surface_count = 2, .palette = t.palette};
            oct_writer *w;
            assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
            for (uint32_t d = 0; d < t.levels; d++)
                assert_int_equal(oct_writer_add_masks(w, d, t.masks[d], t.count[d]), OCT_OK);
            assert_int_equal(oct_writer_add_voxels(w, t.voxels, t.surfaces, t.voxel_count), OCT_OK);
            errno = 0;
            uint64_t written = 1;
            oct_err rc = oct_writer_finish(w, f, &written);
            int e = errno;
            oct_writer_free(w);
            fclose(f);
            if (rc == OCT_OK) {
                assert_true(fs.calls < n); /* all writes done before the fault */
                assert_int_equal(written, good_len);
                break;
            }
            assert_int_equal(rc, OCT_EIO);
            assert_int_equal(e, ENOSPC);
            assert_int_equal(written, 0);
            assert_true(n < 1000);
        }
    }
    FILE *full = fopen("/dev/full", "wb");
    if (full) { /* a full disk shows at the flush */
        oct_writer_params p = {.levels = t.levels, .edge = t.edge, .surface_count = 1};
        oct_writer *w;
        assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
        assert_int_equal(oct_writer_finish(w, full, NULL), OCT_EIO); /* an empty tree */
        oct_writer_free(w);
        fclose(full);
    }
    free(good);
    test_tree_free(&t);
}

/* Feeds t to a new writer in chunks, the voxel records spooled in
 * spool_dir (NULL: in memory); on ENOMEM retries the call once when `retry`
 * (a single injected failure must leave the writer usable). */
static oct_err feed_spooled(const test_tree *t, const char *spool_dir, int retry,
                            unsigned char **out, size_t *out_len)
{
    oct_writer_params p = {.levels = t->levels, .edge = t->edge, .surface_count = t->surface_count,
                           .palette = t->palette, .spool_dir = spool_dir};
    memcpy(p.origin, t->origin, sizeof p.origin);
    oct_writer *w = NULL;
    oct_err rc = oct_writer_create(&p, &w);
    if (rc == OCT_ENOMEM && retry)
        rc = oct_writer_create(&p, &w);
    for (uint32_t d = 0; d < t->levels && rc == OCT_OK; d++) {
        for (size_t i = 0; i < t->count[d] && rc == OCT_OK; i += 5000) {
            size_t n = t->count[d] - i < 5000 ? t->count[d] - i : 5000;
            rc = oct_writer_add_masks(w, d, t->masks[d] + i, n);
            if (rc == OCT_ENOMEM && retry)
                rc = oct_writer_add_masks(w, d, t->masks[d] + i, n);
        }
    }
    for (size_t i = 0; i < t->voxel_count && rc == OCT_OK; i += 3000) {
        size_t n = t->voxel_count - i < 3000 ? t->voxel_count - i : 3000;
        rc = oct_writer_add_voxels(w, t->voxels + i, t->surfaces + i, n);
        if (rc == OCT_ENOMEM && retry)
            rc = oct_writer_add_voxels(w, t->voxels + i, t->surfaces + i, n);
        if (rc == OCT_OK) /* nothing, which may come without an array */
            rc = oct_writer_add_voxels(w, NULL, NULL, 0);
    }
    char *mem = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&mem, &len);
    if (rc == OCT_OK)
        rc = oct_writer_finish(w, f, NULL);
    oct_writer_free(w);
    fclose(f);
    *out = (unsigned char *)mem;
    *out_len = len;
    return rc;
}

static oct_err feed_writer(const test_tree *t, int retry, unsigned char **out, size_t *out_len)
{
    return feed_spooled(t, NULL, retry, out, out_len);
}

/* Every allocation made to fail in turn, once (retried: the same bytes as
 * `good`) and from then on (OCT_ENOMEM), the records spooled in spool_dir
 * (NULL: memory) with the scratch file full after spool_limit bytes. */
static void check_alloc_failures(const test_tree *t, const char *spool_dir, uint64_t spool_limit,
                                 const unsigned char *good, size_t good_len)
{
    for (int sticky = 0; sticky <= 1; sticky++) {
        for (long n = 1;; n++) {
            unsigned char *out;
            size_t len;
            oct__spool_limit(spool_limit);
            oct__alloc_fail_after(n, sticky);
            oct_err rc = feed_spooled(t, spool_dir, !sticky, &out, &len);
            oct__alloc_fail_after(0, 0);
            oct__spool_limit(UINT64_MAX);
            if (rc == OCT_OK) {
                assert_int_equal(len, good_len);
                assert_memory_equal(out, good, len);
                free(out);
                if (!sticky && n < 40)
                    continue; /* the failure may land after the last allocation */
                break;
            }
            free(out);
            assert_int_equal(rc, OCT_ENOMEM);
            assert_true(sticky);
            assert_true(n < 1000);
        }
    }
}

static void test_allocation_failures(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 7, 30000, 3, 21, 0);
    unsigned char *good;
    size_t good_len;
    assert_int_equal(feed_writer(&t, 0, &good, &good_len), OCT_OK);
    check_alloc_failures(&t, NULL, UINT64_MAX, good, good_len);
    /* The reader allocates its handle and, for a misaligned buffer, a copy. */
    unsigned char *raw = malloc(good_len + 1);
    memcpy(raw + 1, good, good_len);
    for (long n = 1; n <= 3; n++) {
        oct_file *f = (oct_file *)1;
        oct__alloc_fail_after(n, 0);
        oct_err rc = oct_open_memory(raw + 1, good_len, 0, &f, NULL);
        oct__alloc_fail_after(0, 0);
        assert_int_equal(rc, n < 3 ? OCT_ENOMEM : OCT_OK);
        oct_close(f);
    }
    free(raw);
    free(good);
    test_tree_free(&t);
}

/* Trees larger than the writer's storage chunks (2 MiB: 512 Ki voxel
 * records, or 2 Mi masks of one depth; from the second on, huge-page
 * aligned): their arrays span several chunks and the appends cross their
 * boundaries, the node groups are read from both sides of one, and the file
 * read back holds exactly the tree. */
static void test_large_tree_spans_chunks(void **state)
{
    (void)state;
    static const struct {
        uint32_t levels, surfaces;
        size_t target;
        uint64_t seed;
        int masks; /* 0: the records span chunks; 1: the deepest masks do */
    } cases[] = {{8, 3, 2500000, 99, 0}, {9, 1, 2600000, 77, 1}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        test_tree t;
        test_tree_random(&t, cases[c].levels, cases[c].target, cases[c].surfaces, cases[c].seed, 0);
        if (cases[c].masks)
            assert_true(t.count[t.levels - 1] > OCT_CHUNK + 8);
        else
            assert_true(t.voxel_count * 4 > 4 * ((size_t)2 << 20));
        unsigned char *out;
        size_t len;
        assert_int_equal(feed_writer(&t, 0, &out, &len), OCT_OK);
        oct_file *f = NULL;
        assert_int_equal(oct_open_memory(out, len, 0, &f, NULL), OCT_OK);
        oct_check_tree(f, &t);
        oct_close(f);
        free(out);
        test_tree_free(&t);
    }
}

/* Entries in directory d other than . and .. */
static int dir_entries(const char *d)
{
    DIR *dir = opendir(d);
    assert_non_null(dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(dir));)
        n += strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(dir);
    return n;
}

/* The voxel records spooled to a scratch file come back as the same bytes,
 * whether the file takes them all, refuses them from any point on (a full
 * disk: the rest in memory) or cannot be made at all; and no file is ever
 * left in (or named in) the directory. */
static void test_spooled_records(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 7, 30000, 3, 23, 0);
    unsigned char *good, *out;
    size_t good_len, len;
    assert_int_equal(feed_writer(&t, 0, &good, &good_len), OCT_OK);
    char dir[] = "/tmp/oct-spool-test-XXXXXX";
    assert_non_null(mkdtemp(dir));
    const size_t bytes = 4 * t.voxel_count;
    const uint64_t limits[] = {UINT64_MAX, 0, 1, 4, 4 * 2999, 4 * 3000, 4 * 3000 + 1, 12345,
                               bytes / 2, bytes - 1, bytes};
    for (size_t i = 0; i < sizeof limits / sizeof *limits; i++) {
        oct__spool_limit(limits[i]);
        assert_int_equal(feed_spooled(&t, dir, 0, &out, &len), OCT_OK);
        oct__spool_limit(UINT64_MAX);
        assert_int_equal(len, good_len);
        assert_memory_equal(out, good, len);
        free(out);
    }
    /* no directory, or not a directory: memory */
    const char *nowhere[] = {"/nonexistent-oct-spool-dir", "/dev/null", ""};
    for (size_t i = 0; i < sizeof nowhere / sizeof *nowhere; i++) {
        assert_int_equal(feed_spooled(&t, nowhere[i], 0, &out, &len), OCT_OK);
        assert_int_equal(len, good_len);
        assert_memory_equal(out, good, len);
        free(out);
    }
    /* the scratch file has no name while the writer holds it */
    oct_writer_params p = {.levels = t.levels, .edge = t.edge, .surface_count = t.surface_count,
                           .palette = t.palette, .spool_dir = dir};
    oct_writer *w;
    assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, t.voxels, t.surfaces, 100), OCT_OK);
    assert_int_equal(dir_entries(dir), 0);
    oct_writer_free(w);
    /* allocation failures anywhere, half the records in the file, half in
       memory */
    check_alloc_failures(&t, dir, bytes / 2, good, good_len);
    assert_int_equal(dir_entries(dir), 0);
    assert_int_equal(rmdir(dir), 0);
    free(good);
    test_tree_free(&t);
}

/* The spool holds exactly the n bytes want: its CRC, and read back
 * (oct_spool_put). */
static void assert_spool_holds(const oct_spool *s, const unsigned char *want, size_t n)
{
    assert_int_equal(oct_spool_crc(s), (uint32_t)crc32_z(0, want, n));
    char *mem = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&mem, &len);
    oct_sink sink = {f, 0, 0, 1};
    assert_int_equal(oct_spool_put(s, &sink), 0);
    fclose(f);
    assert_int_equal(len, n);
    assert_memory_equal(mem, want, n);
    free(mem);
}

/* The scratch file takes at most half the space that was free where it
 * was made (its share of that half, when spools are opened together); past
 * its cap the bytes go to memory, and all come back in order with the CRC
 * of what was appended. */
static void test_spool_leaves_room(void **state)
{
    (void)state;
    char dir[] = "/tmp/oct-spool-test-XXXXXX";
    assert_non_null(mkdtemp(dir));
    struct statvfs before, after;
    assert_int_equal(statvfs(dir, &before), 0);
    oct_spool s;
    oct_spool_open(&s, dir, 1, 1);
    assert_int_equal(statvfs(dir, &after), 0);
    assert_true(s.has_file);
    const uint64_t a = (uint64_t)before.f_bavail * before.f_frsize / 2,
                   b = (uint64_t)after.f_bavail * after.f_frsize / 2;
    const uint64_t slack = (uint64_t)64 << 20; /* other writers to the same disk */
    assert_true(s.file_cap + slack >= (a < b ? a : b));
    assert_true(s.file_cap <= (a > b ? a : b) + slack);
    /* spools opened together split it: a fifth of it here */
    oct_spool fifth;
    oct_spool_open(&fifth, dir, 1, 5);
    assert_true(fifth.has_file);
    assert_true(fifth.file_cap + slack >= (a < b ? a : b) / 5);
    assert_true(fifth.file_cap <= (a > b ? a : b) / 5 + slack);
    oct_spool_free(&fifth);
    s.file_cap = 1000; /* a nearly full disk */
    unsigned char bytes[3000];
    for (size_t i = 0; i < sizeof bytes; i++)
        bytes[i] = (unsigned char)(i * 7 + (i >> 8));
    for (size_t i = 0; i < sizeof bytes; i += 700)
        assert_int_equal(oct_spool_append(&s, bytes + i, sizeof bytes - i < 700 ? sizeof bytes - i : 700), 0);
    assert_int_equal(s.on_disk, 1000);
    assert_int_equal(s.mem.n, 2000);
    assert_spool_holds(&s, bytes, sizeof bytes);
    oct_spool_free(&s);
    assert_int_equal(dir_entries(dir), 0);
    assert_int_equal(rmdir(dir), 0);
}

/* A spool rewound to a mark comes back as the bytes before the mark and
 * those appended after the rewind, with their CRC, whether the bytes
 * dropped were in the file, across the file's cap or in memory, and
 * without a file at all (the writer's all-or-nothing append of the
 * surface indices and the records). */
static void test_spool_rewind(void **state)
{
    (void)state;
    char dir[] = "/tmp/oct-spool-test-XXXXXX";
    assert_non_null(mkdtemp(dir));
    unsigned char bytes[3000];
    for (size_t i = 0; i < sizeof bytes; i++)
        bytes[i] = (unsigned char)(i * 13 + (i >> 7));
    for (int with_file = 0; with_file <= 1; with_file++) {
        oct_spool s;
        oct_spool_open(&s, with_file ? dir : NULL, 1, 1);
        assert_int_equal(s.has_file, with_file);
        s.file_cap = 1000;
        assert_int_equal(oct_spool_append(&s, bytes, 600), 0); /* (in the file, if any) */
        oct_spool_mark m = oct_spool_tell(&s);
        assert_int_equal(oct_spool_append(&s, bytes + 600, 700), 0); /* across the cap */
        oct_spool_rewind(&s, m);
        assert_int_equal(oct_spool_size(&s), 600);
        /* in memory: the file refused bytes */
        assert_int_equal(oct_spool_append(&s, bytes + 1300, 500), 0);
        m = oct_spool_tell(&s);
        assert_int_equal(oct_spool_append(&s, bytes + 1800, 900), 0);
        oct_spool_rewind(&s, m);
        assert_int_equal(oct_spool_append(&s, bytes + 2700, 300), 0);
        assert_int_equal(s.on_disk, with_file ? 600 : 0);
        unsigned char want[1400];
        memcpy(want, bytes, 600);
        memcpy(want + 600, bytes + 1300, 500);
        memcpy(want + 1100, bytes + 2700, 300);
        assert_spool_holds(&s, want, sizeof want);
        oct_spool_free(&s);
    }
    assert_int_equal(dir_entries(dir), 0);
    assert_int_equal(rmdir(dir), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_writer_usage_errors),
        cmocka_unit_test(test_writer_write_failures),
        cmocka_unit_test(test_allocation_failures),
        cmocka_unit_test(test_large_tree_spans_chunks),
        cmocka_unit_test(test_spooled_records),
        cmocka_unit_test(test_spool_leaves_room),
        cmocka_unit_test(test_spool_rewind),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
