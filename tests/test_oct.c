/* Tests for format/oct_read.c and format/oct_write.c: round trips, every kind
 * of damage a reader must refuse, the writer's contract and failure paths. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/atomic_file.h"
#include "format/oct.h"
#include "format/oct_layout.h"
#include "format/oct_normal.h"
#include "tests/oct_testutil.h"

/* The bound FORMAT.md states for the 24-bit normal ("Voxel record"). */
#define NORMAL_MAX_ERROR_DEG 0.06

/* Walks the file's tree from the root through oct_child_index and checks it
 * reaches exactly t's voxels, in Morton order, with their records. */
static void walk_and_compare(const oct_tree *ft, const test_tree *t)
{
    assert_int_equal(ft->voxel_count, t->voxel_count);
    size_t seen = 0;
    if (ft->node_count[0] == 0) {
        assert_int_equal(t->voxel_count, 0);
        return;
    }
    /* Depth-first with an explicit stack; visits children in increasing i,
     * so voxels come out in Morton order. */
    struct { uint64_t node, code; unsigned depth, next; } st[OCT_MAX_LEVELS + 1];
    int sp = 0;
    st[0].node = 0; st[0].code = 0; st[0].depth = 0; st[0].next = 0;
    while (sp >= 0) {
        unsigned d = st[sp].depth;
        uint8_t m = oct_node_mask(ft->groups[d], st[sp].node);
        unsigned c = st[sp].next;
        while (c < 8 && !(m & (1u << c)))
            c++;
        if (c == 8) {
            sp--;
            continue;
        }
        st[sp].next = c + 1;
        uint64_t idx = oct_child_index(ft->groups[d], st[sp].node, c);
        uint64_t code = (st[sp].code << 3) | c;
        if (d + 1 == ft->levels) {
            assert_true(seen < t->voxel_count);
            assert_int_equal(idx, seen);
            assert_int_equal(code, t->codes[seen]);
            assert_int_equal(ft->voxels[idx], t->voxels[seen]);
            if (t->surface_count > 1)
                assert_int_equal(ft->surfaces[idx], t->surfaces[seen]);
            seen++;
        } else {
            assert_true(idx < ft->node_count[d + 1]);
            sp++;
            st[sp].node = idx; st[sp].code = code; st[sp].depth = d + 1; st[sp].next = 0;
        }
    }
    assert_int_equal(seen, t->voxel_count);
}

static void compare(const oct_file *f, const test_tree *t)
{
    const oct_tree *ft = oct_get_tree(f);
    assert_int_equal(ft->levels, t->levels);
    assert_int_equal(ft->surface_count, t->surface_count);
    for (uint32_t d = 0; d < t->levels; d++) {
        assert_int_equal(ft->node_count[d], t->count[d]);
        for (size_t i = 0; i < t->count[d]; i++)
            assert_int_equal(oct_node_mask(ft->groups[d], i), t->masks[d][i]);
    }
    for (size_t i = 0; i < t->voxel_count; i++)
        assert_int_equal(ft->voxels[i], t->voxels[i]);
    if (t->surface_count > 1) {
        for (size_t i = 0; i < t->voxel_count; i++)
            assert_int_equal(ft->surfaces[i], t->surfaces[i]);
    } else {
        assert_null(ft->surfaces);
    }
    assert_memory_equal(ft->palette, t->palette, 12 * t->surface_count);
    if (t->root_depth == 0) {
        assert_true(ft->edge == t->edge);
        for (int i = 0; i < 3; i++)
            assert_true(ft->origin[i] == t->origin[i]);
    } else {
        assert_true(ft->edge == t->edge);
        for (int i = 0; i < 3; i++)
            assert_true(fabs(ft->origin[i] - t->origin[i]) <= 1e-12 * (1 + fabs(t->origin[i])));
    }
    const oct_info *in = oct_get_info(f);
    assert_int_equal(in->version_major, OCT_VERSION_MAJOR);
    assert_int_equal(in->root_depth, t->root_depth);
    walk_and_compare(ft, t);
}

/* A small valid file: 3 levels, 2 surfaces, a few dozen voxels. */
static void small_file(unsigned char **buf, size_t *len, test_tree *t)
{
    test_tree_random(t, 3, 40, 2, 7, 1);
    assert_int_equal(test_tree_write(t, buf, len), OCT_OK);
}

static oct_err open_buf(const unsigned char *buf, size_t len, unsigned flags, uint64_t *at)
{
    oct_file *f = NULL;
    uint64_t where = 0;
    oct_err rc = oct_open_memory(buf, len, flags, &f, &where);
    if (rc == OCT_OK) {
        assert_non_null(f);
        oct_close(f);
    } else {
        assert_null(f);
        assert_true(where <= len || rc == OCT_ETRUNC);
    }
    if (at)
        *at = where;
    return rc;
}

/* --- round trips --------------------------------------------------------- */

