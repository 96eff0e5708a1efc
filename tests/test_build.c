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
#include "tests/scene_util.h"

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

static void build_with(const scene *sc, const build_params *bp, built *b)
{
    memset(b, 0, sizeof *b);
    float palette[3 * OCT_MAX_SURFACES];
    oct_writer_params wp;
    build_writer_params(sc, bp->levels, palette, &wp);
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    assert_int_equal(build_octree(sc, bp, w, &b->st), OCT_OK);
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

static void build_in_memory(const scene *sc, unsigned levels, build_method method, unsigned threads,
                            built *b)
{
    build_params bp = {.levels = levels, .method = method, .threads = threads};
    build_with(sc, &bp, b);
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

/* Every voxel of the window [lo, lo + w)^3 (in voxels) whose (k+1)^3
 * sample lattice (corners included) holds a sign change of any surface, or
 * an exact zero, must be in the tree. Samples outside the scene's bounds do
 * not count: the surface lives in them. */
static void check_window_no_voxel_lost(const char *path, unsigned levels, unsigned k,
                                       build_method method, const unsigned lo[3], unsigned w)
{
    scene *sc = test_scene_load(path);
    built b;
    build_in_memory(sc, levels, method, 2, &b);
    double origin[3], edge;
    build_cube(sc, origin, &edge);
    unsigned n = 1u << levels, r = w * k + 1;
    assert_true(lo[0] + w <= n && lo[1] + w <= n && lo[2] + w <= n);
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
                    const unsigned q[3] = {lo[0] * k + x, lo[1] * k + y, lo[2] * k + z};
                    double p[3];
                    for (int a = 0; a < 3; a++)
                        p[a] = origin[a] + edge * q[a] / ((double)n * k);
                    signed char sg = 2; /* 2: does not count */
                    if (p[0] <= sc->hi[0] && p[1] <= sc->hi[1] && p[2] <= sc->hi[2]) {
                        double f = tape_eval(t, p[0], p[1], p[2], slots);
                        sg = isnan(f) ? 2 : f > 0 ? 1 : f < 0 ? -1 : 0;
                    }
                    sign[((size_t)z * r + y) * r + x] = sg;
                }
        for (unsigned vz = 0; vz < w; vz++)
            for (unsigned vy = 0; vy < w; vy++)
                for (unsigned vx = 0; vx < w; vx++) {
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
                        if (find_voxel(b.tree, lo[0] + vx, lo[1] + vy, lo[2] + vz) < 0)
                            fail_msg("%s: levels %u: voxel %u,%u,%u of surface %zu lost", path,
                                     levels, lo[0] + vx, lo[1] + vy, lo[2] + vz, s);
                    }
                }
    }
    /* The shell stays thin: the kept voxels are not many more than the ideal. */
    print_message("%s: levels %u: %llu voxels kept, %llu required by sign changes in a window "
                  "of %u^3\n", path, levels, (unsigned long long)b.st.voxels,
                  (unsigned long long)must, w);
    assert_true(must > 0); /* (a window the surface crosses) */
    free(sign);
    free(slots);
    built_free(&b);
    scene_free(sc);
}

/* The same over the whole grid. */
static void check_no_voxel_lost(const char *path, unsigned levels, unsigned k, build_method method)
{
    static const unsigned origin[3] = {0, 0, 0};
    check_window_no_voxel_lost(path, levels, k, method, origin, 1u << levels);
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

/* From levels 8 on the leaf-parents' candidates take the form centred on
 * each voxel (MEAN_VALUE_ALONE_DEPTH): f at the centre from the a-priori
 * rounding bound (blobs_a: no kink, nothing frozen), from the interval
 * evaluation at the centre (manyblobs: far blobs frozen into constants;
 * csg: kinks). A window of 48^3 voxels about a point of the surface at
 * levels 8 (centre: in voxels), sampled 3 times finer. */
static void test_retested_levels_lose_nothing(void **state)
{
    (void)state;
    static const struct { const char *path; unsigned centre[3]; } cases[] = {
        {"scenes/blobs_a.scene", {143, 200, 200}},
        {"scenes/manyblobs.scene", {68, 74, 151}},
        {"scenes/csg.scene", {221, 180, 163}},
    };
    const unsigned w = SANITIZED ? 32 : 48;
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        const unsigned lo[3] = {cases[c].centre[0] - w / 2, cases[c].centre[1] - w / 2,
                                cases[c].centre[2] - w / 2};
        check_window_no_voxel_lost(cases[c].path, 8, SANITIZED ? 2 : 3, BUILD_INTERVAL, lo, w);
    }
}

