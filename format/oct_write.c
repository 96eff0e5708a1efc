/* oct_write: the streaming .oct writer — per-depth buffers of masks and
 * spools of voxel records and surface indices (format/oct_store.h), then one
 * deterministic serialization (bases and CRCs computed at finish; the
 * spools' CRCs are kept as their bytes come). */
#include "format/oct.h"
#include "format/oct_layout.h"
#include "format/oct_sink.h"
#include "format/oct_store.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <zlib.h>

struct oct_writer {
    oct_writer_params p;
    float palette[OCT_MAX_SURFACES * 3];
    oct_chunks masks[OCT_MAX_LEVELS]; /* a byte a node: its count is the depth's node count */
    oct_spool voxels;     /* 4 bytes a voxel (little-endian host); none with OCT_FLAG_SHELL_ONLY */
    oct_spool surfaces;   /* a byte a voxel, with more than one surface */
    size_t voxel_count;
    unsigned char *function; /* copy of the FUNCTION section, or NULL */
    int v11;  /* something of 1.1 is used: minor 1, header 320, six sections */
    int done; /* finish was called: the writer accepts nothing more */
};

static int finite_unit(float v) { return isfinite(v) && v >= 0.0f && v <= 1.0f; }

/* The 1.1 parameters as the reader checks them (FORMAT.md §5, §8). */
static int params_1_1_ok(const oct_writer_params *p)
{
    if ((p->flags & ~OCT_FLAGS_KNOWN) || ((p->flags & OCT_FLAG_SHELL_ONLY) && !p->function))
        return 0;
    if (p->function) {
        uint64_t where;
        const char *what;
        if (oct__function_check(p->function, p->function_size, 0, p->surface_count, NULL, &where,
                                &what) != 0)
            return 0;
    }
    if (p->shard_count == 0)
        return p->shard_index == 0 && p->shard_depth == 0 && p->partition_crc == 0 &&
               p->morton_lo == 0 && p->morton_hi == 0;
    return p->root_depth == 0 && p->shard_index < p->shard_count && p->shard_depth <= p->levels &&
           p->morton_hi <= UINT64_C(1) << (3 * p->shard_depth) && p->morton_lo <= p->morton_hi;
}

oct_err oct_writer_create(const oct_writer_params *p, oct_writer **out)
{
    *out = NULL;
    if (!p || p->levels < 1 || p->levels > OCT_MAX_LEVELS || !isfinite(p->edge) || !(p->edge > 0.0) ||
        p->root_depth > OCT_MAX_ROOT_DEPTH || p->surface_count < 1 ||
        p->surface_count > OCT_MAX_SURFACES)
        return OCT_EUSAGE;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(p->origin[i]) || p->root_cell[i] >= (UINT64_C(1) << p->root_depth))
            return OCT_EUSAGE;
    }
    double grid_edge = ldexp(p->edge, (int)p->root_depth);
    for (int i = 0; i < 3; i++) {
        if (!oct_cube_ok(p->origin[i] - (double)p->root_cell[i] * p->edge, grid_edge, p->root_depth, p->levels))
            return OCT_EUSAGE; /* the reader would refuse the cube */
    }
    for (uint32_t i = 0; p->palette && i < 3 * p->surface_count; i++) {
        if (!finite_unit(p->palette[i]))
            return OCT_EUSAGE;
    }
    if (!params_1_1_ok(p))
        return OCT_EUSAGE;
    oct_writer *w = oct__calloc(1, sizeof *w);
    if (!w)
        return OCT_ENOMEM;
    w->p = *p;
    w->p.function = NULL;
    if (p->function) {
        w->function = oct__realloc(NULL, p->function_size);
        if (!w->function) {
            free(w);
            return OCT_ENOMEM;
        }
        memcpy(w->function, p->function, p->function_size);
        w->p.function = w->function;
    }
    w->v11 = p->flags || p->function || p->shard_count;
    /* the scratch files' share of half the free space: a byte a voxel of
     * surface indices for every four of records */
    const int recs = !(p->flags & OCT_FLAG_SHELL_ONLY), idx = p->surface_count > 1;
    oct_spool_open(&w->voxels, recs ? p->spool_dir : NULL, idx ? 4 : 1, idx ? 5 : 1);
    oct_spool_open(&w->surfaces, idx ? p->spool_dir : NULL, 1, recs ? 5 : 1);
    w->p.spool_dir = NULL; /* (not kept: only the open needs it) */
    for (uint32_t i = 0; i < 3 * p->surface_count; i++)
        w->palette[i] = p->palette ? p->palette[i] : 0.8f;
    w->p.palette = w->palette;
    *out = w;
    return OCT_OK;
}

