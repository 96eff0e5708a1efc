/* oct_read: map an .oct file read-only and validate all of it, in one linear
 * pass, before handing out the tree view (FORMAT.md, "Reader checks"). */
#include "format/oct.h"
#include "format/oct_layout.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

struct oct_file {
    const unsigned char *data; /* the validated bytes */
    size_t size;
    void *map;   /* mmap'd region (oct_open), or NULL */
    void *owned; /* aligned copy (oct_open_memory of a misaligned buffer), or NULL */
    oct_tree tree;
    oct_info info;
    int has_function;
    oct_function_tape function[OCT_MAX_SURFACES];
};

static const char *const err_text[OCT_ERR_COUNT] = {
    [OCT_OK] = "success",
    [OCT_EIO] = "I/O error",
    [OCT_ENOMEM] = "out of memory",
    [OCT_ENOTFILE] = "not a regular file",
    [OCT_ETRUNC] = "truncated file",
    [OCT_EMAGIC] = "not an .oct file (bad magic)",
    [OCT_EVERSION] = "unsupported format version",
    [OCT_EHEADER] = "corrupt: header field out of range",
    [OCT_ERESERVED] = "corrupt: reserved field or padding not zero",
    [OCT_ESECTION] = "corrupt: section misplaced, misaligned or of the wrong size",
    [OCT_ETREE] = "corrupt: inconsistent tree structure",
    [OCT_EVOXEL] = "corrupt: voxel, surface or palette value out of range",
    [OCT_ECRC] = "corrupt: checksum mismatch",
    [OCT_EUSAGE] = "API misuse",
    [OCT_EFUNCTION] = "corrupt: invalid function section",
};

const char *oct_strerror(oct_err err)
{
    if ((unsigned)err >= OCT_ERR_COUNT)
        return "unknown error";
    return err_text[err];
}

/* Fails the validation with `err` at byte offset `off` unless `cond` holds.
 * With -DOCT_TRACE_CHECKS the failing check is named on stderr (debugging
 * only: library code does not print otherwise). */
#ifdef OCT_TRACE_CHECKS
#define TRACE_FAIL(cond) fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond)
#else
#define TRACE_FAIL(cond) ((void)0)
#endif
#define CHECK(cond, err, off)                                                                      \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            TRACE_FAIL(cond);                                                                      \
            *where = (off);                                                                        \
            return (err);                                                                          \
        }                                                                                          \
    } while (0)

static uint64_t groups_of(uint64_t nodes) { return nodes / 8 + (nodes % 8 != 0); }

static int all_zero(const unsigned char *p, uint64_t n, uint64_t *first)
{
    for (uint64_t i = 0; i < n; i++) {
        if (p[i]) {
            *first = i;
            return 0;
        }
    }
    return 1;
}

/* 0x80 in every byte of v that is zero (the classic "has zero byte" test,
 * exact when restricted to the high bits of bytes that were zero). */
static uint64_t zero_bytes(uint64_t v)
{
    const uint64_t lo7 = UINT64_C(0x7f7f7f7f7f7f7f7f);
    return ~(((v & lo7) + lo7) | v | lo7);
}

static oct_err check_tree(const unsigned char *p, uint64_t nodes_off, uint64_t levels_off,
                          const oct_tree *t, uint64_t *where)
{
    uint64_t g_off = nodes_off;
    for (uint32_t d = 0; d < t->levels; d++) {
        const uint64_t n = t->node_count[d], ng = groups_of(n);
        uint64_t sum = 0;
        for (uint64_t g = 0; g < ng; g++, g_off += 16) {
            CHECK(rd_u64le(p + g_off) == sum, OCT_ETREE, g_off); /* forward, dense, unshared */
            uint64_t m = rd_u64le(p + g_off + 8);
            uint64_t live = n - 8 * g >= 8 ? 8 : n - 8 * g; /* nodes in this group */
            uint64_t used = live == 8 ? ~UINT64_C(0) : (UINT64_C(1) << (8 * live)) - 1;
            uint64_t z = zero_bytes(m) & used;
            CHECK(z == 0, OCT_ETREE, g_off + 8 + (uint64_t)(__builtin_ctzll(z | (UINT64_C(1) << 63)) / 8));
            uint64_t pad = m & ~used;
            CHECK(pad == 0, OCT_ERESERVED, g_off + 8 + (uint64_t)(__builtin_ctzll(pad | (UINT64_C(1) << 63)) / 8));
            sum += oct_popcount64(m);
        }
        if (d + 1 < t->levels)
            CHECK(sum == t->node_count[d + 1], OCT_ETREE, levels_off + 8 * (d + 1));
        else
            CHECK(sum == t->voxel_count, OCT_ETREE, (uint64_t)OCT_OFF_VOXEL_COUNT);
    }
    return OCT_OK;
}

