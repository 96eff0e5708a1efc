/* shellratio: how much thicker than the surface the rasterizer's shell is.
 * The dense reference: every voxel of the grid whose plain interval test at
 * its own size does not exclude 0 is a candidate; a candidate is real when
 * a (K+1)^3 lattice of samples over it (corners included, K per voxel edge)
 * shows a sign change or an exact zero of some surface. Samples beyond the
 * scene's bounds and undefined ones do not count, as in tests/test_build.c.
 * The candidates come from a subdivision by the same sound interval test, so
 * no voxel with a sign change is missed. The tree is walked alongside: a real
 * voxel absent from it is lost (the rasterizer's guarantee says none is). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/scene_oct.h"
#include "common/diag.h"
#include "common/expr/scene.h"
#include "common/parse_num.h"
#include "format/oct.h"

static const char usage_text[] =
    "usage: shellratio SCENE OCT [--lattice K] [--csv]\n"
    "Counts the voxels the surfaces of SCENE really pass through at the levels of\n"
    "OCT (rasterized from SCENE): candidates by the interval test at the voxel's\n"
    "own size, real ones by a sign change or zero on a (K+1)^3 lattice over the\n"
    "voxel (default K = 4). Prints the voxels kept, the real ones, kept / real and\n"
    "the real ones missing from OCT; with --csv one line kept,real,ratio,lost.\n"
    "Exit status: 0 ok (nothing lost), 1 run-time failure or a voxel lost, 2 bad usage.\n";

typedef struct walk {
    const scene *sc;
    const oct_tree *t;
    unsigned levels, k;
    double origin[3], edge;
    interval *slots;
    double *pslots;
    uint32_t *scratch;
    tape_insn *insn; /* [(levels + 1) * total]: the pruned tapes of each depth */
    tape *tapes;     /* [(levels + 1) * nsurf] */
    uint8_t *live;   /* [(levels + 1) * nsurf]: the interval test let the surface through */
    uint32_t *off, total;
    uint64_t candidates, real, lost;
} walk;

/* Axis a of cell c at depth d, rounded outward and clipped to the bounds. */
static int span(const walk *w, unsigned d, uint64_t c, int a, interval *s)
{
    double h = ldexp(w->edge, -(int)d);
    s->lo = interval_next_down(w->origin[a] + (double)c * h);
    s->hi = fmin(interval_next_up(w->origin[a] + (double)(c + 1) * h), w->sc->hi[a]);
    return s->lo <= s->hi;
}

/* A sign change or a zero of tape t on the voxel's lattice. Corners first:
 * most real voxels show their change there. */
static int lattice_crossing(walk *w, const tape *t, const uint64_t v[3])
{
    const unsigned k = w->k;
    const double h = ldexp(w->edge, -(int)w->levels) / k;
    int pos = 0, neg = 0;
    for (int pass = 0; pass < 2; pass++)
        for (unsigned dz = 0; dz <= k; dz++)
            for (unsigned dy = 0; dy <= k; dy++)
                for (unsigned dx = 0; dx <= k; dx++) {
                    int corner = (dx % k == 0) && (dy % k == 0) && (dz % k == 0);
                    if (corner != (pass == 0))
                        continue;
                    double p[3] = {w->origin[0] + (double)(v[0] * k + dx) * h,
                                   w->origin[1] + (double)(v[1] * k + dy) * h,
                                   w->origin[2] + (double)(v[2] * k + dz) * h};
                    if (p[0] > w->sc->hi[0] || p[1] > w->sc->hi[1] || p[2] > w->sc->hi[2])
                        continue;
                    double f = tape_eval(t, p[0], p[1], p[2], w->pslots);
                    if (f == 0.0)
                        return 1;
                    pos |= f > 0.0;
                    neg |= f < 0.0;
                    if (pos && neg)
                        return 1;
                }
    return 0;
}

/* The cell (d, c), whose parent's tapes are at depth d - 1 (d >= 1), or the
 * root (d = 0). node is its index in the tree at depth d, -1 when absent. */
