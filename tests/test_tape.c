/* Tests for common/expr/tape on the example scenes: point evaluation of
 * every scene against hand-written C, gradients against central
 * differences, interval and interval-gradient enclosures, the lane
 * evaluator against the one-point one, and the rules for undefined points.
 * Random trees and pruning are in test_tape_prune.c. Run from the
 * repository root (reads scenes/). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "common/expr/sincos_kernel.h"
#include "common/expr/tape.h"
#include "tests/test_tape_util.h"
#include "tests/scene_util.h"

/* ---- the scenes in plain C ---------------------------------------------- */

static double sq(double v) { return v * v; }
static double r2(double x, double y, double z, double a, double b, double c)
{
    return sq(x - a) + sq(y - b) + sq(z - c);
}
static double mn(double a, double b) { return a < b ? a : b; }
static double mx(double a, double b) { return a > b ? a : b; }

static double f_blobs_a(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    return exp(-3.25 * r2(x, y, z, 0.78, 0.78, 0.78)) + exp(-3.25 * r2(x, y, z, 0.23, 0.23, 0.23)) - 0.9;
}
static double f_blobs_b(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    return exp(-196 * (sq(sq(x - 0.23)) + sq(sq(y - 0.23)) + sq(sq(z - 0.68)))) +
           exp(-196 * (sq(sq(x - 0.68)) + sq(sq(y - 0.68)) + sq(sq(z - 0.23)))) +
           exp(-7 * r2(x, y, z, 0.68, 0.68, 0.68)) + exp(-7 * r2(x, y, z, 0.23, 0.23, 0.23)) - 0.9;
}
static double f_sphere(const double *p, int s)
{
    (void)s;
    return sq(p[0]) + sq(p[1]) + sq(p[2]) - 1;
}
static double f_torus(const double *p, int s)
{
    (void)s;
    return sq(sqrt(sq(p[0]) + sq(p[1])) - 1) + sq(p[2]) - sq(0.3);
}
static double f_csg(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    double cube = mx(mx(fabs(x), fabs(y)), fabs(z)) - 0.8;
    double ball = sq(x) + sq(y) + sq(z) - 1.0;
    double cyl = 0.16 - mn(mn(sq(x) + sq(y), sq(y) + sq(z)), sq(z) + sq(x));
    return mx(mx(cube, ball), cyl);
}
static double f_gyroid(const double *p, int s)
{
    (void)s;
    double k = 3 * M_PI, x = p[0], y = p[1], z = p[2];
    double g = sin(k * x) * cos(k * y) + sin(k * y) * cos(k * z) + sin(k * z) * cos(k * x);
    return mx(fabs(g) - 0.3, sq(x) + sq(y) + sq(z) - 1);
}
static double f_barth(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2], ph = (1 + sqrt(5)) / 2, p2 = sq(ph);
    double f = 4 * (p2 * sq(x) - sq(y)) * (p2 * sq(y) - sq(z)) * (p2 * sq(z) - sq(x)) -
               (1 + 2 * ph) * sq(sq(x) + sq(y) + sq(z) - 1);
    return mx(f, sq(x) + sq(y) + sq(z) - sq(1.6));
}
static double f_thin(const double *p, int s)
{
    double x = p[0], y = p[1], z = p[2];
    if (s == 0)
        return mx(fabs(z - 0.1) - 0.001, sq(x) + sq(y) - 0.64);
    return mx(fabs(sqrt(sq(x) + sq(y) + sq(z)) - 0.5) - 0.0015, -z - 0.2);
}
static double f_multi(const double *p, int s)
{
    double x = p[0], y = p[1], z = p[2];
    if (s == 0)
        return sq(x + 1.2) + sq(y) + sq(z) - sq(0.6);
    if (s == 1)
        return sq(sqrt(sq(x) + sq(z)) - 0.55) + sq(y) - sq(0.18);
    return sq(sq(x - 1.25)) + sq(sq(y)) + sq(sq(z)) - sq(sq(0.55));
}
static const double blob_c[20][3] = {
    {0.394, 0.291, 0.591}, {0.243, 0.522, 0.419}, {0.235, 0.504, 0.222}, {0.46, 0.242, 0.254},
    {0.455, 0.696, 0.274}, {0.334, 0.576, 0.769}, {0.546, 0.438, 0.786}, {0.228, 0.715, 0.374},
    {0.287, 0.271, 0.385}, {0.69, 0.308, 0.549},  {0.583, 0.423, 0.529}, {0.238, 0.236, 0.324},
    {0.608, 0.457, 0.388}, {0.551, 0.472, 0.38},  {0.677, 0.619, 0.346}, {0.545, 0.515, 0.725},
    {0.638, 0.373, 0.788}, {0.271, 0.451, 0.654}, {0.291, 0.493, 0.224}, {0.601, 0.659, 0.544}};
