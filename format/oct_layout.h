/* oct_layout: byte offsets and sizes of the .oct header and sections, shared by
 * the reader, the writer and the tests (normative text: FORMAT.md). */
#ifndef OCT_LAYOUT_H
#define OCT_LAYOUT_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the .oct reader maps files in place and needs a little-endian host"
#endif

#define OCT_HEADER_SIZE 256u   /* header_size of a 1.0 file */
#define OCT_HEADER_SIZE_1_1 320u /* header_size of a 1.1 file (the least for minors >= 1) */
#define OCT_ALIGN 64u          /* every section starts on a multiple of this */
#define OCT_BOM_U32 0x01020304u
#define OCT_BOM_F64 370.5      /* byte-order / float-format probe (exact in binary64) */
#define OCT_MAX_ROOT_DEPTH 40u /* a subtree's root lies at most this deep in its grid */
#define OCT_MAX_COORD 1e30     /* |grid_origin[i]| and grid_edge are at most this */
#define OCT_MIN_VOXEL_RES 0x1p-48 /* finest voxel edge >= this x (|origin| + edge) */

enum { /* header field offsets */
    OCT_OFF_MAGIC = 0,
    OCT_OFF_MAJOR = 8,
    OCT_OFF_MINOR = 10,
    OCT_OFF_HEADER_SIZE = 12,
    OCT_OFF_BOM_U32 = 16,
    OCT_OFF_FLAGS = 20,
    OCT_OFF_BOM_F64 = 24,
    OCT_OFF_LEVELS = 32,
    OCT_OFF_ROOT_DEPTH = 36,
    OCT_OFF_ROOT_CELL = 40,   /* 3 x u64 */
    OCT_OFF_GRID_ORIGIN = 64, /* 3 x f64 */
    OCT_OFF_GRID_EDGE = 88,
    OCT_OFF_SURFACE_COUNT = 96,
    OCT_OFF_RESERVED0 = 100,  /* u32, zero */
    OCT_OFF_VOXEL_COUNT = 104,
    OCT_OFF_SECTIONS = 112,   /* OCT_SEC_COUNT x 24 bytes */
    OCT_OFF_RESERVED1 = 232,  /* 1.0: 20 bytes, zero */
    OCT_OFF_HEADER_CRC = 252, /* 1.0: CRC-32 of bytes [0, header_size - 4) */
    /* 1.1 (header_size 320): the FUNCTION entry takes 232..255, then: */
    OCT_OFF_SHARD_COUNT = 256,
    OCT_OFF_SHARD_INDEX = 260,
    OCT_OFF_SHARD_DEPTH = 264,
    OCT_OFF_PARTITION_CRC = 268,
    OCT_OFF_MORTON_LO = 272,
    OCT_OFF_MORTON_HI = 280,
    OCT_OFF_RESERVED2 = 288,  /* 1.1: 28 bytes, zero */
    OCT_OFF_HEADER_CRC_1_1 = 316
};

/* The sections of a 1.0 file (OCT_SEC_COUNT_1_0 entries) and of a 1.1 file,
 * whose FUNCTION entry sits where 1.0 had reserved bytes. */
enum { OCT_SEC_LEVELS, OCT_SEC_NODES, OCT_SEC_VOXELS, OCT_SEC_SURFACES, OCT_SEC_PALETTE,
       OCT_SEC_FUNCTION, OCT_SEC_COUNT };
#define OCT_SEC_COUNT_1_0 OCT_SEC_FUNCTION
#define OCT_SEC_ENTRY 24u /* u64 offset, u64 size, u32 crc, u32 reserved */
#define OCT_SEC_OFF(k) (OCT_OFF_SECTIONS + OCT_SEC_ENTRY * (unsigned)(k))

_Static_assert(OCT_OFF_SECTIONS + OCT_SEC_ENTRY * OCT_SEC_COUNT_1_0 == OCT_OFF_RESERVED1,
               "the 1.0 section table ends where its reserved bytes begin");
_Static_assert(OCT_OFF_HEADER_CRC + 4 == OCT_HEADER_SIZE, "the header CRC is last");
_Static_assert(OCT_OFF_SECTIONS + OCT_SEC_ENTRY * OCT_SEC_COUNT == OCT_OFF_SHARD_COUNT,
               "the 1.1 section table ends where the shard fields begin");
_Static_assert(OCT_OFF_HEADER_CRC_1_1 + 4 == OCT_HEADER_SIZE_1_1, "the 1.1 header CRC is last");

/* The FUNCTION section (FORMAT.md §8): a u32 tape count and a reserved u32,
 * then per tape a 16-byte head (u32 insn_count, const_count, root, reserved),
 * const_count constants (f64 v, lo, hi), insn_count instructions (u32 op, a,
 * b) and zero padding to a multiple of 8. Op codes: OCT_OP_* in oct.h. */
#define OCT_FN_HEAD 8u
#define OCT_FN_TAPE_HEAD 16u
#define OCT_FN_CONST_SIZE 24u
#define OCT_FN_INSN_SIZE 12u

static inline uint16_t rd_u16le(const unsigned char *p) { uint16_t v; memcpy(&v, p, 2); return v; }
static inline uint32_t rd_u32le(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static inline uint64_t rd_u64le(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static inline double rd_f64le(const unsigned char *p) { double v; memcpy(&v, p, 8); return v; }
static inline void wr_u16le(unsigned char *p, uint16_t v) { memcpy(p, &v, 2); }
static inline void wr_u32le(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static inline void wr_u64le(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static inline void wr_f64le(unsigned char *p, double v) { memcpy(p, &v, 8); }

/* The cube rule (FORMAT.md, "Cube"): true when a grid with this corner
 * coordinate and edge, with its finest voxels 2^-(root_depth+levels) of the
 * edge, is representable: coordinates in range, voxel edge a normal double
 * and resolvable next to the largest coordinate. NaN fails. */
static inline int oct_cube_ok(double grid_origin, double grid_edge, uint32_t root_depth, uint32_t levels)
{
    double voxel = ldexp(grid_edge, -(int)(root_depth + levels));
    return grid_edge > 0.0 && grid_edge <= OCT_MAX_COORD && voxel >= DBL_MIN &&
           fabs(grid_origin) <= OCT_MAX_COORD && fabs(grid_origin) + grid_edge <= voxel / OCT_MIN_VOXEL_RES;
}

/* Allocation inside format/ (oct_alloc.c). Tests arm a failure of the nth
 * allocation from now (and, when sticky, of every later one); n = 0 disarms. */
void *oct__calloc(size_t n, size_t size);
void *oct__realloc(void *p, size_t size);
void *oct__aligned_alloc(size_t align, size_t size);
void oct__alloc_fail_after(long n, int sticky);

/* Checks a FUNCTION section of `size` bytes at p (FORMAT.md §8) that holds
 * `count` tapes and lies at file offset `base`; fills tapes[0..count) with
 * pointers into p when `tapes` is not NULL. Returns 0, or -1 with the file
 * offset of the failing field in *where and the broken rule in *what
 * (oct_function.c). */
struct oct_function_tape;
int oct__function_check(const unsigned char *p, uint64_t size, uint64_t base, uint32_t count,
                        struct oct_function_tape *tapes, uint64_t *where, const char **what);

static inline uint64_t oct_align_up(uint64_t v) { return (v + (OCT_ALIGN - 1)) & ~(uint64_t)(OCT_ALIGN - 1); }

#endif
