/* oct_check: cmocka assertions shared by the .oct test suites. Only test
 * programs (linked with cmocka) may call these. */
#ifndef OCT_CHECK_H
#define OCT_CHECK_H

#include <stddef.h>
#include <stdint.h>

#include "format/oct.h"
#include "bench/oct_synth.h"

/* Asserts that the opened file holds exactly t: header fields, counts, masks,
 * voxel records, surfaces and palette, and that a walk from the root through
 * oct_child_index reaches t's voxels in Morton order. */
void oct_check_tree(const oct_file *f, const test_tree *t);

/* A small valid file: 3 levels, 2 surfaces, a few dozen voxels. */
void oct_check_small_file(unsigned char **buf, size_t *len, test_tree *t);

/* oct_open_memory of buf, asserting the contract of its result (a file on
 * success, none and an offset inside the buffer on failure); closes the file.
 * *at (if not NULL) gets the reported offset. Returns the reader's error. */
oct_err oct_check_open(const unsigned char *buf, size_t len, unsigned flags, uint64_t *at);

#endif