static void test_output_independent_of_threads(void **state)
{
    (void)state;
    /* blobs_b below and at the levels where leaf-parents make their records
     * together (second-order model), csg where the kinked tapes face the
     * plain test at the voxels too */
    static const struct { const char *path; unsigned levels, san_levels; } cases[] = {
        {"scenes/blobs_b.scene", 7, 5}, {"scenes/blobs_b.scene", 8, 8}, {"scenes/csg.scene", 8, 8}};
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        scene *sc = test_scene_load(cases[k].path);
        built one, two;
        unsigned levels = SANITIZED ? cases[k].san_levels : cases[k].levels;
        build_in_memory(sc, levels, BUILD_INTERVAL, 1, &one);
        build_in_memory(sc, levels, BUILD_INTERVAL, 3, &two);
        assert_int_equal(one.size, two.size);
        assert_memory_equal(one.bytes, two.bytes, one.size);
        built_free(&one);
        built_free(&two);
        scene_free(sc);
    }
}

/* shell_only makes the same voxels (tree and surfaces) as a full build,
 * every record 0: at levels where the leaf-parents' records are made
 * together (8) and below (6), on one surface and on several. */
static void test_shell_only_same_voxels(void **state)
{
    (void)state;
    static const char *paths[] = {"scenes/blobs_b.scene", "scenes/multi.scene", "scenes/csg.scene"};
    for (size_t k = 0; k < sizeof paths / sizeof *paths; k++)
        for (unsigned levels = 6; levels <= (SANITIZED ? 6u : 8u); levels += 2) {
            scene *sc = test_scene_load(paths[k]);
            build_params full = {.levels = levels, .method = BUILD_INTERVAL, .threads = 2};
            build_params shell = full;
            shell.shell_only = 1;
            built a, b;
            build_with(sc, &full, &a);
            build_with(sc, &shell, &b);
            const oct_tree *ta = a.tree, *tb = b.tree;
            assert_int_equal(ta->voxel_count, tb->voxel_count);
            assert_true(ta->voxel_count > 0);
            for (unsigned d = 0; d < levels; d++) {
                assert_int_equal(ta->node_count[d], tb->node_count[d]);
                assert_memory_equal(ta->groups[d], tb->groups[d],
                                    (size_t)(ta->node_count[d] + 7) / 8 * sizeof *ta->groups[d]);
            }
            if (ta->surfaces)
                assert_memory_equal(ta->surfaces, tb->surfaces, (size_t)ta->voxel_count);
            for (uint64_t v = 0; v < tb->voxel_count; v++)
                assert_int_equal(tb->voxels[v], 0);
            assert_true(b.st.point_evals < a.st.point_evals);
            built_free(&a);
            built_free(&b);
            scene_free(sc);
        }
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

/* The exact record of the voxel with centre c: Newton's projection of c onto
 * f = 0 on the whole function, iterated to convergence, gives the foot
 * point; the normal is the normalised gradient there, the offset the
 * distance from c to it along the normal, in voxel edges. 0 when the
 * projection does not settle within half a voxel diagonal of c. */
static int exact_record(const tape *t, tape_dual *slots, const double c[3], double h, double n[3],
                        double *offset)
{
    double p[3] = {c[0], c[1], c[2]}, g[3];
    for (int it = 0; it < 30; it++) {
        double f = tape_eval_grad(t, p, g, slots), g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0.0) || !isfinite(f))
            return 0;
        double step = 0.0;
        for (int k = 0; k < 3; k++) {
            p[k] -= f / g2 * g[k];
            step += fabs(f / g2 * g[k]);
        }
        if (step < 1e-9 * h)
            break;
    }
    tape_eval_grad(t, p, g, slots);
    double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), dist = 0.0;
    *offset = 0.0;
    for (int k = 0; k < 3; k++) {
        n[k] = g[k] / len;
        *offset += n[k] * (p[k] - c[k]) / h;
        dist += (p[k] - c[k]) * (p[k] - c[k]);
    }
    return sqrt(dist) <= 0.8660254037844386 * h;
}

