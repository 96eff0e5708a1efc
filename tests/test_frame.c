/* Tests for render/frame: identical bytes whatever the thread count and
 * whether rays are traced whole or in their beam's window; depth is finite or
 * +inf, never NaN, for degenerate cameras, under FE_INVALID traps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fenv.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/view/image.h"
#include "format/oct_normal.h"
#include "render/frame.h"
#include "bench/rng.h"
#include "bench/tree_util.h"

static oct_tree *ball(unsigned levels)
{
    const uint32_t n = UINT32_C(1) << levels;
    uint32_t(*xyz)[3] = malloc((size_t)n * n * n * sizeof *xyz);
    uint32_t *attr = malloc((size_t)n * n * n * sizeof *attr);
    assert_non_null(xyz);
    assert_non_null(attr);
    size_t cnt = 0;
    double c = 0.5 * n, r = 0.35 * n;
    for (uint32_t z = 0; z < n; z++)
        for (uint32_t y = 0; y < n; y++)
            for (uint32_t x = 0; x < n; x++) {
                double p[3] = {x + 0.5 - c, y + 0.5 - c, z + 0.5 - c};
                double d = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                if (fabs(d - r) < 0.9) {
                    xyz[cnt][0] = x;
                    xyz[cnt][1] = y;
                    xyz[cnt][2] = z;
                    attr[cnt++] = oct_voxel_pack(p, 0.1);
                }
            }
    const double origin[3] = {-1, -1, -1};
    oct_tree *t = tree_util_build(levels, origin, 2.0, (const uint32_t(*)[3])xyz, cnt, attr, NULL,
                                  1, NULL);
    free(xyz);
    free(attr);
    assert_non_null(t);
    return t;
}

static void render_beam(const oct_tree *t, const camera *cam, unsigned threads, int refine,
                        unsigned beam, uint8_t *rgb, float *depth, uint8_t *nrm,
                        frame_stats *st)
{
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = t;
    job.cam = cam;
    job.opts.split = t->levels - 2;
    job.opts.refine = refine;
    job.shade.ambient = 0.2f;
    shade_default_light(cam, job.shade.light);
    job.rgb = rgb;
    job.depth = depth;
    job.normals = nrm;
    job.threads = threads;
    job.beam_size = beam;
    assert_int_equal(frame_render(&job, st), 0);
}

static void render(const oct_tree *t, const camera *cam, unsigned threads, int refine,
                   uint8_t *rgb, float *depth, uint8_t *nrm, frame_stats *st)
{
    render_beam(t, cam, threads, refine, FRAME_BEAM_DEFAULT, rgb, depth, nrm, st);
}

/* A few voxels scattered at random: small targets the beams must not lose. */
static oct_tree *scattered(unsigned levels, size_t n, uint64_t seed)
{
    uint32_t(*xyz)[3] = malloc(n * sizeof *xyz);
    uint32_t *attr = malloc(n * sizeof *attr);
    assert_non_null(xyz);
    assert_non_null(attr);
    const uint32_t lim = UINT32_C(1) << levels;
    for (size_t i = 0; i < n; i++) {
        for (int a = 0; a < 3; a++) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            xyz[i][a] = (uint32_t)(seed >> 33) % lim;
        }
        const double nrm[3] = {(double)(i % 3) - 1.0, 1.0, 0.5};
        attr[i] = oct_voxel_pack(nrm, 0.25);
    }
    const double origin[3] = {-1, -1, -1};
    oct_tree *t = tree_util_build(levels, origin, 2.0, (const uint32_t(*)[3])xyz, n, attr, NULL,
                                  1, NULL);
    free(xyz);
    free(attr);
    assert_non_null(t);
    return t;
}

/* The beam only skips what no ray can hit: with any block size the image,
 * depth and normals are those of rays traced whole, byte for byte. Eyes
 * outside, on a face, inside the cube and inside the surface; wide, narrow
 * and odd-sized views; tiny isolated targets. */
