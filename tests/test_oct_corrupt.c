/* Every kind of damage the .oct reader must refuse (format/oct_read.c):
 * truncation, bit flips, header fields out of range, tree damage, trailing
 * bytes and versions, huge counts, misaligned buffers, non-regular files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "format/oct.h"
#include "format/oct_layout.h"
#include "tests/oct_check.h"

static void test_every_truncated_prefix(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t);
    for (size_t n = 0; n < len; n++) {
        unsigned char *copy = malloc(n ? n : 1); /* exact size: ASan sees any over-read */
        memcpy(copy, buf, n);
        assert_int_equal(oct_check_open(copy, n, 0, NULL), OCT_ETRUNC);
        assert_int_equal(oct_check_open(copy, n, OCT_OPEN_TRUST, NULL), OCT_ETRUNC);
        free(copy);
    }
    free(buf);
    test_tree_free(&t);
}

static void walk_everything(const oct_file *f)
{
    const oct_tree *ft = oct_get_tree(f);
    uint64_t sum = 0;
    for (uint32_t d = 0; d < ft->levels; d++) {
        for (uint64_t i = 0; i < ft->node_count[d]; i++) {
            uint8_t m = oct_node_mask(ft->groups[d], i);
            assert_true(m != 0);
            for (unsigned c = 0; c < 8; c++) {
                if (!(m & (1u << c)))
                    continue;
                uint64_t idx = oct_child_index(ft->groups[d], i, c);
                if (d + 1 < ft->levels)
                    assert_true(idx < ft->node_count[d + 1]);
                else
                    sum += ft->voxels[idx];
            }
        }
    }
    (void)sum;
}

static void test_every_bit_flip(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t);
    unsigned char *copy = malloc(len);
    size_t opened_trusting = 0;
    for (size_t bit = 0; bit < 8 * len; bit++) {
        memcpy(copy, buf, len);
        copy[bit / 8] ^= (unsigned char)(1u << (bit % 8));
        oct_file *f = NULL;
        uint64_t at;
        oct_err rc = oct_open_memory(copy, len, 0, &f, &at);
        assert_true(rc != OCT_OK); /* CRC-32 detects every single-bit error */
        assert_true(at < len);
        rc = oct_open_memory(copy, len, OCT_OPEN_TRUST, &f, NULL);
        if (rc == OCT_OK) {
            walk_everything(f);
            oct_close(f);
            opened_trusting++;
        }
    }
    /* Flips in normals, offsets and palette bits leave a valid structure. */
    assert_true(opened_trusting > 0);
    free(copy);
    free(buf);
    test_tree_free(&t);
}

static void test_bit_pairs_in_header_and_nodes(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t);
    uint64_t nodes = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES));
    /* Header bits and the first 64 node bytes, every pair (TESTPLAN 1.3). */
    size_t bits[(256 + 64) * 8], nb = 0;
    for (size_t i = 0; i < 256 * 8; i++)
        bits[nb++] = i;
    for (size_t i = 0; i < 64 * 8 && nodes * 8 + i < 8 * len; i++)
        bits[nb++] = nodes * 8 + i;
    unsigned char *copy = malloc(len);
    for (size_t i = 0; i < nb; i++) {
        for (size_t j = i + 1; j < nb; j++) {
            memcpy(copy, buf, len);
            copy[bits[i] / 8] ^= (unsigned char)(1u << (bits[i] % 8));
            copy[bits[j] / 8] ^= (unsigned char)(1u << (bits[j] % 8));
            oct_file *f = NULL;
            if (oct_open_memory(copy, len, OCT_OPEN_TRUST, &f, NULL) == OCT_OK) {
                walk_everything(f);
                oct_close(f);
            }
        }
    }
    free(copy);
    free(buf);
    test_tree_free(&t);
}

typedef struct field_case {
    const char *what;
    unsigned offset, width; /* width 2, 4 or 8 (integer) or 9 (f64) */
    uint64_t value;
    double fvalue;
    oct_err want;
} field_case;

static void put_field(unsigned char *p, const field_case *c)
{
    switch (c->width) {
    case 1: p[c->offset] = (unsigned char)c->value; break;
    case 2: wr_u16le(p + c->offset, (uint16_t)c->value); break;
    case 4: wr_u32le(p + c->offset, (uint32_t)c->value); break;
    case 8: wr_u64le(p + c->offset, c->value); break;
    default: wr_f64le(p + c->offset, c->fvalue); break;
    }
}

