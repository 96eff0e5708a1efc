/* Tests for render/exact_sub (the sub-cells of --exact's coarse cells): on
 * scenes with min, max and abs, a sub-cell's Hessian bound holds sampled
 * finite-difference Hessians of f at random points of it; its pruned tape
 * gives f and the gradient bit for bit; an empty one holds no sign change;
 * rays aimed at crease lines and rays along voxel planes hit where the
 * exact reference caster (bench/refcast) does, on CSG and on gyroid_ball
 * (whose kinked cells get no sub-cells); the result of a ray does not
 * depend on the order rays are cast, on a cache emptied on the way, or on
 * the thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/refcast.h"
#include "bench/rng.h"
#include "render/exact_sub.h"
#include "render/frame.h"
#include "tests/exact_built.h"

static const char *const csg =
    "bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
    "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
    " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n";

/* The kinked scenes: CSG (scenes/csg.scene), the creased box of
 * scenes/crease.scene, the turned cube of scenes/cube.scene, and a gyroid
 * cut by a ball (curved branches: the Hessian varies). */
static const char *const kinked[] = {
    "bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
    "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
    " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n",
    "bounds -1 -1 -1 1 1 1\n"
    "surface min(max(abs(x) - 0.7, abs(y) - 0.5, abs(z) - 0.45, x^2 + (z + 0.3)^2 - 1,"
    " 0.04 - y^2 - z^2, 0.55 - abs(x + y) - 0.3*z), (x - 0.45)^2 + (y - 0.25)^2 +"
    " (z - 0.45)^2 - 0.04)\n",
    "bounds -1 -1 -1 1 1 1\n"
    "surface max(abs(0.8*x + 0.6*y), abs(0.8*y - 0.6*x), abs(z + 0.05)) - 0.6\n",
    "bounds -1 -1 -1 1 1 1\n"
    "surface max(abs(sin(6*x)*cos(6*y) + sin(6*y)*cos(6*z) + sin(6*z)*cos(6*x)) - 0.2,"
    " x^2 + y^2 + z^2 - 0.81)\n",
};

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double unit(void) { return rng_unit(rng_xorshift64(&rng)); }

static const int hr[TAPE_HN] = {0, 0, 0, 1, 1, 2}, hc[TAPE_HN] = {0, 1, 2, 1, 2, 2};

/* Central-difference Hessian entry e of t at p, step h. */
static double fd_entry(const tape *t, const double p[3], int e, double h, double *slots)
{
    double s = 0.0;
    for (int k = 0; k < 4; k++) {
        double q[3] = {p[0], p[1], p[2]};
        q[hr[e]] += k & 1 ? -h : h;
        q[hc[e]] += k & 2 ? -h : h;
        const double v = tape_eval(t, q[0], q[1], q[2], slots);
        s += (k == 0 || k == 3) ? v : -v;
    }
    return s / (4.0 * h * h);
}

/* A random voxel of a registered coarse cell of b (the sub-cells exist
 * for those alone), or 0 after many tries. */
static int random_voxel(const exact_built *b, uint32_t v[3], uint32_t *slot)
{
    const unsigned L = b->tree->levels, D = b->es.depth;
    const uint32_t dim = UINT32_C(1) << D;
    for (int tries = 0; tries < 10000; tries++) {
        for (int a = 0; a < 3; a++)
            v[a] = (uint32_t)(unit() * (double)(UINT32_C(1) << L)) & ((UINT32_C(1) << L) - 1u);
        const uint32_t s = b->es.cell_slot[((size_t)(v[2] >> (L - D)) * dim + (v[1] >> (L - D))) *
                                               dim + (v[0] >> (L - D))];
        if (s != UINT32_MAX && b->es.first[s + 1] > b->es.first[s]) {
            *slot = s;
            return 1;
        }
    }
    return 0;
}

/* A random point of the box, `margin` inside each face. */
static void in_box(const interval box[3], double margin, double p[3])
{
    for (int a = 0; a < 3; a++)
        p[a] = box[a].lo + margin + unit() * (box[a].hi - box[a].lo - 2.0 * margin);
}