static void test_round_trip_random_trees(void **state)
{
    (void)state;
    for (uint32_t levels = 1; levels <= 12; levels++) {
        for (uint64_t seed = 1; seed <= 6; seed++) {
            test_tree t;
            uint32_t surfaces = seed % 3 == 0 ? 1 : (uint32_t)(seed % 5 + 1);
            size_t target = seed == 1 ? 1 : (size_t)(seed * 700);
            test_tree_random(&t, levels, target, surfaces, seed * 100 + levels, (int)(seed & 1));
            if (seed == 5) { /* a subtree of a bigger grid */
                t.root_depth = 3;
                t.root_cell[0] = 5; t.root_cell[1] = 0; t.root_cell[2] = 7;
                t.edge = 0.25;
                t.origin[0] = -1.0 + 5 * 0.25; t.origin[1] = -1.0; t.origin[2] = -1.0 + 7 * 0.25;
            }
            unsigned char *buf;
            size_t len;
            assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
            assert_int_equal(len % 4, 0);
            oct_file *f = NULL;
            uint64_t at = 99;
            assert_int_equal(oct_open_memory(buf, len, 0, &f, &at), OCT_OK);
            assert_int_equal(at, 0);
            compare(f, &t);
            assert_int_equal(oct_get_info(f)->file_size, len);
            oct_close(f);
            assert_int_equal(oct_open_memory(buf, len, OCT_OPEN_TRUST, &f, NULL), OCT_OK);
            oct_close(f);
            free(buf);
            test_tree_free(&t);
        }
    }
}

static void test_round_trip_through_file(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 5000, 3, 42, 1);
    char path[] = "/tmp/test_oct_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *fp = fdopen(fd, "wb");
    oct_writer_params p = {.levels = 8, .edge = t.edge, .surface_count = 3, .palette = t.palette};
    memcpy(p.origin, t.origin, sizeof p.origin);
    oct_writer *w;
    assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
    for (uint32_t d = 0; d < 8; d++)
        assert_int_equal(oct_writer_add_masks(w, d, t.masks[d], t.count[d]), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, t.voxels, t.surfaces, t.voxel_count), OCT_OK);
    uint64_t n = 0;
    assert_int_equal(oct_writer_finish(w, fp, &n), OCT_OK);
    oct_writer_free(w);
    assert_int_equal(fclose(fp), 0);
    oct_file *f;
    assert_int_equal(oct_open(path, 0, &f, NULL), OCT_OK);
    assert_int_equal(oct_get_info(f)->file_size, n);
    compare(f, &t);
    char *text = NULL;
    size_t tlen = 0;
    FILE *mf = open_memstream(&text, &tlen);
    assert_int_equal(oct_print_info(mf, f), 0);
    fclose(mf);
    assert_non_null(strstr(text, "levels:      8"));
    assert_non_null(strstr(text, "bytes/voxel:"));
    free(text);
    oct_close(f);
    unlink(path);
    test_tree_free(&t);
}

static void test_empty_trees(void **state)
{
    (void)state;
    for (uint32_t levels = 1; levels <= OCT_MAX_LEVELS; levels += 19) {
        test_tree t;
        test_tree_random(&t, levels, 0, 1, 1, 0);
        unsigned char *buf;
        size_t len;
        assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
        oct_file *f;
        assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
        const oct_tree *ft = oct_get_tree(f);
        assert_int_equal(ft->node_count[0], 0);
        assert_int_equal(ft->voxel_count, 0);
        assert_null(ft->voxels);
        oct_close(f);
        free(buf);
        test_tree_free(&t);
    }
}

static void test_deepest_tree(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, OCT_MAX_LEVELS, 3000, 2, 5, 1);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    compare(f, &t);
    oct_close(f);
    /* A would-be DAG: one group of the deepest depth reuses an earlier
     * group's children. Refused by the flat scan, CRCs fixed or not. */
    uint64_t nodes = rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES)), g = 0;
    for (uint32_t d = 0; d + 1 < OCT_MAX_LEVELS; d++)
        g += t.count[d] / 8 + (t.count[d] % 8 != 0);
    assert_true(t.count[OCT_MAX_LEVELS - 1] > 8);
    wr_u64le(buf + nodes + 16 * (g + 1), 0);
    uint64_t at;
    assert_int_equal(open_buf(buf, len, OCT_OPEN_TRUST, &at), OCT_ETREE);
    assert_int_equal(at, nodes + 16 * (g + 1));
    test_oct_refresh_crcs(buf, len);
    assert_int_equal(open_buf(buf, len, 0, NULL), OCT_ETREE);
    free(buf);
    test_tree_free(&t);
}

/* A subtree at the deepest root_depth, at the far corner of its grid. */
static void test_subtree_at_depth_40(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 500, 1, 8, 1);
    t.root_depth = 40;
    uint64_t last = (UINT64_C(1) << 40) - 1;
    t.root_cell[0] = last; t.root_cell[1] = 0; t.root_cell[2] = last / 3;
    t.edge = 0x1p-40;
    for (int i = 0; i < 3; i++)
        t.origin[i] = (double)t.root_cell[i] * t.edge; /* the grid is the unit cube at 0 */
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    oct_file *f;
    assert_int_equal(oct_open_memory(buf, len, 0, &f, NULL), OCT_OK);
    compare(f, &t);
    const oct_info *in = oct_get_info(f);
    assert_true(in->grid_edge == 1.0);
    for (int i = 0; i < 3; i++) {
        assert_true(in->grid_origin[i] == 0.0);
        assert_true(oct_get_tree(f)->origin[i] == t.origin[i]); /* exact: dyadic */
        assert_int_equal(in->root_cell[i], t.root_cell[i]);
    }
    char *text = NULL;
    size_t tlen = 0;
    FILE *mf = open_memstream(&text, &tlen);
    assert_int_equal(oct_print_info(mf, f), 0);
    fclose(mf);
    assert_non_null(strstr(text, "subtree:     depth 40, cell (1099511627775, 0, 366503875925)"));
    free(text);
    oct_close(f);
    free(buf);
    /* One level more and the finest voxel is too small next to the grid. */
    t.levels = 9;
    oct_writer_params p = {.levels = 9, .edge = t.edge, .root_depth = 40, .surface_count = 1};
    memcpy(p.origin, t.origin, sizeof p.origin);
    memcpy(p.root_cell, t.root_cell, sizeof p.root_cell);
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    t.levels = 8;
    test_tree_free(&t);
}