static void test_header_fields_out_of_range(void **state)
{
    (void)state;
    const double inf = INFINITY, nan = NAN;
    const unsigned S = OCT_OFF_SECTIONS;
    static field_case cases[64];
    field_case list[] = {
        {"magic", 0, 1, 0x88, 0, OCT_EMAGIC},
        {"magic text", 1, 1, 'o', 0, OCT_EMAGIC},
        {"major 0", OCT_OFF_MAJOR, 2, 0, 0, OCT_EVERSION},
        {"major 2", OCT_OFF_MAJOR, 2, 2, 0, OCT_EVERSION},
        {"header_size 128", OCT_OFF_HEADER_SIZE, 4, 128, 0, OCT_EHEADER},
        {"header_size 257", OCT_OFF_HEADER_SIZE, 4, 257, 0, OCT_EHEADER},
        {"header_size 320", OCT_OFF_HEADER_SIZE, 4, 320, 0, OCT_EHEADER},
        {"u32 probe", OCT_OFF_BOM_U32, 4, 0x04030201, 0, OCT_EHEADER},
        {"f64 probe", OCT_OFF_BOM_F64, 9, 0, -370.5, OCT_EHEADER},
        {"flags", OCT_OFF_FLAGS, 4, 1, 0, OCT_EHEADER},
        {"levels 0", OCT_OFF_LEVELS, 4, 0, 0, OCT_EHEADER},
        {"levels 21", OCT_OFF_LEVELS, 4, 21, 0, OCT_EHEADER},
        {"levels 32", OCT_OFF_LEVELS, 4, 32, 0, OCT_EHEADER},
        {"levels 255", OCT_OFF_LEVELS, 4, 255, 0, OCT_EHEADER},
        {"root_depth 41", OCT_OFF_ROOT_DEPTH, 4, 41, 0, OCT_EHEADER},
        {"root_cell x with depth 0", OCT_OFF_ROOT_CELL, 8, 1, 0, OCT_EHEADER},
        {"root_cell z with depth 0", OCT_OFF_ROOT_CELL + 16, 8, UINT64_MAX, 0, OCT_EHEADER},
        {"grid_origin NaN", OCT_OFF_GRID_ORIGIN, 9, 0, nan, OCT_EHEADER},
        {"grid_origin inf", OCT_OFF_GRID_ORIGIN + 8, 9, 0, -inf, OCT_EHEADER},
        {"grid_origin huge", OCT_OFF_GRID_ORIGIN + 16, 9, 0, 1.7e308, OCT_EHEADER},
        {"grid_origin beyond 1e30", OCT_OFF_GRID_ORIGIN + 16, 9, 0, -2e30, OCT_EHEADER},
        {"voxels unresolvable", OCT_OFF_GRID_ORIGIN + 8, 9, 0, 1e20, OCT_EHEADER},
        {"grid_edge 1e31", OCT_OFF_GRID_EDGE, 9, 0, 1e31, OCT_EHEADER},
        {"grid_edge tiny", OCT_OFF_GRID_EDGE, 9, 0, 0x1p-1074, OCT_EHEADER},
        {"grid_edge 0", OCT_OFF_GRID_EDGE, 9, 0, 0.0, OCT_EHEADER},
        {"grid_edge -1", OCT_OFF_GRID_EDGE, 9, 0, -1.0, OCT_EHEADER},
        {"grid_edge NaN", OCT_OFF_GRID_EDGE, 9, 0, nan, OCT_EHEADER},
        {"grid_edge inf", OCT_OFF_GRID_EDGE, 9, 0, inf, OCT_EHEADER},
        {"surface_count 0", OCT_OFF_SURFACE_COUNT, 4, 0, 0, OCT_EHEADER},
        {"surface_count 256", OCT_OFF_SURFACE_COUNT, 4, 256, 0, OCT_EHEADER},
        {"reserved0", OCT_OFF_RESERVED0, 4, 1, 0, OCT_ERESERVED},
        {"reserved1", OCT_OFF_RESERVED1 + 7, 1, 1, 0, OCT_ERESERVED},
        {"section reserved", S + 24 * 2 + 20, 4, 1, 0, OCT_ERESERVED},
        {"voxel_count + 1", OCT_OFF_VOXEL_COUNT, 8, 0 /* set below */, 0, OCT_ESECTION},
        {"voxel_count 4G", OCT_OFF_VOXEL_COUNT, 8, UINT64_C(1) << 32, 0, OCT_ETREE},
        {"voxel_count max", OCT_OFF_VOXEL_COUNT, 8, UINT64_MAX, 0, OCT_ETREE},
        {"levels size", S + 8, 8, 16, 0, OCT_ESECTION},
        {"levels into header", S, 8, 192, 0, OCT_ESECTION},
        {"levels misaligned", S, 8, 260, 0, OCT_ESECTION},
        {"levels gap", S, 8, 320, 0, OCT_ESECTION},
        {"levels past the end", S, 8, UINT64_MAX - 63, 0, OCT_ESECTION},
        {"nodes overlaps levels", S + 24, 8, 256, 0, OCT_ESECTION},
        {"nodes size", S + 24 + 8, 8, UINT64_MAX, 0, OCT_ESECTION},
        {"voxels offset 0", S + 48, 8, 0, 0, OCT_ESECTION},
        {"surfaces size", S + 72 + 8, 8, 0, 0, OCT_ESECTION},
        {"palette size", S + 96 + 8, 8, 12, 0, OCT_ESECTION},
    };
    size_t nc = sizeof list / sizeof list[0];
    memcpy(cases, list, sizeof list);
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t); /* 3 levels, about 40 voxels, 2 surfaces */
    for (size_t i = 0; i < nc; i++)
        if (strcmp(cases[i].what, "voxel_count + 1") == 0)
            cases[i].value = t.voxel_count + 1;
    unsigned char *copy = malloc(len);
    for (size_t i = 0; i < nc; i++) {
        memcpy(copy, buf, len);
        put_field(copy, &cases[i]);
        test_oct_refresh_crcs(copy, len);
        uint64_t at = 0;
        oct_err rc = oct_check_open(copy, len, 0, &at);
        if (rc != cases[i].want)
            fail_msg("%s: got %s (at %llu), want %s", cases[i].what, oct_strerror(rc),
                     (unsigned long long)at, oct_strerror(cases[i].want));
        /* The reported offset points into the header, at or near the field. */
        if (cases[i].want != OCT_ETREE && cases[i].want != OCT_ESECTION)
            assert_true(at == cases[i].offset || at == cases[i].offset - cases[i].offset % 8);
    }
    free(copy);
    free(buf);
    test_tree_free(&t);
}