typedef struct sub_counts {
    unsigned sub_finite, sub_inf, empty, entries, points;
    uint64_t cell_n, sub_n;
} sub_counts;

/* Sub-cells of random voxels of a kinked scene: Hessian enclosures against
 * finite differences where two steps agree, the pruned tape against the
 * whole one bit for bit (value and gradient), empty ones sign-definite. */
static void check_scene(const char *text, unsigned levels, unsigned depth, sub_counts *n)
{
    exact_built b;
    exact_built_make(text, levels, depth, &b);
    assert_true(b.es.sub_max > 0);
    exact_sub_cache c;
    assert_int_equal(exact_sub_init(&c, b.es.ncand, b.es.max_n), 0);
    const tape *whole = &b.st.tapes[0];
    double *slots = malloc(b.es.max_n * sizeof *slots);
    tape_dual *ds = malloc(b.es.max_n * sizeof *ds);
    assert_true(slots && ds);
    for (unsigned it = 0; it < 1500; it++) {
        uint32_t v[3], slot = 0; /* set by random_voxel, which the assert requires */
        assert_true(random_voxel(&b, v, &slot));
        exact_sub_reserve(&c);
        const uint32_t k = b.es.first[slot];
        const exact_region rg = *exact_sub_find(&c, &b.es, k, v);
        if (rg.key == 0)
            continue; /* the cell's own bound is finite */
        interval box[3];
        exact_scene_box(&b.es, rg.depth, rg.corner, box);
        for (int a = 0; a < 3; a++) /* the voxel lies in its region */
            assert_true(box[a].lo <= b.tree->origin[a] + v[a] * b.es.h &&
                        b.tree->origin[a] + (v[a] + 1.0) * b.es.h <= box[a].hi);
        const double width = box[0].hi - box[0].lo, h = 1e-3 * width;
        if (rg.empty) {
            n->empty++;
            double p[3];
            in_box(box, 0.0, p);
            const double f0 = tape_eval(whole, p[0], p[1], p[2], slots);
            for (int s = 0; s < 8; s++) {
                in_box(box, 0.0, p);
                const double f = tape_eval(whole, p[0], p[1], p[2], slots);
                assert_true(f != 0.0 && (f < 0.0) == (f0 < 0.0));
            }
            continue;
        }
        n->cell_n += b.es.cand[k].t.n;
        n->sub_n += rg.t.n;
        if (rg.hmag[0] < INFINITY)
            n->sub_finite++;
        else
            n->sub_inf++;
        for (int s = 0; s < 8; s++) {
            double p[3], g0[3], g1[3];
            in_box(box, 3.0 * h, p);
            const double f0 = tape_eval(whole, p[0], p[1], p[2], slots);
            const double f1 = tape_eval(&rg.t, p[0], p[1], p[2], slots);
            assert_memory_equal(&f0, &f1, sizeof f0);
            tape_eval_grad(whole, p, g0, ds);
            tape_eval_grad(&rg.t, p, g1, ds);
            assert_memory_equal(g0, g1, sizeof g0);
            n->points++;
            if (!(rg.hmag[0] < INFINITY))
                continue;
            for (int e = 0; e < TAPE_HN; e++) {
                const double d1 = fd_entry(whole, p, e, h, slots);
                const double d2 = fd_entry(whole, p, e, 0.5 * h, slots);
                const double tol = 1e-3 * (1.0 + fabs(d1));
                if (!(fabs(d1 - d2) <= tol))
                    continue; /* a kink within the stencil: no witness */
                n->entries++;
                if (!(fabs(d1) <= rg.hmag[e] + tol))
                    fail_msg("%s: entry %d at (%.17g, %.17g, %.17g): %.6g beyond %.6g", text, e,
                             p[0], p[1], p[2], d1, rg.hmag[e]);
            }
        }
    }
    free(slots);
    free(ds);
    exact_sub_free(&c);
    exact_built_free(&b);
}

