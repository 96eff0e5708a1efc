/* oct: the .oct sparse-octree file — constants, errors, the validated tree view,
 * the mmap reader and the streaming writer. The byte layout is normative in
 * format/FORMAT.md; this header is its C face.
 *
 * Tree model. A file with L levels covers a 2^L x 2^L x 2^L voxel grid. Nodes
 * live at depths 0..L-1 (depth 0 is the root cell). Each node has an 8-bit
 * child mask; bit i is set when child i is non-empty, where i = x + 2y + 4z
 * (x, y, z in {0,1}: the child's half along each axis, the paper's order).
 * Children of depth-d nodes are the nodes of depth d+1 (or, for d = L-1, the
 * voxels), stored in the order of their parents and, within a parent, in
 * increasing i. That is breadth-first order, and within a depth it is Morton
 * (z-order) order. Every stored node has a non-zero mask; an empty tree has no
 * nodes and no voxels.
 *
 * Nodes of one depth are packed in groups of eight (oct_group): the masks of
 * nodes 8g..8g+7 and `base`, the index in depth d+1 of the first child of node
 * 8g. The child index of any node is then one 64-bit popcount away
 * (oct_child_index). Two bytes a node, no pointers.
 *
 * Voxels are one little-endian uint32 each (OCT_VOXEL_*): a 24-bit octahedral
 * normal and a signed 8-bit plane offset (the surface's distance from the
 * voxel centre along the normal, in voxel edges). When the scene has more than
 * one surface, a parallel uint8 array names each voxel's surface, which
 * indexes the palette.
 *
 * Format 1.1 adds a FUNCTION section (each surface's tape, validated in
 * place: oct_get_function; common/expr/tape_io.c makes tapes of it), the
 * SHELL_ONLY flag (no voxel records) and shard fields. The writer writes 1.0
 * unless one of them is used.
 */
#ifndef OCT_H
#define OCT_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define OCT_MAGIC "\x89OCT\r\n\x1a\n" /* 8 bytes; the 0x89 is not text */
#define OCT_MAGIC_SIZE 8
#define OCT_VERSION_MAJOR 1 /* a reader refuses a higher major */
#define OCT_VERSION_MINOR 1 /* a reader accepts any minor; the writer writes 0 or 1 */
#define OCT_MAX_LEVELS 20   /* deepest grid: 2^20 voxels a side */
#define OCT_MAX_SURFACES 255

typedef enum oct_err {
    OCT_OK = 0,
    OCT_EIO,       /* open/stat/read/mmap/write failed: see errno */
    OCT_ENOMEM,    /* allocation failed */
    OCT_ENOTFILE,  /* not a regular file (directory, FIFO, device) */
    OCT_ETRUNC,    /* file shorter than its header or sections claim */
    OCT_EMAGIC,    /* not an .oct file */
    OCT_EVERSION,  /* major version newer than this reader */
    OCT_EHEADER,   /* a header field out of range (levels, cube, counts, flags) */
    OCT_ERESERVED, /* a reserved field or padding byte is not zero */
    OCT_ESECTION,  /* a section misaligned, overlapping or past the end */
    OCT_ETREE,     /* tree structure inconsistent (empty mask, bad base, counts) */
    OCT_EVOXEL,    /* a voxel record out of range (surface index, normal code) */
    OCT_ECRC,      /* a CRC-32 does not match */
    OCT_EUSAGE,    /* the caller broke the API contract (writer fed out of order) */
    OCT_EFUNCTION, /* the FUNCTION section breaks one of its invariants */
    OCT_ERR_COUNT
} oct_err;

/* Static English text for an error code; never NULL. */
const char *oct_strerror(oct_err err);

/* The cube rule (FORMAT.md §6), the usable range of both programs: a grid
 * edge in [OCT_MIN_EDGE, OCT_MAX_COORD], |grid_origin| <= OCT_MAX_COORD on
 * each axis, and the finest voxel no finer than 2^-OCT_RES_BITS of
 * |grid_origin| + grid_edge, so that its corners are distinct doubles with
 * bits to spare. Within it every squared distance the renderer forms stays a
 * normal double. */