/* Offsets inside the small file's node section. */
typedef struct geo {
    uint64_t levels_off, nodes_off, vox_off, surf_off, pal_off;
} geo;
static geo geometry(const unsigned char *buf)
{
    geo g;
    g.levels_off = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_LEVELS));
    g.nodes_off = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES));
    g.vox_off = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_VOXELS));
    g.surf_off = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_SURFACES));
    g.pal_off = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_PALETTE));
    return g;
}

static void expect_damage(const unsigned char *buf, size_t len, void (*edit)(unsigned char *, geo),
                          oct_err want, const char *what)
{
    unsigned char *copy = malloc(len);
    memcpy(copy, buf, len);
    edit(copy, geometry(buf));
    test_oct_refresh_crcs(copy, len);
    uint64_t at;
    oct_err rc = oct_check_open(copy, len, 0, &at);
    if (rc != want)
        fail_msg("%s: got %s, want %s", what, oct_strerror(rc), oct_strerror(want));
    assert_int_equal(oct_check_open(copy, len, OCT_OPEN_TRUST, NULL), want);
    free(copy);
}

/* The depth-1 groups start after depth 0's one group. */
static void base_backwards(unsigned char *p, geo g) { wr_u64le(p + g.nodes_off + 16, UINT64_MAX); }
static void base_forward(unsigned char *p, geo g) { wr_u64le(p + g.nodes_off + 16, 1); }
static void base_root(unsigned char *p, geo g) { wr_u64le(p + g.nodes_off, 3); }
static void base_shared(unsigned char *p, geo g) /* second group of depth 2 reuses the first's children */
{
    wr_u64le(p + g.nodes_off + 16 + 16 * 1 /* depth 1 groups */ + 16, 0);
}
static void mask_zero(unsigned char *p, geo g) { p[g.nodes_off + 8] = 0; }
static void mask_extra_bit(unsigned char *p, geo g) { p[g.nodes_off + 8] = 0xff; }
static void pad_mask(unsigned char *p, geo g) { p[g.nodes_off + 9] = 1; }
static void root_count_2(unsigned char *p, geo g) { wr_u64le(p + g.levels_off, 2); }
static void surface_index(unsigned char *p, geo g) { p[g.surf_off + 5] = 2; }
static void palette_nan(unsigned char *p, geo g) { float v = NAN; memcpy(p + g.pal_off + 4, &v, 4); }
static void palette_big(unsigned char *p, geo g) { float v = 1.5f; memcpy(p + g.pal_off, &v, 4); }
static void voxel_offset_reserved(unsigned char *p, geo g) { p[g.vox_off + 4 * 3 + 3] = 0x80; }
static void padding_byte(unsigned char *p, geo g) { p[g.levels_off + 24 + 3] = 1; }
static void header_pad(unsigned char *p, geo g) { (void)g; p[OCT_HEADER_SIZE - 1] ^= 0; }

