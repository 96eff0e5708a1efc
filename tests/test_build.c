/* Tests for rasterize/build: nothing of the surface is lost (a dense
 * sign-change reference on every scene), the output does not depend on the
 * thread count, and normals and plane offsets match a sphere's closed form. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "format/oct.h"
#include "format/oct_normal.h"
#include "rasterize/build.h"

#if defined(__SANITIZE_ADDRESS__)
#define SANITIZED 1
#else
#define SANITIZED 0
#endif

/* An octree built in memory and mapped back through the reader. */
typedef struct built {
    char *bytes;
    size_t size;
    oct_file *file;
    const oct_tree *tree;
    build_stats st;
} built;

static void build_in_memory(const scene *sc, unsigned levels, build_method method, unsigned threads,
                            built *b)
{
    memset(b, 0, sizeof *b);
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, levels, palette, &wp);
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    build_params bp = {.levels = levels, .method = method, .threads = threads};
    assert_int_equal(build_octree(sc, &bp, w, &b->st), OCT_OK);
    FILE *mem = open_memstream(&b->bytes, &b->size);
    assert_non_null(mem);
    uint64_t n = 0;
    assert_int_equal(oct_writer_finish(w, mem, &n), OCT_OK);
    assert_int_equal(fclose(mem), 0);
    assert_int_equal(n, b->size);
    oct_writer_free(w);
    uint64_t off = 0;
    assert_int_equal(oct_open_memory(b->bytes, b->size, 0, &b->file, &off), OCT_OK);
    b->tree = oct_get_tree(b->file);
    assert_int_equal(b->tree->voxel_count, b->st.voxels);
}

static void built_free(built *b)
{
    oct_close(b->file);
    free(b->bytes);
}

/* Index of voxel (x, y, z) in the voxel array, or -1 when absent. */
static int64_t find_voxel(const oct_tree *t, uint64_t x, uint64_t y, uint64_t z)
{
    if (t->node_count[0] == 0)
        return -1;
    uint64_t node = 0;
    for (unsigned d = 0; d < t->levels; d++) {
        unsigned bit = t->levels - 1 - d;
        unsigned i = (unsigned)(((x >> bit) & 1) | (((y >> bit) & 1) << 1) | (((z >> bit) & 1) << 2));
        if (!(oct_node_mask(t->groups[d], node) & (1u << i)))
            return -1;
        node = oct_child_index(t->groups[d], node, i);
    }
    return (int64_t)node;
}

static scene *load(const char *path)
{
    scene *sc = NULL;
    scene_error err;
    if (scene_load(path, &sc, &err) != 0)
        fail_msg("%s:%u:%u: %s", path, err.line, err.col, err.message);
    return sc;
}

/* Every voxel whose (k+1)^3 sample lattice (corners included) holds a sign
 * change of any surface, or an exact zero, must be in the tree. Samples
 * outside the scene's bounds do not count: the surface lives in them. */