/* Where validate found things: the header size and version class, and each
 * section's offset and length, as checked. */
typedef struct layout {
    uint32_t hsize;
    int known_minor; /* minor <= ours: reserved bytes and trailing bytes are ours to check */
    int nsec;        /* section entries: OCT_SEC_COUNT_1_0 (minor 0) or OCT_SEC_COUNT */
    uint64_t off[OCT_SEC_COUNT], len[OCT_SEC_COUNT];
    const char *what; /* the FUNCTION check that failed, or NULL */
} layout;

/* Magic, version, header size and the byte-order marks. */
static oct_err check_identity(const unsigned char *p, uint64_t size, oct_info *in, layout *lo,
                              uint64_t *where)
{
    size_t mlen = size < OCT_MAGIC_SIZE ? (size_t)size : OCT_MAGIC_SIZE;
    CHECK(size > 0, OCT_ETRUNC, 0);
    CHECK(memcmp(p, OCT_MAGIC, mlen) == 0, OCT_EMAGIC, 0);
    CHECK(size >= OCT_HEADER_SIZE, OCT_ETRUNC, size);
    in->version_major = rd_u16le(p + OCT_OFF_MAJOR);
    in->version_minor = rd_u16le(p + OCT_OFF_MINOR);
    CHECK(in->version_major == OCT_VERSION_MAJOR, OCT_EVERSION, (uint64_t)OCT_OFF_MAJOR);
    lo->known_minor = in->version_minor <= OCT_VERSION_MINOR;
    lo->nsec = in->version_minor == 0 ? OCT_SEC_COUNT_1_0 : OCT_SEC_COUNT;
    lo->hsize = rd_u32le(p + OCT_OFF_HEADER_SIZE);
    const uint32_t hsize = lo->hsize;
    /* 256 for 1.0, 320 for 1.1, a multiple of 64 >= 320 for a newer minor */
    const uint32_t least = in->version_minor == 0 ? OCT_HEADER_SIZE : OCT_HEADER_SIZE_1_1;
    CHECK(hsize % OCT_ALIGN == 0 && (lo->known_minor ? hsize == least : hsize >= least),
          OCT_EHEADER, (uint64_t)OCT_OFF_HEADER_SIZE);
    CHECK(hsize <= size, OCT_ETRUNC, (uint64_t)OCT_OFF_HEADER_SIZE);
    CHECK(rd_u32le(p + OCT_OFF_BOM_U32) == OCT_BOM_U32, OCT_EHEADER, (uint64_t)OCT_OFF_BOM_U32);
    CHECK(rd_f64le(p + OCT_OFF_BOM_F64) == OCT_BOM_F64, OCT_EHEADER, (uint64_t)OCT_OFF_BOM_F64);
    in->flags = rd_u32le(p + OCT_OFF_FLAGS);
    CHECK(in->version_minor == 0 ? in->flags == 0 : (in->flags & ~OCT_FLAGS_KNOWN) == 0, OCT_EHEADER,
          (uint64_t)OCT_OFF_FLAGS); /* every flag is required: unknown ones refuse the file */
    return OCT_OK;
}

