/* oct_synth: random sparse voxel trees for the .oct tests, the fuzz corpus
 * generator and the validation benchmark: Morton-sorted voxels, their masks
 * per depth, and the bytes the writer makes of them. */
#ifndef OCT_SYNTH_H
#define OCT_SYNTH_H

#include <stddef.h>
#include <stdint.h>

#include "format/oct.h"

typedef struct test_tree {
    uint32_t levels, surface_count, root_depth;
    uint64_t root_cell[3];
    double origin[3], edge;
    size_t voxel_count;
    uint64_t *codes;    /* Morton code of each voxel (3 bits a level, x + 2y + 4z) */
    uint32_t *voxels;   /* voxel records */
    uint8_t *surfaces;  /* surface index of each voxel */
    float palette[3 * OCT_MAX_SURFACES];
    uint8_t *masks[OCT_MAX_LEVELS];
    size_t count[OCT_MAX_LEVELS];
} test_tree;

/* A random tree of about `target` voxels (fewer if the grid is smaller),
 * deterministic for a seed. `clustered` grows blobs rather than scattering
 * voxels uniformly. Aborts on allocation failure. */
void test_tree_random(test_tree *t, uint32_t levels, size_t target, uint32_t surface_count,
                      uint64_t seed, int clustered);
/* Builds the masks of the voxels in t->codes (sorted, unique). */
void test_tree_build_masks(test_tree *t);
void test_tree_free(test_tree *t);

/* Writes the tree through the streaming writer (depths fed in random-size
 * chunks, deepest first) into a malloc'd buffer. Returns the writer's error. */
oct_err test_tree_write(const test_tree *t, unsigned char **buf, size_t *len);
/* The same with v11's format 1.1 fields (flags, shard fields, function;
 * everything else comes from t). */
oct_err test_tree_write_1_1(const test_tree *t, const oct_writer_params *v11, unsigned char **buf,
                            size_t *len);

/* Recomputes the header's section CRCs and the header CRC after a test has
 * edited a file, so that a check other than the CRC's is exercised. Uses the
 * header's own offsets and skips any section outside the buffer. */
void test_oct_refresh_crcs(unsigned char *buf, size_t len);

/* xorshift64* (bench/rng.h); a zero *state starts from a fixed seed. */
uint64_t test_rand(uint64_t *state);

#endif
