/* oct_merge: the shards of one partition streamed into the whole file
 * (FORMAT.md §6, "Shards"). The result is byte for byte the file the whole
 * run writes: the depths at and below the partition depth k are the parts'
 * streams one after the other in shard order, the depths above k are
 * rebuilt from the union of the parts' depth-k cells, and the header is the
 * parts' own with the counts, sections and checksums of the whole and the
 * shard fields zero. Time is linear in the parts' total size; memory is a
 * fixed buffer plus O(8^k + N), independent of the sizes (each part is
 * validated through oct_open, one at a time, then read sequentially). */
#ifndef OCT_MERGE_H
#define OCT_MERGE_H

#include <stddef.h>
#include <stdint.h>

#include "format/oct.h"

#define OCT_MERGE_MAX_DEPTH 7 /* deepest partition depth merged: 8^7 cell flags (--shard uses <= 6) */

typedef struct oct_merge_error {
    const char *path; /* the part at fault, or NULL for the output */
    oct_err err;      /* OCT_EIO: errno tells; OCT_EUSAGE: the parts do not go together */
    char msg[256];    /* what is wrong, in English, without the path */
} oct_merge_error;

/* Merges the n parts into `out` (a FILE * open for writing on a seekable
 * file, positioned at 0), in any order of `paths`. Every part must be a
 * valid shard file of the same grid, scene and partition, each shard
 * exactly once. Returns OCT_OK (and *bytes, when not NULL, the output
 * size) or the first failure, described in *e. */
oct_err oct_merge(const char *const *paths, size_t n, void *out /* FILE * */, uint64_t *bytes,
                  oct_merge_error *e);

#endif
