/* Tests for render/aa and the frame's antialiasing pass: coverage (alpha)
 * of a sphere's silhouette against the exact area of the disc over each
 * pixel square (numeric integration); the edge test's rule; colour
 * averaged in linear light; depth kept from the centre ray; the image the
 * same whatever the thread count and traversal implementation; the beam's
 * edge trigger finds what lies between centre rays; samples started at
 * their sub-block's start are those traced whole; samples walked as
 * packets are those traced one by one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench/tree_util.h"
#include "common/view/image.h"
#include "render/aa.h"
#include "render/frame.h"
#include "render/views.h"
#include "tests/voxel_shapes.h"

#define W 80
#define H 72

typedef struct scene {
    oct_tree *tree;
    camera cam;
    double rho; /* the silhouette's radius in (u, v) units */
} scene;

/* A sphere of radius r voxels at the centre of a 2^levels cube, seen along
 * -z from distance dist voxels. */
static scene sphere_scene(unsigned levels, double r, double dist, double fov)
{
    scene s;
    const double n = (double)(1u << levels), c = 0.5 * n;
    shape sh = shape_sphere(c, c, c, r);
    s.tree = shapes_build(levels, n, &sh, 1, 1);
    assert_non_null(s.tree);
    const double eye[3] = {c, c, c + dist}, target[3] = {c, c, c}, up[3] = {0, 1, 0};
    assert_int_equal(camera_init(&s.cam, eye, target, up, fov, W, H), CAMERA_OK);
    s.rho = r / sqrt(dist * dist - r * r);
    return s;
}

/* Exact area fraction of the disc u^2 + v^2 < rho^2 over pixel (i, j), by
 * 128 x 128 midpoint samples. */
static double disc_cover(const camera *cam, double rho, uint32_t i, uint32_t j)
{
    const int k = 128;
    unsigned in = 0;
    for (int b = 0; b < k; b++)
        for (int a = 0; a < k; a++) {
            const double x = i + (a + 0.5) / k, y = j + (b + 0.5) / k;
            const double u = (2.0 * x / cam->width - 1.0) * cam->h * cam->width / cam->height;
            const double v = (1.0 - 2.0 * y / cam->height) * cam->h;
            in += u * u + v * v < rho * rho;
        }
    return (double)in / (k * k);
}

static void render_kept(const scene *s, unsigned aa, int refine, trace_traverse_fn fn,
                        unsigned threads, frame_keep *keep, uint8_t *rgb, uint8_t *alpha,
                        float *depth, frame_stats *st)
{
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = s->tree;
    job.cam = &s->cam;
    job.opts.split = s->tree->levels;
    job.opts.refine = refine;
    job.shade.ambient = 0.2f;
    shade_default_light(&s->cam, job.shade.light);
    job.rgb = rgb;
    job.alpha = alpha;
    job.depth = depth;
    job.threads = threads;
    job.beam_size = FRAME_BEAM_DEFAULT;
    job.traverse = fn;
    job.aa = aa;
    job.keep = keep;
    assert_int_equal(frame_render(&job, st), 0);
}

static void render(const scene *s, unsigned aa, int refine, trace_traverse_fn fn,
                   unsigned threads, uint8_t *rgb, uint8_t *alpha, float *depth, frame_stats *st)
{
    render_kept(s, aa, refine, fn, threads, NULL, rgb, alpha, depth, st);
}