static void test_sub_cells(void **state)
{
    (void)state;
    for (size_t s = 0; s < sizeof kinked / sizeof *kinked; s++) {
        /* coarse depth 3 at levels 8: sub-cells of depth 5 and 7 */
        sub_counts n;
        memset(&n, 0, sizeof n);
        check_scene(kinked[s], 8, 3, &n);
        if (getenv("EXACT_VERBOSE"))
            printf("scene %zu: sub-cells %u finite, %u +inf, %u empty; %u points, %u entries;"
                   " instructions %llu -> %llu\n",
                   s, n.sub_finite, n.sub_inf, n.empty, n.points, n.entries,
                   (unsigned long long)n.cell_n, (unsigned long long)n.sub_n);
        if (strstr(kinked[s], "sin(")) {
            /* the gyroid: its cells keep an abs of an operand that changes
             * sign there, so none gets sub-cells (exact_sub_wanted) */
            assert_int_equal(n.sub_finite + n.sub_inf + n.empty, 0);
            continue;
        }
        assert_true(n.sub_finite > 50);
        assert_true(n.entries > 1000);
        assert_true(n.sub_n < n.cell_n); /* the pruned tapes are shorter */
    }
}

/* The first ray hit against refcast: same hit or miss, t within 1e-9. */
static unsigned against_refcast(const exact_built *b, exact_worker *w, refcast_scratch *rw,
                                const double eye[3], const double dir_in[3])
{
    const double len = sqrt(dir_in[0] * dir_in[0] + dir_in[1] * dir_in[1] + dir_in[2] * dir_in[2]);
    const double dir[3] = {dir_in[0] / len, dir_in[1] / len, dir_in[2] / len};
    trace_opts opts = {b->tree->levels, 0, w};
    trace_hit h;
    trace_ray_cast(b->tree, &opts, eye, dir, &h);
    refcast_hit rh;
    refcast_stats rs = {0, 0, 0, 0};
    refcast_ray(b->sc, rw, eye, dir, &rh, &rs);
    if (rh.touch)
        return 0; /* grazing within rounding: either answer */
    if (h.hit != (rh.t < INFINITY) || (h.hit && !(fabs(h.t - rh.t) <= 1e-9)))
        fail_msg("eye (%.17g, %.17g, %.17g) dir (%.17g, %.17g, %.17g): t %.17g, refcast %.17g",
                 eye[0], eye[1], eye[2], dir[0], dir[1], dir[2], h.hit ? h.t : INFINITY, rh.t);
    return (unsigned)h.hit;
}

/* CSG's creases: rays from several eyes aimed at points of the circles
 * where the cube's faces meet the ball and the drilled holes, and rays in
 * voxel planes (starts on a grid plane, directions in it, some along an
 * axis), at levels 7. */
static void test_csg_creases_vs_refcast(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make(csg, 7, EXACT_CELL_DEPTH, &b);
    exact_worker w;
    assert_int_equal(exact_worker_init(&w, &b.es), 0);
    refcast_scratch *rw = refcast_scratch_new(b.sc);
    assert_non_null(rw);
    static const double eyes[][3] = {{2.2, 1.6, 1.9}, {2.5, 0.3, 0.2}, {0.4, -2.4, 1.1},
                                     {-1.7, -1.9, -2.0}};
    static const double radius[2] = {0.6, 0.4}; /* face and ball; face and hole */
    unsigned hits = 0;
    for (unsigned e = 0; e < 4; e++)
        for (unsigned k = 0; k < 600; k++) {
            const double th = 2.0 * M_PI * k / 600.0 + 0.01 * e, r = radius[k % 2];
            const int ax = (int)(k / 2 % 3);
            const double sg = k / 6 % 2 ? -0.8 : 0.8;
            double p[3];
            p[ax] = sg;
            p[(ax + 1) % 3] = r * cos(th);
            p[(ax + 2) % 3] = r * sin(th);
            const double dir[3] = {p[0] - eyes[e][0], p[1] - eyes[e][1], p[2] - eyes[e][2]};
            hits += against_refcast(&b, &w, rw, eyes[e], dir);
        }
    const double h = ldexp(b.tree->edge, -(int)b.tree->levels);
    for (unsigned k = 0; k < 900; k++) {
        const int ax = (int)(k % 3);
        double eye[3], dir[3];
        for (int a = 0; a < 3; a++) {
            /* on grid planes in the two other axes, outside along ax */
            eye[a] = a == ax ? -1.6 : b.tree->origin[a] + h * (double)(8 + (k * 7 + 13 * a) % 112);
            dir[a] = a == ax ? 1.0 : 0.0;
        }
        if (k % 2) /* oblique inside the plane of the first other axis */
            dir[(ax + 2) % 3] = 0.25 * cos(0.1 * k);
        hits += against_refcast(&b, &w, rw, eye, dir);
    }
    if (getenv("EXACT_VERBOSE"))
        printf("%u hits; fast %llu, slow %llu\n", hits, (unsigned long long)w.fast,
               (unsigned long long)w.slow);
    assert_true(hits > 2000);
    refcast_scratch_free(rw);
    exact_worker_free(&w);
    exact_built_free(&b);
}