static double f_manyblobs(const double *p, int s)
{
    (void)s;
    double v = 0;
    for (int i = 0; i < 20; i++)
        v += exp(-40 * r2(p[0], p[1], p[2], blob_c[i][0], blob_c[i][1], blob_c[i][2]));
    return v - 0.5;
}

/* the scenes render --exact is checked on */
static double f_crease(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    double box = mx(mx(fabs(x) - 0.7, fabs(y) - 0.5), fabs(z) - 0.45);
    double cut = mx(mx(sq(x) + sq(z + 0.3) - 1, 0.04 - sq(y) - sq(z)), 0.55 - fabs(x + y) - 0.3 * z);
    return mn(mx(box, cut), r2(x, y, z, 0.45, 0.25, 0.45) - 0.04);
}
static double f_gyroid_ball(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    double g = sin(20 * x) * cos(20 * y) + sin(20 * y) * cos(20 * z) + sin(20 * z) * cos(20 * x);
    return mx(fabs(g) - 0.2, sq(x) + sq(y) + sq(z) - 0.81);
}
static double f_plate(const double *p, int s)
{
    (void)s;
    return mx(fabs(0.3 * p[0] + 0.2 * p[1] + p[2] - 0.0123) - 0.0004, sq(p[0]) + sq(p[1]) - 0.6);
}
static double f_cube(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2];
    return mx(mx(fabs(0.8 * x + 0.6 * y), fabs(0.8 * y - 0.6 * x)), fabs(z + 0.05)) - 0.6;
}
static double f_heart(const double *p, int s)
{
    (void)s;
    double x = p[0], y = p[1], z = p[2], z3 = z * z * z;
    return pow(sq(x) + 2.25 * sq(y) + sq(z) - 1, 3) - sq(x) * z3 - 0.1125 * sq(y) * z3;
}
/* the generator of scenes/blobs64.scene: a jittered 4x4x4 lattice */
static double f_blobs64(const double *p, int s)
{
    (void)s;
    double v = 0;
    for (int n = 0; n < 64; n++) {
        double c[3];
        const int idx[3] = {n / 16, n / 4 % 4, n % 4}, mul[3] = {7, 11, 13};
        for (int a = 0; a < 3; a++)
            c[a] = round((0.2 + 0.2 * idx[a] + 0.001 * (mul[a] * n % 37)) * 1000) / 1000;
        v += exp(-90 * r2(p[0], p[1], p[2], c[0], c[1], c[2]));
    }
    return v - 0.4;
}