static void test_coverage_matches_disc(void **state)
{
    (void)state;
    scene s = sphere_scene(9, 200.0, 700.0, 100.0);
    uint8_t *rgb = malloc(W * H * 3), *alpha = malloc(W * H);
    assert_non_null(rgb);
    assert_non_null(alpha);
    for (int refine = 0; refine <= 1; refine++) {
        frame_stats st;
        render(&s, 4, refine, NULL, 2, rgb, alpha, NULL, &st);
        double sum_edge = 0.0, sum_all = 0.0;
        unsigned edge = 0;
        for (uint32_t j = 0; j < H; j++)
            for (uint32_t i = 0; i < W; i++) {
                const double exact = disc_cover(&s.cam, s.rho, i, j);
                const double err = fabs(alpha[j * W + i] / 255.0 - exact);
                sum_all += err;
                if (exact > 0.0 && exact < 1.0) {
                    sum_edge += err;
                    edge++;
                }
            }
        print_message("refine %d: %u silhouette pixels, mean |alpha - exact| %.4f there, "
                      "%.5f over the image, %.1f%% edge pixels, %.1f%% supersampled\n",
                      refine, edge, sum_edge / edge, sum_all / (W * H),
                      100.0 * (double)st.aa_pixels / (W * H), 100.0 * (double)st.aa_full / (W * H));
        assert_true(edge > 60);
        assert_true(sum_edge / edge <= 0.08);
        assert_true(sum_all / (W * H) <= 0.002);
    }
    free(rgb);
    free(alpha);
    tree_util_free(s.tree);
}

/* Same image whatever the thread count, the implementation and the beam;
 * depth is the centre ray's (the image with --aa 1); only pixels next to
 * an edge are supersampled, and every one of them is. */
static void test_deterministic_and_centre_depth(void **state)
{
    (void)state;
    scene s = sphere_scene(7, 40.0, 160.0, 40.0);
    const size_t np = W * H;
    uint8_t *rgb = malloc(np * 3), *ref = malloc(np * 3), *alpha = malloc(np),
            *aref = malloc(np), *plain = malloc(np * 3);
    float *depth = malloc(np * sizeof *depth), *dref = malloc(np * sizeof *dref);
    assert_true(rgb && ref && alpha && aref && plain && depth && dref);
    frame_stats st, st1;
    render(&s, 1, 0, NULL, 1, plain, NULL, dref, &st1);
    render(&s, 3, 0, NULL, 1, ref, aref, depth, &st);
    assert_memory_equal(depth, dref, np * sizeof *depth);
    assert_true(st.aa_pixels > 0 && st.aa_pixels < np / 4);
    /* 3 x 3: the four corners of each edge pixel, the five others where
       those disagree */
    assert_true(st.rays == np + 4 * st.aa_pixels + 5 * st.aa_full);
    assert_true(st.aa_full > 0 && st.aa_full < st.aa_pixels);
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (unsigned th = 1; th <= 5; th += 2) {
            render(&s, 3, 0, trace_impls[impl].traverse, th, rgb, alpha, depth, &st1);
            assert_memory_equal(rgb, ref, np * 3);
            assert_memory_equal(alpha, aref, np);
            assert_memory_equal(depth, dref, np * sizeof *depth);
            assert_true(st1.aa_pixels == st.aa_pixels && st1.aa_full == st.aa_full);
        }
    /* a pixel that is not supersampled keeps its one ray's colour; one
       whose alpha is partial was supersampled */
    unsigned partial = 0;
    for (size_t k = 0; k < np; k++)
        if (aref[k] != 0 && aref[k] != 255)
            partial++;
    assert_true(partial > 20 && partial <= st.aa_full);
    free(rgb);
    free(ref);
    free(alpha);
    free(aref);
    free(plain);
    free(depth);
    free(dref);
    tree_util_free(s.tree);
}

/* The edge rule, one criterion at a time. */
static void test_edge_rule(void **state)
{
    (void)state;
    aa_probe a = {100.0f, INFINITY, {0, 0, 1}, 0, 1, 0}, b = a;
    assert_false(aa_differs(&a, &b));
    b.hit = 0;
    assert_true(aa_differs(&a, &b));
    b = a;
    b.surface = 1;
    assert_true(aa_differs(&a, &b));
    b = a;
    b.t = 100.0f * (1.0f + 0.9f * AA_DEPTH_REL);
    assert_false(aa_differs(&a, &b));
    b.t = 100.0f * (1.0f + 1.1f * AA_DEPTH_REL);
    assert_true(aa_differs(&a, &b));
    b = a;
    b.n[0] = 0.6f; /* 37 degrees */
    b.n[2] = 0.8f;
    assert_true(aa_differs(&a, &b));
    b.n[0] = 0.3f; /* 17 degrees */
    b.n[2] = 0.954f;
    assert_false(aa_differs(&a, &b));
    /* inside a rectangle: each pixel that differs from a 4-neighbour
       inside it, a mark kept, nothing across its sides */
    aa_probe grid[4 * 3];
    for (int k = 0; k < 12; k++) {
        grid[k] = a;
        grid[k].hit = 0;
    }
    grid[0].need = 1;     /* a beam mark stays */
    grid[6].hit = 1;      /* (2, 1) of the 3 x 3 at stride 4 */
    grid[3].hit = 1;      /* column 3: outside it */
    aa_mark_inside(grid, 4, 3, 3);
    for (int k = 0; k < 12; k++)
        assert_int_equal(grid[k].need, k == 0 || k == 6 || k == 2 || k == 5 || k == 10);
    aa_probe m1 = a, m2 = a; /* two misses never differ */
    m1.hit = m2.hit = 0;
    m1.t = 1.0f;
    assert_false(aa_differs(&m1, &m2));
}