/* The tree's header fields, each in its range: levels, the subtree's place
 * in its grid, the cube, the surface and voxel counts. */
static oct_err check_header_fields(const unsigned char *p, oct_tree *t, oct_info *in, uint64_t *where)
{
    t->levels = rd_u32le(p + OCT_OFF_LEVELS);
    CHECK(t->levels >= 1 && t->levels <= OCT_MAX_LEVELS, OCT_EHEADER, (uint64_t)OCT_OFF_LEVELS);
    in->root_depth = rd_u32le(p + OCT_OFF_ROOT_DEPTH);
    CHECK(in->root_depth <= OCT_MAX_ROOT_DEPTH, OCT_EHEADER, (uint64_t)OCT_OFF_ROOT_DEPTH);
    for (int i = 0; i < 3; i++) {
        in->root_cell[i] = rd_u64le(p + OCT_OFF_ROOT_CELL + 8 * i);
        CHECK(in->root_cell[i] < (UINT64_C(1) << in->root_depth), OCT_EHEADER,
              (uint64_t)OCT_OFF_ROOT_CELL + 8 * (uint64_t)i);
    }
    in->grid_edge = rd_f64le(p + OCT_OFF_GRID_EDGE);
    CHECK(oct_cube_ok(0.0, in->grid_edge, in->root_depth, t->levels), OCT_EHEADER,
          (uint64_t)OCT_OFF_GRID_EDGE);
    t->edge = ldexp(in->grid_edge, -(int)in->root_depth); /* exact: the voxel edge is normal */
    for (int i = 0; i < 3; i++) {
        in->grid_origin[i] = rd_f64le(p + OCT_OFF_GRID_ORIGIN + 8 * i);
        CHECK(oct_cube_ok(in->grid_origin[i], in->grid_edge, in->root_depth, t->levels), OCT_EHEADER,
              (uint64_t)OCT_OFF_GRID_ORIGIN + 8 * (uint64_t)i);
        t->origin[i] = in->grid_origin[i] + (double)in->root_cell[i] * t->edge;
    }
    t->surface_count = rd_u32le(p + OCT_OFF_SURFACE_COUNT);
    CHECK(t->surface_count >= 1 && t->surface_count <= OCT_MAX_SURFACES, OCT_EHEADER,
          (uint64_t)OCT_OFF_SURFACE_COUNT);
    t->voxel_count = rd_u64le(p + OCT_OFF_VOXEL_COUNT);
    return OCT_OK;
}

/* The shard fields of a 1.1 header: all zero for a whole file; for shard i
 * of N, i < N, a whole-grid tree, a partition depth k <= levels and a Morton
 * range lo <= hi <= 8^k. (That the voxels lie in the range is the merger's
 * business, not the reader's.) */
static oct_err check_shard_fields(const unsigned char *p, const oct_tree *t, oct_info *in,
                                  uint64_t *where)
{
    if (in->version_minor == 0)
        return OCT_OK;
    in->shard_count = rd_u32le(p + OCT_OFF_SHARD_COUNT);
    in->shard_index = rd_u32le(p + OCT_OFF_SHARD_INDEX);
    in->shard_depth = rd_u32le(p + OCT_OFF_SHARD_DEPTH);
    in->partition_crc = rd_u32le(p + OCT_OFF_PARTITION_CRC);
    in->morton_lo = rd_u64le(p + OCT_OFF_MORTON_LO);
    in->morton_hi = rd_u64le(p + OCT_OFF_MORTON_HI);
    if (in->shard_count == 0) {
        CHECK(in->shard_index == 0, OCT_EHEADER, (uint64_t)OCT_OFF_SHARD_INDEX);
        CHECK(in->shard_depth == 0, OCT_EHEADER, (uint64_t)OCT_OFF_SHARD_DEPTH);
        CHECK(in->partition_crc == 0, OCT_EHEADER, (uint64_t)OCT_OFF_PARTITION_CRC);
        CHECK(in->morton_lo == 0, OCT_EHEADER, (uint64_t)OCT_OFF_MORTON_LO);
        CHECK(in->morton_hi == 0, OCT_EHEADER, (uint64_t)OCT_OFF_MORTON_HI);
        return OCT_OK;
    }
    CHECK(in->root_depth == 0, OCT_EHEADER, (uint64_t)OCT_OFF_ROOT_DEPTH); /* a shard is whole-grid */
    CHECK(in->shard_index < in->shard_count, OCT_EHEADER, (uint64_t)OCT_OFF_SHARD_INDEX);
    CHECK(in->shard_depth <= t->levels, OCT_EHEADER, (uint64_t)OCT_OFF_SHARD_DEPTH);
    CHECK(in->morton_hi <= UINT64_C(1) << (3 * in->shard_depth), OCT_EHEADER, (uint64_t)OCT_OFF_MORTON_HI);
    CHECK(in->morton_lo <= in->morton_hi, OCT_EHEADER, (uint64_t)OCT_OFF_MORTON_LO);
    return OCT_OK;
}

