/* oct_check: assertions shared by the .oct test suites (cmocka). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "format/oct.h"
#include "tests/oct_check.h"

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

void oct_check_tree(const oct_file *f, const test_tree *t)
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
void oct_check_small_file(unsigned char **buf, size_t *len, test_tree *t)
{
    test_tree_random(t, 3, 40, 2, 7, 1);
    assert_int_equal(test_tree_write(t, buf, len), OCT_OK);
}

oct_err oct_check_open(const unsigned char *buf, size_t len, unsigned flags, uint64_t *at)
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