#define OCT_MAX_COORD 1e30
#define OCT_MIN_EDGE 1e-30
#define OCT_RES_BITS 48

typedef enum oct_cube_err {
    OCT_CUBE_OK = 0,
    OCT_CUBE_EDGE_LARGE,  /* grid_edge > OCT_MAX_COORD, infinite or NaN */
    OCT_CUBE_EDGE_SMALL,  /* grid_edge < OCT_MIN_EDGE (zero and negative included) */
    OCT_CUBE_ORIGIN_FAR,  /* |grid_origin| > OCT_MAX_COORD, infinite or NaN */
    OCT_CUBE_VOXEL_FINE   /* |grid_origin| + grid_edge > 2^OCT_RES_BITS voxel edges */
} oct_cube_err;

/* Checks one axis of a grid whose finest voxels are 2^-(root_depth+levels)
 * of its edge (levels + root_depth <= 60). The first rule broken, in the
 * order of the enum. */
oct_cube_err oct_cube_check(double grid_origin, double grid_edge, uint32_t root_depth,
                            uint32_t levels);

/* Eight nodes of one depth, exactly as stored (little-endian, 16 bytes). */
typedef struct oct_group {
    uint64_t base;    /* next-depth index of the first child of node 8g */
    uint8_t mask[8];  /* child masks of nodes 8g..8g+7; 0 past the last node */
} oct_group;
_Static_assert(sizeof(oct_group) == 16, "oct_group is 16 bytes on disk");

/* Header flags (every bit is "required": a reader refuses bits it does not
 * know). SHELL_ONLY: no voxel records (VOXELS is empty although voxel_count
 * > 0): the tree only brackets the surface; needs a FUNCTION section. */
#define OCT_FLAG_SHELL_ONLY 1u
#define OCT_FLAGS_KNOWN OCT_FLAG_SHELL_ONLY

/* Op codes of the FUNCTION section's instructions (FORMAT.md §8). They are
 * the file's numbers, not any in-memory enum's. */
enum {
    OCT_OP_CONST = 0, /* a: constant pool index; b: 0 */
    OCT_OP_X = 1, OCT_OP_Y = 2, OCT_OP_Z = 3, /* a, b: 0 */
    OCT_OP_NEG = 4, OCT_OP_SQUARE = 5, OCT_OP_SQRT = 6, OCT_OP_EXP = 7, OCT_OP_LOG = 8,
    OCT_OP_ABS = 9, OCT_OP_SIN = 10, OCT_OP_COS = 11, OCT_OP_TAN = 12, /* a: slot; b: 0 */
    OCT_OP_ADD = 13, OCT_OP_SUB = 14, OCT_OP_MUL = 15, OCT_OP_DIV = 16, OCT_OP_MIN = 17,
    OCT_OP_MAX = 18, /* a, b: slots */
    OCT_OP_POWC = 19, /* a: slot; b: pool index of an exact, non-integer exponent */
    OCT_OP_COUNT = 20
};
#define OCT_FN_MAX_INSNS (1u << 22)  /* per tape (the expression engine's limit) */
#define OCT_FN_MAX_CONSTS (1u << 22) /* per tape */

/* One surface's tape in a validated FUNCTION section, in place in the file:
 * insn[3i], insn[3i+1], insn[3i+2] are instruction i's op (OCT_OP_*), a and
 * b; konst[3j..3j+2] are constant j's v, lo, hi. Every invariant of FORMAT.md
 * §8 holds: known ops, operands strictly earlier, pool indices in range,
 * root < insn_count, constants finite with lo <= v <= hi. */
typedef struct oct_function_tape {
    uint32_t insn_count, const_count, root;
    const uint32_t *insn;
    const double *konst; /* NULL when const_count is 0 */
} oct_function_tape;

/* Voxel record fields. */
#define OCT_VOXEL_NORMAL_BITS 24u
#define OCT_VOXEL_NORMAL_MASK 0x00ffffffu
#define OCT_VOXEL_OFFSET_SHIFT 24u
#define OCT_OFFSET_UNIT (1.0 / 128.0) /* plane offset step, in voxel edges */