static void test_beam_same_image(void **state)
{
    (void)state;
    oct_tree *trees[] = {ball(6), scattered(7, 40, 1), scattered(9, 300, 2)};
    static const double eyes[][3] = {
        {2.2, 1.6, 1.9}, {-3, 0.1, 0.2}, {0.1, -1, 0.3}, {0.2, 0.1, -0.3}, {0.7, 0, 0}, {0, 0, 9},
    };
    static const double fovs[] = {40, 120, 5, 60, 90, 25};
    static const unsigned beams[] = {1, 3, 16, 32};
    const uint32_t w = 67, h = 45;
    const size_t px = (size_t)w * h;
    uint8_t *a = malloc(px * 3), *b = malloc(px * 3), *na = malloc(px * 3), *nb = malloc(px * 3);
    float *da = malloc(px * 4), *db = malloc(px * 4);
    uint64_t hits = 0;
    for (size_t ti = 0; ti < sizeof trees / sizeof trees[0]; ti++)
        for (size_t k = 0; k < sizeof eyes / sizeof eyes[0]; k++) {
            camera cam;
            const double target[3] = {0.05, -0.1, 0.02}, up[3] = {0, 0, 1};
            assert_int_equal(camera_init(&cam, eyes[k], target, up, fovs[k], w, h), CAMERA_OK);
            for (int refine = 0; refine <= 1; refine++) {
                frame_stats sa, sb;
                render_beam(trees[ti], &cam, 2, refine, 0, a, da, na, &sa);
                hits += sa.hits;
                for (size_t bi = 0; bi < sizeof beams / sizeof beams[0]; bi++) {
                    render_beam(trees[ti], &cam, 2, refine, beams[bi], b, db, nb, &sb);
                    assert_memory_equal(a, b, px * 3);
                    assert_memory_equal(na, nb, px * 3);
                    assert_memory_equal(da, db, px * 4);
                    assert_int_equal(sa.hits, sb.hits);
                    assert_true(sb.steps <= sa.steps);
                }
            }
        }
    assert_true(hits > 0);
    free(a), free(b), free(na), free(nb), free(da), free(db);
    for (size_t ti = 0; ti < sizeof trees / sizeof trees[0]; ti++)
        tree_util_free(trees[ti]);
}

static void test_threads_identical(void **state)
{
    (void)state;
    oct_tree *t = ball(6);
    camera cam;
    const double eye[3] = {2.2, 1.6, 1.9}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    assert_int_equal(camera_init(&cam, eye, target, up, 40, 97, 61), CAMERA_OK);
    size_t px = 97 * 61;
    for (int refine = 0; refine <= 1; refine++) {
        uint8_t *a = malloc(px * 3), *b = malloc(px * 3), *na = malloc(px * 3), *nb = malloc(px * 3);
        float *da = malloc(px * 4), *db = malloc(px * 4);
        frame_stats sa, sb;
        render(t, &cam, 1, refine, a, da, na, &sa);
        assert_true(sa.hits > px / 10);
        /* 8 tiles in bands of 2 or 3, and more threads than tiles: every
           tile once (the hit count too) */
        for (unsigned threads = 3; threads <= 9; threads += 6) {
            render(t, &cam, threads, refine, b, db, nb, &sb);
            assert_memory_equal(a, b, px * 3);
            assert_memory_equal(na, nb, px * 3);
            assert_memory_equal(da, db, px * 4);
            assert_int_equal(sa.hits, sb.hits);
        }
        free(a), free(b), free(na), free(nb), free(da), free(db);
    }
    tree_util_free(t);
}

