/* Tests for render/exact_scene and `--exact` through the traversal: images
 * of small scenes rasterized in memory against the exact reference caster
 * (bench/refcast) within the targets, with the tapes the files
 * store (format 1.1); every traversal
 * implementation gives the same hits; roots on voxel faces; the nearest
 * root of several surfaces; a function undefined on part of the grid; the
 * coarse cells' candidate lists and pruned tapes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/compare.h"
#include "bench/refcast.h"
#include "common/expr/scene.h"
#include "render/exact_scene.h"
#include "render/frame.h"
#include "render/trace_impl.h"
#include "tests/exact_built.h"

static void look(camera *cam, const double eye[3], const double target[3], uint32_t size)
{
    const double up[3] = {0, 0, 1};
    assert_int_equal(camera_init(cam, eye, target, up, 30.0, size, size), CAMERA_OK);
}

/* --exact image (depth, float normals) through frame_render, beam on or off */
static void render_exact_kept(const exact_built *b, const camera *cam, unsigned beam,
                              frame_keep *keep, float *depth, float *nrm)
{
    const size_t px = (size_t)cam->width * cam->height;
    uint8_t *rgb = malloc(px * 3);
    assert_non_null(rgb);
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = b->tree;
    job.cam = cam;
    job.opts.split = b->tree->levels;
    job.exact = &b->es;
    job.shade.ambient = 0.15f;
    shade_default_light(cam, job.shade.light);
    job.rgb = rgb;
    job.depth = depth;
    job.normals_f = nrm;
    job.threads = 2;
    job.beam_size = beam;
    job.keep = keep;
    frame_stats st;
    assert_int_equal(frame_render(&job, &st), 0);
    free(rgb);
}

static void render_exact(const exact_built *b, const camera *cam, unsigned beam, float *depth,
                         float *nrm)
{
    render_exact_kept(b, cam, beam, NULL, depth, nrm);
}

/* The targets against refcast: mean depth error <= 0.001 voxel,
 * p99 <= 0.01 voxel, hit/miss disagreement <= 0.05 % of pixels (at least
 * one pixel allowed on these small images), normals within 0.01 degree, no
 * NaN anywhere. */
static void check_vs_refcast(const char *text, unsigned levels, const double eye[3],
                             const double target[3], uint32_t size)
{
    exact_built b;
    exact_built_make(text, levels, EXACT_CELL_DEPTH, &b);
    camera cam;
    look(&cam, eye, target, size);
    const size_t px = (size_t)size * size;
    float *d = malloc(px * sizeof *d), *n = malloc(3 * px * sizeof *n);
    float *rd = malloc(px * sizeof *rd), *rn = malloc(3 * px * sizeof *rn);
    float *d0 = malloc(px * sizeof *d0), *n0 = malloc(3 * px * sizeof *n0);
    assert_true(d && n && rd && rn && d0 && n0);
    render_exact(&b, &cam, FRAME_BEAM_DEFAULT, d, n);
    render_exact(&b, &cam, 0, d0, n0);
    /* the beam pre-pass changes where rays start, never what they hit */
    assert_memory_equal(d, d0, px * sizeof *d);
    assert_memory_equal(n, n0, 3 * px * sizeof *n);
    assert_int_equal(refcast_image(b.sc, &cam, 2, rd, rn, NULL, NULL), 0);
    for (size_t k = 0; k < px; k++) {
        assert_false(isnan(d[k]));
        for (int a = 0; a < 3; a++)
            assert_false(isnan(n[3 * k + (size_t)a]));
    }
    compare_stats cs;
    const double voxel = ldexp(b.tree->edge, -(int)levels);
    assert_int_equal(compare_depth(d, rd, px, voxel, n, rn, &cs), 0);
    const size_t allowed = px / 2000 > 1 ? px / 2000 : 1;
    if (!(cs.mean <= 0.001 && cs.p99 <= 0.01 && cs.disagree <= allowed &&
          (cs.both_hit == 0 || (cs.nmean <= 0.01 && cs.np99 <= 0.01))))
        fail_msg("%s: mean %.3g p99 %.3g vox, %zu of %zu disagree, normals %.3g / %.3g deg",
                 text, cs.mean, cs.p99, cs.disagree, px, cs.nmean, cs.np99);
    assert_true(cs.both_hit > px / 10); /* the view sees the surface */
    if (getenv("EXACT_VERBOSE"))
        printf("mean %.3g p99 %.3g max %.3g vox, %zu of %zu disagree, normals %.3g / %.3g deg\n",
               cs.mean, cs.p99, cs.max, cs.disagree, px, cs.nmean, cs.np99);
    free(d);
    free(n);
    free(rd);
    free(rn);
    free(d0);
    free(n0);
    exact_built_free(&b);
}

