/* normalerr: how far a tree's voxel records are from the exact surface.
 * For every voxel, Newton's projection from its centre onto f = 0 (its
 * surface's whole function, iterated to convergence without the clamp to the
 * voxel) gives the foot point; the exact normal is the normalised gradient
 * there, the exact offset the distance from the centre to the foot point
 * along it, in voxel edges. Voxels whose foot point lies farther than half a
 * voxel diagonal (the surface misses them, or the projection fails) are
 * counted apart. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/scene_oct.h"
#include "common/diag.h"
#include "common/expr/scene.h"
#include "format/oct.h"
#include "format/oct_normal.h"

static const char usage_text[] =
    "usage: normalerr SCENE OCT [--csv]\n"
    "Angle (degrees) between each voxel's stored normal and the exact gradient at\n"
    "the foot point of the voxel centre on the surface, and the error of the stored\n"
    "plane offset (voxel edges): mean, 99th percentile and maximum over the voxels\n"
    "the surface passes near, and how many it misses. With --csv one line\n"
    "voxels,missed,angle_mean,angle_p99,angle_max,offset_mean,offset_p99,offset_max.\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

typedef struct errs {
    const scene *sc;
    const oct_tree *t;
    tape_dual *slots;
    double h;
    float *angle, *offset;
    uint64_t n, missed;
} errs;

/* The foot point of c on surface s: 0 when the projection does not settle
 * within a voxel diagonal of c. */
static int foot_point(errs *e, unsigned s, const double c[3], double p[3], double g[3])
{
    const tape *t = &e->sc->surfaces[s].tape;
    memcpy(p, c, 3 * sizeof *p);
    for (int it = 0; it < 30; it++) {
        double f = tape_eval_grad(t, p, g, e->slots);
        double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0.0) || !isfinite(g2) || !isfinite(f))
            return 0;
        double step = 0.0;
        for (int k = 0; k < 3; k++) {
            double dk = f / g2 * g[k];
            p[k] -= dk;
            step += dk * dk;
        }
        if (sqrt(step) < 1e-9 * e->h) {
            tape_eval_grad(t, p, g, e->slots);
            double d2 = 0.0;
            for (int k = 0; k < 3; k++)
                d2 += (p[k] - c[k]) * (p[k] - c[k]);
            return sqrt(d2) <= 0.8660254037844386 * e->h;
        }
    }
    return 0;
}

static void voxel(errs *e, uint64_t v, const uint64_t xyz[3])
{
    unsigned s = e->t->surfaces ? e->t->surfaces[v] : 0;
    double c[3], p[3], g[3];
    for (int k = 0; k < 3; k++)
        c[k] = e->t->origin[k] + ((double)xyz[k] + 0.5) * e->h;
    if (!foot_point(e, s, c, p, g)) {
        e->missed++;
        return;
    }
    double len = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]), exact = 0.0, dot = 0.0;
    float n[3];
    uint32_t rec = e->t->voxels[v];
    oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, n);
    for (int k = 0; k < 3; k++) {
        exact += g[k] / len * (p[k] - c[k]) / e->h;
        dot += g[k] / len * n[k];
    }
    double d = oct_offset_decode((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
    e->angle[e->n] = (float)(acos(fmin(1.0, fmax(-1.0, dot))) * 180.0 / M_PI);
    e->offset[e->n] = (float)fabs(d - exact);
    e->n++;
}

static void walk(errs *e, unsigned d, uint64_t node, const uint64_t xyz[3])
{
    oct_children ch = oct_node_children(e->t->groups[d], node);
    for (unsigned i = 0; i < 8; i++) {
        if (!(ch.mask & (1u << i)))
            continue;
        uint64_t cx[3] = {2 * xyz[0] + (i & 1), 2 * xyz[1] + ((i >> 1) & 1), 2 * xyz[2] + (i >> 2)};
        uint64_t idx = ch.first + oct_popcount64(ch.mask & ((1u << i) - 1u));
        if (d + 1 == e->t->levels)
            voxel(e, idx, cx);
        else
            walk(e, d + 1, idx, cx);
    }
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* Mean, 99th percentile and maximum of v[0..n) (sorted in place). */
static void summary(float *v, uint64_t n, double out[3])
{
    double sum = 0.0;
    for (uint64_t i = 0; i < n; i++)
        sum += v[i];
    qsort(v, (size_t)n, sizeof *v, cmp_float);
    out[0] = n ? sum / (double)n : 0.0;
    out[1] = n ? v[(size_t)((double)(n - 1) * 0.99)] : 0.0;
    out[2] = n ? v[n - 1] : 0.0;
}

int main(int argc, char **argv)
{
    diag_set_progname("normalerr");
    const char *paths[2] = {NULL, NULL};
    int csv = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(argv[i], "--csv")) {
            csv = 1;
        } else if (argv[i][0] != '-' && !paths[1]) {
            paths[paths[0] ? 1 : 0] = argv[i];
        } else {
            return diag_usage_error(usage_text, "unexpected argument '%s'", argv[i]);
        }
    }
    if (!paths[1])
        return diag_usage_error(usage_text, "%s", "want a scene and an octree");
    scene *sc;
    oct_file *f;
    if (scene_oct_open(paths[0], paths[1], &sc, &f) != EXIT_OK)
        return EXIT_RUNTIME;
    const oct_tree *t = oct_get_tree(f);
    errs e;
    memset(&e, 0, sizeof e);
    e.sc = sc;
    e.t = t;
    e.h = t->edge / (double)(UINT64_C(1) << t->levels);
    size_t len = 1;
    for (size_t s = 0; s < sc->nsurfaces; s++)
        if (sc->surfaces[s].tape.n > len)
            len = sc->surfaces[s].tape.n;
    e.slots = malloc(len * sizeof *e.slots);
    e.angle = malloc((t->voxel_count + 1) * sizeof *e.angle);
    e.offset = malloc((t->voxel_count + 1) * sizeof *e.offset);
    int status = EXIT_OK;
    if (t->surface_count != sc->nsurfaces) {
        diag_error("%s: not rasterized from %s", paths[1], paths[0]);
        status = EXIT_RUNTIME;
    } else if (!e.slots || !e.angle || !e.offset) {
        diag_error("out of memory");
        status = EXIT_RUNTIME;
    } else {
        const uint64_t root[3] = {0, 0, 0};
        if (t->node_count[0])
            walk(&e, 0, 0, root);
        double a[3], o[3];
        summary(e.angle, e.n, a);
        summary(e.offset, e.n, o);
        if (csv)
            printf("%llu,%llu,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f\n", (unsigned long long)e.n,
                   (unsigned long long)e.missed, a[0], a[1], a[2], o[0], o[1], o[2]);
        else
            printf("normalerr: %s: %llu voxels (%llu the surface misses): normal %.4f mean, %.4f p99, "
                   "%.4f max deg; offset %.5f mean, %.5f p99, %.5f max voxel\n",
                   paths[1], (unsigned long long)e.n, (unsigned long long)e.missed, a[0], a[1], a[2],
                   o[0], o[1], o[2]);
    }
    free(e.slots);
    free(e.angle);
    free(e.offset);
    oct_close(f);
    scene_free(sc);
    return status;
}