static const struct {
    const char *path;
    double (*f)(const double *p, int surface);
    int nsurf;
} scenes[] = {
    {"scenes/blobs_a.scene", f_blobs_a, 1}, {"scenes/blobs_b.scene", f_blobs_b, 1},
    {"scenes/sphere.scene", f_sphere, 1},   {"scenes/torus.scene", f_torus, 1},
    {"scenes/csg.scene", f_csg, 1},         {"scenes/gyroid.scene", f_gyroid, 1},
    {"scenes/barth.scene", f_barth, 1},     {"scenes/thin.scene", f_thin, 2},
    {"scenes/multi.scene", f_multi, 3},     {"scenes/manyblobs.scene", f_manyblobs, 1},
    {"scenes/crease.scene", f_crease, 1},   {"scenes/gyroid_ball.scene", f_gyroid_ball, 1},
    {"scenes/plate.scene", f_plate, 1},     {"scenes/cube.scene", f_cube, 1},
    {"scenes/heart.scene", f_heart, 1},     {"scenes/blobs64.scene", f_blobs64, 1},
};
#define NSCENES (sizeof scenes / sizeof scenes[0])

static scene *load(const char *path)
{
    scene *s = test_scene_load(path);
    assert_true(s->nsurfaces >= 1);
    for (size_t i = 0; i < s->nsurfaces; i++)
        assert_true(s->surfaces[i].tape.n <= MAXSLOTS);
    return s;
}

static void rand_point(const scene *s, double p[3])
{
    for (int a = 0; a < 3; a++)
        p[a] = s->lo[a] + unit() * (s->hi[a] - s->lo[a]);
}

static void test_scene_files_all_listed(void **state)
{
    (void)state;
    /* There are at least ten scenes, and each one is checked here. */
    FILE *ls = popen("ls scenes/*.scene | wc -l", "r");
    assert_non_null(ls);
    int n = 0;
    assert_int_equal(fscanf(ls, "%d", &n), 1);
    pclose(ls);
    assert_true(n >= 10);
    assert_int_equal((size_t)n, NSCENES);
}

static void test_point_vs_c(void **state)
{
    (void)state;
    double slots[MAXSLOTS];
    for (size_t k = 0; k < NSCENES; k++) {
        scene *s = load(scenes[k].path);
        assert_int_equal(s->nsurfaces, scenes[k].nsurf);
        for (int i = 0; i < 10000; i++) {
            double p[3];
            rand_point(s, p);
            for (size_t j = 0; j < s->nsurfaces; j++) {
                double v = tape_eval(&s->surfaces[j].tape, p[0], p[1], p[2], slots);
                double w = scenes[k].f(p, (int)j);
                if (!(fabs(v - w) <= 1e-12 * (1 + fabs(w))))
                    fail_msg("%s surface %zu at (%g,%g,%g): tape %.17g, C %.17g", scenes[k].path, j,
                             p[0], p[1], p[2], v, w);
            }
        }
        scene_free(s);
    }
}

/* Each surface lies inside its bounds: f has one sign, never 0, on a grid
 * over the faces of the bounds box. */
static void test_surfaces_inside_bounds(void **state)
{
    (void)state;
    double slots[MAXSLOTS];
    for (size_t k = 0; k < NSCENES; k++) {
        scene *s = load(scenes[k].path);
        for (size_t j = 0; j < s->nsurfaces; j++) {
            int sign = 0;
            for (int face = 0; face < 6; face++)
                for (int u = 0; u <= 40; u++)
                    for (int v = 0; v <= 40; v++) {
                        double p[3];
                        int a = face % 3, b = (a + 1) % 3, c = (a + 2) % 3;
                        p[a] = face < 3 ? s->lo[a] : s->hi[a];
                        p[b] = s->lo[b] + (s->hi[b] - s->lo[b]) * u / 40;
                        p[c] = s->lo[c] + (s->hi[c] - s->lo[c]) * v / 40;
                        double f = tape_eval(&s->surfaces[j].tape, p[0], p[1], p[2], slots);
                        int sg = f > 0 ? 1 : f < 0 ? -1 : 0;
                        if (sg == 0 || (sign && sg != sign))
                            fail_msg("%s surface %zu crosses its bounds at (%g,%g,%g)",
                                     scenes[k].path, j, p[0], p[1], p[2]);
                        sign = sg;
                    }
            /* ... and it is not empty: some sample inside has the other sign. */
            int found = 0;
            for (int i = 0; i < 200000 && !found; i++) {
                double p[3];
                rand_point(s, p);
                double f = tape_eval(&s->surfaces[j].tape, p[0], p[1], p[2], slots);
                found = (f > 0 ? 1 : -1) != sign;
            }
            if (!found && strstr(scenes[k].path, "thin") == NULL)
                fail_msg("%s surface %zu: no interior sample found", scenes[k].path, j);
        }
        scene_free(s);
    }
}