static const double eye_std[3] = {2.2, 1.6, 1.9}, centre[3] = {0, 0, 0};

static void test_sphere_vs_refcast(void **state)
{
    (void)state;
    check_vs_refcast("bounds -1 -1 -1 1 1 1\nsurface x^2 + y^2 + z^2 - 0.64\n", 7, eye_std,
                     centre, 64);
}

static void test_csg_vs_refcast(void **state)
{
    (void)state;
    /* creases of min/max and abs */
    check_vs_refcast("bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
                     "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
                     " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n",
                     7, eye_std, centre, 64);
}

static void test_thin_plate_vs_refcast(void **state)
{
    (void)state;
    /* 0.003 thick, a level-7 voxel is 0.0156: both faces in one voxel */
    check_vs_refcast("bounds -1 -1 -1 1 1 1\n"
                     "surface max(abs(z - 0.1 - 0.2*x) - 0.0015, x^2 + y^2 - 0.64)\n",
                     7, eye_std, centre, 64);
}

static void test_multi_surface_vs_refcast(void **state)
{
    (void)state;
    /* two overlapping balls and a torus: the nearest root of any wins */
    check_vs_refcast("bounds -1 -1 -1 1 1 1\n"
                     "surface (x-0.2)^2 + y^2 + z^2 - 0.25\ncolor 1 0 0\n"
                     "surface (x+0.2)^2 + y^2 + z^2 - 0.25\ncolor 0 1 0\n"
                     "surface (sqrt(x^2 + y^2) - 0.7)^2 + z^2 - 0.01\n",
                     7, eye_std, centre, 64);
}

static void test_undefined_vs_refcast(void **state)
{
    (void)state;
    /* undefined for x < -0.5 (sqrt of a negative) and at the log's 0 */
    check_vs_refcast("bounds -1 -1 -1 1 1 1\n"
                     "surface sqrt(x + 0.5) + 0.3*log(y^2 + z^2 + 0.25) - 0.5\n",
                     7, eye_std, centre, 64);
}

/* Every traversal implementation built gives the same exact hits, bit for
 * bit, and a ray's hit carries the surface refcast finds. */
