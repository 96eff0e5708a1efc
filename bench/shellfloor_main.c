/* shellfloor: the depth error the paper's hit rule cannot avoid. A ray
 * stops at the entry of the first voxel the surface passes through, so even
 * the ideal shell (exactly the voxels the surface meets, nothing lost,
 * nothing extra) reports a depth short of the surface by the length the ray
 * travels inside voxels before reaching it. This measures that length, in
 * voxels, for a sphere much larger than a voxel seen along one direction:
 * locally a plane, whose normal is drawn as a sphere shows them (uniform over
 * the projected disc) and whose offset and ray origin are uniform in the
 * voxel grid. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/diag.h"
#include "common/parse_num.h"
#include "bench/rng.h"

static const char usage_text[] =
    "usage: shellfloor DX,DY,DZ [--samples N]\n"
    "Depth error (voxels) of the paper's rule, hit = entry of the first voxel the\n"
    "surface passes through, on an ideal shell: a large sphere viewed along the\n"
    "direction DX,DY,DZ (eye minus target is its opposite). Prints mean, median,\n"
    "99th percentile over N samples (default 200000).\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

static uint64_t rng_state = 0x2545f4914f6cdd1dULL;
static double urand(void) { return rng_unit(rng_xorshift64(&rng_state)); }

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* One sample: plane n . p = c ahead of a ray o + t d (unit d, n . d < 0).
 * A voxel meets the plane iff its centre is within h = (|nx|+|ny|+|nz|)/2 of
 * it. Walks the ray's voxels (a plain DDA) to the first such voxel and
 * returns (plane t - entry t). */
static double sample(const double d[3], const double n[3])
{
    double o[3];
    for (int a = 0; a < 3; a++)
        o[a] = 64.0 * urand();
    const double nd = dot(n, d);
    /* start 2.5..6.5 voxels from the plane, normal distance: the first voxel
     * is never in the shell, whatever the incidence */
    const double c = dot(n, o) + nd * (2.5 + 4.0 * urand()) / fabs(nd);
    const double t_plane = (c - dot(n, o)) / nd;
    const double h = 0.5 * (fabs(n[0]) + fabs(n[1]) + fabs(n[2]));
    long v[3];
    double tmax[3], tdel[3];
    int step[3];
    for (int a = 0; a < 3; a++) {
        v[a] = (long)floor(o[a]);
        step[a] = d[a] > 0 ? 1 : -1;
        tdel[a] = d[a] != 0 ? fabs(1.0 / d[a]) : INFINITY;
        tmax[a] = d[a] != 0 ? ((double)v[a] + (d[a] > 0) - o[a]) / d[a] : INFINITY;
    }
    double t = 0.0;
    for (;;) {
        double cen[3] = {(double)v[0] + 0.5, (double)v[1] + 0.5, (double)v[2] + 0.5};
        if (fabs(dot(n, cen) - c) <= h)
            return t_plane - t;
        int a = tmax[0] < tmax[1] ? (tmax[0] < tmax[2] ? 0 : 2) : (tmax[1] < tmax[2] ? 1 : 2);
        t = tmax[a];
        v[a] += step[a];
        tmax[a] += tdel[a];
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    diag_set_progname("shellfloor");
    const char *dir_arg = NULL;
    long ns = 200000;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(argv[i], "--samples") && i + 1 < argc) {
            if (parse_long(argv[++i], 1, 100000000, &ns) != PARSE_OK)
                return diag_usage_error(usage_text, "--samples '%s': want an integer in 1..1e8", argv[i]);
        } else if (!dir_arg && (argv[i][0] != '-' || (argv[i][1] >= '0' && argv[i][1] <= '9') ||
                                argv[i][1] == '.')) { /* a direction may start with '-' */
            dir_arg = argv[i];
        } else {
            return diag_usage_error(usage_text, "unexpected argument '%s'", argv[i]);
        }
    }
    double d[3];
    if (!dir_arg || parse_vec3(dir_arg, d) != PARSE_OK || dot(d, d) == 0.0)
        return diag_usage_error(usage_text, "%s", "want a non-zero direction DX,DY,DZ");
    const double len = sqrt(dot(d, d));
    for (int a = 0; a < 3; a++)
        d[a] /= len;
    /* an orthonormal frame (e1, e2, -d) */
    double e1[3], e2[3];
    const double *ax = fabs(d[0]) < 0.9 ? (const double[3]){1, 0, 0} : (const double[3]){0, 1, 0};
    e1[0] = ax[1] * d[2] - ax[2] * d[1];
    e1[1] = ax[2] * d[0] - ax[0] * d[2];
    e1[2] = ax[0] * d[1] - ax[1] * d[0];
    const double l1 = sqrt(dot(e1, e1));
    for (int a = 0; a < 3; a++)
        e1[a] /= l1;
    e2[0] = d[1] * e1[2] - d[2] * e1[1];
    e2[1] = d[2] * e1[0] - d[0] * e1[2];
    e2[2] = d[0] * e1[1] - d[1] * e1[0];
    double *err = malloc((size_t)ns * sizeof *err);
    if (!err) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    double sum = 0.0;
    for (long k = 0; k < ns; k++) {
        /* a point uniform on the projected unit disc; the sphere's normal there */
        double x, y;
        do {
            x = 2.0 * urand() - 1.0;
            y = 2.0 * urand() - 1.0;
        } while (x * x + y * y >= 0.999); /* the last 0.05 % of the rim: error unbounded */
        const double z = sqrt(1.0 - x * x - y * y);
        double n[3];
        for (int a = 0; a < 3; a++)
            n[a] = x * e1[a] + y * e2[a] - z * d[a];
        err[k] = sample(d, n);
        sum += err[k];
    }
    qsort(err, (size_t)ns, sizeof *err, cmp_double);
    printf("shellfloor: direction %.4f,%.4f,%.4f, %ld samples: mean %.3f, median %.3f, p99 %.3f voxels\n",
           d[0], d[1], d[2], ns, sum / (double)ns, err[ns / 2], err[(size_t)((double)ns * 0.99)]);
    free(err);
    return EXIT_OK;
}