/* gyroid_ball (scenes/gyroid_ball.scene): its rim's cells have both an
 * abs that changes sign and a max whose operands overlap, and get no
 * sub-cells (exact_sub_wanted); rays aimed at the rim, where the ball cuts
 * the sheet, and rays along voxel planes hit where refcast does, at levels
 * 7. */
static void test_gyroid_ball_vs_refcast(void **state)
{
    (void)state;
    static const char *const text =
        "bounds -1 -1 -1 1 1 1\n"
        "surface max(abs(sin(20*x)*cos(20*y) + sin(20*y)*cos(20*z) + sin(20*z)*cos(20*x)) - 0.2,"
        " x^2 + y^2 + z^2 - 0.81)\n";
    exact_built b;
    exact_built_make(text, 7, EXACT_CELL_DEPTH, &b);
    unsigned both = 0;
    for (uint32_t k = 0; k < b.es.ncand; k++)
        both += (b.es.cand[k].kinks & (TAPE_KINK_ABS | TAPE_KINK_MINMAX)) ==
                (TAPE_KINK_ABS | TAPE_KINK_MINMAX);
    assert_true(both > 20);
    exact_worker w;
    assert_int_equal(exact_worker_init(&w, &b.es), 0);
    refcast_scratch *rw = refcast_scratch_new(b.sc);
    assert_non_null(rw);
    static const double eyes[][3] = {{2.2, 1.6, 1.9}, {0.3, -2.6, 0.4}, {-1.5, 1.2, -2.1}};
    unsigned hits = 0;
    for (unsigned e = 0; e < 3; e++)
        for (unsigned k = 0; k < 400; k++) {
            /* a point of the ball's sphere on the side facing the eye */
            const double ph = acos(1.0 - 2.0 * (k + 0.5) / 400.0), th = 2.39996 * k;
            double p[3] = {0.9 * sin(ph) * cos(th), 0.9 * sin(ph) * sin(th), 0.9 * cos(ph)};
            if (p[0] * eyes[e][0] + p[1] * eyes[e][1] + p[2] * eyes[e][2] < 0.0)
                continue;
            const double dir[3] = {p[0] - eyes[e][0], p[1] - eyes[e][1], p[2] - eyes[e][2]};
            hits += against_refcast(&b, &w, rw, eyes[e], dir);
        }
    const double h = ldexp(b.tree->edge, -(int)b.tree->levels);
    for (unsigned k = 0; k < 300; k++) {
        const int ax = (int)(k % 3);
        double eye[3], dir[3];
        for (int a = 0; a < 3; a++) {
            eye[a] = a == ax ? -1.5 : b.tree->origin[a] + h * (double)(16 + (k * 7 + 13 * a) % 96);
            dir[a] = a == ax ? 1.0 : 0.0;
        }
        if (k % 2)
            dir[(ax + 1) % 3] = 0.3 * sin(0.1 * k);
        hits += against_refcast(&b, &w, rw, eye, dir);
    }
    if (getenv("EXACT_VERBOSE"))
        printf("gyroid_ball: %u cells with abs and max kinks, %u hits; fast %llu, slow %llu,"
               " sub-cells %llu\n", both, hits, (unsigned long long)w.fast,
               (unsigned long long)w.slow, (unsigned long long)w.sub.made);
    assert_true(hits > 500);
    refcast_scratch_free(rw);
    exact_worker_free(&w);
    exact_built_free(&b);
}

