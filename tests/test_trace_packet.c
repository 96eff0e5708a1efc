/* Tests for render/trace_packet: every ray of a packet gets the hit, voxel,
 * xyz and t that the traversal (every implementation built, from the
 * root) gives it alone, on random sparse trees with packets of nearby
 * directions, rays on voxel planes, axis-aligned and zero-component
 * directions and clipped starts; on a sphere's shell with the samples of
 * the pixels along its silhouette (grazing rays); and packets whose
 * directions disagree in sign are refused. The walk is checked as the
 * build takes it (SSE2 steps on x86) and in plain C. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench/tree_util.h"
#include "common/view/camera.h"
#include "render/aa.h"
#include "render/trace_packet.h"
#include "tests/trace_oracle.h"
#include "tests/voxel_shapes.h"

static uint64_t rng_state = 0x2545f4914f6cdd1du;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static double urand(void) { return (double)(rng() >> 11) * 0x1p-53; }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

typedef struct counts {
    unsigned long packets, rays, hits;
} counts;

/* The packet walks built: the build's own and the plain C one. */
typedef void (*packet_fn)(const oct_tree *, const trace_ray *, unsigned, trace_hit *);
static const packet_fn walks[] = {trace_packet_first, trace_packet_first_portable};

/* One walk's hits for the packet against the traversal's, h[k] for ray k. */
static void check_walk(const oct_tree *t, packet_fn walk, const trace_ray *r, unsigned n,
                       const trace_hit *h0)
{
    trace_hit ph[TRACE_PACKET_MAX];
    walk(t, r, n, ph);
    for (unsigned k = 0; k < n; k++) {
        const trace_hit *h = &h0[k];
        if (h->hit != ph[k].hit || (h->hit && (h->voxel != ph[k].voxel || h->t != ph[k].t ||
                                               memcmp(h->xyz, ph[k].xyz, sizeof h->xyz) != 0)))
            print_error("%s walk, ray %u of %u: o %a %a %a d %a %a %a [%a, %a): traversal %d "
                        "(%u %u %u) t %a, packet %d (%u %u %u) t %a\n",
                        walk == trace_packet_first ? "build's" : "plain C", k, n, r[k].o[0],
                        r[k].o[1], r[k].o[2], r[k].d[0], r[k].d[1], r[k].d[2], r[k].t_start,
                        r[k].t_end, h->hit, h->xyz[0], h->xyz[1], h->xyz[2], h->t, ph[k].hit,
                        ph[k].xyz[0], ph[k].xyz[1], ph[k].xyz[2], ph[k].t);
        assert_int_equal(ph[k].hit, h->hit);
        assert_int_equal(ph[k].steps, 0);
        assert_int_equal(ph[k].exact, 0);
        if (h->hit) {
            assert_true(ph[k].voxel == h->voxel);
            assert_true(ph[k].t == h->t);
            assert_memory_equal(ph[k].xyz, h->xyz, sizeof h->xyz);
        }
    }
}

/* Each ray of the packet, by every packet walk, against the traversal of
 * it alone. */
static void check_packet(const oct_tree *t, const trace_ray *r, unsigned n, counts *c)
{
    trace_hit h[TRACE_PACKET_MAX];
    const trace_opts plain = {t->levels, 0, NULL};
    for (unsigned k = 0; k < n; k++)
        trace_prepared_all(t, &plain, &r[k], &h[k]);
    for (unsigned wi = 0; wi < sizeof walks / sizeof walks[0]; wi++)
        check_walk(t, walks[wi], r, n, h);
    for (unsigned k = 0; k < n; k++) {
        c->rays++;
        c->hits += (unsigned long)h[k].hit;
    }
    c->packets++;
}

/* A coordinate on a grid plane, a root face, a dyadic point, anywhere. */
static double pick_coord(uint32_t lim)
{
    switch (irand(5)) {
    case 0: return (double)irand(lim + 1);
    case 1: return irand(2) ? 0.0 : (double)lim;
    case 2: return -1.5 * lim + 4.0 * lim * urand();
    case 3: return (double)irand(lim) + (double)irand(8) / 8.0;
    default: return (double)lim * urand();
    }
}

/* A direction component: zero of either sign, tiny, axis-like, any. */
static double pick_dir(void)
{
    switch (irand(8)) {
    case 0: return 0.0;
    case 1: return -0.0;
    case 2: return irand(2) ? 1e-30 : -1e-30;
    case 3: return irand(2) ? 1.0 : -1.0;
    default: return 2.0 * urand() - 1.0;
    }
}

/* Ray k of a packet: the base direction, the same, moved a little (keeping
 * its signs), or with a component zeroed; from the base eye or one moved
 * along a grid plane; a third clipped to start at a plane time or
 * anywhere before the ray's end. Returns 0 when it misses the cube. */
