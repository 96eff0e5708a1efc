/* oct_store: see oct_store.h. */
#include "format/oct_store.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "format/oct_layout.h"

/* Chunk k of a store. From the second on, one huge page: aligned to its
 * size with a huge-page hint, so filling it takes one page fault, not 512
 * (each some 15 us of CPU on a virtual machine). The first keeps small
 * pages, so a small store (the upper depths' masks) costs no more memory
 * than it fills. (Chunks, not one doubling realloc: a realloc of hundreds
 * of megabytes copies them on some systems and on others moves their pages,
 * which a virtual machine may then fault in again one by one when they are
 * next read: docs/perf-log.md.) */
static void *chunk_alloc(size_t k)
{
    if (k == 0)
        return oct__realloc(NULL, OCT_CHUNK);
    void *p = oct__aligned_alloc(OCT_CHUNK, OCT_CHUNK);
#ifdef MADV_HUGEPAGE
    if (p)
        (void)madvise(p, OCT_CHUNK, MADV_HUGEPAGE); /* a hint: small pages are fine */
#endif
    return p;
}

int oct_chunks_append(oct_chunks *a, const void *data, size_t n)
{
    if (n > SIZE_MAX - OCT_CHUNK - a->n)
        return -1;
    const size_t need = (a->n + n + OCT_CHUNK - 1) >> OCT_CHUNK_BITS;
    if (need > a->cap) {
        size_t cap = a->cap ? a->cap : 16;
        while (cap < need)
            cap *= 2;
        unsigned char **c = oct__realloc(a->c, cap * sizeof *c);
        if (!c)
            return -1;
        a->c = c;
        a->cap = cap;
    }
    for (; a->nchunks < need; a->nchunks++) /* kept on failure: capacity */
        if (!(a->c[a->nchunks] = chunk_alloc(a->nchunks)))
            return -1;
    const unsigned char *p = data;
    while (n) {
        const size_t off = a->n & (OCT_CHUNK - 1);
        const size_t k = OCT_CHUNK - off < n ? OCT_CHUNK - off : n;
        memcpy(a->c[a->n >> OCT_CHUNK_BITS] + off, p, k);
        a->n += k;
        p += k;
        n -= k;
    }
    return 0;
}

int oct_chunks_put(const oct_chunks *a, oct_sink *s)
{
    for (size_t i = 0; i < a->n; i += OCT_CHUNK) {
        const size_t k = a->n - i < OCT_CHUNK ? a->n - i : OCT_CHUNK;
        if (oct_sink_put(s, a->c[i >> OCT_CHUNK_BITS], k) != 0)
            return -1;
    }
    return 0;
}

void oct_chunks_free(oct_chunks *a)
{
    for (size_t i = 0; i < a->nchunks; i++)
        free(a->c[i]);
    free(a->c);
    memset(a, 0, sizeof *a);
}

static uint64_t spool_limit = UINT64_MAX;

void oct__spool_limit(uint64_t bytes) { spool_limit = bytes; }

/* A scratch file in dir that no directory entry names, or -1: O_TMPFILE
 * where the filesystem has it, else a unique name removed at once. */
static int scratch_file(const char *dir)
{
    int fd = -1;
#ifdef O_TMPFILE
    fd = open(dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd >= 0)
        return fd;
#endif
    const size_t n = strlen(dir);
    char *path = oct__realloc(NULL, n + sizeof "/.oct-spool-XXXXXX");
    if (!path)
        return -1;
    memcpy(path, dir, n);
    memcpy(path + n, "/.oct-spool-XXXXXX", sizeof "/.oct-spool-XXXXXX");
    fd = mkostemp(path, O_CLOEXEC);
    if (fd >= 0 && unlink(path) != 0) { /* a file left behind is worse than memory */
        close(fd);
        fd = -1;
    }
    free(path);
    return fd;
}

#define READ_BLOCK ((size_t)1 << 20)

void oct_spool_open(oct_spool *s, const char *dir, unsigned share_num, unsigned share_den)
{
    memset(s, 0, sizeof *s);
    s->fd = -1;
    s->crc = crc32_z(0, NULL, 0);
    if (!dir || !*dir || (s->fd = scratch_file(dir)) < 0)
        return;
    if (!(s->buf = oct__realloc(NULL, READ_BLOCK))) {
        close(s->fd);
        s->fd = -1;
        return;
    }
    s->has_file = 1;
    /* a shared /tmp is not ours to fill: at most half of what is free now,
     * split between the spools */
    struct statvfs sv;
    s->file_cap = fstatvfs(s->fd, &sv) == 0
                      ? (uint64_t)sv.f_bavail * sv.f_frsize / 2 / share_den * share_num
                      : UINT64_MAX;
}

int oct_spool_append(oct_spool *s, const void *data, size_t n)
{
    if (n == 0)
        return 0; /* (data may be NULL then: zlib's CRC would restart) */
    const unsigned char *p = data;
    const uint64_t start = s->on_disk;
    const size_t all = n;
    while (n && s->has_file && !s->file_full) {
        size_t k = n < ((size_t)1 << 30) ? n : (size_t)1 << 30;
        const uint64_t room = (s->file_cap < spool_limit ? s->file_cap : spool_limit) - s->on_disk;
        if (room < k)
            k = (size_t)room;
        ssize_t w = -1;
        if (k) {
            w = pwrite(s->fd, p, k, (off_t)s->on_disk);
            if (w < 0 && errno == EINTR)
                continue;
        } else if (spool_limit <= s->file_cap) {
            spool_limit = UINT64_MAX; /* (tests) refused once: a disk whose space comes back */
        }
        if (w <= 0) {
            s->file_full = 1; /* the rest, from here on, in memory */
            break;
        }
        s->on_disk += (uint64_t)w;
        p += w;
        n -= (size_t)w;
    }
    if (n && oct_chunks_append(&s->mem, p, n) != 0) {
        s->on_disk = start; /* all or nothing: the file's bytes past start are dropped */
        return -1;
    }
    s->crc = crc32_z(s->crc, data, all);
    return 0;
}

int oct_spool_put(const oct_spool *s, oct_sink *sink)
{
    for (uint64_t o = 0; o < s->on_disk;) {
        const size_t k = s->on_disk - o < READ_BLOCK ? (size_t)(s->on_disk - o) : READ_BLOCK;
        const ssize_t r = pread(s->fd, s->buf, k, (off_t)o);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0 || oct_sink_put(sink, s->buf, (size_t)r) != 0) {
            if (r == 0)
                errno = EIO; /* the file is shorter than what was written to it */
            return -1;
        }
        o += (uint64_t)r;
    }
    return oct_chunks_put(&s->mem, sink);
}

void oct_spool_free(oct_spool *s)
{
    if (s->has_file)
        close(s->fd);
    free(s->buf);
    oct_chunks_free(&s->mem);
    memset(s, 0, sizeof *s);
    s->fd = -1;
}