/* The pixels sampled are those the rule picks over the whole image
 * (brute force on the centre rays' depth and normal), pairs across tile
 * borders included: views whose silhouettes and a ball's inside cross
 * tile borders, several beam sizes and thread counts. */
static void test_edge_test_whole_image(void **state)
{
    (void)state;
    const uint32_t w = 3 * FRAME_TILE - 7, h = 2 * FRAME_TILE + 9;
    const size_t np = (size_t)w * h;
    scene s = sphere_scene(7, 40.0, 150.0, 40.0);
    camera cams[2];
    const double c = 64.0, eye[3] = {c + 30.0, c - 20.0, c + 100.0}, target[3] = {c, c, c},
                 up[3] = {0, 1, 0}, near[3] = {c + 10.0, c - 5.0, c + 42.0};
    assert_int_equal(camera_init(&cams[0], eye, target, up, 40.0, w, h), CAMERA_OK);
    assert_int_equal(camera_init(&cams[1], near, target, up, 60.0, w, h), CAMERA_OK);
    uint8_t *rgb = malloc(np * 3);
    float *depth = malloc(np * sizeof *depth), *nrm = malloc(np * 3 * sizeof *nrm);
    aa_probe *pr = malloc(np * sizeof *pr);
    assert_true(rgb && depth && nrm && pr);
    for (int v = 0; v < 2; v++) {
        frame_job job;
        memset(&job, 0, sizeof job);
        job.tree = s.tree;
        job.cam = &cams[v];
        job.opts.split = s.tree->levels;
        job.shade.ambient = 0.2f;
        shade_default_light(&cams[v], job.shade.light);
        job.rgb = rgb;
        job.depth = depth;
        job.normals_f = nrm;
        job.threads = 1;
        job.beam_size = FRAME_BEAM_DEFAULT;
        job.no_beam_edge = 1;
        frame_stats st;
        assert_int_equal(frame_render(&job, &st), 0);
        for (size_t k = 0; k < np; k++) {
            memset(&pr[k], 0, sizeof pr[k]);
            pr[k].hit = depth[k] < INFINITY;
            pr[k].t = depth[k];
            for (int a = 0; a < 3; a++)
                pr[k].n[a] = nrm[3 * k + (size_t)a];
        }
        uint64_t want = 0, across = 0;
        for (uint32_t j = 0; j < h; j++)
            for (uint32_t i = 0; i < w; i++) {
                const aa_probe *p = &pr[(size_t)j * w + i];
                const int l = i > 0 && aa_differs(p, p - 1), r = i + 1 < w && aa_differs(p, p + 1);
                const int u = j > 0 && aa_differs(p, p - w), d = j + 1 < h && aa_differs(p, p + w);
                want += l || r || u || d;
                across += (l && i % FRAME_TILE == 0) || (u && j % FRAME_TILE == 0);
            }
        assert_true(across > 4);
        job.depth = NULL;
        job.normals_f = NULL;
        job.aa = 2;
        static const unsigned beams[] = {0, 5, FRAME_BEAM_DEFAULT};
        for (size_t b = 0; b < sizeof beams / sizeof beams[0]; b++)
            for (unsigned th = 1; th <= 3; th += 2) {
                job.beam_size = beams[b];
                job.threads = th;
                assert_int_equal(frame_render(&job, &st), 0);
                assert_int_equal(st.aa_pixels, want);
            }
    }
    free(rgb);
    free(depth);
    free(nrm);
    free(pr);
    tree_util_free(s.tree);
}