static void check_no_voxel_lost(const char *path, unsigned levels, unsigned k, build_method method)
{
    scene *sc = load(path);
    built b;
    build_in_memory(sc, levels, method, 2, &b);
    double origin[3], edge;
    build_cube(sc, origin, &edge);
    unsigned n = 1u << levels, r = n * k + 1;
    double *slots = malloc(sizeof(double) * 65536);
    signed char *sign = malloc((size_t)r * r * r);
    assert_non_null(slots);
    assert_non_null(sign);
    uint64_t must = 0;
    for (size_t s = 0; s < sc->nsurfaces; s++) {
        const tape *t = &sc->surfaces[s].tape;
        assert_true(t->n <= 65536);
        for (unsigned z = 0; z < r; z++)
            for (unsigned y = 0; y < r; y++)
                for (unsigned x = 0; x < r; x++) {
                    double p[3] = {origin[0] + edge * x / (r - 1), origin[1] + edge * y / (r - 1),
                                   origin[2] + edge * z / (r - 1)};
                    signed char sg = 2; /* 2: does not count */
                    if (p[0] <= sc->hi[0] && p[1] <= sc->hi[1] && p[2] <= sc->hi[2]) {
                        double f = tape_eval(t, p[0], p[1], p[2], slots);
                        sg = isnan(f) ? 2 : f > 0 ? 1 : f < 0 ? -1 : 0;
                    }
                    sign[((size_t)z * r + y) * r + x] = sg;
                }
        for (unsigned vz = 0; vz < n; vz++)
            for (unsigned vy = 0; vy < n; vy++)
                for (unsigned vx = 0; vx < n; vx++) {
                    int pos = 0, neg = 0, zero = 0;
                    for (unsigned dz = 0; dz <= k; dz++)
                        for (unsigned dy = 0; dy <= k; dy++)
                            for (unsigned dx = 0; dx <= k; dx++) {
                                size_t i = ((size_t)(vz * k + dz) * r + vy * k + dy) * r + vx * k + dx;
                                pos |= sign[i] == 1;
                                neg |= sign[i] == -1;
                                zero |= sign[i] == 0;
                            }
                    if ((pos && neg) || zero) {
                        must++;
                        if (find_voxel(b.tree, vx, vy, vz) < 0)
                            fail_msg("%s: levels %u: voxel %u,%u,%u of surface %zu lost", path,
                                     levels, vx, vy, vz, s);
                    }
                }
    }
    /* The shell stays thin: the kept voxels are not many more than the ideal. */
    print_message("%s: levels %u: %llu voxels kept, %llu required by sign changes\n", path, levels,
                  (unsigned long long)b.st.voxels, (unsigned long long)must);
    free(sign);
    free(slots);
    built_free(&b);
    scene_free(sc);
}

static void for_each_scene(void (*fn)(const char *path))
{
    DIR *d = opendir("scenes");
    assert_non_null(d);
    struct dirent *e;
    int count = 0;
    while ((e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 7 || strcmp(e->d_name + len - 6, ".scene") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "scenes/%s", e->d_name);
        fn(path);
        count++;
    }
    closedir(d);
    assert_true(count >= 2);
}

static void lossless_interval(const char *path)
{
    check_no_voxel_lost(path, SANITIZED ? 4 : 6, 2, BUILD_INTERVAL);
    check_no_voxel_lost(path, SANITIZED ? 3 : 5, 4, BUILD_INTERVAL);
}

static void lossless_lipschitz(const char *path)
{
    check_no_voxel_lost(path, SANITIZED ? 4 : 5, 2, BUILD_LIPSCHITZ);
}

static void test_interval_method_loses_nothing(void **state)
{
    (void)state;
    for_each_scene(lossless_interval);
}

static void test_lipschitz_method_loses_nothing(void **state)
{
    (void)state;
    for_each_scene(lossless_lipschitz);
}

static void test_output_independent_of_threads(void **state)
{
    (void)state;
    scene *sc = load("scenes/blobs_b.scene");
    built one, two;
    unsigned levels = SANITIZED ? 5 : 7;
    build_in_memory(sc, levels, BUILD_INTERVAL, 1, &one);
    build_in_memory(sc, levels, BUILD_INTERVAL, 3, &two);
    assert_int_equal(one.size, two.size);
    assert_memory_equal(one.bytes, two.bytes, one.size);
    built_free(&one);
    built_free(&two);
    scene_free(sc);
}

/* Sphere of radius R about C: normals radial, plane offsets the distance from
 * the voxel centre to the sphere along the normal. */