/* The mapping outlives a rename over the file; a truncation in place is
 * documented (FORMAT.md §10) to raise SIGBUS on the lost pages. */
static void test_mapped_file_replaced_or_truncated(void **state)
{
    (void)state;
    test_tree a, b;
    test_tree_random(&a, 6, 20000, 2, 11, 0);
    test_tree_random(&b, 3, 10, 1, 12, 0);
    unsigned char *ba, *bb;
    size_t la, lb;
    assert_int_equal(test_tree_write(&a, &ba, &la), OCT_OK);
    assert_int_equal(test_tree_write(&b, &bb, &lb), OCT_OK);
    char dir[] = "/tmp/test_oct_map_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char pa[600], pb[600];
    snprintf(pa, sizeof pa, "%s/a.oct", dir);
    snprintf(pb, sizeof pb, "%s/b.oct", dir);
    FILE *fa = fopen(pa, "wb"), *fb = fopen(pb, "wb");
    assert_int_equal(fwrite(ba, 1, la, fa), la);
    assert_int_equal(fwrite(bb, 1, lb, fb), lb);
    fclose(fa);
    fclose(fb);
    oct_file *f;
    assert_int_equal(oct_open(pa, 0, &f, NULL), OCT_OK);
    assert_int_equal(rename(pb, pa), 0);
    compare(f, &a); /* still the old inode */
    oct_close(f);

    fa = fopen(pa, "wb");
    assert_int_equal(fwrite(ba, 1, la, fa), la);
    fclose(fa);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGBUS, SIG_DFL); /* cmocka catches it otherwise */
        if (oct_open(pa, 0, &f, NULL) != OCT_OK)
            _exit(2);
        if (truncate(pa, 0) != 0)
            _exit(3);
        const oct_tree *t = oct_get_tree(f);
        volatile uint32_t x = t->voxels[t->voxel_count - 1]; /* on a lost page */
        (void)x;
        _exit(0);
    }
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status));
    assert_int_equal(WTERMSIG(status), SIGBUS);
    unlink(pa);
    rmdir(dir);
    free(ba);
    free(bb);
    test_tree_free(&a);
    test_tree_free(&b);
}

/* FORMAT.md, Appendix A: the writer makes exactly the example's bytes. */
static void test_spec_example(void **state)
{
    (void)state;
    float pal[3] = {1.0f, 0.5f, 0.25f};
    oct_writer_params p = {.levels = 2, .origin = {-1, -1, -1}, .edge = 2.0, .surface_count = 1, .palette = pal};
    oct_writer *w;
    assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
    const uint8_t root = 0x81, d1[2] = {0x01, 0x80};
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, d1, 2), OCT_OK);
    const double n1[3] = {0, 0, 1}, n2[3] = {1, 1, 1};
    uint32_t v[2] = {oct_voxel_pack(n1, 0.25), oct_voxel_pack(n2, -0.5)};
    assert_int_equal(v[0], 0x20800800u);
    assert_int_equal(v[1], 0xc0aaaaaau);
    assert_int_equal(oct_writer_add_voxels(w, v, NULL, 2), OCT_OK);
    char *mem;
    size_t len;
    FILE *f = open_memstream(&mem, &len);
    uint64_t n;
    assert_int_equal(oct_writer_finish(w, f, &n), OCT_OK);
    oct_writer_free(w);
    fclose(f);
    const unsigned char *b = (const unsigned char *)mem;
    assert_int_equal(len, 460);
    assert_int_equal(rd_u32le(b + OCT_OFF_HEADER_CRC), 0x506ac706u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_LEVELS) + 16), 0x00f6ddb9u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_NODES) + 16), 0x912a2f8cu);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_VOXELS) + 16), 0xb0091dd6u);
    assert_int_equal(rd_u32le(b + OCT_SEC_OFF(OCT_SEC_PALETTE) + 16), 0xb5cb6adau);
    static const unsigned char nodes[32] = {0, 0, 0, 0, 0, 0, 0, 0, 0x81, 0, 0, 0, 0, 0, 0, 0,
                                            0, 0, 0, 0, 0, 0, 0, 0, 0x01, 0x80, 0, 0, 0, 0, 0, 0};
    assert_memory_equal(b + 320, nodes, 32);
    oct_file *of;
    assert_int_equal(oct_open_memory(mem, len, 0, &of, NULL), OCT_OK);
    const oct_tree *t = oct_get_tree(of);
    assert_int_equal(oct_child_index(t->groups[0], 0, 7), 1);
    assert_int_equal(oct_child_index(t->groups[1], 1, 7), 1);
    oct_close(of);
    free(mem);
}

static void test_writer_is_deterministic(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 6, 2000, 4, 3, 1);
    unsigned char *a, *b;
    size_t la, lb;
    assert_int_equal(test_tree_write(&t, &a, &la), OCT_OK);
    assert_int_equal(test_tree_write(&t, &b, &lb), OCT_OK);
    assert_int_equal(la, lb);
    assert_memory_equal(a, b, la);
    free(a);
    free(b);
    test_tree_free(&t);
}