/* Per-cell pruning may freeze a far blob's term into a constant while
 * subdividing, which keeps f's value within a thousandth of a voxel's
 * spread but drops that term's gradient (normals off by up to 3.5 degrees,
 * offsets by 0.18 voxel): the records must come from the whole function.
 * blobs_b at levels 8, where the leaf-parents' records come from the
 * second-order model, every voxel (every 7th under the sanitizers) against
 * the exact record. */
static void test_normals_from_whole_function(void **state)
{
    (void)state;
    scene *sc = test_scene_load("scenes/blobs_b.scene");
    const unsigned levels = 8;
    built b;
    build_in_memory(sc, levels, BUILD_INTERVAL, 2, &b);
    const oct_tree *t = b.tree;
    const tape *tp = &sc->surfaces[0].tape;
    tape_dual *slots = malloc(tp->n * sizeof *slots);
    assert_non_null(slots);
    const double h = t->edge / (double)(UINT64_C(1) << levels);
    const uint64_t n = UINT64_C(1) << levels;
    double worst_angle = 0.0, worst_offset = 0.0, sum_angle = 0.0;
    uint64_t seen = 0, near = 0;
    for (uint64_t z = 0; z < n; z++)
        for (uint64_t y = 0; y < n; y++)
            for (uint64_t x = 0; x < n; x++) {
                const int64_t vi = find_voxel(t, x, y, z);
                if (vi < 0 || seen++ % (SANITIZED ? 7 : 1))
                    continue;
                const double c[3] = {t->origin[0] + ((double)x + 0.5) * h,
                                     t->origin[1] + ((double)y + 0.5) * h,
                                     t->origin[2] + ((double)z + 0.5) * h};
                double nr[3], dr;
                if (!exact_record(tp, slots, c, h, nr, &dr))
                    continue; /* the surface misses the voxel: no exact record */
                near++;
                const uint32_t rec = t->voxels[vi];
                float nf[3];
                oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
                const double dot = nf[0] * nr[0] + nf[1] * nr[1] + nf[2] * nr[2];
                const double angle = acos(fmin(1.0, dot)) * 180.0 / M_PI;
                sum_angle += angle;
                worst_angle = fmax(worst_angle, angle);
                const double d = oct_offset_decode((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
                worst_offset = fmax(worst_offset, fabs(d - dr));
            }
    assert_true(near > 0);
    print_message("blobs_b levels %u: %llu voxels near the surface: normal %.4f mean, %.4f worst deg, "
                  "worst offset %.4f voxel\n", levels, (unsigned long long)near, sum_angle / (double)near,
                  worst_angle, worst_offset);
    assert_true(sum_angle / (double)near < 0.1); /* measured 0.051 */
    assert_true(worst_angle < 1.5);               /* measured 0.99 where curvature is high */
    assert_true(worst_offset < 0.012);            /* half a 1/128 step plus curvature: 0.0082 */
    free(slots);
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
        cmocka_unit_test(test_retested_levels_lose_nothing),
        cmocka_unit_test(test_output_independent_of_threads),
        cmocka_unit_test(test_shell_only_same_voxels),
        cmocka_unit_test(test_sphere_normals_and_offsets),
        cmocka_unit_test(test_normals_from_whole_function),
        cmocka_unit_test(test_undefined_half_space_is_empty),
        cmocka_unit_test(test_surface_outside_bounds_gives_empty_tree),
    };
    return cmocka_run_group_tests_name("build", tests, NULL, NULL);
}