static void visit(walk *w, unsigned d, const uint64_t c[3], int64_t node)
{
    const unsigned ns = (unsigned)w->sc->nsurfaces;
    interval box[3];
    for (int a = 0; a < 3; a++)
        if (!span(w, d, c[a], a, &box[a]))
            return;
    unsigned n = 0;
    for (unsigned s = 0; s < ns; s++) {
        uint8_t *live = &w->live[(size_t)d * ns + s];
        *live = 0;
        if (d > 0 && !w->live[(size_t)(d - 1) * ns + s])
            continue;
        const tape *pt = d > 0 ? &w->tapes[(size_t)(d - 1) * ns + s] : &w->sc->surfaces[s].tape;
        unsigned fl = 0;
        interval v = tape_eval_interval(pt, box, w->slots, &fl);
        if (interval_is_nan(v) || v.lo > 0.0 || v.hi < 0.0)
            continue;
        *live = 1;
        n++;
        tape_prune(pt, w->slots, fl, w->insn + (size_t)d * w->total + w->off[s], w->scratch,
                   &w->tapes[(size_t)d * ns + s]);
    }
    if (!n)
        return;
    if (d == w->levels) {
        w->candidates++;
        for (unsigned s = 0; s < ns; s++)
            if (w->live[(size_t)d * ns + s] &&
                lattice_crossing(w, &w->tapes[(size_t)d * ns + s], c)) {
                w->real++;
                w->lost += node < 0;
                return;
            }
        return;
    }
    oct_children ch = {0, 0};
    if (node >= 0)
        ch = oct_node_children(w->t->groups[d], (uint64_t)node);
    for (unsigned i = 0; i < 8; i++) {
        uint64_t cc[3] = {2 * c[0] + (i & 1), 2 * c[1] + ((i >> 1) & 1), 2 * c[2] + (i >> 2)};
        int64_t cn = -1;
        if (ch.mask & (1u << i))
            cn = (int64_t)(ch.first + oct_popcount64(ch.mask & ((1u << i) - 1u)));
        visit(w, d + 1, cc, cn);
    }
}

static int run(walk *w)
{
    const unsigned ns = (unsigned)w->sc->nsurfaces;
    size_t depths = (size_t)w->levels + 1, len = 1;
    w->off = calloc(ns, sizeof *w->off);
    if (!w->off)
        return -1;
    for (unsigned s = 0; s < ns; s++) {
        w->off[s] = w->total;
        w->total += w->sc->surfaces[s].tape.n;
        if (w->sc->surfaces[s].tape.n > len)
            len = w->sc->surfaces[s].tape.n;
    }
    w->slots = malloc(len * sizeof *w->slots);
    w->pslots = malloc(len * sizeof *w->pslots);
    w->scratch = malloc(len * sizeof *w->scratch);
    w->insn = malloc(depths * w->total * sizeof *w->insn);
    w->tapes = calloc(depths * ns, sizeof *w->tapes);
    w->live = calloc(depths * ns, 1);
    if (!w->slots || !w->pslots || !w->scratch || !w->insn || !w->tapes || !w->live)
        return -1;
    const uint64_t root[3] = {0, 0, 0};
    visit(w, 0, root, w->t->node_count[0] ? 0 : -1);
    return 0;
}

static void walk_free(walk *w)
{
    free(w->off); free(w->slots); free(w->pslots); free(w->scratch);
    free(w->insn); free(w->tapes); free(w->live);
}

int main(int argc, char **argv)
{
    diag_set_progname("shellratio");
    const char *paths[2] = {NULL, NULL};
    long k = 4;
    int csv = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(argv[i], "--lattice") && i + 1 < argc) {
            if (parse_long(argv[++i], 1, 16, &k) != PARSE_OK)
                return diag_usage_error(usage_text, "--lattice '%s': want an integer in 1..16", argv[i]);
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
    const oct_info *info = oct_get_info(f);
    int status = EXIT_OK;
    walk w;
    memset(&w, 0, sizeof w);
    w.sc = sc;
    w.t = t;
    w.levels = t->levels;
    w.k = (unsigned)k;
    w.edge = t->edge;
    memcpy(w.origin, t->origin, sizeof w.origin);
    if (info->root_depth != 0 || t->surface_count != sc->nsurfaces) {
        diag_error("%s: not a whole-grid tree of %s", paths[1], paths[0]);
        status = EXIT_RUNTIME;
    } else if (run(&w) != 0) {
        diag_error("out of memory");
        status = EXIT_RUNTIME;
    } else {
        double ratio = w.real ? (double)t->voxel_count / (double)w.real : 0.0;
        if (csv)
            printf("%llu,%llu,%.4f,%llu\n", (unsigned long long)t->voxel_count,
                   (unsigned long long)w.real, ratio, (unsigned long long)w.lost);
        else
            printf("shellratio: %s levels %u: %llu voxels kept, %llu candidates, %llu real "
                   "(lattice %u), kept / real %.4f, %llu lost\n",
                   paths[0], w.levels, (unsigned long long)t->voxel_count,
                   (unsigned long long)w.candidates, (unsigned long long)w.real, w.k, ratio,
                   (unsigned long long)w.lost);
        if (w.lost)
            status = EXIT_RUNTIME;
    }
    walk_free(&w);
    oct_close(f);
    scene_free(sc);
    return status;
}