static void test_gradient_vs_differences(void **state)
{
    (void)state;
    tape_dual duals[MAXSLOTS];
    double slots[MAXSLOTS];
    for (size_t k = 0; k < NSCENES; k++) {
        scene *s = load(scenes[k].path);
        for (size_t j = 0; j < s->nsurfaces; j++) {
            const tape *t = &s->surfaces[j].tape;
            int tried = 0, skipped = 0;
            for (int i = 0; i < 2000; i++) {
                double p[3], g[3];
                rand_point(s, p);
                double v = tape_eval_grad(t, p, g, duals);
                assert_true(v == tape_eval(t, p[0], p[1], p[2], slots));
                double gn = fabs(g[0]) + fabs(g[1]) + fabs(g[2]);
                tried++;
                for (int a = 0; a < 3; a++) {
                    double fd[2];
                    for (int r = 0; r < 2; r++) {
                        double h = r == 0 ? 1e-5 : 5e-6, q[3] = {p[0], p[1], p[2]}, f1, f0;
                        q[a] = p[a] + h;
                        f1 = tape_eval(t, q[0], q[1], q[2], slots);
                        q[a] = p[a] - h;
                        f0 = tape_eval(t, q[0], q[1], q[2], slots);
                        fd[r] = (f1 - f0) / (2 * h);
                    }
                    double tol = 1e-6 * (gn + 1);
                    if (fabs(fd[0] - fd[1]) > tol) { /* a kink nearby: not smooth here */
                        skipped++;
                        break;
                    }
                    if (!(fabs(g[a] - fd[1]) <= tol))
                        fail_msg("%s: d/d%c at (%g,%g,%g): AD %.12g, differences %.12g",
                                 scenes[k].path, 'x' + a, p[0], p[1], p[2], g[a], fd[1]);
                }
            }
            assert_true(skipped < tried / 10);
        }
        scene_free(s);
    }
}

static void rand_box(const scene *s, interval box[3])
{
    double w = ldexp(1.0, -(int)(next_u64() % 24));
    for (int a = 0; a < 3; a++) {
        double len = (s->hi[a] - s->lo[a]) * w;
        double lo = s->lo[a] + unit() * (s->hi[a] - s->lo[a] - len);
        box[a].lo = lo;
        box[a].hi = next_u64() % 16 == 0 ? lo : lo + len;
    }
}