/* The header's reserved fields are zero, for the minors this reader knows
 * (a newer minor may give meaning to these bytes). */
static oct_err check_header_reserved(const unsigned char *p, const layout *lo, uint64_t *where)
{
    if (!lo->known_minor)
        return OCT_OK;
    uint64_t at;
    CHECK(rd_u32le(p + OCT_OFF_RESERVED0) == 0, OCT_ERESERVED, (uint64_t)OCT_OFF_RESERVED0);
    for (int k = 0; k < lo->nsec; k++)
        CHECK(rd_u32le(p + OCT_SEC_OFF(k) + 20) == 0, OCT_ERESERVED, (uint64_t)OCT_SEC_OFF(k) + 20);
    if (lo->nsec == OCT_SEC_COUNT_1_0)
        CHECK(all_zero(p + OCT_OFF_RESERVED1, OCT_OFF_HEADER_CRC - OCT_OFF_RESERVED1, &at),
              OCT_ERESERVED, OCT_OFF_RESERVED1 + at);
    else
        CHECK(all_zero(p + OCT_OFF_RESERVED2, OCT_OFF_HEADER_CRC_1_1 - OCT_OFF_RESERVED2, &at),
              OCT_ERESERVED, OCT_OFF_RESERVED2 + at);
    return OCT_OK;
}

/* The byte length section k must have, given the header and level counts
 * (FUNCTION describes its own length: oct__function_check). */
static uint64_t section_size(int k, const oct_tree *t, uint32_t flags)
{
    uint64_t want;
    switch (k) {
    case OCT_SEC_LEVELS: want = 8u * t->levels; break;
    case OCT_SEC_NODES:
        want = 0;
        for (uint32_t d = 0; d < t->levels; d++)
            want += 16 * groups_of(t->node_count[d]); /* counts <= 8^d: no overflow */
        break;
    case OCT_SEC_VOXELS: /* voxel_count <= 8^20 */
        want = flags & OCT_FLAG_SHELL_ONLY ? 0 : 4 * t->voxel_count;
        break;
    case OCT_SEC_SURFACES: want = t->surface_count > 1 ? t->voxel_count : 0; break;
    default: want = 12u * t->surface_count; break;
    }
    return want;
}

/* The level counts (section at `off`): each at most 8 times the one above,
 * since the counts bound every later size. */
static oct_err check_level_counts(const unsigned char *p, uint64_t off, oct_tree *t, uint64_t *where)
{
    for (uint32_t d = 0; d < t->levels; d++) {
        t->node_count[d] = rd_u64le(p + off + 8 * d);
        uint64_t cap = d == 0 ? 1 : 8 * t->node_count[d - 1];
        CHECK(t->node_count[d] <= cap, OCT_ETREE, off + 8 * d);
    }
    CHECK(t->voxel_count <= 8 * t->node_count[t->levels - 1], OCT_ETREE, (uint64_t)OCT_OFF_VOXEL_COUNT);
    return OCT_OK;
}

