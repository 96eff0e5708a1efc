/* exact_ray_oracle: exact first-voxel oracle (tests/exact_ray_oracle.h). */
#include "tests/exact_ray_oracle.h"

#include <math.h>

static int bitlen(unsigned __int128 x)
{
    int n = 0;
    while (x) {
        n++;
        x >>= 1;
    }
    return n;
}

/* sign of X * 2^ex - Y * 2^ey for X, Y > 0 (unsigned, < 2^120) */
static int cmp_scaled(unsigned __int128 X, int ex, unsigned __int128 Y, int ey)
{
    int bx = bitlen(X) + ex, by = bitlen(Y) + ey;
    if (bx != by)
        return bx < by ? -1 : 1;
    if (ex > ey)
        X <<= ex - ey; /* bit lengths become equal: no overflow */
    else
        Y <<= ey - ex;
    return X < Y ? -1 : X > Y;
}

static int xcmp(const xtime *a, const xtime *b)
{
    int sa = a->num < 0 ? -1 : a->num > 0, sb = b->num < 0 ? -1 : b->num > 0;
    if (sa != sb || sa == 0)
        return sa < sb ? -1 : sa > sb;
    unsigned __int128 na = (unsigned __int128)(a->num < 0 ? -a->num : a->num);
    unsigned __int128 nb = (unsigned __int128)(b->num < 0 ? -b->num : b->num);
    /* |a| vs |b|: na / (a.dm 2^a.de) vs nb / (b.dm 2^b.de) */
    int c = cmp_scaled(na * (unsigned __int128)b->dm, b->de, nb * (unsigned __int128)a->dm, a->de);
    return sa > 0 ? c : -c;
}

static xtime xplane(const xray *r, int a, int64_t k)
{
    xtime t;
    t.num = ((i128)k << FRAC_BITS) - r->O[a];
    if (r->sgn[a] < 0)
        t.num = -t.num;
    t.dm = r->dm[a];
    t.de = r->de[a];
    return t;
}

static long double xtime_ld(const xtime *t)
{
    return ldexpl((long double)t->num, -FRAC_BITS - t->de) / (long double)t->dm;
}

int xray_init(xray *r, const double o[3], const double d[3])
{
    for (int a = 0; a < 3; a++) {
        double s = ldexp(o[a], FRAC_BITS);
        if (!(fabs(o[a]) < 0x1p46) || s != floor(s))
            return 0;
        r->O[a] = (int64_t)s;
        r->o[a] = o[a];
        r->d[a] = d[a];
        double inv = 1.0 / d[a];
        if (d[a] == 0.0 || !isfinite(inv)) { /* trace.h: a zero axis */
            r->sgn[a] = 0;
            r->dm[a] = 1;
            r->de[a] = 0;
            continue;
        }
        int e;
        double m = frexp(fabs(d[a]), &e);
        r->dm[a] = (int64_t)ldexp(m, 53);
        r->de[a] = e - 53;
        while (!(r->dm[a] & 1)) {
            r->dm[a] >>= 1;
            r->de[a]++;
        }
        r->sgn[a] = d[a] > 0 ? 1 : -1;
    }
    return 1;
}

/* Exact occupancy interval [tin, tout) of voxel v, tin clipped at 0.
 * Returns 0 when it is empty; *inf_out set when tout is +inf. */
static int xvoxel(const xray *r, uint32_t lim, const uint32_t v[3], xtime *tin, xtime *tout,
                  int *inf_out)
{
    xtime lo = {0, 1, 0}, hi = {0, 1, 0};
    int hi_inf = 1;
    for (int a = 0; a < 3; a++) {
        if (r->sgn[a] == 0) {
            /* zero axis: voxel floor(o), the closed upper face in N-1 */
            if (r->O[a] < 0 || r->O[a] > ((int64_t)lim << FRAC_BITS))
                return 0;
            int64_t k = r->O[a] >> FRAC_BITS;
            if (k == (int64_t)lim)
                k--;
            if ((int64_t)v[a] != k)
                return 0;
            continue;
        }
        int64_t k = v[a];
        xtime en = xplane(r, a, r->sgn[a] > 0 ? k : k + 1);
        xtime ex = xplane(r, a, r->sgn[a] > 0 ? k + 1 : k);
        if (xcmp(&en, &lo) > 0)
            lo = en;
        if (hi_inf || xcmp(&ex, &hi) < 0) {
            hi = ex;
            hi_inf = 0;
        }
    }
    if (!hi_inf && xcmp(&lo, &hi) >= 0)
        return 0;
    *tin = lo;
    *tout = hi;
    *inf_out = hi_inf;
    return 1;
}

/* Cheap long-double pre-test: 0 only when voxel v is surely not crossed
 * (margin far above long double rounding). */
static int maybe_crossed(const xray *r, const uint32_t v[3])
{
    long double lo = 0, hi = INFINITY;
    for (int a = 0; a < 3; a++) {
        if (r->sgn[a] == 0)
            continue; /* the exact test decides */
        long double k0 = (long double)v[a], o = r->o[a], d = r->d[a];
        long double t0 = (k0 - o) / d, t1 = (k0 + 1 - o) / d;
        long double en = t0 < t1 ? t0 : t1, ex = t0 < t1 ? t1 : t0;
        if (en > lo)
            lo = en;
        if (ex < hi)
            hi = ex;
    }
    return lo <= hi + 0x1p-40L * (fabsl(lo) + fabsl(hi) + 1);
}

long oracle_exact(const xray *r, unsigned levels, const uint32_t (*vox)[3], size_t n,
                  long double *t_out)
{
    const uint32_t lim = UINT32_C(1) << levels;
    long best = -1;
    xtime best_t = {0, 1, 0};
    for (size_t i = 0; i < n; i++) {
        if (!maybe_crossed(r, vox[i]))
            continue;
        xtime tin, tout;
        int inf;
        if (!xvoxel(r, lim, vox[i], &tin, &tout, &inf))
            continue;
        if (best < 0 || xcmp(&tin, &best_t) < 0) {
            best = (long)i;
            best_t = tin;
        }
    }
    *t_out = best >= 0 ? xtime_ld(&best_t) : INFINITY;
    return best;
}