static void test_tree_damage(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    oct_check_small_file(&buf, &len, &t);
    assert_int_equal(t.count[0], 1);
    assert_true(t.count[1] <= 8 && t.count[2] > 8); /* depth 1: one group; depth 2: two or more */
    expect_damage(buf, len, base_backwards, OCT_ETREE, "base backwards");
    expect_damage(buf, len, base_forward, OCT_ETREE, "base skips a child");
    expect_damage(buf, len, base_root, OCT_ETREE, "root base past the end");
    expect_damage(buf, len, base_shared, OCT_ETREE, "shared child");
    expect_damage(buf, len, mask_zero, OCT_ETREE, "empty node");
    expect_damage(buf, len, mask_extra_bit, OCT_ETREE, "children count mismatch");
    expect_damage(buf, len, pad_mask, OCT_ERESERVED, "mask past the last node");
    expect_damage(buf, len, root_count_2, OCT_ETREE, "two roots");
    expect_damage(buf, len, surface_index, OCT_EVOXEL, "surface index");
    expect_damage(buf, len, palette_nan, OCT_EVOXEL, "palette NaN");
    expect_damage(buf, len, palette_big, OCT_EVOXEL, "palette > 1");
    expect_damage(buf, len, voxel_offset_reserved, OCT_EVOXEL, "offset -128");
    expect_damage(buf, len, padding_byte, OCT_ERESERVED, "padding between sections");
    expect_damage(buf, len, header_pad, OCT_OK, "no change");
    free(buf);
    test_tree_free(&t);
}

/* The small 1.0 file as a newer minor (OCT_VERSION_MINOR + 1) would write
 * it: a 384-byte header (1.1's fields zero, "new fields" 0xab in 320..379,
 * garbage in 1.1's reserved bytes) and the sections shifted by 128, plus
 * `extra` trailing bytes of garbage. */
static unsigned char *newer_minor_file(const unsigned char *buf, size_t len, size_t extra, size_t *out_len)
{
    const size_t shift = 384 - OCT_HEADER_SIZE;
    *out_len = len + shift + extra;
    unsigned char *big = calloc(1, *out_len);
    assert_non_null(big);
    memcpy(big, buf, OCT_OFF_RESERVED1);
    memcpy(big + 384, buf + OCT_HEADER_SIZE, len - OCT_HEADER_SIZE);
    memset(big + len + shift, 0x5a, extra);
    wr_u16le(big + OCT_OFF_MINOR, OCT_VERSION_MINOR + 1);
    wr_u32le(big + OCT_OFF_HEADER_SIZE, 384);
    for (int k = 0; k < OCT_SEC_COUNT; k++) {
        uint64_t off = rd_u64le(big + OCT_SEC_OFF(k));
        if (off)
            wr_u64le(big + OCT_SEC_OFF(k), off + shift);
    }
    big[OCT_OFF_RESERVED2 + 3] = 7;            /* reserved in 1.1: ignored */
    big[OCT_SEC_OFF(OCT_SEC_FUNCTION) + 21] = 7; /* an entry's reserved field: ignored */
    memset(big + 320, 0xab, 60);               /* fields 1.1 does not know */
    test_oct_refresh_crcs(big, *out_len);      /* header CRC at 380 */
    return big;
}