/* --- damage -------------------------------------------------------------- */

static void test_every_truncated_prefix(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    small_file(&buf, &len, &t);
    for (size_t n = 0; n < len; n++) {
        unsigned char *copy = malloc(n ? n : 1); /* exact size: ASan sees any over-read */
        memcpy(copy, buf, n);
        assert_int_equal(open_buf(copy, n, 0, NULL), OCT_ETRUNC);
        assert_int_equal(open_buf(copy, n, OCT_OPEN_TRUST, NULL), OCT_ETRUNC);
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
    small_file(&buf, &len, &t);
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
    small_file(&buf, &len, &t);
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
    small_file(&buf, &len, &t); /* 3 levels, about 40 voxels, 2 surfaces */
    for (size_t i = 0; i < nc; i++)
        if (strcmp(cases[i].what, "voxel_count + 1") == 0)
            cases[i].value = t.voxel_count + 1;
    unsigned char *copy = malloc(len);
    for (size_t i = 0; i < nc; i++) {
        memcpy(copy, buf, len);
        put_field(copy, &cases[i]);
        test_oct_refresh_crcs(copy, len);
        uint64_t at = 0;
        oct_err rc = open_buf(copy, len, 0, &at);
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
    oct_err rc = open_buf(copy, len, 0, &at);
    if (rc != want)
        fail_msg("%s: got %s, want %s", what, oct_strerror(rc), oct_strerror(want));
    assert_int_equal(open_buf(copy, len, OCT_OPEN_TRUST, NULL), want);
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
    small_file(&buf, &len, &t);
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

static void test_trailing_bytes_and_versions(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    small_file(&buf, &len, &t);
    unsigned char *big = calloc(1, len + 64);
    memcpy(big, buf, len);
    assert_int_equal(open_buf(big, len + 1, 0, NULL), OCT_ESECTION); /* trailing garbage */
    /* A newer minor: accepted, and its trailing data and reserved bytes ignored. */
    wr_u16le(big + OCT_OFF_MINOR, OCT_VERSION_MINOR + 1);
    big[OCT_OFF_RESERVED1] = 7;
    test_oct_refresh_crcs(big, len);
    oct_file *f;
    assert_int_equal(oct_open_memory(big, len + 64, 0, &f, NULL), OCT_OK);
    assert_int_equal(oct_get_info(f)->version_minor, OCT_VERSION_MINOR + 1);
    compare(f, &t);
    oct_close(f);
    /* A newer major: refused before anything else is looked at. */
    wr_u16le(big + OCT_OFF_MAJOR, OCT_VERSION_MAJOR + 1);
    wr_u32le(big + OCT_OFF_LEVELS, 99);
    assert_int_equal(open_buf(big, len, 0, NULL), OCT_EVERSION);
    free(big);
    free(buf);
    test_tree_free(&t);
}

/* A newer minor with a 320-byte header (new fields in it, sections shifted
 * by 64) opens; the same layout claiming minor 0 is refused. */
static void test_newer_minor_longer_header(void **state)
{
    (void)state;
    test_tree t;
    unsigned char *buf;
    size_t len;
    small_file(&buf, &len, &t);
    size_t big_len = len + 64;
    unsigned char *big = calloc(1, big_len);
    memcpy(big, buf, OCT_HEADER_SIZE);
    memcpy(big + 320, buf + OCT_HEADER_SIZE, len - OCT_HEADER_SIZE);
    wr_u16le(big + OCT_OFF_MINOR, OCT_VERSION_MINOR + 1);
    wr_u32le(big + OCT_OFF_HEADER_SIZE, 320);
    memset(big + OCT_OFF_HEADER_CRC, 0xab, 64); /* "new fields" where 1.0 had its CRC */
    for (int k = 0; k < OCT_SEC_COUNT; k++) {
        uint64_t off = rd_u64le(big + OCT_SEC_OFF(k));
        if (off)
            wr_u64le(big + OCT_SEC_OFF(k), off + 64);
    }
    test_oct_refresh_crcs(big, big_len); /* header CRC at 316 */
    oct_file *f;
    assert_int_equal(oct_open_memory(big, big_len, 0, &f, NULL), OCT_OK);
    compare(f, &t);
    oct_close(f);
    big[0x130] ^= 1; /* the new header bytes are covered by the header CRC */
    uint64_t at;
    assert_int_equal(open_buf(big, big_len, 0, &at), OCT_ECRC);
    assert_int_equal(at, 316);
    big[0x130] ^= 1;
    wr_u16le(big + OCT_OFF_MINOR, OCT_VERSION_MINOR);
    test_oct_refresh_crcs(big, big_len);
    assert_int_equal(open_buf(big, big_len, 0, &at), OCT_EHEADER);
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
    assert_int_equal(open_buf(small, sizeof small, 0, NULL), OCT_ETRUNC);
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
    assert_int_equal(open_buf(copy, len, 0, NULL), OCT_ETREE); /* > 8 children of one node */
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
    assert_int_equal(open_buf(h, 512, 0, NULL), OCT_ETRUNC);
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
        compare(f, &t);
        oct_close(f);
        raw[shift + 200] ^= 1; /* and damage is still found */
        assert_int_not_equal(open_buf(raw + shift, len, 0, NULL), OCT_OK);
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
    assert_int_equal(open_buf(NULL, 0, 0, NULL), OCT_ETRUNC);
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

/* --- normal codec -------------------------------------------------------- */

static void test_normal_codec_error(void **state)
{
    (void)state;
    uint64_t rs = 12345;
    double worst = 0.0;
    for (int i = 0; i < 2000000; i++) {
        double v[3], l;
        do { /* uniform on the sphere by rejection */
            for (int k = 0; k < 3; k++)
                v[k] = (double)(test_rand(&rs) >> 11) * 0x1p-53 * 2.0 - 1.0;
            l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (l > 1.0 || l < 1e-3);
        for (int k = 0; k < 3; k++)
            v[k] /= l;
        if (i < 64) { /* the axes, diagonals and fold edges, where errors peak */
            static const double e[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1},
                                          {1, 1, 0}, {1, -1, 0}, {0, 1, -1}, {1, 1, -1}, {-1, -1, -1}};
            const double *a = e[i % 11];
            double al = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            for (int k = 0; k < 3; k++)
                v[k] = a[k] / al;
        }
        uint32_t code = oct_normal_encode(v);
        assert_true(code <= OCT_VOXEL_NORMAL_MASK);
        float n[3];
        oct_normal_decode(code, n);
        double dot = (double)n[0] * v[0] + (double)n[1] * v[1] + (double)n[2] * v[2];
        double cross[3] = {n[1] * v[2] - n[2] * v[1], n[2] * v[0] - n[0] * v[2], n[0] * v[1] - n[1] * v[0]};
        double ang = atan2(sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]), dot);
        if (ang > worst)
            worst = ang;
        double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        assert_true(fabs(nl - 1.0) < 1e-6);
    }
    double deg = worst * 180.0 / M_PI;
    print_message("normal codec: max angular error %.4f degrees over 2e6 unit vectors\n", deg);
    assert_true(deg < NORMAL_MAX_ERROR_DEG);
    /* Degenerate input encodes +z. */
    double z[3] = {0, 0, 0}, nanv[3] = {NAN, 0, 0};
    float n[3];
    oct_normal_decode(oct_normal_encode(z), n);
    assert_true(n[2] > 0.99999f);
    oct_normal_decode(oct_normal_encode(nanv), n);
    assert_true(n[2] > 0.99999f);
}

static void test_offset_codec(void **state)
{
    (void)state;
    for (int q = -127; q <= 127; q++)
        assert_int_equal(oct_offset_encode(oct_offset_decode((int8_t)q)), q);
    for (double d = -0.99; d < 0.99; d += 0.001) {
        double back = oct_offset_decode(oct_offset_encode(d));
        assert_true(fabs(back - d) <= 0.5 * OCT_OFFSET_UNIT + 1e-12);
    }
    assert_int_equal(oct_offset_encode(5.0), 127);
    assert_int_equal(oct_offset_encode(-5.0), -127); /* never -128: reserved */
    assert_int_equal(oct_offset_encode(NAN), -127);
    double nz[3] = {0, 0, 1};
    uint32_t rec = oct_voxel_pack(nz, -0.25);
    assert_int_equal((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT), -32);
}

/* --- writer contract ----------------------------------------------------- */

static void test_writer_usage_errors(void **state)
{
    (void)state;
    float pal[6] = {0.1f, 0.2f, 0.3f, 1, 1, 1};
    oct_writer_params ok = {.levels = 2, .edge = 1.0, .surface_count = 2, .palette = pal};
    oct_writer *w = (oct_writer *)1;
    oct_writer_params p = ok;
    p.levels = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    assert_null(w);
    p = ok; p.levels = 21;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.edge = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.edge = NAN;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.origin[1] = INFINITY;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.surface_count = 0;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.surface_count = 256;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.root_cell[2] = 1; /* root_depth 0 has one cell */
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    p = ok; p.root_depth = 41;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);
    float bad[6] = {0, 0, 0, 0, 2, 0};
    p = ok; p.palette = bad;
    assert_int_equal(oct_writer_create(&p, &w), OCT_EUSAGE);

    char *mem;
    size_t memlen;
    FILE *f = open_memstream(&mem, &memlen);
    const uint8_t root = 0x81, zero = 0, two[2] = {1, 1};
    uint32_t vox[3] = {1, 2, 3};
    uint8_t surf_ok[3] = {0, 1, 1}, surf_bad[3] = {0, 2, 0};
    /* Each case: a fresh writer, fed something inconsistent. */
    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &zero, 1), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_masks(w, 2, &root, 1), OCT_EUSAGE); /* depth >= levels */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_bad, 3), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_voxels(w, vox, NULL, 3), OCT_EUSAGE); /* 2 surfaces: needed */
    uint32_t reserved = 0x80000000u;
    assert_int_equal(oct_writer_add_voxels(w, &reserved, surf_ok, 1), OCT_EUSAGE);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 2), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 3), OCT_OK);
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE); /* 2 voxels under the masks, 3 given */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 1), OCT_EUSAGE); /* finished */
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 1), OCT_OK); /* mask says 2 nodes */
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 1), OCT_OK);
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE);
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, two, 2), OCT_OK); /* two roots */
    assert_int_equal(oct_writer_finish(w, f, NULL), OCT_EUSAGE);
    oct_writer_free(w);

    assert_int_equal(oct_writer_create(&ok, &w), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 0, &root, 1), OCT_OK);
    assert_int_equal(oct_writer_add_masks(w, 1, two, 2), OCT_OK);
    assert_int_equal(oct_writer_add_voxels(w, vox, surf_ok, 2), OCT_OK);
    assert_int_equal(oct_writer_finish(w, NULL, NULL), OCT_EUSAGE);
    oct_writer_free(w);
    oct_writer_free(NULL);
    fclose(f);
    free(mem);
}