/* What a ray finds does not depend on the sub-cells its worker made before
 * (rays cast in reverse order, with a cache emptied every 64 sub-cells) nor
 * on the thread count (frame_render with 1 and 2 threads). */
static void test_order_and_threads(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make(csg, 8, EXACT_CELL_DEPTH, &b);
    camera cam;
    const double eye[3] = {2.2, 1.6, 1.9}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    const uint32_t size = 64;
    assert_int_equal(camera_init(&cam, eye, target, up, 30.0, size, size), CAMERA_OK);
    exact_worker w1, w2;
    assert_int_equal(exact_worker_init(&w1, &b.es), 0);
    assert_int_equal(exact_worker_init(&w2, &b.es), 0);
    w2.sub.max_nodes = 64;
    trace_opts o1 = {b.tree->levels, 0, &w1}, o2 = {b.tree->levels, 0, &w2};
    const uint32_t n = size * size;
    trace_hit *h1 = malloc(n * sizeof *h1);
    assert_non_null(h1);
    unsigned hits = 0;
    for (uint32_t k = 0; k < n; k++) {
        double dir[3];
        camera_ray(&cam, k % size, k / size, dir);
        trace_ray_cast(b.tree, &o1, cam.eye, dir, &h1[k]);
    }
    for (uint32_t k = n; k-- > 0;) {
        double dir[3];
        camera_ray(&cam, k % size, k / size, dir);
        trace_hit h;
        trace_ray_cast(b.tree, &o2, cam.eye, dir, &h);
        assert_int_equal(h.hit, h1[k].hit);
        if (!h.hit)
            continue;
        hits++;
        assert_memory_equal(&h.t, &h1[k].t, sizeof h.t);
        assert_memory_equal(h.normal, h1[k].normal, sizeof h.normal);
    }
    assert_true(hits > n / 4);
    assert_true(w2.sub.resets > 2);
    free(h1);
    exact_worker_free(&w1);
    exact_worker_free(&w2);

    const size_t px = (size_t)size * size;
    float *d[2], *nrm[2];
    uint8_t *rgb = malloc(px * 3);
    assert_non_null(rgb);
    for (unsigned t = 0; t < 2; t++) {
        d[t] = malloc(px * sizeof *d[t]);
        nrm[t] = malloc(3 * px * sizeof *nrm[t]);
        assert_true(d[t] && nrm[t]);
        frame_job job;
        memset(&job, 0, sizeof job);
        job.tree = b.tree;
        job.cam = &cam;
        job.opts.split = b.tree->levels;
        job.exact = &b.es;
        job.shade.ambient = 0.15f;
        shade_default_light(&cam, job.shade.light);
        job.rgb = rgb;
        job.depth = d[t];
        job.normals_f = nrm[t];
        job.threads = t + 1;
        job.beam_size = FRAME_BEAM_DEFAULT;
        frame_stats st;
        assert_int_equal(frame_render(&job, &st), 0);
    }
    assert_memory_equal(d[0], d[1], px * sizeof *d[0]);
    assert_memory_equal(nrm[0], nrm[1], 3 * px * sizeof *nrm[0]);
    for (unsigned t = 0; t < 2; t++) {
        free(d[t]);
        free(nrm[t]);
    }
    free(rgb);
    exact_built_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sub_cells),
        cmocka_unit_test(test_csg_creases_vs_refcast),
        cmocka_unit_test(test_gyroid_ball_vs_refcast),
        cmocka_unit_test(test_order_and_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
