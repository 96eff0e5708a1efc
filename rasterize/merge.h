/* merge: rasterize --merge, the command around oct_merge. */
#ifndef MERGE_H
#define MERGE_H

#include <stddef.h>

/* Merges the n shard files into out_path, written atomically; prints a
 * summary unless quiet. Returns the exit status: 0, or 1 with a message
 * naming the file at fault and no output left behind. */
int merge_main(const char *out_path, const char *const *parts, size_t n, int quiet);

#endif
