/* fuzz_scene: scene_parse on raw bytes. Whatever parses is evaluated at a
 * few points and boxes inside its bounds with every evaluator; the point
 * value must lie in the enclosure of any box holding the point (when the
 * enclosure is not flagged as maybe-NaN), and the pruned tape must agree
 * with the full one at the point. Aborts on a violation. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/interval.h"
#include "common/expr/scene.h"
#include "common/expr/tape.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* a point in the bounds from a fraction in [0, 1] per axis */
static void point_in(const scene *s, const double f[3], double p[3])
{
    for (int a = 0; a < 3; a++) {
        p[a] = s->lo[a] + f[a] * (s->hi[a] - s->lo[a]);
        if (!(p[a] >= s->lo[a]))
            p[a] = s->lo[a];
        if (!(p[a] <= s->hi[a]))
            p[a] = s->hi[a];
    }
}

static void check_surface(const scene *s, const tape *t)
{
    double *d = malloc(t->n * sizeof *d);
    interval *iv = malloc(t->n * sizeof *iv);
    tape_dual *du = malloc(t->n * sizeof *du);
    tape_idual *idu = malloc(t->n * sizeof *idu);
    tape_insn *pins = malloc(t->n * sizeof *pins);
    uint32_t *scratch = malloc(t->n * sizeof *scratch);
    if (!d || !iv || !du || !idu || !pins || !scratch)
        goto done;
    static const double fr[5][3] = {
        {0.5, 0.5, 0.5}, {0, 0, 0}, {1, 1, 1}, {0.25, 0.75, 0.125}, {0.9, 0.1, 0.6}};
    for (int i = 0; i < 5; i++) {
        double p[3];
        point_in(s, fr[i], p);
        double v = tape_eval(t, p[0], p[1], p[2], d);
        double g[3];
        double vg = tape_eval_grad(t, p, g, du);
        if (!(vg == v || (vg != vg && v != v)))
            abort(); /* the gradient evaluator computes the same value */
        /* boxes around p: the point itself, and up to the whole bounds */
        for (int k = 0; k < 3; k++) {
            interval box[3];
            for (int a = 0; a < 3; a++) {
                double w = k == 0 ? 0.0 : (s->hi[a] - s->lo[a]) * (k == 1 ? 0.01 : 1.0);
                box[a].lo = k == 2 ? s->lo[a] : fmax(s->lo[a], p[a] - w);
                box[a].hi = k == 2 ? s->hi[a] : fmin(s->hi[a], p[a] + w);
            }
            unsigned flags = 0;
            interval r = tape_eval_interval(t, box, iv, &flags);
            if (!flags && isfinite(v) && !(r.lo <= v && v <= r.hi)) {
                fprintf(stderr, "fuzz_scene: f = %.17g outside [%.17g, %.17g]\n", v, r.lo, r.hi);
                abort();
            }
            interval ig[3];
            unsigned gflags = 0;
            interval r2 = tape_eval_interval_grad(t, box, ig, idu, &gflags);
            if (!flags && !gflags && !(r2.lo <= r.hi && r.lo <= r2.hi))
                abort(); /* both enclose f(p) */
            tape pt;
            tape_prune(t, iv, flags, pins, scratch, &pt);
            double vp = tape_eval(&pt, p[0], p[1], p[2], d);
            if (!(vp == v || (vp != vp && v != v))) {
                fprintf(stderr, "fuzz_scene: pruned %.17g, full %.17g\n", vp, v);
                abort();
            }
        }
    }
done:
    free(d);
    free(iv);
    free(du);
    free(idu);
    free(pins);
    free(scratch);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    scene *s = NULL;
    scene_error err;
    if (scene_parse((const char *)data, size, &s, &err) != 0) {
        if (s || err.line < 1 || err.col < 1 || !memchr(err.message, '\0', sizeof err.message))
            abort(); /* a rejection names its place, leaves no scene */
        return 0;
    }
    for (int a = 0; a < 3; a++)
        if (!(s->lo[a] < s->hi[a]) || !isfinite(s->lo[a]) || !isfinite(s->hi[a]))
            abort(); /* scene.h: lo < hi, both finite */
    for (size_t i = 0; i < s->nsurfaces && i < 8; i++)
        check_surface(s, &s->surfaces[i].tape);
    scene_free(s);
    return 0;
}