oct_err oct_writer_add_masks(oct_writer *w, unsigned depth, const uint8_t *masks, size_t n)
{
    if (!w || w->done || depth >= w->p.levels || (n && !masks))
        return OCT_EUSAGE;
    for (size_t i = 0; i < n; i++) {
        if (masks[i] == 0)
            return OCT_EUSAGE; /* only non-empty nodes are stored */
    }
    return oct_chunks_append(&w->masks[depth], masks, n) == 0 ? OCT_OK : OCT_ENOMEM;
}

oct_err oct_writer_add_voxels(oct_writer *w, const uint32_t *voxels, const uint8_t *surfaces, size_t n)
{
    const int shell = w && (w->p.flags & OCT_FLAG_SHELL_ONLY);
    if (!w || w->done || (n && !voxels && !shell) || (n && w->p.surface_count > 1 && !surfaces))
        return OCT_EUSAGE;
    for (size_t i = 0; i < n; i++) {
        if (!shell && (voxels[i] >> OCT_VOXEL_OFFSET_SHIFT) == 0x80u)
            return OCT_EUSAGE; /* offset -128 is reserved */
        if (w->p.surface_count > 1 && surfaces[i] >= w->p.surface_count)
            return OCT_EUSAGE;
    }
    if (n > SIZE_MAX / sizeof *voxels - w->voxel_count)
        return OCT_ENOMEM;
    /* the surfaces first: when the voxels then fail, the surfaces appended
       are taken back, so that the next call retries from the same state */
    const oct_spool_mark ms = oct_spool_tell(&w->surfaces);
    if (w->p.surface_count > 1 && oct_spool_append(&w->surfaces, surfaces, n) != 0)
        return OCT_ENOMEM;
    if (!shell && oct_spool_append(&w->voxels, voxels, n * sizeof *voxels) != 0) {
        oct_spool_rewind(&w->surfaces, ms);
        return OCT_ENOMEM;
    }
    w->voxel_count += n;
    return OCT_OK;
}

static uint64_t groups_of(uint64_t nodes) { return nodes / 8 + (nodes % 8 != 0); }

/* Streams the node section (every depth's groups, depth 0 first). */
static int put_nodes(const oct_writer *w, oct_sink *s)
{
    enum { CHUNK = 4096 };
    unsigned char buf[CHUNK * 16];
    for (uint32_t d = 0; d < w->p.levels; d++) {
        const oct_chunks *m = &w->masks[d];
        uint64_t base = 0, n = m->n;
        size_t fill = 0;
        for (uint64_t g = 0, ng = groups_of(n); g < ng; g++) {
            unsigned char *rec = buf + 16 * fill;
            wr_u64le(rec, base);
            /* the group's eight masks, in one chunk (chunks hold whole groups) and
               zeros past the depth's last node, copied and counted as one word */
            const uint64_t i = 8 * g;
            if (i + 8 <= n) {
                memcpy(rec + 8, m->c[i >> OCT_CHUNK_BITS] + (i & (OCT_CHUNK - 1)), 8);
            } else {
                for (unsigned k = 0; k < 8; k++)
                    rec[8 + k] = i + k < n ? oct_chunks_at(m, i + k) : 0;
            }
            uint64_t masks;
            memcpy(&masks, rec + 8, 8);
            base += oct_popcount64(masks);
            if (++fill == CHUNK) {
                if (oct_sink_put(s, buf, sizeof buf) != 0)
                    return -1;
                fill = 0;
            }
        }
        if (oct_sink_put(s, buf, 16 * fill) != 0)
            return -1;
    }
    return 0;
}