static void test_interval_scenes(void **state)
{
    (void)state;
    static interval slots[MAXSLOTS];
    static tape_idual islots[MAXSLOTS];
    static tape_dual duals[MAXSLOTS];
    double dslots[MAXSLOTS];
    for (size_t k = 0; k < NSCENES; k++) {
        scene *s = load(scenes[k].path);
        const int nbox = 100000 / SCALE / (int)s->nsurfaces;
        for (size_t j = 0; j < s->nsurfaces; j++) {
            const tape *t = &s->surfaces[j].tape;
            for (int i = 0; i < nbox; i++) {
                interval box[3];
                rand_box(s, box);
                unsigned f;
                interval r = tape_eval_interval(t, box, slots, &f);
                int do_grad = i % 8 == 0;
                interval ig[3];
                unsigned gf = 0;
                if (do_grad) {
                    interval r2 = tape_eval_interval_grad(t, box, ig, islots, &gf);
                    assert_true(r2.lo == r.lo && r2.hi == r.hi);
                }
                for (int w = 0; w < 4; w++) {
                    double p[3] = {in_box(box[0]), in_box(box[1]), in_box(box[2])};
                    double v = tape_eval(t, p[0], p[1], p[2], dslots);
                    if (!encloses(r, f, v))
                        fail_msg("%s: f(%a,%a,%a) = %a outside [%a, %a]", scenes[k].path, p[0], p[1],
                                 p[2], v, r.lo, r.hi);
                    if (do_grad && !gf) {
                        double g[3];
                        tape_eval_grad(t, p, g, duals);
                        for (int a = 0; a < 3; a++)
                            if (!encloses(ig[a], gf, g[a]))
                                fail_msg("%s: df/d%c = %a outside [%a, %a]", scenes[k].path,
                                         'x' + a, g[a], ig[a].lo, ig[a].hi);
                    }
                }
            }
        }
        scene_free(s);
    }
}

/* Bitwise equality, NaN equal to NaN. */
static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b));
}

/* tape_eval_grad_lanes gives, lane by lane, tape_eval_grad's bits, and
 * tape_eval_lanes tape_eval's (the same f): random trees (every operation)
 * and the scenes, with 1 to TAPE_LANES points. */
static void check_lanes(const tape *t, const double pts[][3], unsigned n, const char *what)
{
    static tape_dual_lanes lslots[MAXSLOTS];
    static tape_dual duals[MAXSLOTS];
    static double vslots[MAXSLOTS];
    double x[TAPE_LANES] = {0}, y[TAPE_LANES] = {0}, z[TAPE_LANES] = {0}; /* lanes past n: unread */
    double f[TAPE_LANES], g[3][TAPE_LANES], fv[TAPE_LANES];
    for (unsigned l = 0; l < n; l++) {
        x[l] = pts[l][0];
        y[l] = pts[l][1];
        z[l] = pts[l][2];
    }
    tape_eval_grad_lanes(t, n, x, y, z, f, g, lslots);
    tape_eval_lanes(t, n, x, y, z, fv, lslots);
    for (unsigned l = 0; l < n; l++) {
        double g1[3], f1 = tape_eval_grad(t, pts[l], g1, duals);
        if (!same_bits(f[l], f1) || !same_bits(g[0][l], g1[0]) || !same_bits(g[1][l], g1[1]) ||
            !same_bits(g[2][l], g1[2]))
            fail_msg("%s lane %u of %u at (%a,%a,%a): %a (%a,%a,%a) vs %a (%a,%a,%a)", what, l, n,
                     pts[l][0], pts[l][1], pts[l][2], f[l], g[0][l], g[1][l], g[2][l], f1, g1[0],
                     g1[1], g1[2]);
        double f0 = tape_eval(t, pts[l][0], pts[l][1], pts[l][2], vslots);
        if (!same_bits(fv[l], f0) || !same_bits(f0, f1))
            fail_msg("%s value lane %u of %u at (%a,%a,%a): %a, tape_eval %a, grad %a", what, l, n,
                     pts[l][0], pts[l][1], pts[l][2], fv[l], f0, f1);
    }
}

static void test_grad_lanes(void **state)
{
    (void)state;
    static char text[16384];
    double pts[TAPE_LANES][3];
    for (int n = 0; n < 2000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        interval box[3];
        rand_tree_box(box);
        unsigned lanes = 1 + (unsigned)n % TAPE_LANES;
        for (unsigned l = 0; l < lanes; l++)
            for (int a = 0; a < 3; a++)
                pts[l][a] = in_box(box[a]);
        check_lanes(&s->surfaces[0].tape, (const double(*)[3])pts, lanes, text);
        scene_free(s);
    }
    for (size_t k = 0; k < NSCENES; k++) {
        scene *s = load(scenes[k].path);
        for (size_t j = 0; j < s->nsurfaces; j++)
            for (int i = 0; i < 200; i++) {
                unsigned lanes = 1 + (unsigned)i % TAPE_LANES;
                for (unsigned l = 0; l < lanes; l++)
                    rand_point(s, pts[l]);
                check_lanes(&s->surfaces[j].tape, (const double(*)[3])pts, lanes, scenes[k].path);
            }
        scene_free(s);
    }
}

