/* compare: mean, percentile and max of depth and normal errors. */
#include "bench/compare.h"

#include <math.h>
#include <stdlib.h>

static int cmp_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* Nearest-rank percentile q (0..1) of v[0..n-1], sorted in place; NAN if n = 0. */
static double percentile(double *v, size_t n, double q)
{
    if (n == 0)
        return NAN;
    qsort(v, n, sizeof *v, cmp_double);
    size_t k = (size_t)ceil(q * (double)n);
    return v[k > 0 ? k - 1 : 0];
}

int compare_depth(const float *a, const float *b, size_t n, double voxel, const float *na,
                  const float *nb, compare_stats *out)
{
    double *err = malloc((n ? n : 1) * sizeof *err);
    double *ang = na && nb ? malloc((n ? n : 1) * sizeof *ang) : NULL;
    if (!err || (na && nb && !ang)) {
        free(err);
        free(ang);
        return -1;
    }
    size_t both = 0, dis = 0, nang = 0, nan = 0;
    double sum = 0.0, mx = 0.0, asum = 0.0, amx = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = na ? na + 3 * i : NULL;
        int bad = isnan(a[i]) || (p && (isnan(p[0]) || isnan(p[1]) || isnan(p[2])));
        nan += (size_t)bad;
        int ha = isfinite(a[i]), hb = isfinite(b[i]);
        if (ha != hb) {
            dis++;
            continue;
        }
        if (!ha)
            continue;
        double e = fabs((double)a[i] - (double)b[i]) / voxel;
        err[both++] = e;
        sum += e;
        if (e > mx)
            mx = e;
        if (ang && !bad) {
            const float *q = nb + 3 * i;
            double d = (double)p[0] * q[0] + (double)p[1] * q[1] + (double)p[2] * q[2];
            double lp = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
            double lq = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2]);
            if (lp > 0.0 && lq > 0.0) {
                double c = fabs(d) / (lp * lq);
                double deg = acos(c > 1.0 ? 1.0 : c) * 180.0 / M_PI;
                ang[nang++] = deg;
                asum += deg;
                if (deg > amx)
                    amx = deg;
            }
        }
    }
    out->pixels = n;
    out->both_hit = both;
    out->disagree = dis;
    out->mean = both ? sum / (double)both : NAN;
    out->max = both ? mx : NAN;
    out->p99 = percentile(err, both, 0.99);
    out->nmean = nang ? asum / (double)nang : NAN;
    out->np99 = ang ? percentile(ang, nang, 0.99) : NAN;
    out->nmax = nang ? amx : NAN;
    out->nan = nan;
    free(err);
    free(ang);
    return 0;
}

void compare_mask(const uint8_t *a, const float *b, size_t n, compare_stats *out)
{
    size_t both = 0, dis = 0;
    for (size_t i = 0; i < n; i++) {
        int ha = a[i] != 0, hb = isfinite(b[i]);
        dis += ha != hb;
        both += ha && hb;
    }
    out->pixels = n;
    out->both_hit = both;
    out->disagree = dis;
    out->mean = out->p99 = out->max = out->nmean = out->np99 = out->nmax = NAN;
    out->nan = 0;
}