/* Colour is averaged in linear light: half the samples on white, half on
 * black gives sRGB of 0.5, not 128. */
static void test_linear_average(void **state)
{
    (void)state;
    /* a plane z = 10.5 over the right half of a 2^5 cube, seen from above:
       pixels whose two sample columns straddle its edge x = 16 are half
       covered */
    shape sh = shape_plane(0, 0, 1, 10.5);
    sh.lo[0] = 16;
    oct_tree *t = shapes_build(5, 32.0, &sh, 1, 1);
    assert_non_null(t);
    scene s;
    s.tree = t;
    /* the edge 0.185 voxel (half a pixel) right of the image's
       middle: between the sample columns of column 40 */
    const double eye[3] = {15.815, 16, 100}, target[3] = {15.815, 16, 0}, up[3] = {0, 1, 0};
    assert_int_equal(camera_init(&s.cam, eye, target, up, 17.0, W, H), CAMERA_OK);
    uint8_t *rgb = malloc(W * H * 3);
    assert_non_null(rgb);
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = t;
    job.cam = &s.cam;
    job.opts.split = 5;
    job.shade.ambient = 1.0f; /* the palette colour, white */
    shade_default_light(&s.cam, job.shade.light);
    job.rgb = rgb;
    job.threads = 1;
    job.beam_size = FRAME_BEAM_DEFAULT;
    job.aa = 2;
    frame_stats st;
    assert_int_equal(frame_render(&job, &st), 0);
    uint8_t *cov = malloc(W * H), *rgba = malloc(W * H * 3);
    assert_non_null(cov);
    assert_non_null(rgba);
    job.alpha = cov; /* the same samples, their coverage */
    job.rgb = rgba;
    assert_int_equal(frame_render(&job, &st), 0);
    unsigned halves = 0;
    for (size_t k = 0; k < (size_t)W * H; k++) {
        const unsigned hits = (cov[k] * 4u + 127u) / 255u;
        assert_int_equal(cov[k], (hits * 255u + 2u) / 4u);
        /* white samples (ambient 1) over black: sRGB of the linear mean */
        assert_int_equal(rgb[3 * k], image_srgb8((float)hits / 4.0f));
        if (hits == 2)
            halves++;
        if (hits) /* straight alpha: the covered part's colour */
            assert_int_equal(rgba[3 * k], 255);
    }
    assert_true(halves >= H / 2);
    assert_true(image_srgb8(0.5f) > 180); /* 188: not the 128 of averaging codes */
    free(cov);
    free(rgba);
    free(rgb);
    tree_util_free(t);
}

/* The beam's edge trigger: one voxel, a third of a pixel wide, at the
 * corner of four pixels, between their centre rays. Every centre ray
 * misses it, so the neighbour test alone samples nothing; the four beam
 * sub-blocks whose pyramids it meets are marked, and the samples of the
 * four pixels round the corner find it. */