typedef struct layout {
    uint64_t off[OCT_SEC_COUNT], size[OCT_SEC_COUNT];
    uint32_t crc[OCT_SEC_COUNT];
    uint64_t file_size;
} layout;

/* Writes (s->f != NULL) or checksums (s->f == NULL) section k. */
static int put_section(const oct_writer *w, int k, oct_sink *s)
{
    switch (k) {
    case OCT_SEC_LEVELS:
        for (uint32_t d = 0; d < w->p.levels; d++) {
            unsigned char b[8];
            wr_u64le(b, w->masks[d].n);
            if (oct_sink_put(s, b, 8) != 0)
                return -1;
        }
        return 0;
    case OCT_SEC_NODES:
        return put_nodes(w, s);
    case OCT_SEC_VOXELS: /* little-endian host; nothing with OCT_FLAG_SHELL_ONLY */
        return oct_spool_put(&w->voxels, s);
    case OCT_SEC_SURFACES:
        return oct_spool_put(&w->surfaces, s); /* (empty with one surface) */
    case OCT_SEC_PALETTE:
        return oct_sink_put(s, w->palette, (size_t)w->p.surface_count * 3 * sizeof(float));
    default:
        return w->function ? oct_sink_put(s, w->function, w->p.function_size) : 0;
    }
}

/* The header (hsize bytes: 256 for 1.0, 320 for 1.1) into h. */
static void build_header(const oct_writer *w, const layout *lay, unsigned char *h, uint32_t hsize)
{
    const oct_writer_params *p = &w->p;
    const int nsec = w->v11 ? OCT_SEC_COUNT : OCT_SEC_COUNT_1_0;
    memset(h, 0, hsize);
    memcpy(h + OCT_OFF_MAGIC, OCT_MAGIC, OCT_MAGIC_SIZE);
    wr_u16le(h + OCT_OFF_MAJOR, OCT_VERSION_MAJOR);
    wr_u16le(h + OCT_OFF_MINOR, w->v11 ? 1 : 0);
    wr_u32le(h + OCT_OFF_HEADER_SIZE, hsize);
    wr_u32le(h + OCT_OFF_BOM_U32, OCT_BOM_U32);
    wr_u32le(h + OCT_OFF_FLAGS, p->flags);
    wr_f64le(h + OCT_OFF_BOM_F64, OCT_BOM_F64);
    wr_u32le(h + OCT_OFF_LEVELS, p->levels);
    wr_u32le(h + OCT_OFF_ROOT_DEPTH, p->root_depth);
    for (int i = 0; i < 3; i++) {
        wr_u64le(h + OCT_OFF_ROOT_CELL + 8 * i, p->root_cell[i]);
        /* The grid's corner; the reader derives this tree's corner back from
         * it (exactly so for a whole grid, root_cell = 0). */
        wr_f64le(h + OCT_OFF_GRID_ORIGIN + 8 * i, p->origin[i] - (double)p->root_cell[i] * p->edge);
    }
    wr_f64le(h + OCT_OFF_GRID_EDGE, ldexp(p->edge, (int)p->root_depth));
    wr_u32le(h + OCT_OFF_SURFACE_COUNT, p->surface_count);
    wr_u64le(h + OCT_OFF_VOXEL_COUNT, w->voxel_count);
    for (int k = 0; k < nsec; k++) {
        wr_u64le(h + OCT_SEC_OFF(k), lay->off[k]);
        wr_u64le(h + OCT_SEC_OFF(k) + 8, lay->size[k]);
        wr_u32le(h + OCT_SEC_OFF(k) + 16, lay->crc[k]);
    }
    if (w->v11) {
        wr_u32le(h + OCT_OFF_SHARD_COUNT, p->shard_count);
        wr_u32le(h + OCT_OFF_SHARD_INDEX, p->shard_index);
        wr_u32le(h + OCT_OFF_SHARD_DEPTH, p->shard_depth);
        wr_u32le(h + OCT_OFF_PARTITION_CRC, p->partition_crc);
        wr_u64le(h + OCT_OFF_MORTON_LO, p->morton_lo);
        wr_u64le(h + OCT_OFF_MORTON_HI, p->morton_hi);
    }
    wr_u32le(h + hsize - 4, (uint32_t)crc32_z(0, h, hsize - 4));
}

