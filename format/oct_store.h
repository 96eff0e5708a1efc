/* oct_store: the writer's append-only byte stores (format/ internal).
 *
 * oct_chunks keeps bytes in memory, in chunks that never move once written.
 * oct_spool keeps them in an unlinked scratch file instead, so that the
 * largest part of a deep file (the voxel records) does not have to sit in
 * the process's memory until the end; where no scratch file can be made, or
 * it stops taking bytes (a full disk, or half the space that was free when
 * it was made: a shared /tmp is left room), the rest goes to memory. Either
 * way the bytes come back in the order they were appended. */
#ifndef OCT_STORE_H
#define OCT_STORE_H

#include <stddef.h>
#include <stdint.h>

#include <zlib.h>

#include "format/oct_sink.h"

#define OCT_CHUNK_BITS 21
#define OCT_CHUNK ((size_t)1 << OCT_CHUNK_BITS)

typedef struct oct_chunks {
    unsigned char **c;
    size_t nchunks, cap; /* chunks allocated, slots in c */
    size_t n;            /* bytes stored */
} oct_chunks;

/* Appends n bytes; -1 (nothing appended) when memory runs out. */
int oct_chunks_append(oct_chunks *a, const void *data, size_t n);
/* The stored bytes into s, in order. */
int oct_chunks_put(const oct_chunks *a, oct_sink *s);
void oct_chunks_free(oct_chunks *a); /* leaves it empty, ready for use */

static inline unsigned char oct_chunks_at(const oct_chunks *a, size_t i)
{
    return a->c[i >> OCT_CHUNK_BITS][i & (OCT_CHUNK - 1)];
}

typedef struct oct_spool {
    int has_file;     /* fd is the scratch file (unlinked) */
    int fd;
    int file_full;    /* it refused bytes: nothing more is written to it */
    unsigned char *buf; /* with the file: the read-back's block (allocated at open,
                           so that the writer's finish allocates nothing) */
    uint64_t file_cap; /* it takes at most this many bytes: its share of half
                          the space free in its filesystem when it was made */
    uint64_t on_disk; /* the first on_disk bytes are in the file */
    oct_chunks mem;   /* the bytes after them */
    uLong crc;        /* CRC-32 of all the bytes appended, kept as they come */
} oct_spool;

/* An empty spool whose bytes go to an unlinked file in directory `dir`
 * (NULL: memory only), the file taking at most share_num / share_den of
 * half the space free there (spools opened together split that half). Never
 * fails: without a file, memory is used. */
void oct_spool_open(oct_spool *s, const char *dir, unsigned share_num, unsigned share_den);
/* Appends n bytes; -1 (nothing appended) when neither the file nor memory
 * takes them. */
int oct_spool_append(oct_spool *s, const void *data, size_t n);
static inline uint64_t oct_spool_size(const oct_spool *s) { return s->on_disk + s->mem.n; }
/* The CRC-32 (zlib's) of the bytes appended: what a pass of oct_spool_put
 * would compute, without reading them back. */
static inline uint32_t oct_spool_crc(const oct_spool *s) { return (uint32_t)s->crc; }
/* A point in a spool's bytes to come back to (oct_spool_rewind). */
typedef struct oct_spool_mark {
    uint64_t on_disk;
    size_t mem_n;
    uLong crc;
} oct_spool_mark;
static inline oct_spool_mark oct_spool_tell(const oct_spool *s)
{
    oct_spool_mark m = {s->on_disk, s->mem.n, s->crc};
    return m;
}
/* Drops the bytes appended since m was told (a caller's all-or-nothing
 * append across two spools). A file that refused bytes meanwhile stays
 * refused: what comes next goes to memory. */
static inline void oct_spool_rewind(oct_spool *s, oct_spool_mark m)
{
    s->on_disk = m.on_disk;
    s->mem.n = m.mem_n;
    s->crc = m.crc;
}
/* The stored bytes into sink, in order; -1 with errno set when the file
 * cannot be read back or the sink fails. */
int oct_spool_put(const oct_spool *s, oct_sink *sink);
void oct_spool_free(oct_spool *s); /* closes the file; accepts a zeroed one */

/* Tests: the scratch file takes `bytes` bytes, then refuses one write
 * (ENOSPC) and takes writes again (a disk whose space comes back: the spool
 * must not). UINT64_MAX disarms; so does the refusal. */
void oct__spool_limit(uint64_t bytes);

#endif