/* A stream whose Nth write fails (fopencookie). Buffered with a small buffer,
 * like a file: a failure surfaces inside some later fwrite, through its
 * return value or the error flag. */
typedef struct fail_stream { int calls, fail_at, sticky; size_t bytes; } fail_stream;
static ssize_t fail_write(void *c, const char *b, size_t n)
{
    (void)b;
    fail_stream *s = c;
    s->calls++;
    if (s->calls == s->fail_at || (s->sticky && s->calls > s->fail_at)) {
        errno = ENOSPC;
        return 0; /* not -1: glibc 2.36 adds a -1 from a cookie to the bytes left to write */
    }
    s->bytes += n;
    return (ssize_t)n;
}

static void test_writer_write_failures(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 8, 60000, 2, 77, 0); /* > 32768 nodes at a depth: several node chunks */
    unsigned char *good;
    size_t good_len;
    assert_int_equal(test_tree_write(&t, &good, &good_len), OCT_OK);
    for (int sticky = 0; sticky <= 1; sticky++) {
        for (int n = 1;; n++) {
            fail_stream fs = {0, n, sticky, 0};
            cookie_io_functions_t io = {.write = fail_write};
            FILE *f = fopencookie(&fs, "w", io);
            static char iobuf[4096];
            setvbuf(f, iobuf, _IOFBF, sizeof iobuf);
            oct_writer_params p = {.levels = t.levels, .edge = t.edge, .surface_count = 2, .palette = t.palette};
            oct_writer *w;
            assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
            for (uint32_t d = 0; d < t.levels; d++)
                assert_int_equal(oct_writer_add_masks(w, d, t.masks[d], t.count[d]), OCT_OK);
            assert_int_equal(oct_writer_add_voxels(w, t.voxels, t.surfaces, t.voxel_count), OCT_OK);
            errno = 0;
            uint64_t written = 1;
            oct_err rc = oct_writer_finish(w, f, &written);
            int e = errno;
            oct_writer_free(w);
            fclose(f);
            if (rc == OCT_OK) {
                assert_true(fs.calls < n); /* all writes done before the fault */
                assert_int_equal(written, good_len);
                break;
            }
            assert_int_equal(rc, OCT_EIO);
            assert_int_equal(e, ENOSPC);
            assert_int_equal(written, 0);
            assert_true(n < 1000);
        }
    }
    FILE *full = fopen("/dev/full", "wb");
    if (full) { /* a full disk shows at the flush */
        oct_writer_params p = {.levels = t.levels, .edge = t.edge, .surface_count = 1};
        oct_writer *w;
        assert_int_equal(oct_writer_create(&p, &w), OCT_OK);
        assert_int_equal(oct_writer_finish(w, full, NULL), OCT_EIO); /* an empty tree */
        oct_writer_free(w);
        fclose(full);
    }
    free(good);
    test_tree_free(&t);
}