oct_err oct_writer_finish(oct_writer *w, void *out_file, uint64_t *bytes_written)
{
    FILE *f = out_file;
    if (bytes_written)
        *bytes_written = 0;
    if (!w || w->done || !f)
        return OCT_EUSAGE;
    w->done = 1;
    const uint32_t L = w->p.levels;
    if (w->masks[0].n > 1)
        return OCT_EUSAGE;
    for (uint32_t d = 0; d < L; d++) {
        const oct_chunks *m = &w->masks[d];
        uint64_t children = 0;
        for (size_t i = 0; i < m->n; i += OCT_CHUNK) {
            const unsigned char *c = m->c[i >> OCT_CHUNK_BITS];
            for (size_t j = 0, k = m->n - i < OCT_CHUNK ? m->n - i : OCT_CHUNK; j < k; j++)
                children += oct_popcount64(c[j]);
        }
        uint64_t want = d + 1 < L ? w->masks[d + 1].n : w->voxel_count;
        if (children != want)
            return OCT_EUSAGE;
    }
    if (L > 1 && w->masks[0].n == 0 && w->voxel_count != 0)
        return OCT_EUSAGE;

    layout lay = {0};
    const uint32_t hsize = w->v11 ? OCT_HEADER_SIZE_1_1 : OCT_HEADER_SIZE;
    const int nsec = w->v11 ? OCT_SEC_COUNT : OCT_SEC_COUNT_1_0;
    uint64_t end = hsize;
    for (int k = 0; k < nsec; k++) {
        uint64_t size;
        switch (k) {
        case OCT_SEC_LEVELS: size = 8u * L; break;
        case OCT_SEC_NODES:
            size = 0;
            for (uint32_t d = 0; d < L; d++)
                size += 16 * groups_of(w->masks[d].n);
            break;
        case OCT_SEC_VOXELS: size = oct_spool_size(&w->voxels); break;
        case OCT_SEC_SURFACES: size = w->p.surface_count > 1 ? w->voxel_count : 0; break;
        case OCT_SEC_PALETTE: size = 12u * w->p.surface_count; break;
        default: size = w->function ? w->p.function_size : 0; break;
        }
        lay.size[k] = size;
        if (size) {
            lay.off[k] = oct_align_up(end);
            end = lay.off[k] + size;
        }
        /* the spools' CRCs were kept as their bytes came: not read back twice */
        if (k == OCT_SEC_VOXELS || k == OCT_SEC_SURFACES) {
            lay.crc[k] = oct_spool_crc(k == OCT_SEC_VOXELS ? &w->voxels : &w->surfaces);
            continue;
        }
        oct_sink crc = {NULL, crc32_z(0, NULL, 0), 0, 0};
        put_section(w, k, &crc);
        lay.crc[k] = (uint32_t)crc.crc;
    }
    lay.file_size = end;

    unsigned char h[OCT_HEADER_SIZE_1_1];
    build_header(w, &lay, h, hsize);
    oct_sink s = {f, 0, 0, 1}; /* the CRCs are in the header already */
    errno = 0;
    if (oct_sink_put(&s, h, hsize) != 0)
        return OCT_EIO;
    for (int k = 0; k < nsec; k++) {
        if (lay.size[k] == 0)
            continue;
        if (oct_sink_pad_to(&s, lay.off[k]) != 0 || put_section(w, k, &s) != 0)
            return OCT_EIO;
    }
    if (fflush(f) != 0 || ferror(f)) {
        if (errno == 0)
            errno = EIO;
        return OCT_EIO;
    }
    if (bytes_written)
        *bytes_written = s.bytes;
    return OCT_OK;
}

void oct_writer_free(oct_writer *w)
{
    if (!w)
        return;
    for (int d = 0; d < OCT_MAX_LEVELS; d++)
        oct_chunks_free(&w->masks[d]);
    oct_spool_free(&w->voxels);
    oct_spool_free(&w->surfaces);
    free(w->function);
    free(w);
}