static void test_impls_agree(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make("bounds -1 -1 -1 1 1 1\n"
          "surface (x-0.2)^2 + y^2 + z^2 - 0.25\nsurface (x+0.2)^2 + y^2 + z^2 - 0.25\n",
          6, 3, &b);
    exact_worker w;
    assert_int_equal(exact_worker_init(&w, &b.es), 0);
    refcast_scratch *rw = refcast_scratch_new(b.sc);
    assert_non_null(rw);
    camera cam;
    look(&cam, eye_std, centre, 40);
    trace_opts opts = {b.tree->levels, 0, &w};
    unsigned hits = 0;
    for (uint32_t j = 0; j < 40; j++)
        for (uint32_t i = 0; i < 40; i++) {
            double dir[3];
            camera_ray(&cam, i, j, dir);
            trace_ray r;
            if (!trace_setup(b.tree, cam.eye, dir, &r))
                continue;
            trace_hit h0, h;
            trace_impls[0].traverse(b.tree, &opts, &r, NULL, &h0);
            for (unsigned k = 1; k < trace_impl_count; k++) {
                trace_impls[k].traverse(b.tree, &opts, &r, NULL, &h);
                assert_int_equal(h.hit, h0.hit);
                if (h.hit) {
                    assert_true(h.t == h0.t && h.surface == h0.surface);
                    assert_memory_equal(h.normal, h0.normal, sizeof h.normal);
                }
            }
            refcast_hit rh;
            refcast_stats rs = {0, 0, 0, 0};
            refcast_ray(b.sc, rw, cam.eye, dir, &rh, &rs);
            assert_int_equal(h0.hit, rh.t < INFINITY);
            if (h0.hit) {
                hits++;
                assert_true(h0.exact);
                assert_true(fabs(h0.t - rh.t) <= 1e-9);
                if (fabs(h0.t - rh.t) > 1e-9 || rh.touch)
                    continue;
                /* where the balls meet both roots are one: either surface */
                double p[3];
                for (int a = 0; a < 3; a++)
                    p[a] = cam.eye[a] + h0.t * dir[a];
                if (fabs(p[0]) > 1e-6)
                    assert_int_equal(h0.surface, rh.surface);
            }
        }
    assert_true(hits > 200);
    refcast_scratch_free(rw);
    exact_worker_free(&w);
    exact_built_free(&b);
}

/* Roots on the grid planes: x = 0 is the face between voxels 31 and 32 at
 * level 6 (bounds -1..1), y = 0.25 the one between voxels 39 and 40; rays
 * along +x (some oblique) and +y from many starts find them to the ulp. */
static void test_roots_on_faces(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make("bounds -1 -1 -1 1 1 1\nsurface x\nsurface y - 0.25\n", 6,
          EXACT_CELL_DEPTH, &b);
    exact_worker w;
    assert_int_equal(exact_worker_init(&w, &b.es), 0);
    trace_opts opts = {b.tree->levels, 0, &w};
    for (unsigned k = 0; k < 200; k++) {
        const double eye[3] = {-1.5, -0.9 + 0.0089 * k, 0.37 - 0.003 * k};
        const double dir[3] = {1, 0, k % 2 ? 1e-3 : 0};
        for (unsigned m = 0; m < trace_impl_count; m++) {
            trace_ray r;
            assert_true(trace_setup(b.tree, eye, dir, &r));
            trace_hit h;
            trace_impls[m].traverse(b.tree, &opts, &r, NULL, &h);
            assert_true(h.hit && h.exact);
            /* y - 0.25 is never crossed */
            if (!(fabs(h.t - 1.5) <= 4.5e-16))
                fail_msg("ray %u: t = %.17g", k, h.t);
            assert_int_equal(h.surface, 0);
        }
    }
    for (unsigned k = 0; k < 50; k++) { /* (x = 0 never: these rays lie beside it) */
        const double eye[3] = {-0.305 + 0.0123 * k, -1.5, 0.1}, dir[3] = {0, 1, 0};
        trace_hit h;
        trace_ray_cast(b.tree, &opts, eye, dir, &h);
        assert_true(h.hit && h.surface == 1 && h.t == 1.75);
    }
    exact_worker_free(&w);
    exact_built_free(&b);
}

/* The fast path (render/exact_fast.c) against the fallback alone (the
 * same scene with every candidate's Hessian bound off): the same hits and
 * misses; t identical or within the noise band of the root, here 2^-46 of
 * t (64 ulps), and normals within 1e-9. The fast path reports a Newton
 * point inside a certified enclosure of the root no wider than twice the
 * band where the double evaluation of f is noise, the fallback a sign
 * change of that evaluation between adjacent doubles inside it
 * (RENDER.md, "The fast path"): the same t for a third of the hits at
 * least (often the same on the caller's ray), a few ulps of the local t
 * apart otherwise. Rays: camera rays, grazing rays along the silhouette,
 * axis-aligned rays (zero direction components), rays in voxel planes
 * (level 7 over [-1, 1]: planes at multiples of 1/64, so for `plane_box`
 * scenes) and rays near tangent to the sphere of radius 0.8 about the
 * centre (aimed at distances 0.8 (1 + 2^-k) from it). The fast path takes
 * the cells' a-priori bound on every tape; with `bounded`, its evaluations
 * mostly use it
 * (tape_err_cell), few models that it cannot decide are decided by the
 * per-point one, a quarter of the hits at least are placed past the voxel
 * whose span was tested (root_beyond in exact_voxel.c), and some voxels are
 * passed untested inside spans it certified root-free. */