/* Feeds t to a new writer in chunks; on ENOMEM retries the call once when
 * `retry` (a single injected failure must leave the writer usable). */
static oct_err feed_writer(const test_tree *t, int retry, unsigned char **out, size_t *out_len)
{
    oct_writer_params p = {.levels = t->levels, .edge = t->edge, .surface_count = t->surface_count,
                           .palette = t->palette};
    memcpy(p.origin, t->origin, sizeof p.origin);
    oct_writer *w = NULL;
    oct_err rc = oct_writer_create(&p, &w);
    if (rc == OCT_ENOMEM && retry)
        rc = oct_writer_create(&p, &w);
    for (uint32_t d = 0; d < t->levels && rc == OCT_OK; d++) {
        for (size_t i = 0; i < t->count[d] && rc == OCT_OK; i += 5000) {
            size_t n = t->count[d] - i < 5000 ? t->count[d] - i : 5000;
            rc = oct_writer_add_masks(w, d, t->masks[d] + i, n);
            if (rc == OCT_ENOMEM && retry)
                rc = oct_writer_add_masks(w, d, t->masks[d] + i, n);
        }
    }
    for (size_t i = 0; i < t->voxel_count && rc == OCT_OK; i += 3000) {
        size_t n = t->voxel_count - i < 3000 ? t->voxel_count - i : 3000;
        rc = oct_writer_add_voxels(w, t->voxels + i, t->surfaces + i, n);
        if (rc == OCT_ENOMEM && retry)
            rc = oct_writer_add_voxels(w, t->voxels + i, t->surfaces + i, n);
    }
    char *mem = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&mem, &len);
    if (rc == OCT_OK)
        rc = oct_writer_finish(w, f, NULL);
    oct_writer_free(w);
    fclose(f);
    *out = (unsigned char *)mem;
    *out_len = len;
    return rc;
}

