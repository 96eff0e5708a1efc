/* Shadows against closed-form geometry: a ball over a slab, lit obliquely,
 * seen from above. A slab pixel is in shadow exactly when the light ray
 * from its point of the slab's plane passes within the ball's radius of its
 * centre; the render must agree except near the outline, within the
 * voxelization (a voxel's diagonal), the start point's documented shift
 * (render/shadow.h) and the hit point's voxel. Same image on every
 * traversal implementation and thread count. */
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
#include "render/frame.h"
#include "render/shadow.h"
#include "render/shadow_map.h"
#include "tests/voxel_shapes.h"

#define LEVELS 7
#define NV 128.0
#define W 128
#define SLAB 30.5
static const double ball_c[3] = {64, 64, 70}, ball_r = 20;

static void render_kept(const oct_tree *t, const camera *cam, const double light[3], int refine,
                        trace_traverse_fn fn, unsigned threads, frame_keep *keep,
                        uint8_t *rgb, float *depth)
{
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = t;
    job.cam = cam;
    job.opts.split = LEVELS;
    job.opts.refine = refine;
    job.shade.ambient = 0.2f;
    job.shade.shadows = 1;
    assert_int_equal(shade_set_light(&job.shade, light), 0);
    job.rgb = rgb;
    job.depth = depth;
    job.threads = threads;
    job.beam_size = FRAME_BEAM_DEFAULT;
    job.traverse = fn;
    job.keep = keep;
    frame_stats st;
    assert_int_equal(frame_render(&job, &st), 0);
    assert_true(st.shadow_rays > 0);
}

static void render(const oct_tree *t, const camera *cam, const double light[3], int refine,
                   trace_traverse_fn fn, unsigned threads, uint8_t *rgb, float *depth)
{
    render_kept(t, cam, light, refine, fn, threads, NULL, rgb, depth);
}

static const double eye[3] = {64, 64, 400};

/* The ball over the slab, and the camera above them. */
static oct_tree *ball_over_slab(camera *cam)
{
    shape sh[2] = {shape_plane(0, 0, 1, SLAB), shape_sphere(ball_c[0], ball_c[1], ball_c[2], ball_r)};
    sh[1].surface = 1;
    oct_tree *t = shapes_build(LEVELS, NV, sh, 2, 2);
    assert_non_null(t);
    const double target[3] = {64, 64, 0}, up[3] = {0, 1, 0};
    assert_int_equal(camera_init(cam, eye, target, up, 19.6, W, W), CAMERA_OK);
    return t;
}

static void test_ball_shadow_on_slab(void **state)
{
    (void)state;
    camera cam;
    oct_tree *t = ball_over_slab(&cam);
    double light[3] = {0.8, 0.3, 1.0};
    const double ll = sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
    for (int a = 0; a < 3; a++)
        light[a] /= ll;
    const double sin_t = sqrt(1.0 - light[2] * light[2]);
    const double tol = sqrt(3.0) + shadow_offset((const float[3]){0, 0, 1}) * sin_t +
                       0.5 * sqrt(2.0) + 1.0; /* voxel, offset, hit voxel, pixel */
    uint8_t *rgb = malloc(W * W * 3), *ref = malloc(W * W * 3);
    float *depth = malloc(W * W * sizeof *depth);
    assert_non_null(rgb);
    assert_non_null(ref);
    assert_non_null(depth);
    const uint8_t dark = image_srgb8(0.2f);
    for (int refine = 0; refine <= 1; refine++) {
        render(t, &cam, light, refine, NULL, 1, ref, depth);
        unsigned shadowed = 0, lit = 0, near = 0;
        for (uint32_t j = 0; j < W; j++)
            for (uint32_t i = 0; i < W; i++) {
                const size_t px = (size_t)j * W + i;
                if (!(depth[px] > 340.0f && depth[px] < 400.0f))
                    continue; /* the ball, or a miss */
                double d[3];
                camera_ray(&cam, i, j, d);
                const double s = (eye[2] - SLAB) / -d[2];
                double p[3], q[3], qd = 0.0, qq = 0.0;
                for (int a = 0; a < 3; a++) {
                    p[a] = eye[a] + s * d[a];
                    q[a] = ball_c[a] - p[a];
                    qd += q[a] * light[a];
                }
                for (int a = 0; a < 3; a++) {
                    const double e = q[a] - qd * light[a];
                    qq += e * e;
                }
                const double dist = qd > 0.0 ? sqrt(qq) : INFINITY;
                const int exact = dist < ball_r;
                const int got = ref[3 * px] == dark;
                if (fabs(dist - ball_r) <= tol) {
                    near++;
                    continue;
                }
                if (got != exact)
                    print_error("pixel %u,%u: %s, %.2f voxels from the outline\n", i, j,
                                got ? "shadowed" : "lit", dist - ball_r);
                assert_int_equal(got, exact);
                shadowed += (unsigned)exact;
                lit += (unsigned)!exact;
            }
        assert_true(shadowed > 600);
        assert_true(lit > 3000);
        assert_true(near > 50);
        for (unsigned impl = 0; impl < trace_impl_count; impl++)
            for (unsigned th = 1; th <= 3; th += 2) {
                render(t, &cam, light, refine, trace_impls[impl].traverse, th, rgb, depth);
                assert_memory_equal(rgb, ref, W * W * 3);
            }
    }
    free(rgb);
    free(ref);
    free(depth);
    tree_util_free(t);
}

/* Views under two lights in turn, one map kept from frame to frame
 * (frame_job.keep, as render's views loop keeps it): each frame the
 * same bytes as a frame that makes its own map, and the two lights' images
 * differ. (That the kept map is remade for a new light is
 * test_shadow_map's test_cache_follows_tree_and_light.) */
static void test_kept_map_same_frames(void **state)
{
    (void)state;
    camera cam;
    oct_tree *t = ball_over_slab(&cam);
    const double lights[3][3] = {{0.8, 0.3, 1.0}, {-0.5, 0.6, 1.0}, {0.8, 0.3, 1.0}};
    uint8_t *rgb = malloc(W * W * 3), *ref = malloc(W * W * 3), *first = malloc(W * W * 3);
    float *depth = malloc(W * W * sizeof *depth);
    assert_true(rgb && ref && first && depth);
    frame_keep keep;
    memset(&keep, 0, sizeof keep);
    for (int k = 0; k < 3; k++) {
        render(t, &cam, lights[k], 0, NULL, 2, ref, depth);
        render_kept(t, &cam, lights[k], 0, NULL, 2, &keep, rgb, depth);
        assert_memory_equal(rgb, ref, W * W * 3);
        assert_non_null(keep.maps.tree);
        if (k == 0)
            memcpy(first, rgb, W * W * 3);
        else
            assert_true((memcmp(first, rgb, W * W * 3) == 0) == (k == 2));
    }
    frame_keep_free(&keep);
    free(rgb);
    free(ref);
    free(first);
    free(depth);
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ball_shadow_on_slab),
        cmocka_unit_test(test_kept_map_same_frames),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