/* Lanes that share arguments, as a cell's children share each coordinate
 * in halves: the lane evaluators take sin and cos once per distinct
 * argument bits and copy them to the other lanes, which must still give
 * each lane tape_eval_grad's and tape_eval's bits. The points are the
 * corners of random boxes (two values an axis, every lane count), with
 * signed zeros, whose sines differ in sign although -0 == +0. */
static void test_lanes_shared_arguments(void **state)
{
    (void)state;
    static const char *texts[] = {
        "bounds -1 -1 -1 1 1 1\nsurface sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)\n",
        "bounds -1 -1 -1 1 1 1\nsurface cos(x) - sin(x) + sin(x*y) + cos(z*3) + sin(z*3)\n",
        "bounds -1 -1 -1 1 1 1\nsurface sin(x+y+z) + cos(x) + sin(y) + cos(z) + sin(x) + cos(y)\n",
    };
    static char text[16384];
    double pts[TAPE_LANES][3];
    for (size_t k = 0; k < sizeof texts / sizeof *texts; k++) {
        scene *s = NULL;
        scene_error e;
        assert_int_equal(scene_parse(texts[k], strlen(texts[k]), &s, &e), 0);
        for (int i = 0; i < 4000 / SCALE; i++) {
            double c[3][2];
            for (int a = 0; a < 3; a++) {
                c[a][0] = 2.0 * unit() - 1.0;
                c[a][1] = i % 4 == 0 ? -c[a][0] : c[a][0] + ldexp(1.0, -(int)(1 + i % 40));
                if (i % 7 == 0) { /* signed zeros side by side */
                    c[a][0] = 0.0;
                    c[a][1] = -0.0;
                }
            }
            unsigned lanes = 1 + (unsigned)i % TAPE_LANES;
            for (unsigned l = 0; l < lanes; l++)
                for (int a = 0; a < 3; a++)
                    pts[l][a] = c[a][(l >> a) & 1u]; /* lane l: child l's corner */
            check_lanes(&s->surfaces[0].tape, (const double(*)[3])pts, lanes, texts[k]);
        }
        scene_free(s);
    }
    /* random trees of every operation, their lanes on two values an axis */
    for (int n = 0; n < 2000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        interval box[3];
        rand_tree_box(box);
        double c[3][2];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 2; b++)
                c[a][b] = in_box(box[a]);
        unsigned lanes = 1 + (unsigned)n % TAPE_LANES;
        for (unsigned l = 0; l < lanes; l++)
            for (int a = 0; a < 3; a++)
                pts[l][a] = c[a][(l >> a) & 1u];
        check_lanes(&s->surfaces[0].tape, (const double(*)[3])pts, lanes, text);
        scene_free(s);
    }
}

/* Every point evaluator takes sin and cos of one argument together
 * (sincos_point: the kernel up to SINCOS_KERNEL_MAX, libm beyond): the
 * gradient evaluators' value and derivative, in lanes and not, and
 * tape_eval's value keep its bits, over many magnitudes (both sides of the
 * kernel's range). */