/* The validated, read-only view of a tree, in world coordinates. A reader
 * fills it after full validation; tests may build one in memory. Every
 * invariant in the file comment above holds for it. */
typedef struct oct_tree {
    uint32_t levels;                       /* 1..OCT_MAX_LEVELS */
    double origin[3];                      /* world min corner of this tree's cube */
    double edge;                           /* world edge length of that cube, > 0 */
    uint64_t node_count[OCT_MAX_LEVELS];   /* nodes at each depth; [0] is 0 or 1 */
    uint64_t voxel_count;
    const oct_group *groups[OCT_MAX_LEVELS]; /* per depth, ceil(count/8) groups */
    const uint32_t *voxels;                /* voxel_count records; NULL in a shell-only file */
    const uint8_t *surfaces;               /* voxel_count indices, NULL if surface_count <= 1 */
    uint32_t surface_count;                /* 1..OCT_MAX_SURFACES */
    const float *palette;                  /* surface_count linear RGB triples in [0,1] */
} oct_tree;

static inline unsigned oct_popcount64(uint64_t v) { return (unsigned)__builtin_popcountll(v); }

static inline uint8_t oct_node_mask(const oct_group *g, uint64_t node)
{
    return g[node >> 3].mask[node & 7];
}

/* The child mask of `node` and the index, in the next depth (or the voxel
 * array), of its first child: what a traversal keeps of a node it enters. */
typedef struct oct_children {
    uint64_t first;
    uint32_t mask;
} oct_children;

static inline oct_children oct_node_children(const oct_group *g, uint64_t node)
{
    const oct_group *gr = &g[node >> 3];
    unsigned k = (unsigned)(node & 7);
    uint64_t masks;
    memcpy(&masks, gr->mask, 8); /* little-endian host: mask[j] is byte j */
    oct_children c;
    c.mask = (uint32_t)(masks >> (8 * k)) & 0xffu;
    c.first = gr->base + oct_popcount64(masks & ((UINT64_C(1) << (8 * k)) - 1)); /* k < 8 */
    return c;
}

/* Index, in the next depth (or the voxel array), of child `child` (0..7) of
 * `node`. Only meaningful when that child's bit is set. */
static inline uint64_t oct_child_index(const oct_group *g, uint64_t node, unsigned child)
{
    const oct_children c = oct_node_children(g, node);
    return c.first + oct_popcount64(c.mask & ((1u << child) - 1u));
}

/* --- Reader ------------------------------------------------------------ */

typedef struct oct_file oct_file;

enum {
    OCT_OPEN_TRUST = 1u /* skip the CRC checks (never the structure checks) */
};

/* Facts of the header that are not part of the tree view. */
typedef struct oct_info {
    uint16_t version_major, version_minor;
    uint32_t flags;            /* OCT_FLAG_* */
    /* Shard fields (1.1; all 0 for a whole file): shard shard_index of a
     * shard_count-way partition of the cells of depth shard_depth, in Morton
     * order; it holds the voxels whose depth-k ancestor c has morton_lo <= c
     * < morton_hi; partition_crc is the CRC-32 of the N+1 boundaries. */
    uint32_t shard_count, shard_index, shard_depth, partition_crc;
    uint64_t morton_lo, morton_hi;
    const void *function;      /* the FUNCTION section's bytes, NULL when absent */
    uint64_t function_size;
    uint32_t root_depth;       /* depth of this tree's root in the whole grid */
    uint64_t root_cell[3];     /* integer cell coordinates of the root at root_depth */
    double grid_origin[3];     /* world min corner of the whole grid */
    double grid_edge;          /* world edge of the whole grid */
    uint64_t file_size;
    uint64_t total_nodes;
} oct_info;

/* Maps `path` read-only and validates all of it before returning (see
 * FORMAT.md, "Reader checks"). On failure returns the error, sets *out to
 * NULL and, when err_offset is not NULL, the byte offset where the check
 * failed (0 when not applicable). errno is meaningful for OCT_EIO. */
oct_err oct_open(const char *path, unsigned flags, oct_file **out, uint64_t *err_offset);