static void test_trailing_bytes_and_versions(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len, big_len;
    oct_check_small_file(&buf, &len, &t);
    unsigned char *big = calloc(1, len + 64);
    memcpy(big, buf, len);
    assert_int_equal(oct_check_open(big, len + 1, 0, NULL), OCT_ESECTION); /* trailing garbage */
    free(big);
    /* A newer minor: accepted, and its trailing data and reserved bytes ignored. */
    big = newer_minor_file(buf, len, 64, &big_len);
    oct_file *f;
    assert_int_equal(oct_open_memory(big, big_len, 0, &f, NULL), OCT_OK);
    assert_int_equal(oct_get_info(f)->version_minor, OCT_VERSION_MINOR + 1);
    oct_check_tree(f, &t);
    oct_close(f);
    /* ... but not an unknown flag: every flag is required. */
    wr_u32le(big + OCT_OFF_FLAGS, 2);
    test_oct_refresh_crcs(big, big_len);
    uint64_t at;
    assert_int_equal(oct_check_open(big, big_len, 0, &at), OCT_EHEADER);
    assert_int_equal(at, OCT_OFF_FLAGS);
    /* A newer major: refused before anything else is looked at. */
    wr_u16le(big + OCT_OFF_MAJOR, OCT_VERSION_MAJOR + 1);
    wr_u32le(big + OCT_OFF_LEVELS, 99);
    assert_int_equal(oct_check_open(big, big_len, 0, NULL), OCT_EVERSION);
    free(big);
    free(buf);
    test_tree_free(&t);
}

/* A newer minor's longer header (new fields in it, sections shifted) opens;
 * its new bytes are under the header CRC; the same layout claiming minor 1
 * (header 320) or minor 0 (header 256) is refused, and so is a newer minor
 * with a header shorter than 1.1's. */
static void test_newer_minor_longer_header(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len, big_len;
    oct_check_small_file(&buf, &len, &t);
    unsigned char *big = newer_minor_file(buf, len, 0, &big_len);
    oct_file *f;
    assert_int_equal(oct_open_memory(big, big_len, 0, &f, NULL), OCT_OK);
    oct_check_tree(f, &t);
    oct_close(f);
    big[0x150] ^= 1; /* the new header bytes are covered by the header CRC */
    uint64_t at;
    assert_int_equal(oct_check_open(big, big_len, 0, &at), OCT_ECRC);
    assert_int_equal(at, 380);
    big[0x150] ^= 1;
    for (unsigned minor = 0; minor <= OCT_VERSION_MINOR; minor++) {
        wr_u16le(big + OCT_OFF_MINOR, (uint16_t)minor);
        test_oct_refresh_crcs(big, big_len);
        assert_int_equal(oct_check_open(big, big_len, 0, &at), OCT_EHEADER);
        assert_int_equal(at, OCT_OFF_HEADER_SIZE);
    }
    free(big);
    /* the 1.0 file relabelled minor 2: a 256-byte header is too short */
    big = malloc(len);
    memcpy(big, buf, len);
    wr_u16le(big + OCT_OFF_MINOR, OCT_VERSION_MINOR + 1);
    test_oct_refresh_crcs(big, len);
    assert_int_equal(oct_check_open(big, len, 0, &at), OCT_EHEADER);
    assert_int_equal(at, OCT_OFF_HEADER_SIZE);
    free(big);
    free(buf);
    test_tree_free(&t);
}

static void test_huge_counts_in_small_files(void **state)
{
    (void)state;
    /* 100 bytes that start like an .oct file and claim 4 Gi of everything. */
    unsigned char small[100] = {0};
    memcpy(small, OCT_MAGIC, OCT_MAGIC_SIZE);
    assert_int_equal(oct_check_open(small, sizeof small, 0, NULL), OCT_ETRUNC);
    /* A full header over a 1-level tree whose counts claim 2^32 voxels. */
    test_tree t;
    test_tree_random(&t, 1, 3, 1, 1, 0);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    unsigned char *copy = malloc(len);
    memcpy(copy, buf, len);
    wr_u64le(copy + OCT_OFF_VOXEL_COUNT, UINT64_C(1) << 32);
    wr_u64le(copy + OCT_SEC_OFF(OCT_SEC_VOXELS) + 8, UINT64_C(1) << 34);
    test_oct_refresh_crcs(copy, len);
    assert_int_equal(oct_check_open(copy, len, 0, NULL), OCT_ETREE); /* > 8 children of one node */
    /* Levels 20 with every count at its cap: sizes near 2^62, no overflow. */
    unsigned char *h = calloc(1, 512);
    memcpy(h, buf, OCT_HEADER_SIZE);
    wr_u32le(h + OCT_OFF_LEVELS, 20);
    wr_u64le(h + OCT_SEC_OFF(OCT_SEC_LEVELS) + 8, 160);
    uint64_t lev = rd_u64le(h + OCT_SEC_OFF(OCT_SEC_LEVELS));
    for (unsigned d = 0; d < 20; d++)
        wr_u64le(h + lev + 8 * d, UINT64_C(1) << (3 * d));
    wr_u64le(h + OCT_OFF_VOXEL_COUNT, UINT64_C(1) << 60);
    uint64_t nodes = 0;
    for (unsigned d = 0; d < 20; d++)
        nodes += 16 * ((UINT64_C(1) << (3 * d)) / 8 + (d == 0));
    wr_u64le(h + OCT_SEC_OFF(OCT_SEC_NODES), 448);
    wr_u64le(h + OCT_SEC_OFF(OCT_SEC_NODES) + 8, nodes);
    test_oct_refresh_crcs(h, 512);
    assert_int_equal(oct_check_open(h, 512, 0, NULL), OCT_ETRUNC);
    free(h);
    free(copy);
    free(buf);
    test_tree_free(&t);
}