static int packet_ray(const oct_tree *t, const double eye[3], const double dir[3], trace_ray *r)
{
    const uint32_t lim = UINT32_C(1) << t->levels;
    double e[3], d[3];
    memcpy(e, eye, sizeof e);
    memcpy(d, dir, sizeof d);
    switch (irand(4)) {
    case 0: break;
    case 1:
        for (int a = 0; a < 3; a++)
            d[a] *= 1.0 + 0.05 * urand();
        break;
    case 2: d[irand(3)] = 0.0; break;
    default:
        for (int a = 0; a < 3; a++)
            e[a] += (double)irand(3) - 1.0;
    }
    for (int a = 0; a < 3; a++)
        e[a] *= t->edge / (double)lim;
    if (!trace_setup(t, e, d, r))
        return 0;
    if (irand(3) == 0) {
        const int a = (int)irand(3);
        double lo = r->t_base + (r->t_end - r->t_start) * urand();
        if (r->active >> a & 1u) {
            const double tp = trace_plane_time(r, a, (double)irand(lim + 1));
            if (tp >= 0.0 && tp < r->t_end)
                lo = r->t_base + tp;
        }
        if (!trace_clip(r, lo, INFINITY))
            return 0;
    }
    return 1;
}

static void test_random_trees(void **state)
{
    (void)state;
    static const double density[] = {0.001, 0.01, 0.05, 0.2, 0.6};
    counts c = {0, 0, 0};
    unsigned long refused = 0;
    for (unsigned levels = 1; levels <= 7; levels++)
        for (unsigned ti = 0; ti < 10; ti++) {
            const uint32_t lim = UINT32_C(1) << levels;
            size_t want = (size_t)(density[ti % 5] * (double)lim * lim * lim) + 1;
            if (want > 4000)
                want = 4000;
            uint32_t(*xyz)[3] = malloc(want * sizeof *xyz);
            assert_non_null(xyz);
            const size_t m = tree_util_distinct_voxels(want, 0, lim, &rng_state, xyz);
            const double origin[3] = {ti % 2 ? -0.75 : 0.0, 0.0, ti % 3 ? 3.0 : 0.0};
            oct_tree *t = tree_util_build(levels, origin, 2.0, (const uint32_t(*)[3])xyz, m, NULL,
                                          NULL, 1, NULL);
            assert_non_null(t);
            for (unsigned pk = 0; pk < 300; pk++) {
                double g[3], dir[3];
                for (int a = 0; a < 3; a++) {
                    g[a] = pick_coord(lim);
                    dir[a] = pick_dir();
                }
                if (pk % 3 == 0) /* aimed at a voxel corner, edge or centre */
                    for (int a = 0; a < 3; a++)
                        dir[a] = (double)irand(lim + 1) + (irand(2) ? 0.5 : 0.0) - g[a];
                if (dir[0] == 0.0 && dir[1] == 0.0 && dir[2] == 0.0)
                    dir[irand(3)] = 1.0;
                for (int a = 0; a < 3; a++)
                    g[a] += origin[a] * (double)lim / 2.0; /* packet_ray scales by edge / lim */
                const unsigned n = 1 + irand(TRACE_PACKET_MAX);
                trace_ray r[TRACE_PACKET_MAX];
                unsigned got = 0;
                for (unsigned k = 0; k < n; k++)
                    got += (unsigned)packet_ray(t, g, dir, &r[got]);
                if (!trace_packet_fits(r, got)) {
                    refused++;
                    continue;
                }
                check_packet(t, r, got, &c);
            }
            tree_util_free(t);
            free(xyz);
        }
    print_message("packets: %lu (%lu refused), %lu rays, %lu hits\n", c.packets, refused, c.rays,
                  c.hits);
    assert_true(c.packets > 15000);
    assert_true(c.hits > c.rays / 5);
}

/* Axis-aligned and diagonal rays from points on voxel planes, edges and
 * corners, in packets mixing directions with zero components. */
static void test_planes_and_axes(void **state)
{
    (void)state;
    const unsigned levels = 5;
    const uint32_t lim = UINT32_C(1) << levels;
    uint32_t xyz[2000][3];
    const size_t m = tree_util_distinct_voxels(2000, 0, lim, &rng_state, xyz);
    oct_tree *t = tree_util_simple(levels, (const uint32_t(*)[3])xyz, m);
    assert_non_null(t);
    counts c = {0, 0, 0};
    for (unsigned pk = 0; pk < 4000; pk++) {
        double sgn[3];
        for (int a = 0; a < 3; a++)
            sgn[a] = irand(2) ? 1.0 : -1.0;
        const unsigned n = 1 + irand(TRACE_PACKET_MAX);
        trace_ray r[TRACE_PACKET_MAX];
        unsigned got = 0;
        for (unsigned k = 0; k < n; k++) {
            double e[3], d[3];
            for (int a = 0; a < 3; a++) {
                /* on a plane, an edge or a corner; sometimes outside */
                e[a] = ((double)irand(lim + 5) - 2.0 + (irand(3) == 0 ? 0.5 : 0.0)) / lim;
                d[a] = irand(3) == 0 ? (irand(2) ? 0.0 : -0.0) : sgn[a] * (irand(2) ? 1.0 : 0.5);
            }
            if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
                d[irand(3)] = 1.0;
            got += (unsigned)trace_setup(t, e, d, &r[got]);
        }
        if (trace_packet_fits(r, got))
            check_packet(t, r, got, &c);
    }
    print_message("plane packets: %lu, %lu rays, %lu hits\n", c.packets, c.rays, c.hits);
    assert_true(c.packets > 3000 && c.hits > c.rays / 4);
    tree_util_free(t);
}