static void test_beam_edge_trigger(void **state)
{
    (void)state;
    const uint32_t vox[1][3] = {{128, 128, 100}};
    oct_tree *t = tree_util_simple(8, vox, 1);
    assert_non_null(t);
    /* from 0.35 above its top face, a pixel is 3 voxels wide there */
    const double c = 128.5 / 256.0, top = 101.0 / 256.0;
    const double eye[3] = {c, c, top + 0.35}, target[3] = {c, c, 0.0}, up[3] = {0, 1, 0};
    camera cam;
    assert_int_equal(camera_init(&cam, eye, target, up, 30.0, 16, 16), CAMERA_OK);
    uint8_t rgb[16 * 16 * 3], alpha[16 * 16];
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = t;
    job.cam = &cam;
    job.opts.split = 8;
    job.shade.ambient = 0.2f;
    shade_default_light(&cam, job.shade.light);
    job.rgb = rgb;
    job.alpha = alpha;
    job.threads = 1;
    job.beam_size = FRAME_BEAM_DEFAULT;
    job.aa = 4;
    frame_stats st;
    for (int trigger = 0; trigger <= 1; trigger++) {
        job.no_beam_edge = !trigger;
        assert_int_equal(frame_render(&job, &st), 0);
        assert_int_equal(st.hits, 0); /* no centre ray meets the voxel */
        unsigned covered = 0;
        for (uint32_t j = 0; j < 16; j++)
            for (uint32_t i = 0; i < 16; i++) {
                const int corner = (i == 7 || i == 8) && (j == 7 || j == 8);
                if (trigger && corner)
                    assert_true(alpha[j * 16 + i] > 0);
                else
                    assert_int_equal(alpha[j * 16 + i], 0);
                covered += alpha[j * 16 + i] > 0;
            }
        /* the four middle sub-blocks of 4 x 4 pixels */
        assert_int_equal(st.aa_pixels, trigger ? 64 : 0);
        assert_int_equal(covered, trigger ? 4 : 0);
    }
    tree_util_free(t);
}

/* The samples start at their pixel's sub-block start, from an anchor:
 * without the edge trigger (which --beam 0 has not), the image is that of
 * samples traced whole (--beam 0), for several beam block sizes. */
static void test_sample_starts_exact(void **state)
{
    (void)state;
    scene s = sphere_scene(7, 40.0, 160.0, 40.0);
    const size_t np = W * H;
    uint8_t *rgb = malloc(np * 3), *ref = malloc(np * 3), *alpha = malloc(np), *aref = malloc(np);
    assert_true(rgb && ref && alpha && aref);
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = s.tree;
    job.cam = &s.cam;
    job.opts.split = s.tree->levels;
    job.shade.ambient = 0.2f;
    shade_default_light(&s.cam, job.shade.light);
    job.threads = 2;
    job.aa = 3;
    job.no_beam_edge = 1;
    frame_stats st, st0;
    for (int refine = 0; refine <= 1; refine++) {
        job.opts.refine = refine;
        job.rgb = ref;
        job.alpha = aref;
        job.beam_size = 0;
        assert_int_equal(frame_render(&job, &st0), 0);
        job.rgb = rgb;
        job.alpha = alpha;
        static const unsigned sizes[] = {5, 16, FRAME_BEAM_DEFAULT};
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
            job.beam_size = sizes[k];
            assert_int_equal(frame_render(&job, &st), 0);
            assert_memory_equal(rgb, ref, np * 3);
            assert_memory_equal(alpha, aref, np);
            assert_true(st.aa_pixels == st0.aa_pixels && st.rays == st0.rays);
        }
    }
    free(rgb);
    free(ref);
    free(alpha);
    free(aref);
    tree_util_free(s.tree);
}

/* The samples walked as packets (the default, paper's rule) and traced
 * one by one give the same image, byte for byte: every N, with shadows,
 * AO and alpha, on a sphere and on a cloud of single voxels (sub-pixel
 * details, rays grazing small cells), from several threads. */