/* Sections: each of the expected size, in table order, each at the first
 * 64-byte boundary after the previous one, inside the file; then no
 * trailing bytes (for a known minor). */
static oct_err check_sections(const unsigned char *p, uint64_t size, oct_tree *t, const oct_info *in,
                              layout *lo, uint64_t *where)
{
    uint64_t end = lo->hsize;
    memset(lo->off, 0, sizeof lo->off);
    memset(lo->len, 0, sizeof lo->len);
    for (int k = 0; k < lo->nsec; k++) {
        const uint64_t e = OCT_SEC_OFF(k);
        const uint64_t off = lo->off[k] = rd_u64le(p + e);
        const uint64_t len = lo->len[k] = rd_u64le(p + e + 8);
        if (k != OCT_SEC_FUNCTION)
            CHECK(len == section_size(k, t, in->flags), OCT_ESECTION, e + 8);
        if (len == 0) {
            CHECK(off == 0 && rd_u32le(p + e + 16) == 0, OCT_ESECTION, e);
        } else {
            CHECK(off % OCT_ALIGN == 0 && off >= end, OCT_ESECTION, e); /* aligned, no overlap */
            CHECK(off == oct_align_up(end), OCT_ESECTION, e);           /* no gap */
            CHECK(off <= size && len <= size - off, OCT_ETRUNC, e);
            uint64_t at;
            CHECK(all_zero(p + end, off - end, &at), OCT_ERESERVED, end + at);
            end = off + len;
        }
        if (k == OCT_SEC_LEVELS) {
            oct_err rc = check_level_counts(p, off, t, where);
            if (rc != OCT_OK)
                return rc;
        }
    }
    CHECK(lo->known_minor ? size == end : size >= end, OCT_ESECTION, end); /* trailing bytes */
    /* without voxel records, the tree needs the function to find the surface */
    CHECK(!(in->flags & OCT_FLAG_SHELL_ONLY) || lo->len[OCT_SEC_FUNCTION] > 0, OCT_ESECTION,
          (uint64_t)OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8);
    return OCT_OK;
}

/* Voxel records, surface indices and palette values in range. */
static oct_err check_records(const unsigned char *p, const oct_tree *t, const layout *lo, uint64_t *where)
{
    const uint64_t voff = lo->off[OCT_SEC_VOXELS], soff = lo->off[OCT_SEC_SURFACES];
    const uint64_t poff = lo->off[OCT_SEC_PALETTE];
    const unsigned char *v = p + voff;
    for (uint64_t i = 0; lo->len[OCT_SEC_VOXELS] && i < t->voxel_count; i++) /* none: shell-only */
        CHECK(v[4 * i + 3] != 0x80, OCT_EVOXEL, voff + 4 * i + 3); /* offset -128 */
    if (t->surface_count > 1) {
        const unsigned char *s = p + soff;
        for (uint64_t i = 0; i < t->voxel_count; i++)
            CHECK(s[i] < t->surface_count, OCT_EVOXEL, soff + i);
    }
    for (uint32_t i = 0; i < 3 * t->surface_count; i++) {
        float c;
        memcpy(&c, p + poff + 4 * i, 4);
        CHECK(isfinite(c) && c >= 0.0f && c <= 1.0f, OCT_EVOXEL, poff + 4 * i);
    }
    return OCT_OK;
}

/* The header CRC, then each section's. */
static oct_err check_crcs(const unsigned char *p, const layout *lo, uint64_t *where)
{
    const uint32_t hsize = lo->hsize;
    CHECK((uint32_t)crc32_z(0, p, hsize - 4) == rd_u32le(p + hsize - 4), OCT_ECRC, hsize - 4);
    for (int k = 0; k < lo->nsec; k++) {
        uLong c = crc32_z(0, lo->len[k] ? p + lo->off[k] : NULL, (size_t)lo->len[k]);
        CHECK((uint32_t)c == rd_u32le(p + OCT_SEC_OFF(k) + 16), OCT_ECRC, (uint64_t)OCT_SEC_OFF(k) + 16);
    }
    return OCT_OK;
}

