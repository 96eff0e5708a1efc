/* oct_merge: stream the shard files of one partition into the whole file
 * (oct_merge.h; FORMAT.md §6, "Shards"). Three passes: each part is
 * validated and described (oct_open, then its header), the partition is
 * checked whole, then the output is written section by section, reading the
 * parts sequentially through one buffer, with the header last. */
#include "format/oct_merge.h"
#include "format/oct_layout.h"
#include "format/oct_sink.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <zlib.h>

#define MERGE_BUF (1u << 16)

typedef struct part {
    const char *path;
    uint32_t index;
    uint64_t lo, hi;
    uint64_t count[OCT_MAX_LEVELS], voxels;
    uint64_t off[OCT_SEC_COUNT], size[OCT_SEC_COUNT];
    uint32_t crc[OCT_SEC_COUNT];
} part;

typedef struct merge {
    oct_merge_error *e;
    size_t n;
    part *parts;         /* in shard order once checked */
    unsigned char head[OCT_HEADER_SIZE_1_1]; /* the first part's header: the template */
    uint32_t hsize, levels, count, depth, crc;
    uint8_t *cells;      /* 8^depth flags: a part holds that depth-k cell */
    unsigned char *buf;  /* MERGE_BUF bytes */
} merge;

static oct_err fail(merge *m, const char *path, oct_err err, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static oct_err fail(merge *m, const char *path, oct_err err, const char *fmt, ...)
{
    m->e->path = path;
    m->e->err = err;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->e->msg, sizeof m->e->msg, fmt, ap);
    va_end(ap);
    return err;
}

static oct_err io_fail(merge *m, const char *path, const char *what)
{
    int saved = errno ? errno : EIO;
    oct_err r = fail(m, path, OCT_EIO, "%s: %s", what, strerror(saved));
    errno = saved;
    return r;
}

static uint64_t groups_of(uint64_t nodes) { return nodes / 8 + (nodes % 8 != 0); }

static int append_bytes(void *ctx, const unsigned char *b, size_t len)
{
    unsigned char **at = ctx;
    memcpy(*at, b, len);
    *at += len;
    return 0;
}

/* Reads n bytes at off of a part, chunk by chunk, into fn (when not NULL)
 * and the running CRC *crc. */
static oct_err read_range(merge *m, const part *p, uint64_t off, uint64_t n, uLong *crc,
                          int (*fn)(void *ctx, const unsigned char *b, size_t len), void *ctx)
{
    if (n == 0)
        return OCT_OK;
    FILE *f = fopen(p->path, "rb");
    if (!f)
        return io_fail(m, p->path, "open");
    oct_err r = OCT_OK;
    if (fseeko(f, (off_t)off, SEEK_SET) != 0)
        r = io_fail(m, p->path, "seek");
    while (r == OCT_OK && n > 0) {
        size_t want = n < MERGE_BUF ? (size_t)n : MERGE_BUF;
        size_t got = fread(m->buf, 1, want, f);
        if (got != want) {
            r = ferror(f) ? io_fail(m, p->path, "read")
                          : fail(m, p->path, OCT_ETRUNC, "%s (it changed while merging)",
                                 oct_strerror(OCT_ETRUNC));
            break;
        }
        *crc = crc32_z(*crc, m->buf, got);
        if (fn && fn(ctx, m->buf, got) != 0)
            r = OCT_EIO; /* the consumer described it */
        n -= got;
    }
    fclose(f);
    return r;
}

/* --- pass 1: each part ------------------------------------------------- */

/* Marks the part's depth-k cells, walking its top levels (at most 8^k
 * nodes), and checks they lie in its range. */