static void fast_vs_fallback(const char *text, const double target[3], double min_fast,
                             int bounded)
{
    exact_built b;
    exact_built_make(text, 7, EXACT_CELL_DEPTH, &b);
    exact_scene off = b.es;
    off.sub_max = 0; /* no sub-cells either */
    off.cand = malloc(b.es.ncand * sizeof *off.cand + 1);
    assert_non_null(off.cand);
    memcpy(off.cand, b.es.cand, b.es.ncand * sizeof *off.cand);
    for (uint32_t k = 0; k < off.ncand; k++)
        for (int e = 0; e < 6; e++)
            off.cand[k].hmag[e] = off.cand[k].hbranch[e] = INFINITY;
    exact_worker w1, w2;
    assert_int_equal(exact_worker_init(&w1, &b.es), 0);
    assert_int_equal(exact_worker_init(&w2, &off), 0);
    w1.bound_min_n = 0; /* the a-priori bound on short tapes too */
    trace_opts o1 = {b.tree->levels, 0, &w1}, o2 = {b.tree->levels, 0, &w2};
    camera cam;
    look(&cam, eye_std, target, 64);
    unsigned hits = 0, same = 0;
    double dn_max = 0.0;
    for (unsigned k = 0; k < 64 * 64 + 5 * 400; k++) {
        double eye[3], dir[3];
        if (k < 64 * 64) {
            memcpy(eye, cam.eye, sizeof eye);
            camera_ray(&cam, k % 64, k / 64, dir);
        } else if (k < 64 * 64 + 400) { /* grazing the unit-ish silhouette along +y */
            const double u = (double)(k - 64 * 64) / 400.0;
            eye[0] = 0.3 + 0.6 * u;
            eye[1] = -1.5;
            eye[2] = 0.05 * sin(40.0 * u);
            dir[0] = 0.0;
            dir[1] = 1.0;
            dir[2] = 1e-3 * cos(17.0 * u);
        } else if (k >= 64 * 64 + 3 * 400) { /* in voxel planes; near tangent */
            const unsigned j = k - 64 * 64 - 3 * 400;
            const double u = (double)(j % 400) / 400.0;
            if (j < 400) { /* z a multiple of 1/64: a voxel plane whatever the box */
                eye[0] = -1.5;
                eye[1] = -0.9 + 1.8 * u;
                eye[2] = (double)((int)(j % 97) - 48) / 64.0;
                dir[0] = 1.0;
                dir[1] = 0.25 * cos(7.0 * u);
                dir[2] = 0.0;
            } else { /* off the centre by 0.8 (1 +- 2^-k) along y, along +x and skewed */
                const double dist = 0.8 * (1.0 + (j % 2 ? 1.0 : -1.0) * ldexp(1.0, -(int)(j % 45)));
                eye[0] = target[0] - 1.5;
                eye[1] = target[1] + dist * cos(u);
                eye[2] = target[2] + dist * sin(u);
                dir[0] = 1.0;
                dir[1] = 0.0;
                dir[2] = j % 3 ? 0.0 : 1e-9;
            }
        } else { /* along the axes, from starts on a line */
            const unsigned j = k - 64 * 64 - 400, ax = j % 3;
            const double u = (double)(j / 3) / 400.0 * 3.0;
            for (unsigned a = 0; a < 3; a++) {
                eye[a] = a == ax ? -1.5 : -0.9 + 1.8 * (a == (ax + 1) % 3 ? u : 1.0 - u);
                dir[a] = a == ax ? 1.0 : 0.0;
            }
        }
        trace_hit h1, h2;
        trace_ray_cast(b.tree, &o1, eye, dir, &h1);
        trace_ray_cast(b.tree, &o2, eye, dir, &h2);
        if (h1.hit != h2.hit)
            fail_msg("%s: ray %u: hit %d, fallback %d (t %.17g / %.17g)", text, k, h1.hit,
                     h2.hit, h1.t, h2.t);
        if (!h1.hit)
            continue;
        hits++;
        /* (two local roots a few ulps apart may give one t on the caller's ray) */
        if (h1.t == h2.t) {
            same++;
            assert_int_equal(h1.surface, h2.surface);
        } else if (!(fabs(h1.t - h2.t) <= 0x1p-46 * h1.t)) { /* (64 ulps at most) */
            fail_msg("%s: ray %u: t %.17g, fallback %.17g", text, k, h1.t, h2.t);
        }
        /* the fast path's normal is f's gradient at its last evaluation, one
         * Newton step from its t inside the root's enclosure (at most 5.2e-8
         * apart on these scenes); the fallback's at its t */
        for (int a = 0; a < 3; a++) {
            const double dn = fabs((double)h1.normal[a] - (double)h2.normal[a]);
            dn_max = dn > dn_max ? dn : dn_max;
            assert_true(dn <= 1e-6);
        }
    }
    if (getenv("EXACT_VERBOSE"))
        printf("%u hits, %u the same (normals at most %.3g apart); fast %llu, slow %llu, beyond "
               "%llu, skipped %llu; a-priori bound %llu, retried %llu, rescued %llu\n", hits, same,
               dn_max, (unsigned long long)w1.fast, (unsigned long long)w1.slow,
               (unsigned long long)w1.beyond, (unsigned long long)w1.skipped,
               (unsigned long long)w1.scratch.nbound,
               (unsigned long long)w1.scratch.nretry, (unsigned long long)w1.scratch.nrescue);
    if (bounded) {
        assert_true(w1.scratch.nbound > (uint64_t)hits && w1.scratch.nrescue * 20 < hits);
        /* most roots of a smooth surface are placed from the ray's first
         * voxel of the cell that holds them (root_beyond) */
        assert_true(w1.beyond * 4 >= hits);
        /* and rays that pass a shell's first voxels without a root skip
         * some of the next ones (a span certified root-free past them) */
        assert_true(w1.skipped > 0);
    }
    assert_true(hits > 500);
    assert_true(same * 3 >= hits);
    assert_true(w2.fast == 0);
    /* (a voxel skipped lies in a span the fast path certified root-free) */
    const double decided = (double)(w1.fast + w1.skipped);
    assert_true(decided >= min_fast * (decided + (double)w1.slow));
    exact_worker_free(&w1);
    exact_worker_free(&w2);
    free(off.cand);
    exact_built_free(&b);
}