static void test_allocation_failures(void **state)
{
    (void)state;
    test_tree t;
    test_tree_random(&t, 7, 30000, 3, 21, 0);
    unsigned char *good;
    size_t good_len;
    assert_int_equal(feed_writer(&t, 0, &good, &good_len), OCT_OK);
    for (int sticky = 0; sticky <= 1; sticky++) {
        for (long n = 1;; n++) {
            unsigned char *out;
            size_t len;
            oct__alloc_fail_after(n, sticky);
            oct_err rc = feed_writer(&t, !sticky, &out, &len);
            oct__alloc_fail_after(0, 0);
            if (rc == OCT_OK) {
                assert_int_equal(len, good_len);
                assert_memory_equal(out, good, len);
                free(out);
                if (!sticky && n < 40)
                    continue; /* the failure may land after the last allocation */
                break;
            }
            free(out);
            assert_int_equal(rc, OCT_ENOMEM);
            assert_true(sticky);
            assert_true(n < 1000);
        }
    }
    /* The reader allocates its handle and, for a misaligned buffer, a copy. */
    unsigned char *raw = malloc(good_len + 1);
    memcpy(raw + 1, good, good_len);
    for (long n = 1; n <= 3; n++) {
        oct_file *f = (oct_file *)1;
        oct__alloc_fail_after(n, 0);
        oct_err rc = oct_open_memory(raw + 1, good_len, 0, &f, NULL);
        oct__alloc_fail_after(0, 0);
        assert_int_equal(rc, n < 3 ? OCT_ENOMEM : OCT_OK);
        oct_close(f);
    }
    free(raw);
    free(good);
    test_tree_free(&t);
}

static int count_tmp_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        n += strstr(e->d_name, ".tmp.") != NULL;
    closedir(d);
    return n;
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n + 1);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *len = (size_t)n;
    return b;
}

/* The caller's sequence (rasterize): atomic_file + oct_writer_finish +
 * commit; run in a child process, so that the fault hook's counters start at
 * zero. Exit status: 0 success, 1 clean failure. */
_Noreturn static void write_and_exit(const char *target, const test_tree *t, const char *fault)
{
    setenv("ATOMIC_FAULT", fault, 1);
    atomic_file *af = atomic_file_open(target);
    if (!af)
        _exit(1);
    oct_writer_params p = {.levels = t->levels, .edge = t->edge, .surface_count = t->surface_count,
                           .palette = t->palette};
    memcpy(p.origin, t->origin, sizeof p.origin);
    oct_writer *w;
    if (oct_writer_create(&p, &w) != OCT_OK)
        _exit(3);
    for (uint32_t d = 0; d < t->levels; d++)
        oct_writer_add_masks(w, d, t->masks[d], t->count[d]);
    oct_writer_add_voxels(w, t->voxels, t->surfaces, t->voxel_count);
    uint64_t n;
    oct_err rc = oct_writer_finish(w, atomic_file_stream(af), &n);
    oct_writer_free(w);
    if (rc != OCT_OK) {
        atomic_file_abort(af);
        _exit(1);
    }
    /* Route one write through the hook too, as a producer appending
     * through atomic_file_write would (zero bytes: the file is complete). */
    if (atomic_file_write(af, "", 0) != 0) {
        atomic_file_abort(af);
        _exit(1);
    }
    const char *op;
    _exit(atomic_file_commit(af, &op) == 0 ? 0 : 1);
}

static int write_in_child(const char *target, const test_tree *t, const char *fault)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        write_and_exit(target, t, fault);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    return WEXITSTATUS(status);
}

static void test_atomic_write_fault_loop(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_oct_af_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char target[600];
    snprintf(target, sizeof target, "%s/out.oct", dir);
    test_tree old, t;
    test_tree_random(&old, 3, 20, 1, 1, 0);
    test_tree_random(&t, 7, 3000, 2, 2, 1);
    assert_int_equal(write_in_child(target, &old, ""), 0);
    size_t old_len;
    unsigned char *old_bytes = slurp(target, &old_len);
    static const char *ops[] = {"write", "fsync", "close", "rename"};
    static const char *errs[] = {"ENOSPC", "EIO"};
    for (int o = 0; o < 4; o++) {
        for (int sticky = 0; sticky <= 1; sticky++) {
            for (int n = 1;; n++) {
                char spec[64];
                snprintf(spec, sizeof spec, "%s:%d:%s%s", ops[o], n, errs[n % 2], sticky ? ":sticky" : "");
                int rc = write_in_child(target, &t, spec);
                assert_true(rc == 0 || rc == 1);
                assert_int_equal(count_tmp_files(dir), 0);
                if (rc == 0) {
                    assert_true(n > 1); /* the first call of each op fails */
                    break;
                }
                size_t l;
                unsigned char *now = slurp(target, &l);
                assert_int_equal(l, old_len);
                assert_memory_equal(now, old_bytes, l);
                free(now);
                assert_true(n < 100);
            }
            /* Success replaced the target: put the old one back for the next op. */
            assert_int_equal(write_in_child(target, &old, ""), 0);
        }
    }
    oct_file *f;
    assert_int_equal(write_in_child(target, &t, ""), 0);
    assert_int_equal(oct_open(target, 0, &f, NULL), OCT_OK);
    compare(f, &t);
    oct_close(f);
    unlink(target);
    rmdir(dir);
    free(old_bytes);
    test_tree_free(&old);
    test_tree_free(&t);
}

/* SIGTERM at random moments of a large atomic write: the target is the old
 * file or the complete new one, and no temporary file is left. */
