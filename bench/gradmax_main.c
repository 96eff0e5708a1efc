/* gradmax: the largest |grad f| of a scene's surfaces sampled on a grid over
 * its bounds, for POV-Ray's isosurface max_gradient. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/diag.h"
#include "common/parse_num.h"
#include "common/expr/scene.h"

static const char usage_text[] =
    "usage: gradmax SCENE [--grid N]\n"
    "Prints the largest |grad f| over an N^3 grid of sample points (default 96)\n"
    "spanning the scene's bounds, the maximum over all its surfaces. A sampled\n"
    "maximum, not a bound: multiply it by a safety factor before trusting it.\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

int main(int argc, char **argv)
{
    diag_set_progname("gradmax");
    const char *path = NULL;
    long n = 96;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(argv[i], "--grid") && i + 1 < argc) {
            if (parse_long(argv[++i], 2, 1024, &n) != PARSE_OK) {
                diag_error("--grid '%s': want an integer in 2..1024", argv[i]);
                return EXIT_USAGE;
            }
        } else if (argv[i][0] != '-' && !path) {
            path = argv[i];
        } else {
            diag_error("unexpected argument '%s'", argv[i]);
            fputs(usage_text, stderr);
            return EXIT_USAGE;
        }
    }
    if (!path) {
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    scene *s = NULL;
    scene_error se;
    if (scene_load(path, &s, &se) != 0) {
        scene_print_error(path, &se);
        return EXIT_RUNTIME;
    }
    double best = 0.0;
    for (size_t k = 0; k < s->nsurfaces; k++) {
        const tape *tp = &s->surfaces[k].tape;
        tape_dual *slots = malloc(tp->n * sizeof *slots);
        if (!slots) {
            diag_error("out of memory");
            scene_free(s);
            return EXIT_RUNTIME;
        }
        for (long a = 0; a < n; a++)
            for (long b = 0; b < n; b++)
                for (long c = 0; c < n; c++) {
                    double p[3], g[3];
                    const long idx[3] = {a, b, c};
                    for (int d = 0; d < 3; d++)
                        p[d] = s->lo[d] + (s->hi[d] - s->lo[d]) * (double)idx[d] / (double)(n - 1);
                    tape_eval_grad(tp, p, g, slots);
                    double m = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                    if (m > best) /* NaN never wins */
                        best = m;
                }
        free(slots);
    }
    printf("%.6g\n", best);
    scene_free(s);
    return EXIT_OK;
}