static void test_fast_vs_fallback(void **state)
{
    (void)state;
    static const double mid[3] = {0.5, 0.5, 0.5};
    fast_vs_fallback("bounds -1 -1 -1 1 1 1\nsurface x^2 + y^2 + z^2 - 0.64\n", centre, 0.95, 1);
    fast_vs_fallback("bounds -0.5 -0.5 -0.5 1.5 1.5 1.5\nsurface exp(-3.25*((x-0.78)^2+"
                     "(y-0.78)^2+(z-0.78)^2)) + exp(-3.25*((x-0.23)^2+(y-0.23)^2+(z-0.23)^2))"
                     " - 0.9\n",
                     mid, 0.95, 1);
    fast_vs_fallback("bounds -1.3 -1.3 -1.3 1.3 1.3 1.3\n"
                     "surface (x^2 + y^2 + z^2 + 0.6^2 - 0.25^2)^2 - 4*0.6^2*(x^2 + y^2)\n",
                     centre, 0.9, 1);
    /* a kink off the surface in most cells (|G| = 0.3: G's zero set a few
     * voxels away), no sub-cells: the bound with the kinks allowed on spans
     * where the kink is decided (branch_test) */
    fast_vs_fallback("bounds -1 -1 -1 1 1 1\nsurface abs(sin(4*x)*cos(4*y) + sin(4*y)*cos(4*z)"
                     " + sin(4*z)*cos(4*x)) - 0.3\n",
                     centre, 0.7, 0);
    /* creases: the sub-cells along them keep the fallback */
    fast_vs_fallback("bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
                     "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
                     " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n",
                     centre, 0.5, 0);
}