static void test_signal_during_write(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_oct_sig_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char target[600];
    snprintf(target, sizeof target, "%s/out.oct", dir);
    test_tree old, t;
    test_tree_random(&old, 3, 20, 1, 1, 0);
    test_tree_random(&t, 10, 400000, 2, 3, 0);
    unsigned char *nb;
    size_t nlen;
    assert_int_equal(test_tree_write(&t, &nb, &nlen), OCT_OK);
    assert_int_equal(write_in_child(target, &old, ""), 0);
    size_t old_len;
    unsigned char *old_bytes = slurp(target, &old_len);
    uint64_t rs = 99;
    int interrupted = 0;
    for (int run = 0; run < 10; run++) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0) {
            signal(SIGTERM, SIG_DFL);
            write_and_exit(target, &t, "");
        }
        usleep((useconds_t)(test_rand(&rs) % 30000));
        kill(pid, SIGTERM);
        int status;
        assert_int_equal(waitpid(pid, &status, 0), pid);
        assert_true(WIFSIGNALED(status) ? WTERMSIG(status) == SIGTERM : WEXITSTATUS(status) == 0);
        assert_int_equal(count_tmp_files(dir), 0);
        size_t l;
        unsigned char *now = slurp(target, &l);
        if (l == old_len) {
            assert_memory_equal(now, old_bytes, l);
            interrupted++;
        } else {
            assert_int_equal(l, nlen);
            assert_memory_equal(now, nb, l);
            free(old_bytes);
            old_bytes = now;
            old_len = l;
            now = NULL;
        }
        free(now);
    }
    print_message("signal during write: %d of 10 runs interrupted before the rename\n", interrupted);
    unlink(target);
    rmdir(dir);
    free(old_bytes);
    free(nb);
    test_tree_free(&old);
    test_tree_free(&t);
}

/* Validation throughput on a synthetic ~50 MB file, when OCT_BENCH is set. */
static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void test_validation_throughput(void **state)
{
    (void)state;
    if (!getenv("OCT_BENCH"))
        skip();
    test_tree t;
    test_tree_random(&t, 12, 8100000, 3, 1, 1);
    unsigned char *buf;
    size_t len;
    assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
    print_message("synthetic file: %.1f MB, %zu voxels, %.2f bytes/voxel\n", (double)len / 1e6,
                  t.voxel_count, (double)len / (double)t.voxel_count);
    for (int trust = 0; trust <= 1; trust++) {
        double best = 1e9;
        for (int r = 0; r < 20; r++) {
            oct_file *f;
            double a = seconds_now();
            assert_int_equal(oct_open_memory(buf, len, trust ? OCT_OPEN_TRUST : 0, &f, NULL), OCT_OK);
            double b = seconds_now() - a;
            oct_close(f);
            if (b < best)
                best = b;
        }
        print_message("validation %s: %.1f ms, %.0f MB/s\n", trust ? "without CRC" : "with CRC   ",
                      best * 1e3, (double)len / 1e6 / best);
    }
    free(buf);
    test_tree_free(&t);
}

/* Writes the fuzz seed corpus when OCT_CORPUS_DIR is set (see
 * tests/fuzz/README.md). */
static void test_make_fuzz_corpus(void **state)
{
    (void)state;
    const char *dir = getenv("OCT_CORPUS_DIR");
    if (!dir)
        skip();
    for (uint32_t levels = 1; levels <= 6; levels++) {
        for (int variant = 0; variant < 3; variant++) {
            test_tree t;
            size_t target = variant == 0 ? 1 : (size_t)(variant == 1 ? 12 : 60) * levels;
            test_tree_random(&t, levels, target, variant == 2 ? 3 : 1, levels * 10 + (uint64_t)variant,
                             variant != 1);
            unsigned char *buf;
            size_t len;
            assert_int_equal(test_tree_write(&t, &buf, &len), OCT_OK);
            for (int corrupt = 0; corrupt < (variant == 2 && levels % 2 ? 2 : 1); corrupt++) {
                char path[512];
                snprintf(path, sizeof path, "%s/%s-l%u-v%d.oct", dir, corrupt ? "bad" : "ok", levels, variant);
                if (corrupt) /* a bad base, CRCs fixed: reaches the tree check */
                    wr_u64le(buf + rd_u64le(buf + OCT_SEC_OFF(OCT_SEC_NODES)), 5), test_oct_refresh_crcs(buf, len);
                FILE *f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len, f), len);
                assert_int_equal(fclose(f), 0);
            }
            if (levels == 4 && variant == 2) { /* a truncated file and a bad checksum */
                char path[512];
                snprintf(path, sizeof path, "%s/bad-trunc-l4.oct", dir);
                FILE *f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len / 2, f), len / 2);
                assert_int_equal(fclose(f), 0);
                buf[len - 1] ^= 0x10; /* a palette bit */
                snprintf(path, sizeof path, "%s/bad-crc-l4.oct", dir);
                f = fopen(path, "wb");
                assert_non_null(f);
                assert_int_equal(fwrite(buf, 1, len, f), len);
                assert_int_equal(fclose(f), 0);
            }
            free(buf);
            test_tree_free(&t);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_random_trees),
        cmocka_unit_test(test_round_trip_through_file),
        cmocka_unit_test(test_empty_trees),
        cmocka_unit_test(test_deepest_tree),
        cmocka_unit_test(test_subtree_at_depth_40),
        cmocka_unit_test(test_mapped_file_replaced_or_truncated),
        cmocka_unit_test(test_spec_example),
        cmocka_unit_test(test_writer_is_deterministic),
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
        cmocka_unit_test(test_normal_codec_error),
        cmocka_unit_test(test_offset_codec),
        cmocka_unit_test(test_writer_usage_errors),
        cmocka_unit_test(test_writer_write_failures),
        cmocka_unit_test(test_allocation_failures),
        cmocka_unit_test(test_atomic_write_fault_loop),
        cmocka_unit_test(test_signal_during_write),
        cmocka_unit_test(test_validation_throughput),
        cmocka_unit_test(test_make_fuzz_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