static void test_degenerate_cameras_no_nan(void **state)
{
    (void)state;
    oct_tree *t = ball(5);
    static const double eyes[][3] = {
        {-5, 0, 0},     /* axis-aligned, odd size: centre ray (1,0,0) exactly */
        {-1, -1, -1},   /* on the root corner */
        {-1, 0.25, 0},  /* on a root face */
        {0.7, 0, 0},    /* inside the cube, inside the ball */
        {1e30, 1e30, 1e30},
    };
    const double target[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    feenableexcept(FE_INVALID);
    for (size_t k = 0; k < sizeof eyes / sizeof eyes[0]; k++) {
        camera cam;
        double fov = k == 4 ? 1e-20 : 60;
        assert_int_equal(camera_init(&cam, eyes[k], target, up, fov, 33, 17), CAMERA_OK);
        uint8_t rgb[33 * 17 * 3];
        float depth[33 * 17];
        frame_stats st;
        for (int refine = 0; refine <= 1; refine++) {
            render(t, &cam, 2, refine, rgb, depth, NULL, &st);
            for (size_t i = 0; i < 33 * 17; i++)
                assert_true(!isnan(depth[i]) && depth[i] >= 0);
        }
        assert_true(st.steps <= st.rays * trace_max_steps(t->levels));
    }
    fedisableexcept(FE_INVALID);
    tree_util_free(t);
}

static float bits_float(uint32_t b)
{
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

/* The renderer's table sRGB encoder is image_srgb8 bit for bit: every float
 * within 256 ulps of each code change, a stride through [0, 1], specials.
 * (An exhaustive run over all 2^30 floats in [0, 1] was done once.) */
static void test_srgb_table_exact(void **state)
{
    (void)state;
    uint32_t changes = 0;
    uint8_t prev = image_srgb8(0.0f);
    for (uint32_t b = 0; b <= 0x3f800000u; b += 61) {
        float x = bits_float(b);
        uint8_t want = image_srgb8(x);
        assert_int_equal(frame_srgb8(x), want);
        if (want != prev) {
            changes++;
            for (uint32_t c = b > 61 + 256 ? b - 61 - 256 : 0; c <= b + 256; c++)
                assert_int_equal(frame_srgb8(bits_float(c)), image_srgb8(bits_float(c)));
        }
        prev = want;
    }
    assert_int_equal(changes, 255);
    static const float special[] = {-0.0f, -1.0f, 1.0f, 1.0000001f, 2.0f, 1e30f, INFINITY,
                                    -INFINITY, NAN, 1e-45f, 0.0031308f};
    for (size_t k = 0; k < sizeof special / sizeof special[0]; k++)
        assert_int_equal(frame_srgb8(special[k]), image_srgb8(special[k]));
}

/* Far from the world origin, with an edge that is not a power of two: the
 * beam must place cells as the traversal does (relative to its eye, in
 * voxels), or it misplaces them by ulp(origin), more than any fixed margin.
 * A full layer of voxels seen from just above (origin 1e9 and 1.08e9), and
 * single voxels under a ray lying exactly on the voxel's face plane x = k,
 * which the tie rule gives to voxel k. */
static void test_beam_far_from_origin(void **state)
{
    (void)state;
    const unsigned L = 6;
    const uint32_t n = 1u << L;
    uint32_t(*xyz)[3] = malloc((size_t)n * n * sizeof *xyz);
    uint32_t *attr = malloc((size_t)n * n * sizeof *attr);
    assert_non_null(xyz);
    assert_non_null(attr);
    const double up_n[3] = {0, 0, 1};
    for (uint32_t k = 0; k < n * n; k++) {
        xyz[k][0] = k % n;
        xyz[k][1] = k / n;
        xyz[k][2] = n / 2;
        attr[k] = oct_voxel_pack(up_n, 0.3);
    }
    const uint32_t w = 61;
    const size_t px = (size_t)w * w;
    uint8_t *a = malloc(px * 3), *b = malloc(px * 3);
    float *da = malloc(px * 4), *db = malloc(px * 4);
    static const double origins[] = {1e9, 1.08e9};
    for (size_t oi = 0; oi < 2; oi++)
        for (int k = 0; k < 4; k++) {
            const double O = origins[oi], edge = 0.7 * (1.0 + 0.01 * k);
            const double origin[3] = {O, O, O};
            oct_tree *t = tree_util_build(L, origin, edge, (const uint32_t(*)[3])xyz, (size_t)n * n,
                                          attr, NULL, 1, NULL);
            assert_non_null(t);
            const double eye[3] = {O + 0.37 * edge, O + 0.41 * edge, O + 0.9 * edge};
            const double target[3] = {eye[0], eye[1], eye[2] - edge}, up[3] = {0, 1, 0};
            camera cam;
            assert_int_equal(camera_init(&cam, eye, target, up, 1.0, w, w), CAMERA_OK);
            for (int refine = 0; refine <= 1; refine++) {
                frame_stats sa, sb;
                render_beam(t, &cam, 1, refine, 0, a, da, NULL, &sa);
                assert_int_equal(sa.hits, px);
                render_beam(t, &cam, 1, refine, 16, b, db, NULL, &sb);
                assert_memory_equal(a, b, px * 3);
                assert_memory_equal(da, db, px * 4);
            }
            tree_util_free(t);
        }
    for (uint32_t kk = 1; kk <= 20; kk++) {
        const double O = 1e9, edge = 64.0 / 3.0, s = edge / 64;
        const uint32_t k = 3u * kk;
        const double ex = O + kk;
        if ((ex - O) * (64 / edge) != (double)k)
            continue; /* the ray exactly on the plane x = k only */
        const uint32_t one[1][3] = {{k, 30, 10}};
        const uint32_t rec = oct_voxel_pack(up_n, 0.0);
        const double origin[3] = {O, O, O};
        oct_tree *t = tree_util_build(L, origin, edge, one, 1, &rec, NULL, 1, NULL);
        assert_non_null(t);
        const double eye[3] = {ex, O + 30.5 * s, O + 50 * s};
        const double target[3] = {eye[0], eye[1], eye[2] - edge}, up[3] = {0, 1, 0};
        camera cam;
        assert_int_equal(camera_init(&cam, eye, target, up, 0.01, 1, 1), CAMERA_OK);
        uint8_t c0[3], c1[3];
        float d0, d1;
        frame_stats s0, s1;
        render_beam(t, &cam, 1, 0, 0, c0, &d0, NULL, &s0);
        assert_int_equal(s0.hits, 1);
        render_beam(t, &cam, 1, 0, 1, c1, &d1, NULL, &s1);
        assert_int_equal(s1.hits, 1);
        assert_true(d0 == d1);
        tree_util_free(t);
    }
    free(a), free(b), free(da), free(db), free(xyz), free(attr);
}

/* A skewed camera: camera_init accepts an up within a sine of 1e-9 of the
 * view, and right = normalise(forward x up) then leaves forward by up to
 * about 1e-7. Far from the eye (3e5 voxels, level 18) that moves a ray by
 * more than any fixed margin; the beam must widen for it (a review found the
 * anchors placed past the rays' start, changing the depth of a pixel). The
 * camera searched for is the most skewed of many; the cube is slid so that
 * the ray through pixel (1, 0) grazes a voxel's corner. */
static uint64_t skew_rng = 88172645463325252ULL;

static double skew_rand(void) /* [-1, 1) */
{
    return rng_unit(rng_xorshift64(&skew_rng)) * 2.0 - 1.0;
}

static void test_beam_skewed_camera(void **state)
{
    (void)state;
    const unsigned L = 18;
    const uint32_t n = 1u << L;
    const double eye[3] = {0, 0, 0};
    camera cam;
    double worst = 0.0, dir[3] = {0, 0, 0};
    for (int it = 0; it < 3000000; it++) {
        const double f[3] = {skew_rand(), skew_rand(), skew_rand()};
        const double s = 0.5 + 3.0 * fabs(skew_rand());
        const double e = pow(10.0, -9.0 + 0.3 * fabs(skew_rand())) * s *
                         sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        const double up[3] = {f[0] * s + e * skew_rand(), f[1] * s + e * skew_rand(),
                              f[2] * s + e * skew_rand()};
        camera c;
        if (camera_init(&c, eye, f, up, 90.0, 2, 1) != CAMERA_OK)
            continue;
        const double rf = c.right[0] * c.forward[0] + c.right[1] * c.forward[1] +
                          c.right[2] * c.forward[2];
        double d[3];
        camera_ray(&c, 1, 0, d);
        if (rf > worst && d[0] < -0.3 && d[1] < -0.3 && d[2] < -0.3) {
            worst = rf;
            cam = c;
            memcpy(dir, d, sizeof dir);
        }
    }
    assert_true(worst > 1e-8); /* skewed indeed */
    const uint32_t one[1][3] = {{n / 2 - 1, n / 2 - 1, n / 2 - 1}};
    const double nrm[3] = {1, 1, 1};
    const uint32_t rec = oct_voxel_pack(nrm, 0.0);
    unsigned long hits = 0;
    for (int k = 0; k < 4000; k++) {
        const double s = 300000.0 + k * 0.00731;
        double origin[3];
        for (int a = 0; a < 3; a++) /* the ray passes 1e-5 voxel inside the voxel's corner */
            origin[a] = eye[a] + dir[a] * s - (n / 2 - 1e-5);
        oct_tree *t = tree_util_build(L, origin, (double)n, one, 1, &rec, NULL, 1, NULL);
        assert_non_null(t);
        for (int refine = 0; refine <= 1; refine++) {
            uint8_t rgb[2][6], nb[2][6];
            float depth[2][2];
            frame_stats st[2];
            for (int b = 0; b < 2; b++) { /* the default split, K = L */
                frame_job job;
                memset(&job, 0, sizeof job);
                job.tree = t;
                job.cam = &cam;
                job.opts.split = L;
                job.opts.refine = refine;
                job.shade.ambient = 0.2f;
                shade_default_light(&cam, job.shade.light);
                job.rgb = rgb[b];
                job.depth = depth[b];
                job.normals = nb[b];
                job.threads = 1;
                job.beam_size = b ? 32 : 0;
                assert_int_equal(frame_render(&job, &st[b]), 0);
            }
            hits += st[0].hits;
            assert_memory_equal(depth[0], depth[1], sizeof depth[0]);
            assert_memory_equal(rgb[0], rgb[1], sizeof rgb[0]);
            assert_memory_equal(nb[0], nb[1], sizeof nb[0]);
        }
        tree_util_free(t);
    }
    print_message("skewed camera: R.F = %.3g, %lu hits, beam and whole rays the same\n", worst,
                  hits);
    assert_true(hits > 1000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_beam_same_image),
        cmocka_unit_test(test_beam_far_from_origin),
        cmocka_unit_test(test_beam_skewed_camera),
        cmocka_unit_test(test_degenerate_cameras_no_nan),
        cmocka_unit_test(test_srgb_table_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
