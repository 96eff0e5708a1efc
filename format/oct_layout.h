/* oct_layout: byte offsets and sizes of the .oct header and sections, shared by
 * the reader, the writer and the tests (normative text: FORMAT.md). */
#ifndef OCT_LAYOUT_H
#define OCT_LAYOUT_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "format/oct.h"

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the .oct reader maps files in place and needs a little-endian host"
#endif

#define OCT_HEADER_SIZE 256u   /* header_size written by this version */
#define OCT_ALIGN 64u          /* every section starts on a multiple of this */
#define OCT_BOM_U32 0x01020304u
#define OCT_BOM_F64 370.5      /* byte-order / float-format probe (exact in binary64) */
#define OCT_MAX_ROOT_DEPTH 40u /* a subtree's root lies at most this deep in its grid */

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
    OCT_OFF_RESERVED1 = 232,  /* 20 bytes, zero */
    OCT_OFF_HEADER_CRC = 252  /* CRC-32 of bytes [0, header_size - 4) */
};

enum { OCT_SEC_LEVELS, OCT_SEC_NODES, OCT_SEC_VOXELS, OCT_SEC_SURFACES, OCT_SEC_PALETTE,
       OCT_SEC_COUNT };
#define OCT_SEC_ENTRY 24u /* u64 offset, u64 size, u32 crc, u32 reserved */
#define OCT_SEC_OFF(k) (OCT_OFF_SECTIONS + OCT_SEC_ENTRY * (unsigned)(k))

_Static_assert(OCT_OFF_SECTIONS + OCT_SEC_ENTRY * OCT_SEC_COUNT == OCT_OFF_RESERVED1,
               "section table ends where the reserved bytes begin");
_Static_assert(OCT_OFF_HEADER_CRC + 4 == OCT_HEADER_SIZE, "the header CRC is last");

static inline uint16_t rd_u16le(const unsigned char *p) { uint16_t v; memcpy(&v, p, 2); return v; }
static inline uint32_t rd_u32le(const unsigned char *p) { uint32_t v; memcpy(&v, p, 4); return v; }
static inline uint64_t rd_u64le(const unsigned char *p) { uint64_t v; memcpy(&v, p, 8); return v; }
static inline double rd_f64le(const unsigned char *p) { double v; memcpy(&v, p, 8); return v; }
static inline void wr_u16le(unsigned char *p, uint16_t v) { memcpy(p, &v, 2); }
static inline void wr_u32le(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static inline void wr_u64le(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static inline void wr_f64le(unsigned char *p, double v) { memcpy(p, &v, 8); }

/* The cube rule (FORMAT.md §6): oct_cube_check (oct.h) finds nothing wrong. */
static inline int oct_cube_ok(double grid_origin, double grid_edge, uint32_t root_depth, uint32_t levels)
{
    return oct_cube_check(grid_origin, grid_edge, root_depth, levels) == OCT_CUBE_OK;
}

/* Allocation inside format/ (oct_alloc.c). Tests arm a failure of the nth
 * allocation from now (and, when sticky, of every later one); n = 0 disarms. */
void *oct__calloc(size_t n, size_t size);
void *oct__realloc(void *p, size_t size);
void *oct__aligned_alloc(size_t align, size_t size);
void oct__alloc_fail_after(long n, int sticky);

static inline uint64_t oct_align_up(uint64_t v) { return (v + (OCT_ALIGN - 1)) & ~(uint64_t)(OCT_ALIGN - 1); }

#endif