/* The view of a validated file. Sections are 64-byte aligned in a buffer at
 * least 8-byte aligned, so the casts below are aligned. */
static void set_view(oct_file *f, const layout *lo)
{
    const unsigned char *p = f->data;
    oct_tree *t = &f->tree;
    oct_info *in = &f->info;
    uint64_t g_off = lo->off[OCT_SEC_NODES];
    in->total_nodes = 0;
    for (uint32_t d = 0; d < t->levels; d++) {
        t->groups[d] = t->node_count[d] ? (const oct_group *)(const void *)(p + g_off) : NULL;
        g_off += 16 * groups_of(t->node_count[d]);
        in->total_nodes += t->node_count[d];
    }
    t->voxels = lo->len[OCT_SEC_VOXELS] ? (const uint32_t *)(const void *)(p + lo->off[OCT_SEC_VOXELS]) : NULL;
    t->surfaces = t->surface_count > 1 && t->voxel_count ? p + lo->off[OCT_SEC_SURFACES] : NULL;
    t->palette = (const float *)(const void *)(p + lo->off[OCT_SEC_PALETTE]);
    in->file_size = f->size;
    f->has_function = lo->len[OCT_SEC_FUNCTION] > 0;
    in->function = f->has_function ? p + lo->off[OCT_SEC_FUNCTION] : NULL;
    in->function_size = lo->len[OCT_SEC_FUNCTION];
}

/* The FUNCTION section, when there is one: its tapes into f->function. */
static oct_err check_function(oct_file *f, layout *lo, uint64_t *where)
{
    const uint64_t len = lo->len[OCT_SEC_FUNCTION], off = lo->off[OCT_SEC_FUNCTION];
    if (len == 0)
        return OCT_OK;
    if (oct__function_check(f->data + off, len, off, f->tree.surface_count, f->function, where,
                            &lo->what) != 0)
        return OCT_EFUNCTION;
    return OCT_OK;
}

/* Every check, in this order: header, sections, tree structure, records,
 * then checksums last: a damaged file is then reported by its first broken
 * structure when it has one, and any other damage still fails here. */
static oct_err validate(oct_file *f, unsigned flags, uint64_t *where, const char **what)
{
    const unsigned char *p = f->data;
    oct_tree *t = &f->tree;
    layout lo;
    lo.what = NULL;
    *where = 0;
    oct_err rc = check_identity(p, f->size, &f->info, &lo, where);
    if (rc == OCT_OK)
        rc = check_header_fields(p, t, &f->info, where);
    if (rc == OCT_OK)
        rc = check_shard_fields(p, t, &f->info, where);
    if (rc == OCT_OK)
        rc = check_header_reserved(p, &lo, where);
    if (rc == OCT_OK)
        rc = check_sections(p, f->size, t, &f->info, &lo, where);
    if (rc == OCT_OK)
        rc = check_tree(p, lo.off[OCT_SEC_NODES], lo.off[OCT_SEC_LEVELS], t, where);
    if (rc == OCT_OK)
        rc = check_records(p, t, &lo, where);
    if (rc == OCT_OK)
        rc = check_function(f, &lo, where);
    if (rc == OCT_OK && !(flags & OCT_OPEN_TRUST))
        rc = check_crcs(p, &lo, where);
    if (rc == OCT_OK)
        set_view(f, &lo);
    *what = lo.what;
    return rc;
}

/* The fault's phrase for an error without a more precise one: the error's
 * text without its "corrupt: " prefix. */
static const char *plain_what(oct_err rc)
{
    const char *s = oct_strerror(rc);
    return strncmp(s, "corrupt: ", 9) == 0 ? s + 9 : s;
}

static void set_fault(oct_fault *fault, oct_err rc, uint64_t where, const char *what)
{
    if (!fault)
        return;
    fault->offset = rc == OCT_OK ? 0 : where;
    fault->what = rc == OCT_OK ? NULL : what ? what : plain_what(rc);
}