static void test_misaligned_buffer(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 5, 300, 3, 9, 1);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    unsigned char *raw = malloc(len + 8);
    for (size_t shift = 1; shift < 8; shift++) {
        memcpy(raw + shift, buf, len);
        oct_file *f;
        assert_int_equal(oct_open_memory(raw + shift, len, 0, &f, NULL), OCT_OK);
        oct_check_tree(f, &t);
        oct_close(f);
        raw[shift + 200] ^= 1; /* and damage is still found */
        assert_int_not_equal(oct_check_open(raw + shift, len, 0, NULL), OCT_OK);
    }
    free(raw);
    free(buf);
    test_tree_free(&t);
}

static void test_not_regular_files(void **state)
{
    (void)state;
    oct_file *f = (oct_file *)1;
    char dir[] = "/tmp/test_oct_dir_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[600];
    assert_int_equal(oct_open(dir, 0, &f, NULL), OCT_ENOTFILE);
    assert_null(f);
    snprintf(path, sizeof path, "%s/fifo", dir);
    assert_int_equal(mkfifo(path, 0600), 0);
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_ENOTFILE); /* and does not block */
    unlink(path);
    assert_int_equal(oct_open("/dev/zero", 0, &f, NULL), OCT_ENOTFILE);
    assert_int_equal(oct_open("/dev/null", 0, &f, NULL), OCT_ENOTFILE);
    snprintf(path, sizeof path, "%s/missing.oct", dir);
    errno = 0;
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_EIO);
    assert_int_equal(errno, ENOENT);
    snprintf(path, sizeof path, "%s/empty.oct", dir);
    FILE *e = fopen(path, "wb");
    fclose(e);
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_ETRUNC);
    unlink(path);
    snprintf(path, sizeof path, "%s/text.oct", dir);
    e = fopen(path, "wb");
    fputs("hello, world\n", e);
    fclose(e);
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_EMAGIC);
    unlink(path);
    rmdir(dir);
    assert_int_equal(oct_check_open(NULL, 0, 0, NULL), OCT_ETRUNC);
}

static void test_strerror_table(void **state)
{
    (void)state;
    for (int e = 0; e < OCT_ERR_COUNT; e++) {
        assert_non_null(oct_strerror((oct_err)e));
        assert_true(strlen(oct_strerror((oct_err)e)) > 3);
        assert_string_not_equal(oct_strerror((oct_err)e), "unknown error");
    }
    assert_string_equal(oct_strerror(OCT_ERR_COUNT), "unknown error");
    assert_string_equal(oct_strerror((oct_err)-1), "unknown error");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_truncated_prefix),
        cmocka_unit_test(test_every_bit_flip),
        cmocka_unit_test(test_bit_pairs_in_header_and_nodes),
        cmocka_unit_test(test_header_fields_out_of_range),
        cmocka_unit_test(test_tree_damage),
        cmocka_unit_test(test_trailing_bytes_and_versions),
        cmocka_unit_test(test_newer_minor_longer_header),
        cmocka_unit_test(test_huge_counts_in_small_files),
        cmocka_unit_test(test_misaligned_buffer),
        cmocka_unit_test(test_not_regular_files),
        cmocka_unit_test(test_strerror_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