/* What a ray finds depends on that ray alone, not on what its worker
 * traced before (the worker keeps the last ray's line, models, curvature
 * bounds and sub-cells): rays traced by one worker one after another, each
 * twice in a row and the one before it again after it, give bit for bit the
 * hits a fresh worker gives each of them alone, with every traversal
 * implementation; on two surfaces, one with creases (sub-cells there). */
static int same_hit(const trace_hit *a, const trace_hit *b)
{
    if (a->hit != b->hit)
        return 0;
    return !a->hit || (!memcmp(&a->t, &b->t, sizeof a->t) && a->surface == b->surface &&
                       !memcmp(a->normal, b->normal, sizeof a->normal));
}

static void test_ray_alone(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make("bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
                     "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
                     " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n"
                     "surface (x - 0.3)^2 + y^2 + (z - 0.5)^2 - 0.2\n",
                     7, EXACT_CELL_DEPTH, &b);
    enum { N = 32 };
    camera cam;
    look(&cam, eye_std, centre, N);
    for (unsigned m = 0; m < trace_impl_count; m++) {
        static trace_hit alone[N * N];
        double dirs[N * N][3];
        unsigned hits = 0;
        for (uint32_t k = 0; k < N * N; k++) {
            camera_ray(&cam, k % N, k / N, dirs[k]);
            exact_worker f;
            assert_int_equal(exact_worker_init(&f, &b.es), 0);
            const trace_opts fo = {b.tree->levels, 0, &f};
            trace_ray r;
            alone[k].hit = 0;
            if (trace_setup(b.tree, cam.eye, dirs[k], &r))
                trace_impls[m].traverse(b.tree, &fo, &r, NULL, &alone[k]);
            hits += (unsigned)alone[k].hit;
            exact_worker_free(&f);
        }
        assert_true(hits > N * N / 4);
        exact_worker w;
        assert_int_equal(exact_worker_init(&w, &b.es), 0);
        const trace_opts o = {b.tree->levels, 0, &w};
        for (uint32_t k = 0; k < N * N; k++)
            for (unsigned rep = 0; rep < 3; rep++) {
                const uint32_t q = rep == 2 && k ? k - 1 : k;
                trace_ray r;
                trace_hit h;
                h.hit = 0;
                if (trace_setup(b.tree, cam.eye, dirs[q], &r))
                    trace_impls[m].traverse(b.tree, &o, &r, NULL, &h);
                if (!same_hit(&h, &alone[q]))
                    fail_msg("%s: ray %u (pass %u): t %.17g, alone %.17g",
                             trace_impls[m].name, q, rep, h.t, alone[q].t);
            }
        exact_worker_free(&w);
    }
    exact_built_free(&b);
}

/* A run of views keeps its exact workers (frame_keep), with the sub-cells
 * and bounds they made and the last ray of the frame before: every frame
 * is bit for bit the one a fresh frame gives, views repeated or not. */