static void test_sphere_normals_and_offsets(void **state)
{
    (void)state;
    static const char text[] = "bounds -1 -1 -1 1 1 1\nsurface sqrt((x-0.1)^2 + (y+0.05)^2 + z^2) - 0.7\n";
    scene *sc = NULL;
    scene_error err;
    assert_int_equal(scene_parse(text, sizeof text - 1, &sc, &err), 0);
    unsigned levels = 7, n = 1u << levels;
    built b;
    build_in_memory(sc, levels, BUILD_INTERVAL, 2, &b);
    const double C[3] = {0.1, -0.05, 0.0}, R = 0.7, h = 2.0 / n;
    double worst_angle = 0.0, worst_offset = 0.0;
    uint64_t seen = 0, outside = 0;
    for (uint64_t z = 0; z < n; z++)
        for (uint64_t y = 0; y < n; y++)
            for (uint64_t x = 0; x < n; x++) {
                int64_t v = find_voxel(b.tree, x, y, z);
                if (v < 0)
                    continue;
                seen++;
                double c[3] = {-1 + (x + 0.5) * h, -1 + (y + 0.5) * h, -1 + (z + 0.5) * h};
                double rad[3] = {c[0] - C[0], c[1] - C[1], c[2] - C[2]};
                double len = sqrt(rad[0] * rad[0] + rad[1] * rad[1] + rad[2] * rad[2]);
                float nf[3];
                uint32_t rec = b.tree->voxels[v];
                oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
                double dot = (nf[0] * rad[0] + nf[1] * rad[1] + nf[2] * rad[2]) / len;
                worst_angle = fmax(worst_angle, acos(fmin(1.0, fabs(dot))) * 180.0 / M_PI);
                /* The gradient points outward, so the normal is radial: the
                 * sphere is (R - |c - C|) / h voxels from the centre along it. */
                double d = oct_offset_decode((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
                double exact = (R - len) / h;
                /* A voxel the enclosures could not drop but the sphere
                 * misses stores the nearest plane that still cuts it. */
                if (fabs(exact) > 0.8660254037844386) {
                    outside++;
                    exact = copysign(0.8660254037844386, exact);
                }
                worst_offset = fmax(worst_offset, fabs(d - exact));
            }
    assert_true(seen > 0);
    print_message("sphere: %llu voxels (%llu the sphere misses), worst normal %.4f deg, "
                  "worst offset %.4f voxel\n",
                  (unsigned long long)seen, (unsigned long long)outside, worst_angle, worst_offset);
    assert_true(outside * 100 < seen); /* the shell stays thin: under 1% extra */
    assert_true(worst_angle < 0.5);   /* 12+12-bit code plus the Newton point */
    assert_true(worst_offset < 0.02); /* 1/256 quantisation plus curvature */
    assert_int_equal(b.st.normal_fallbacks, 0);
    built_free(&b);
    scene_free(sc);
}

/* Voxel (x, y, z) of levels L in the cube: its Newton point from the centre
 * on the scene's whole function, as documented (guarded steps, clamped to
 * the voxel, stop below a quarter voxel), then the normal and the offset of
 * the linearised surface along it, in voxel edges. */
static void reference_record(const tape *t, const double origin[3], double h, const uint64_t v[3],
                             double n[3], double *offset)
{
    tape_dual *slots = malloc(t->n * sizeof *slots);
    assert_non_null(slots);
    double c[3], p[3], lo[3], hi[3], g[3], f = 0.0;
    for (int k = 0; k < 3; k++) {
        lo[k] = origin[k] + (double)v[k] * h;
        hi[k] = lo[k] + h;
        c[k] = p[k] = lo[k] + 0.5 * h;
    }
    for (int step = 0; step <= 4; step++) {
        f = tape_eval_grad(t, p, g, slots);
        const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (step == 4 || f == 0.0)
            break;
        double q[3], moved = 0.0;
        for (int k = 0; k < 3; k++) {
            q[k] = fmin(fmax(p[k] - f / g2 * g[k], lo[k]), hi[k]);
            moved = fmax(moved, fabs(q[k] - p[k]));
        }
        if (moved < 0.25 * h)
            break;
        memcpy(p, q, sizeof p);
    }
    const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2], len = sqrt(g2);
    *offset = 0.0;
    for (int k = 0; k < 3; k++) {
        n[k] = g[k] / len;
        *offset += n[k] * (p[k] - f / g2 * g[k] - c[k]) / h;
    }
    *offset = fmin(fmax(*offset, -0.8660254037844386), 0.8660254037844386);
    free(slots);
}

/* Per-cell pruning may freeze a far blob's term into a constant while
 * subdividing, which keeps f's value within a thousandth of a voxel's
 * spread but drops that term's gradient: the normals and offsets must come
 * from the whole function. blobs_b, every voxel against the reference. */
static void test_normals_from_whole_function(void **state)
{
    (void)state;
    scene *sc = load("scenes/blobs_b.scene");
    const unsigned levels = SANITIZED ? 6 : 8;
    built b;
    build_in_memory(sc, levels, BUILD_INTERVAL, 2, &b);
    const oct_tree *t = b.tree;
    const double h = t->edge / (double)(UINT64_C(1) << levels);
    const uint64_t n = UINT64_C(1) << levels;
    double worst_angle = 0.0, worst_offset = 0.0;
    for (uint64_t z = 0; z < n; z++)
        for (uint64_t y = 0; y < n; y++)
            for (uint64_t x = 0; x < n; x++) {
                const int64_t vi = find_voxel(t, x, y, z);
                if (vi < 0)
                    continue;
                const uint64_t v[3] = {x, y, z};
                double nr[3], dr;
                reference_record(&sc->surfaces[0].tape, t->origin, h, v, nr, &dr);
                const uint32_t rec = t->voxels[vi];
                float nf[3];
                oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
                const double dot = nf[0] * nr[0] + nf[1] * nr[1] + nf[2] * nr[2];
                worst_angle = fmax(worst_angle, acos(fmin(1.0, dot)) * 180.0 / M_PI);
                const double d = oct_offset_decode((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
                worst_offset = fmax(worst_offset, fabs(d - dr));
            }
    print_message("blobs_b levels %u: worst normal %.4f deg, worst offset %.4f voxel\n", levels,
                  worst_angle, worst_offset);
    assert_true(worst_angle < 0.1);            /* the 24-bit code: 0.06 deg */
    assert_true(worst_offset < 1.0 / 256 + 1e-9); /* half a 1/128 step */
    built_free(&b);
    scene_free(sc);
}

/* f = sqrt(x) - 0.5 is undefined on half the box: those cells hold no surface
 * point and must not fill the volume, while the plane x = 0.25 is kept. */
static void test_undefined_half_space_is_empty(void **state)
{
    (void)state;
    static const char text[] = "bounds -1 -1 -1 1 1 1\nsurface sqrt(x) - 0.5\n";
    scene *sc = NULL;
    scene_error err;
    assert_int_equal(scene_parse(text, sizeof text - 1, &sc, &err), 0);
    unsigned levels = 6, n = 1u << levels;
    built b;
    build_in_memory(sc, levels, BUILD_INTERVAL, 2, &b);
    /* x = 0.25 lies inside voxel column 40 of 64 (cells are 1/32 wide). */
    for (uint64_t z = 0; z < n; z++)
        for (uint64_t y = 0; y < n; y++)
            assert_true(find_voxel(b.tree, 40, y, z) >= 0);
    assert_true(b.st.voxels <= 2 * (uint64_t)n * n);
    built_free(&b);
    scene_free(sc);
}

/* A surface entirely outside its bounds gives a valid, empty tree. */
static void test_surface_outside_bounds_gives_empty_tree(void **state)
{
    (void)state;
    static const char text[] = "bounds 0 0 0 1 1 1\nsurface (x-5)^2 + y^2 + z^2 - 1\n";
    scene *sc = NULL;
    scene_error err;
    assert_int_equal(scene_parse(text, sizeof text - 1, &sc, &err), 0);
    built b;
    build_in_memory(sc, 6, BUILD_INTERVAL, 2, &b);
    assert_int_equal(b.tree->voxel_count, 0);
    assert_int_equal(b.tree->node_count[0], 0);
    built_free(&b);
    scene_free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interval_method_loses_nothing),
        cmocka_unit_test(test_lipschitz_method_loses_nothing),
        cmocka_unit_test(test_output_independent_of_threads),
        cmocka_unit_test(test_sphere_normals_and_offsets),
        cmocka_unit_test(test_normals_from_whole_function),
        cmocka_unit_test(test_undefined_half_space_is_empty),
        cmocka_unit_test(test_surface_outside_bounds_gives_empty_tree),
    };
    return cmocka_run_group_tests_name("build", tests, NULL, NULL);
}
