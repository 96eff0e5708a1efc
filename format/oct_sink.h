/* oct_sink: the byte sink of the .oct writer and of the merge. Every byte
 * written goes through it: it keeps the running CRC-32 and the count, and
 * writes to a stream when it has one (none: a checksum-only pass; no_crc: a
 * pass whose CRCs are known already). */
#ifndef OCT_SINK_H
#define OCT_SINK_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <zlib.h>

#include "format/oct.h"

typedef struct oct_sink {
    FILE *f; /* NULL: count and checksum only */
    uLong crc;
    uint64_t bytes;
    int no_crc; /* 1: the CRC is not kept (the writer's second pass knows it) */
    oct_copy_fn copy; /* NULL, or how bytes of a file may reach the stream (oct.h) */
    void *copy_ctx;
} oct_sink;

/* 0, or -1 with errno set (EIO when the stream gave no reason). */
int oct_sink_put(oct_sink *s, const void *data, size_t n);

/* The first bytes of len bytes of file fd from offset off, as many as the
 * sink's copy function moves (*done of them; 0 without one, or where the
 * CRC is kept: that needs the bytes read); the caller puts the rest. 0, or
 * -1 with errno set when the output failed. */
int oct_sink_copy(oct_sink *s, int fd, uint64_t off, uint64_t len, uint64_t *done);

/* Zero bytes up to offset `target` (no-op when already there). */
int oct_sink_pad_to(oct_sink *s, uint64_t target);

#endif