static void test_trig_gradient_bits(void **state)
{
    (void)state;
    static const char *texts[2] = {"bounds -1 -1 -1 1 1 1\nsurface sin(x)\n",
                                   "bounds -1 -1 -1 1 1 1\nsurface cos(x)\n"};
    static const double scales[] = {1e-300, 1e-8, 1.0, 3.0, 1e2, 1e5, 0x1p17, 1e6, 1e15, 1e300};
    uint64_t st = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < 2; k++) {
        scene *s = NULL;
        scene_error e;
        assert_int_equal(scene_parse(texts[k], strlen(texts[k]), &s, &e), 0);
        const tape *t = &s->surfaces[0].tape;
        tape_dual duals[8];
        double values[8];
        static tape_dual_lanes lslots[8];
        for (size_t j = 0; j < sizeof scales / sizeof *scales; j++)
            for (int i = 0; i < 20000 / SCALE; i++) {
                double x[TAPE_LANES], y[TAPE_LANES] = {0}, z[TAPE_LANES] = {0}, f[TAPE_LANES];
                double g[3][TAPE_LANES];
                for (unsigned l = 0; l < TAPE_LANES; l++) {
                    x[l] = (2.0 * rng_unit(rng_xorshift64(&st)) - 1.0) * scales[j];
                }
                tape_eval_grad_lanes(t, TAPE_LANES, x, y, z, f, g, lslots);
                for (unsigned l = 0; l < TAPE_LANES; l++) {
                    double p[3] = {x[l], 0.0, 0.0}, g1[3];
                    double f1 = tape_eval_grad(t, p, g1, duals);
                    double f0 = tape_eval(t, x[l], 0.0, 0.0, values);
                    double sv, cv;
                    sincos_point(x[l], &sv, &cv);
                    double v = k ? cv : sv, d = k ? -sv : cv;
                    if (!same_bits(f1, v) || !same_bits(g1[0], d) || !same_bits(f[l], v) ||
                        !same_bits(g[0][l], d) || !same_bits(f0, v))
                        fail_msg("%s at %a: %a %a, lanes %a %a, value %a, sincos_point %a %a",
                                 texts[k], x[l], f1, g1[0], f[l], g[0][l], f0, v, d);
                }
            }
        scene_free(s);
    }
}

/* Documented rules for undefined points (TESTPLAN 23, 24). */
static void test_undefined_points(void **state)
{
    (void)state;
    static const char text[] = "bounds -1 -1 -1 1 1 1\nsurface sqrt(x) + log(y) + 1/z\n";
    scene *s = NULL;
    scene_error e;
    assert_int_equal(scene_parse(text, sizeof text - 1, &s, &e), 0);
    const tape *t = &s->surfaces[0].tape;
    double d[64];
    assert_true(tape_eval(t, 0, 1, 1, d) == 1.0);                /* sqrt(0) = 0 */
    assert_true(tape_eval(t, 1, 0, 1, d) == -INFINITY);          /* log(0) = -inf */
    assert_true(tape_eval(t, 1, 1, 0, d) == INFINITY);           /* 1/0 = +inf */
    assert_true(isnan(tape_eval(t, -1, 1, 1, d)));               /* sqrt(-1) */
    interval slots[64], box[3] = {{0, 0}, {0, 1}, {0, 1}};
    unsigned f;
    interval r = tape_eval_interval(t, box, slots, &f);
    assert_true(r.lo == -INFINITY && r.hi == INFINITY); /* 1/[0,1] */
    box[0].lo = -1;
    r = tape_eval_interval(t, box, slots, &f);
    assert_true(f == INTERVAL_MAYBE_NAN);
    box[0].hi = -0.5;
    r = tape_eval_interval(t, box, slots, &f);
    assert_true(interval_is_nan(r) && f == INTERVAL_MAYBE_NAN);
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scene_files_all_listed),
        cmocka_unit_test(test_point_vs_c),
        cmocka_unit_test(test_surfaces_inside_bounds),
        cmocka_unit_test(test_gradient_vs_differences),
        cmocka_unit_test(test_interval_scenes),
        cmocka_unit_test(test_grad_lanes),
        cmocka_unit_test(test_lanes_shared_arguments),
        cmocka_unit_test(test_trig_gradient_bits),
        cmocka_unit_test(test_undefined_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