static oct_err finish_open(oct_file *f, unsigned flags, oct_file **out, oct_fault *fault)
{
    uint64_t where = 0;
    const char *what = NULL;
    oct_err rc = validate(f, flags, &where, &what);
    set_fault(fault, rc, where, what);
    if (rc != OCT_OK) {
        oct_close(f);
        return rc;
    }
    *out = f;
    return OCT_OK;
}

oct_err oct_open(const char *path, unsigned flags, oct_file **out, uint64_t *err_offset)
{
    oct_fault fault;
    oct_err rc = oct_open_fault(path, flags, out, &fault);
    if (err_offset)
        *err_offset = fault.offset;
    return rc;
}

oct_err oct_open_memory(const void *data, size_t size, unsigned flags, oct_file **out,
                        uint64_t *err_offset)
{
    oct_fault fault;
    oct_err rc = oct_open_memory_fault(data, size, flags, out, &fault);
    if (err_offset)
        *err_offset = fault.offset;
    return rc;
}

oct_err oct_open_fault(const char *path, unsigned flags, oct_file **out, oct_fault *fault)
{
    *out = NULL;
    set_fault(fault, OCT_OK, 0, NULL);
    /* O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused below. */
    int fd = open(path, O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
        set_fault(fault, OCT_EIO, 0, NULL);
        return OCT_EIO;
    }
    oct_err rc = OCT_OK;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        rc = OCT_EIO;
        goto fail;
    }
    if (!S_ISREG(st.st_mode)) {
        rc = OCT_ENOTFILE;
        goto fail;
    }
    if (st.st_size == 0) {
        rc = OCT_ETRUNC; /* mmap of zero bytes is an error */
        goto fail;
    }
    if ((uint64_t)st.st_size > SIZE_MAX) {
        rc = OCT_ENOMEM;
        goto fail;
    }
    oct_file *f = oct__calloc(1, sizeof *f);
    if (!f) {
        rc = OCT_ENOMEM;
        goto fail;
    }
    f->size = (size_t)st.st_size;
    f->map = mmap(NULL, f->size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (f->map == MAP_FAILED) {
        int e = errno;
        free(f);
        errno = e;
        rc = OCT_EIO;
        goto fail;
    }
    f->data = f->map;
    close(fd);
    return finish_open(f, flags, out, fault);
fail:;
    int e = errno;
    close(fd);
    set_fault(fault, rc, 0, NULL);
    errno = e;
    return rc;
}

oct_err oct_open_memory_fault(const void *data, size_t size, unsigned flags, oct_file **out,
                              oct_fault *fault)
{
    *out = NULL;
    set_fault(fault, OCT_OK, 0, NULL);
    if (!data && size) {
        set_fault(fault, OCT_EUSAGE, 0, NULL);
        return OCT_EUSAGE;
    }
    oct_file *f = oct__calloc(1, sizeof *f);
    if (!f) {
        set_fault(fault, OCT_ENOMEM, 0, NULL);
        return OCT_ENOMEM;
    }
    f->size = size;
    f->data = data ? data : (const unsigned char *)"";
    if ((uintptr_t)data % 8 != 0) { /* the view casts to uint64_t-bearing structs */
        f->owned = oct__aligned_alloc(OCT_ALIGN, oct_align_up(size ? size : 1));
        if (!f->owned) {
            free(f);
            set_fault(fault, OCT_ENOMEM, 0, NULL);
            return OCT_ENOMEM;
        }
        memcpy(f->owned, data, size);
        f->data = f->owned;
    }
    return finish_open(f, flags, out, fault);
}

void oct_close(oct_file *f)
{
    if (!f)
        return;
    if (f->map)
        munmap(f->map, f->size);
    free(f->owned);
    free(f);
}

const oct_tree *oct_get_tree(const oct_file *f) { return &f->tree; }
const oct_info *oct_get_info(const oct_file *f) { return &f->info; }
const oct_function_tape *oct_get_function(const oct_file *f) { return f->has_function ? f->function : NULL; }