static void test_packets_same_image(void **state)
{
    (void)state;
    scene sp = sphere_scene(8, 70.0, 260.0, 45.0);
    uint32_t(*xyz)[3] = malloc(3000 * sizeof *xyz);
    assert_non_null(xyz);
    uint64_t seed = 0x5eed;
    const size_t m = tree_util_distinct_voxels(3000, 40, 48, &seed, xyz);
    oct_tree *cloud = tree_util_simple(7, (const uint32_t(*)[3])xyz, m);
    assert_non_null(cloud);
    const oct_tree *trees[2] = {sp.tree, cloud};
    const size_t np = W * H;
    uint8_t *rgb = malloc(np * 3), *ref = malloc(np * 3), *alpha = malloc(np), *aref = malloc(np);
    assert_true(rgb && ref && alpha && aref);
    camera cc;
    const double eye[3] = {1.3, -0.4, 1.1}, target[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1};
    assert_int_equal(camera_init(&cc, eye, target, up, 30.0, W, H), CAMERA_OK);
    const camera *cams[2] = {&sp.cam, &cc};
    unsigned long sampled = 0;
    for (int sc = 0; sc < 2; sc++)
        for (unsigned aa = 2; aa <= 5; aa++) {
            frame_job job;
            memset(&job, 0, sizeof job);
            job.tree = trees[sc];
            job.cam = cams[sc];
            job.opts.split = trees[sc]->levels;
            job.shade.ambient = 0.2f;
            job.shade.shadows = aa % 2;
            job.shade.ao_rays = aa == 4 ? 8 : 0;
            job.shade.ao_distance = VIEWS_AO_DISTANCE;
            shade_default_light(cams[sc], job.shade.light);
            job.beam_size = FRAME_BEAM_DEFAULT;
            job.aa = aa;
            frame_stats st, st0;
            job.threads = 1;
            job.no_packets = 1;
            job.rgb = ref;
            job.alpha = aa == 3 ? NULL : aref;
            assert_int_equal(frame_render(&job, &st0), 0);
            job.threads = 3;
            job.no_packets = 0;
            job.rgb = rgb;
            job.alpha = aa == 3 ? NULL : alpha;
            assert_int_equal(frame_render(&job, &st), 0);
            assert_memory_equal(rgb, ref, np * 3);
            if (aa != 3)
                assert_memory_equal(alpha, aref, np);
            assert_true(st.rays == st0.rays && st.aa_full == st0.aa_full);
            sampled += st.aa_pixels;
        }
    print_message("packets: %lu pixels sampled, the same bytes as ray by ray\n", sampled);
    assert_true(sampled > 400);
    free(rgb);
    free(ref);
    free(alpha);
    free(aref);
    free(xyz);
    tree_util_free(cloud);
    tree_util_free(sp.tree);
}

/* Frames of several sizes in turn with one frame_keep (render's views
 * loop): the border probes kept from a larger frame, or grown for a larger
 * one, give each frame the bytes of a frame that makes its own. */
static void test_kept_border_same_frames(void **state)
{
    (void)state;
    scene s = sphere_scene(7, 40.0, 200.0, 40.0);
    const uint32_t sizes[4][2] = {{W, H}, {3 * W, 2 * H}, {W / 2, H}, {3 * W, 2 * H}};
    const size_t most = (size_t)3 * W * 2 * H;
    uint8_t *rgb = malloc(most * 3), *ref = malloc(most * 3), *alpha = malloc(most),
            *aref = malloc(most);
    assert_true(rgb && ref && alpha && aref);
    frame_keep keep;
    memset(&keep, 0, sizeof keep);
    const double eye[3] = {64, 64, 264}, target[3] = {64, 64, 64}, up[3] = {0, 1, 0};
    for (int k = 0; k < 4; k++) {
        assert_int_equal(camera_init(&s.cam, eye, target, up, 40.0, sizes[k][0], sizes[k][1]),
                         CAMERA_OK);
        const size_t px = (size_t)sizes[k][0] * sizes[k][1];
        frame_stats st;
        render(&s, 4, 0, NULL, 2, ref, aref, NULL, &st);
        assert_true(st.aa_pixels > 0);
        render_kept(&s, 4, 0, NULL, 2, &keep, rgb, alpha, NULL, &st);
        assert_memory_equal(rgb, ref, px * 3);
        assert_memory_equal(alpha, aref, px);
        assert_non_null(keep.border);
    }
    frame_keep_free(&keep);
    assert_null(keep.border);
    free(rgb);
    free(ref);
    free(alpha);
    free(aref);
    tree_util_free(s.tree);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coverage_matches_disc),
        cmocka_unit_test(test_deterministic_and_centre_depth),
        cmocka_unit_test(test_edge_rule),
        cmocka_unit_test(test_edge_test_whole_image),
        cmocka_unit_test(test_linear_average),
        cmocka_unit_test(test_beam_edge_trigger),
        cmocka_unit_test(test_sample_starts_exact),
        cmocka_unit_test(test_packets_same_image),
        cmocka_unit_test(test_kept_border_same_frames),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
