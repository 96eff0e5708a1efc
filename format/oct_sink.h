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

typedef struct oct_sink {
    FILE *f; /* NULL: count and checksum only */
    uLong crc;
    uint64_t bytes;
    int no_crc; /* 1: the CRC is not kept (the writer's second pass knows it) */
} oct_sink;

/* 0, or -1 with errno set (EIO when the stream gave no reason). */
int oct_sink_put(oct_sink *s, const void *data, size_t n);

/* Zero bytes up to offset `target` (no-op when already there). */
int oct_sink_pad_to(oct_sink *s, uint64_t target);

#endif