/* Where and why validation failed: the byte offset of the failing field
 * and a static English phrase naming the broken rule (for the FUNCTION
 * section, the invariant; otherwise oct_strerror's text without its
 * "corrupt: " prefix). Never NULL after a failed open. */
typedef struct oct_fault {
    uint64_t offset;
    const char *what;
} oct_fault;

/* oct_open and oct_open_memory with the fault described; `fault` may be NULL. */
oct_err oct_open_fault(const char *path, unsigned flags, oct_file **out, oct_fault *fault);
oct_err oct_open_memory_fault(const void *data, size_t size, unsigned flags, oct_file **out,
                              oct_fault *fault);

/* The same over a caller's buffer, which must outlive the oct_file and is
 * not copied. Any alignment is accepted (misaligned data is copied once). */
oct_err oct_open_memory(const void *data, size_t size, unsigned flags, oct_file **out,
                        uint64_t *err_offset);

void oct_close(oct_file *f); /* accepts NULL */
const oct_tree *oct_get_tree(const oct_file *f);
const oct_info *oct_get_info(const oct_file *f);
/* The validated tapes of the FUNCTION section, tree.surface_count of them in
 * palette order, or NULL when the file stores no function. */
const oct_function_tape *oct_get_function(const oct_file *f);

/* Prints the human summary `render --info` shows (format version, levels,
 * cube, nodes per depth, voxels, file bytes, bytes per voxel) to `out`, a
 * FILE *. Returns 0, or -1 when the stream reports an error. */
int oct_print_info(void *out /* FILE * */, const oct_file *f);

/* --- Writer ------------------------------------------------------------ */

typedef struct oct_writer oct_writer;

typedef struct oct_writer_params {
    uint32_t levels;           /* 1..OCT_MAX_LEVELS */
    double origin[3];          /* world min corner of this tree's cube */
    double edge;               /* its edge, finite and > 0 */
    uint32_t root_depth;       /* 0 for a whole grid */
    uint64_t root_cell[3];     /* 0,0,0 for a whole grid */
    uint32_t surface_count;    /* 1..OCT_MAX_SURFACES */
    const float *palette;      /* surface_count RGB triples, copied */
    /* Format 1.1 (all zero: a 1.0 file, byte for byte as before). */
    uint32_t flags;            /* OCT_FLAG_*; SHELL_ONLY needs `function` */
    uint32_t shard_count, shard_index, shard_depth, partition_crc; /* oct_info's meaning */
    uint64_t morton_lo, morton_hi;
    const void *function;      /* FUNCTION section bytes (FORMAT.md §8), copied; NULL: none */
    size_t function_size;
    /* Where the voxel records, and with several surfaces their surface
     * indices, wait until finish: unlinked scratch files in this directory
     * (format/oct_store.h), or memory where none can be made there or one
     * fills up; NULL: memory. The file's bytes are the same. */
    const char *spool_dir;
} oct_writer_params;

/* Streaming construction. Nodes of each depth, and voxels, must be appended
 * in their final (breadth-first, Morton) order; depths are independent
 * streams, so a producer can emit finished subtrees as they come, one depth
 * at a time, and the levels above them at the end. Memory held is the output
 * itself, once, less the voxel records and surface indices when they are
 * spooled (spool_dir). */
oct_err oct_writer_create(const oct_writer_params *p, oct_writer **out);
oct_err oct_writer_add_masks(oct_writer *w, unsigned depth, const uint8_t *masks, size_t n);
/* `surfaces` may be NULL when surface_count == 1; `voxels` may be NULL with
 * OCT_FLAG_SHELL_ONLY (the records are not stored then, only counted). */
oct_err oct_writer_add_voxels(oct_writer *w, const uint32_t *voxels, const uint8_t *surfaces,
                              size_t n);
/* Checks the counts agree (OCT_EUSAGE if not), computes bases and CRCs and
 * writes the whole file to `out`, checking every write (OCT_EIO, errno set).
 * Does not close `out`. Byte-identical output for identical input. */
oct_err oct_writer_finish(oct_writer *w, void *out_file /* FILE * */, uint64_t *bytes_written);
void oct_writer_free(oct_writer *w); /* accepts NULL */

#endif