static oct_err mark_cells(merge *m, part *p, const oct_tree *t)
{
    const unsigned k = m->depth;
    uint64_t n = t->node_count[0]; /* nodes at the current depth, codes in order */
    uint64_t *code = malloc(sizeof *code), *next = NULL; /* the root, if any: code 0 */
    if (!code)
        return fail(m, p->path, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    code[0] = 0;
    for (unsigned d = 0; d < k && n; d++) {
        next = malloc(sizeof *next * (t->node_count[d + 1] ? t->node_count[d + 1] : 1));
        if (!next) {
            free(code);
            return fail(m, p->path, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
        }
        uint64_t j = 0;
        for (uint64_t i = 0; i < n; i++) {
            uint8_t mask = oct_node_mask(t->groups[d], i);
            for (unsigned c = 0; c < 8; c++)
                if (mask & (1u << c))
                    next[j++] = 8 * code[i] + c; /* validated: j stays < node_count[d + 1] */
        }
        free(code);
        code = next;
        n = j;
    }
    oct_err r = OCT_OK;
    for (uint64_t i = 0; i < n && r == OCT_OK; i++) {
        if (code[i] < p->lo || code[i] >= p->hi)
            r = fail(m, p->path, OCT_ETREE, "holds voxels outside its shard's cells [%llu, %llu)",
                     (unsigned long long)p->lo, (unsigned long long)p->hi);
        else
            m->cells[code[i]] = 1;
    }
    free(code);
    return r;
}

/* The header fields every part must share with the first, and what a
 * difference means. */
static oct_err same_as_first(merge *m, const part *p, const unsigned char *h, uint32_t hsize)
{
    static const struct { unsigned from, to; const char *what; } same[] = {
        {0, OCT_OFF_LEVELS, "a different format version or flags"},
        {OCT_OFF_LEVELS, OCT_OFF_SURFACE_COUNT, "a different grid (levels, origin or edge)"},
        {OCT_OFF_SURFACE_COUNT, OCT_OFF_VOXEL_COUNT, "a different scene (surface count)"},
        {OCT_SEC_OFF(OCT_SEC_PALETTE) + 8, OCT_SEC_OFF(OCT_SEC_PALETTE) + 24, "a different scene (palette)"},
        {OCT_SEC_OFF(OCT_SEC_FUNCTION) + 8, OCT_SEC_OFF(OCT_SEC_FUNCTION) + 24, "a different scene (function)"},
        {OCT_OFF_SHARD_COUNT, OCT_OFF_SHARD_INDEX, "a different partition (shard count)"},
        {OCT_OFF_SHARD_DEPTH, OCT_OFF_MORTON_LO, "a different partition (depth or boundaries)"},
        {OCT_OFF_RESERVED2, OCT_HEADER_SIZE_1_1, "a different header"},
    };
    if (hsize != m->hsize)
        return fail(m, p->path, OCT_EUSAGE, "has a different header size from %s", m->parts[0].path);
    for (size_t i = 0; i < sizeof same / sizeof same[0]; i++) {
        unsigned to = same[i].to < hsize - 4 ? same[i].to : hsize - 4;
        if (same[i].from < to && memcmp(h + same[i].from, m->head + same[i].from, to - same[i].from))
            return fail(m, p->path, OCT_EUSAGE, "has %s from %s", same[i].what, m->parts[0].path);
    }
    return OCT_OK;
}

/* Section k of a part, whole, in memory (PALETTE and FUNCTION: small). */
static oct_err read_section(merge *m, const part *p, int k, unsigned char **out)
{
    *out = NULL;
    if (p->size[k] > (uint64_t)MERGE_BUF * 64)
        return fail(m, p->path, OCT_EUSAGE, "has a section of %llu bytes, too large to compare",
                    (unsigned long long)p->size[k]);
    unsigned char *b = malloc(p->size[k] ? (size_t)p->size[k] : 1);
    if (!b)
        return fail(m, p->path, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    *out = b;
    uLong crc = 0;
    return read_range(m, p, p->off[k], p->size[k], &crc, append_bytes, &b);
}

/* A part's PALETTE and FUNCTION bytes equal the first part's (their sizes
 * and CRCs are equal already: this leaves no doubt). */
static oct_err same_scene_bytes(merge *m, const part *p)
{
    for (int k = OCT_SEC_PALETTE; k <= OCT_SEC_FUNCTION; k++) {
        unsigned char *a = NULL, *b = NULL;
        oct_err r = read_section(m, &m->parts[0], k, &a);
        if (r == OCT_OK)
            r = read_section(m, p, k, &b);
        if (r == OCT_OK && memcmp(a, b, (size_t)p->size[k]) != 0)
            r = fail(m, p->path, OCT_EUSAGE, "has a different scene (%s) from %s",
                     k == OCT_SEC_PALETTE ? "palette" : "function", m->parts[0].path);
        free(a);
        free(b);
        if (r != OCT_OK)
            return r;
    }
    return OCT_OK;
}

/* Reads a part's header (validated by oct_open already) into h. */
static oct_err read_header(merge *m, const part *p, unsigned char *h, uint32_t *hsize)
{
    uLong crc = 0;
    unsigned char *at = h;
    oct_err r = read_range(m, p, 0, OCT_HEADER_SIZE, &crc, append_bytes, &at);
    if (r != OCT_OK)
        return r;
    *hsize = rd_u32le(h + OCT_OFF_HEADER_SIZE);
    uint16_t minor = rd_u16le(h + OCT_OFF_MINOR);
    if (minor > 1) /* its new fields could matter: merging would drop them */
        return fail(m, p->path, OCT_EUSAGE, "is format 1.%u, newer than this merge knows (1.1)",
                    (unsigned)minor);
    if (minor < 1 || *hsize != OCT_HEADER_SIZE_1_1)
        return fail(m, p->path, OCT_EUSAGE, "is not a shard (a whole file)");
    r = read_range(m, p, OCT_HEADER_SIZE, *hsize - OCT_HEADER_SIZE, &crc, append_bytes, &at);
    if (r == OCT_OK && rd_u32le(h + OCT_OFF_SHARD_COUNT) == 0)
        r = fail(m, p->path, OCT_EUSAGE, "is not a shard (a whole file)");
    return r;
}

/* Pass 1 for part i: validate it, read its shard fields and sections,
 * compare it with the first part and mark its depth-k cells. */
static oct_err describe_part(merge *m, size_t i, const char *path)
{
    part *p = &m->parts[i];
    p->path = path;
    oct_file *f = NULL;
    oct_fault fault = {0, NULL};
    errno = 0;
    oct_err r = oct_open_fault(path, 0, &f, &fault);
    if (r == OCT_EIO)
        return io_fail(m, path, "open");
    if (r == OCT_EFUNCTION) /* the broken rule of the FUNCTION section, as render says it */
        return fail(m, path, r, "corrupt: %s at offset %llu", fault.what, (unsigned long long)fault.offset);
    if (r != OCT_OK && fault.offset)
        return fail(m, path, r, "%s at offset %llu", oct_strerror(r), (unsigned long long)fault.offset);
    if (r != OCT_OK)
        return fail(m, path, r, "%s", oct_strerror(r));
    const oct_tree *t = oct_get_tree(f);
    unsigned char h[OCT_HEADER_SIZE_1_1] = {0};
    uint32_t hsize = 0;
    r = read_header(m, p, h, &hsize);
    p->index = rd_u32le(h + OCT_OFF_SHARD_INDEX);
    p->lo = rd_u64le(h + OCT_OFF_MORTON_LO);
    p->hi = rd_u64le(h + OCT_OFF_MORTON_HI);
    uint32_t count = rd_u32le(h + OCT_OFF_SHARD_COUNT), depth = rd_u32le(h + OCT_OFF_SHARD_DEPTH);
    if (r == OCT_OK && (p->index >= count || depth > OCT_MERGE_MAX_DEPTH || depth >= t->levels ||
                        p->lo > p->hi || p->hi > (UINT64_C(1) << (3 * depth))))
        r = fail(m, path, OCT_EHEADER, "shard fields out of range (shard %u/%u, depth %u)",
                 (unsigned)p->index, (unsigned)count, (unsigned)depth);
    if (r == OCT_OK && i == 0) {
        memcpy(m->head, h, hsize);
        m->hsize = hsize;
        m->levels = t->levels;
        m->count = count;
        m->depth = depth;
        m->crc = rd_u32le(h + OCT_OFF_PARTITION_CRC);
        m->cells = calloc((size_t)1 << (3 * depth), 1);
        if (!m->cells)
            r = fail(m, path, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    } else if (r == OCT_OK) {
        r = same_as_first(m, p, h, hsize);
    }
    for (int k = 0; k < OCT_SEC_COUNT; k++) {
        p->off[k] = rd_u64le(h + OCT_SEC_OFF(k));
        p->size[k] = rd_u64le(h + OCT_SEC_OFF(k) + 8);
        p->crc[k] = rd_u32le(h + OCT_SEC_OFF(k) + 16);
    }
    memcpy(p->count, t->node_count, sizeof p->count);
    p->voxels = t->voxel_count;
    if (r == OCT_OK)
        r = mark_cells(m, p, t);
    oct_close(f);
    if (r == OCT_OK && i > 0)
        r = same_scene_bytes(m, p);
    return r;
}

/* --- pass 2: the partition --------------------------------------------- */

static int by_index(const void *a, const void *b)
{
    const part *x = a, *y = b;
    return (x->index > y->index) - (x->index < y->index);
}

/* Sorts the parts into shard order and checks they are the partition's N
 * shards, each once, with contiguous ranges matching its checksum. */
static oct_err check_partition(merge *m)
{
    qsort(m->parts, m->n, sizeof *m->parts, by_index);
    for (size_t i = 1; i < m->n; i++)
        if (m->parts[i].index == m->parts[i - 1].index)
            return fail(m, m->parts[i].path, OCT_EUSAGE, "is shard %u/%u, as %s is",
                        (unsigned)m->parts[i].index, (unsigned)m->count, m->parts[i - 1].path);
    for (size_t i = 0; i < m->count; i++)
        if (i >= m->n || m->parts[i].index != i)
            return fail(m, NULL, OCT_EUSAGE, "shard %u/%u is missing (%zu of %u parts given)",
                        (unsigned)i, (unsigned)m->count, m->n, (unsigned)m->count);
    uLong crc = crc32_z(0, NULL, 0);
    for (size_t i = 0; i <= m->n; i++) {
        unsigned char b[8];
        uint64_t bound = i < m->n ? m->parts[i].lo : m->parts[m->n - 1].hi;
        wr_u64le(b, bound);
        crc = crc32_z(crc, b, 8);
        const char *path = m->parts[i < m->n ? i : m->n - 1].path;
        if ((i == 0 && bound != 0) || (i > 0 && i < m->n && bound != m->parts[i - 1].hi) ||
            (i == m->n && bound != UINT64_C(1) << (3 * m->depth)))
            return fail(m, path, OCT_EUSAGE, "its range [%llu, %llu) does not continue the other shards'",
                        (unsigned long long)m->parts[i < m->n ? i : m->n - 1].lo,
                        (unsigned long long)m->parts[i < m->n ? i : m->n - 1].hi);
    }
    if ((uint32_t)crc != m->crc)
        return fail(m, m->parts[0].path, OCT_EUSAGE,
                    "the shards' ranges do not match their partition checksum");
    return OCT_OK;
}

/* --- pass 3: the output ------------------------------------------------ */

/* The output: the format's sink, and the merge that reports its failure. */
typedef struct sink {
    merge *m;
    oct_sink out;
} sink;

static int put(sink *s, const void *data, size_t n)
{
    if (oct_sink_put(&s->out, data, n) != 0) {
        io_fail(s->m, NULL, "write");
        return -1;
    }
    return 0;
}

static int pad_to(sink *s, uint64_t target)
{
    if (oct_sink_pad_to(&s->out, target) != 0) {
        io_fail(s->m, NULL, "write");
        return -1;
    }
    return 0;
}

static int put_sink(void *ctx, const unsigned char *b, size_t len) { return put(ctx, b, len); }

/* One depth's groups, packed as nodes arrive: the base is the running
 * popcount of the masks before the group. */
typedef struct packer {
    sink *s;
    uint64_t base;
    unsigned char group[16];
    unsigned fill;
    uint64_t left; /* nodes of the part being read still to come */
} packer;

static int pack(packer *pk, uint8_t mask)
{
    if (pk->fill == 0) {
        memset(pk->group, 0, sizeof pk->group);
        wr_u64le(pk->group, pk->base);
    }
    pk->group[8 + pk->fill++] = mask;
    pk->base += oct_popcount64(mask);
    if (pk->fill == 8) {
        pk->fill = 0;
        return put(pk->s, pk->group, sizeof pk->group);
    }
    return 0;
}

static int pack_flush(packer *pk)
{
    unsigned fill = pk->fill;
    pk->fill = 0;
    return fill ? put(pk->s, pk->group, sizeof pk->group) : 0;
}

/* The masks of a part's groups (whole groups: reads start on a group and
 * MERGE_BUF is a multiple of 16). */
static int pack_groups(void *ctx, const unsigned char *b, size_t len)
{
    packer *pk = ctx;
    for (size_t g = 0; g + 16 <= len; g += 16)
        for (unsigned k = 0; k < 8 && pk->left; k++, pk->left--)
            if (pack(pk, b[g + 8 + k]) != 0)
                return -1;
    return 0;
}

/* Offset of depth d's groups in a part. */
static uint64_t depth_offset(const part *p, unsigned d)
{
    uint64_t off = p->off[OCT_SEC_NODES];
    for (unsigned j = 0; j < d; j++)
        off += 16 * groups_of(p->count[j]);
    return off;
}

/* The nodes: depths above k from the union of the parts' cells, the rest
 * the parts' depths one after the other. Each part's NODES bytes are read
 * in order, so their CRC is checked against its header on the way. */
static oct_err put_nodes(merge *m, sink *s, uint8_t *const *top, const uint64_t *top_count)
{
    uLong *crc = malloc(m->n * sizeof *crc);
    if (!crc)
        return fail(m, NULL, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    oct_err r = OCT_OK;
    for (size_t i = 0; i < m->n && r == OCT_OK; i++) { /* the parts' own top levels: CRC only */
        const part *p = &m->parts[i];
        crc[i] = crc32_z(0, NULL, 0);
        r = read_range(m, p, p->off[OCT_SEC_NODES], depth_offset(p, m->depth) - p->off[OCT_SEC_NODES],
                       &crc[i], NULL, NULL);
    }
    for (unsigned d = 0; d < m->levels && r == OCT_OK; d++) {
        packer pk = {s, 0, {0}, 0, 0};
        if (d < m->depth) {
            for (uint64_t i = 0; i < top_count[d] && r == OCT_OK; i++)
                r = pack(&pk, top[d][i]) ? OCT_EIO : OCT_OK;
        } else {
            for (size_t i = 0; i < m->n && r == OCT_OK; i++) {
                const part *p = &m->parts[i];
                pk.left = p->count[d];
                r = read_range(m, p, depth_offset(p, d), 16 * groups_of(p->count[d]), &crc[i], pack_groups, &pk);
            }
        }
        if (r == OCT_OK && pack_flush(&pk) != 0)
            r = OCT_EIO;
    }
    for (size_t i = 0; i < m->n && r == OCT_OK; i++)
        if ((uint32_t)crc[i] != m->parts[i].crc[OCT_SEC_NODES])
            r = fail(m, m->parts[i].path, OCT_ECRC, "%s (it changed while merging)", oct_strerror(OCT_ECRC));
    free(crc);
    return r;
}

/* VOXELS or SURFACES: the parts' sections one after the other, each
 * checked against its CRC. */
static oct_err put_concat(merge *m, sink *s, int k)
{
    for (size_t i = 0; i < m->n; i++) {
        const part *p = &m->parts[i];
        uLong crc = crc32_z(0, NULL, 0);
        oct_err r = read_range(m, p, p->off[k], p->size[k], &crc, put_sink, s);
        if (r != OCT_OK)
            return r;
        if ((uint32_t)crc != p->crc[k])
            return fail(m, p->path, OCT_ECRC, "%s (it changed while merging)", oct_strerror(OCT_ECRC));
    }
    return OCT_OK;
}

/* The masks of the depths above k, from the flags of the depth-k cells:
 * top[d] holds the top_count[d] non-zero masks of depth d in Morton order. */
static oct_err rebuild_top(merge *m, uint8_t **top, uint64_t *top_count)
{
    uint64_t n = UINT64_C(1) << (3 * m->depth);
    uint8_t *cur = malloc(n), *up = malloc(n / 8 + 1);
    if (!cur || !up) {
        free(cur);
        free(up);
        return fail(m, NULL, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    }
    memcpy(cur, m->cells, n);
    oct_err r = OCT_OK;
    for (unsigned d = m->depth; d-- > 0 && r == OCT_OK;) {
        n /= 8;
        top[d] = malloc(n);
        if (!top[d]) {
            r = fail(m, NULL, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
            break;
        }
        top_count[d] = 0;
        for (uint64_t u = 0; u < n; u++) {
            uint8_t mask = 0;
            for (unsigned i = 0; i < 8; i++)
                mask |= (uint8_t)((cur[8 * u + i] ? 1u : 0u) << i);
            up[u] = mask != 0;
            if (mask)
                top[d][top_count[d]++] = mask;
        }
        memcpy(cur, up, n);
    }
    free(cur);
    free(up);
    return r;
}

/* Writes the sections after a zero header, then the header. */
static oct_err write_whole(merge *m, FILE *f, uint64_t *bytes, uint8_t *const *top, const uint64_t *top_count)
{
    uint64_t count[OCT_MAX_LEVELS] = {0}, voxels = 0, size[OCT_SEC_COUNT] = {0}, off[OCT_SEC_COUNT] = {0};
    uint32_t crc[OCT_SEC_COUNT] = {0};
    for (unsigned d = 0; d < m->levels; d++) {
        for (size_t i = 0; d >= m->depth && i < m->n; i++)
            count[d] += m->parts[i].count[d];
        if (d < m->depth)
            count[d] = top_count[d];
        size[OCT_SEC_NODES] += 16 * groups_of(count[d]);
    }
    size[OCT_SEC_LEVELS] = 8u * m->levels;
    for (size_t i = 0; i < m->n; i++) {
        voxels += m->parts[i].voxels;
        size[OCT_SEC_VOXELS] += m->parts[i].size[OCT_SEC_VOXELS];
        size[OCT_SEC_SURFACES] += m->parts[i].size[OCT_SEC_SURFACES];
    }
    size[OCT_SEC_PALETTE] = m->parts[0].size[OCT_SEC_PALETTE];
    size[OCT_SEC_FUNCTION] = m->parts[0].size[OCT_SEC_FUNCTION];

    /* As the writer: 1.1 only when a flag or a function is there, else the
     * 1.0 header of 256 bytes (the whole file is no shard). */
    const int v11 = rd_u32le(m->head + OCT_OFF_FLAGS) != 0 || size[OCT_SEC_FUNCTION] != 0;
    const uint32_t hsize = v11 ? OCT_HEADER_SIZE_1_1 : OCT_HEADER_SIZE;
    const int nsec = v11 ? OCT_SEC_COUNT : OCT_SEC_COUNT_1_0;
    sink s = {m, {f, 0, 0, 0}};
    static const unsigned char zero[OCT_HEADER_SIZE_1_1];
    if (put(&s, zero, hsize) != 0)
        return OCT_EIO;
    oct_err r = OCT_OK;
    for (int k = 0; k < nsec && r == OCT_OK; k++) {
        if (!size[k])
            continue;
        off[k] = oct_align_up(s.out.bytes);
        if (pad_to(&s, off[k]) != 0)
            return OCT_EIO;
        s.out.crc = crc32_z(0, NULL, 0);
        if (k == OCT_SEC_LEVELS) {
            for (unsigned d = 0; d < m->levels && r == OCT_OK; d++) {
                unsigned char b[8];
                wr_u64le(b, count[d]);
                r = put(&s, b, 8) ? OCT_EIO : OCT_OK;
            }
        } else if (k == OCT_SEC_NODES) {
            r = put_nodes(m, &s, top, top_count);
        } else if (k == OCT_SEC_VOXELS || k == OCT_SEC_SURFACES) {
            r = put_concat(m, &s, k);
        } else {
            uLong ignored = 0;
            r = read_range(m, &m->parts[0], m->parts[0].off[k], size[k], &ignored, put_sink, &s);
        }
        crc[k] = (uint32_t)s.out.crc;
    }
    if (r != OCT_OK)
        return r;
    *bytes = s.out.bytes;

    /* The parts' header up to the section table (identity, grid, surface
     * count: equal in every part), then the whole's own fields. */
    unsigned char h[OCT_HEADER_SIZE_1_1];
    memset(h, 0, sizeof h);
    memcpy(h, m->head, OCT_OFF_SECTIONS);
    wr_u16le(h + OCT_OFF_MINOR, v11 ? 1 : 0);
    wr_u32le(h + OCT_OFF_HEADER_SIZE, hsize);
    wr_u64le(h + OCT_OFF_VOXEL_COUNT, voxels);
    for (int k = 0; k < nsec; k++) {
        wr_u64le(h + OCT_SEC_OFF(k), off[k]);
        wr_u64le(h + OCT_SEC_OFF(k) + 8, size[k]);
        wr_u32le(h + OCT_SEC_OFF(k) + 16, crc[k]);
    }
    wr_u32le(h + hsize - 4, (uint32_t)crc32_z(0, h, hsize - 4));
    if (fseeko(f, 0, SEEK_SET) != 0 || fwrite(h, 1, hsize, f) != hsize || fflush(f) != 0 ||
        fseeko(f, 0, SEEK_END) != 0)
        return io_fail(m, NULL, "write");
    return OCT_OK;
}

oct_err oct_merge(const char *const *paths, size_t n, void *out, uint64_t *bytes, oct_merge_error *e)
{
    memset(e, 0, sizeof *e);
    merge m;
    memset(&m, 0, sizeof m);
    m.e = e;
    m.n = n;
    uint8_t *top[OCT_MAX_LEVELS] = {0};
    uint64_t top_count[OCT_MAX_LEVELS] = {0}, written = 0;
    m.parts = calloc(n ? n : 1, sizeof *m.parts);
    m.buf = malloc(MERGE_BUF);
    oct_err r = m.parts && m.buf ? OCT_OK : fail(&m, NULL, OCT_ENOMEM, "%s", oct_strerror(OCT_ENOMEM));
    if (r == OCT_OK && n == 0)
        r = fail(&m, NULL, OCT_EUSAGE, "no parts to merge");
    for (size_t i = 0; i < n && r == OCT_OK; i++)
        r = describe_part(&m, i, paths[i]);
    if (r == OCT_OK)
        r = check_partition(&m);
    if (r == OCT_OK)
        r = rebuild_top(&m, top, top_count);
    if (r == OCT_OK)
        r = write_whole(&m, out, &written, top, top_count);
    if (bytes)
        *bytes = r == OCT_OK ? written : 0;
    for (unsigned d = 0; d < OCT_MAX_LEVELS; d++)
        free(top[d]);
    free(m.cells);
    free(m.buf);
    free(m.parts);
    return r;
}