/* The N x N samples of every pixel along a sphere's silhouette (and of
 * the others), as the frame makes them: grazing rays through the shell's
 * smallest cells, some clipped at a start before their hit. */
static void test_sphere_silhouette_samples(void **state)
{
    (void)state;
    const unsigned levels = 8;
    const double n = (double)(1u << levels), cen = 0.5 * n;
    shape sh = shape_sphere(cen, cen, cen, 90.0);
    oct_tree *t = shapes_build(levels, 1.0, &sh, 1, 1);
    assert_non_null(t);
    const uint32_t w = 48, hgt = 40;
    const double eye[3] = {0.5, -1.3, 0.62}, target[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1};
    camera cam;
    assert_int_equal(camera_init(&cam, eye, target, up, 24.0, w, hgt), CAMERA_OK);
    trace_eye te;
    assert_true(trace_eye_init(t, cam.eye, &te));
    counts c = {0, 0, 0};
    unsigned long mixed = 0, refused = 0;
    for (uint32_t j = 0; j < hgt; j++)
        for (uint32_t i = 0; i < w; i++) {
            const unsigned na = 4;
            trace_ray r[16];
            unsigned got = 0;
            for (unsigned k = 0; k < na * na; k++) {
                double fx, fy, dir[3];
                aa_sample_offset(na, k, &fx, &fy);
                const double u = (2.0 * (i + fx) / w - 1.0) * cam.h * w / hgt;
                const double v = (1.0 - 2.0 * (j + fy) / hgt) * cam.h;
                camera_ray_uv(&cam, u, v, dir);
                got += (unsigned)trace_setup_eye(&te, dir, &r[got]);
            }
            if ((i + j) % 2)
                for (unsigned k = 0; k < got; k++) { /* a start some way along */
                    trace_ray rc = r[k];
                    if (trace_clip(&rc, rc.t_base + 0.3 * rc.t_end, INFINITY))
                        r[k] = rc;
                }
            if (!trace_packet_fits(r, got)) { /* the middle column: x of the
                                                   direction changes sign */
                refused++;
                continue;
            }
            const unsigned long h0 = c.hits;
            check_packet(t, r, got, &c);
            mixed += c.hits != h0 && c.hits - h0 < got;
        }
    print_message("sphere: %lu pixels (%lu refused), %lu of them part hit, part missed\n",
                  c.packets, refused, mixed);
    assert_true(mixed > 40 && refused <= 2 * hgt);
    tree_util_free(t);
}

/* Signs that disagree cannot share the walk's order. */
static void test_fits(void **state)
{
    (void)state;
    const uint32_t xyz[1][3] = {{1, 1, 1}};
    oct_tree *t = tree_util_simple(2, xyz, 1);
    assert_non_null(t);
    const double e[3] = {0.1, 0.1, 0.1};
    const double d0[3] = {1, 1, 1}, d1[3] = {1, -1, 1}, d2[3] = {1, 0, 1}, d3[3] = {1, -0.0, 1};
    trace_ray r[3];
    assert_true(trace_setup(t, e, d0, &r[0]));
    assert_true(trace_setup(t, e, d1, &r[1]));
    assert_true(trace_setup(t, e, d2, &r[2]));
    assert_true(trace_packet_fits(r, 1));
    assert_false(trace_packet_fits(r, 2));
    r[1] = r[2]; /* a zero axis agrees with both */
    assert_true(trace_packet_fits(r, 2));
    assert_true(trace_setup(t, e, d3, &r[2]));
    assert_true(trace_packet_fits(r, 3));
    assert_false(trace_packet_fits(r, TRACE_PACKET_MAX + 1));
    counts c = {0, 0, 0};
    check_packet(t, r, 3, &c);
    assert_int_equal(c.hits, 1); /* the two along y = 0.4 pass below the voxel */
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fits),
        cmocka_unit_test(test_random_trees),
        cmocka_unit_test(test_planes_and_axes),
        cmocka_unit_test(test_sphere_silhouette_samples),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