static void test_views_keep_workers(void **state)
{
    (void)state;
    exact_built b;
    exact_built_make("bounds -1.1 -1.1 -1.1 1.1 1.1 1.1\n"
                     "surface max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0,"
                     " 0.16 - min(x^2 + y^2, y^2 + z^2, z^2 + x^2))\n"
                     "surface exp(-3*((x-0.2)^2 + y^2 + z^2)) + exp(-3*(x^2 + (y-0.3)^2 + z^2))"
                     " + exp(-3*(x^2 + y^2 + (z+0.2)^2)) + 0.2*x - 1.1\n",
                     8, EXACT_CELL_DEPTH, &b);
    enum { N = 48, PX = N * N };
    const double eyes[][3] = {{2.2, 1.6, 1.9}, {-2.4, 2.0, 1.0}, {2.2, 1.6, 1.9}, {0.5, -3.0, 2.5},
                              {-2.4, 2.0, 1.0}};
    static float d[PX], n[3 * PX], d0[PX], n0[3 * PX];
    frame_keep keep;
    memset(&keep, 0, sizeof keep);
    size_t hits = 0;
    for (size_t v = 0; v < sizeof eyes / sizeof eyes[0]; v++) {
        camera cam;
        look(&cam, eyes[v], centre, N);
        render_exact_kept(&b, &cam, FRAME_BEAM_DEFAULT, &keep, d, n);
        assert_non_null(keep.exact);
        render_exact(&b, &cam, FRAME_BEAM_DEFAULT, d0, n0);
        assert_memory_equal(d, d0, sizeof d);
        assert_memory_equal(n, n0, sizeof n);
        for (size_t k = 0; k < PX; k++)
            hits += d[k] < INFINITY;
    }
    assert_true(hits > PX); /* the views see the surfaces */
    frame_keep_free(&keep);
    assert_null(keep.exact);
    exact_built_free(&b);
}

/* The coarse cells: a far surface is no candidate in a cell it cannot
 * reach, and a long sum of far blobs is pruned to a few instructions. */
static void test_cells_prune(void **state)
{
    (void)state;
    char text[8192] = "bounds 0 0 0 1 1 1\nsurface ";
    for (int k = 0; k < 20; k++) {
        char term[128];
        snprintf(term, sizeof term, "exp(-400*((x-%.3f)^2+(y-%.3f)^2+(z-0.5)^2)) + ",
                 0.1 + 0.04 * k, 0.15 + 0.15 * (k % 5));
        strcat(text, term);
    }
    strcat(text, "0 - 0.5\nsurface (x-0.9)^2 + (y-0.9)^2 + (z-0.9)^2 - 0.0025\n");
    exact_built b;
    exact_built_make(text, 6, 4, &b);
    assert_int_equal(b.es.depth, 4);
    assert_true(b.es.ncells > 0 && b.es.ncand >= b.es.ncells);
    /* every cell has one candidate at most here: the blobs and the small
     * ball lie apart */
    for (uint32_t c = 0; c < b.es.ncells; c++)
        assert_true(b.es.first[c + 1] - b.es.first[c] <= 1);
    assert_true(b.es.whole_insns > 100);
    if (getenv("EXACT_VERBOSE"))
        printf("cells %u cand %u insns %llu -> %llu, cull %llu\n", b.es.ncells, b.es.ncand,
               (unsigned long long)b.es.whole_insns, (unsigned long long)b.es.pruned_insns,
               (unsigned long long)b.es.cull_insns);
    assert_true(b.es.pruned_insns * 2 < b.es.whole_insns);
    /* the culling tapes, pruned with the rasterizer's threshold, are shorter still */
    assert_true(b.es.cull_insns < b.es.pruned_insns);
    exact_built_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_vs_refcast),
        cmocka_unit_test(test_csg_vs_refcast),
        cmocka_unit_test(test_thin_plate_vs_refcast),
        cmocka_unit_test(test_multi_surface_vs_refcast),
        cmocka_unit_test(test_undefined_vs_refcast),
        cmocka_unit_test(test_impls_agree),
        cmocka_unit_test(test_roots_on_faces),
        cmocka_unit_test(test_fast_vs_fallback),
        cmocka_unit_test(test_ray_alone),
        cmocka_unit_test(test_views_keep_workers),
        cmocka_unit_test(test_cells_prune),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
