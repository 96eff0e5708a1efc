/* scene2pov: a scene as a POV-Ray file of isosurfaces (flat white on black,
 * for silhouettes), camera from an include file the caller writes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/povexpr.h"
#include "common/diag.h"
#include "common/parse_num.h"
#include "common/expr/scene.h"

#define EXPR_CAP (4u << 20)

static const char usage_text[] =
    "usage: scene2pov SCENE --max-gradient G --accuracy A [--camera FILE.inc]\n"
    "Prints a POV-Ray 3.7 scene on stdout: each surface of SCENE as an open\n"
    "isosurface (threshold 0) contained by the scene's bounds, white, ambient\n"
    "only, on a black background; the camera comes from #include FILE.inc\n"
    "(default camera.inc). Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

int main(int argc, char **argv)
{
    diag_set_progname("scene2pov");
    const char *path = NULL, *cam = "camera.inc";
    double grad = 0.0, acc = 0.0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--max-gradient") && i + 1 < argc) {
            if (parse_double(argv[++i], &grad) != PARSE_OK || !(grad > 0.0)) {
                diag_error("--max-gradient '%s': want a positive number", argv[i]);
                return EXIT_USAGE;
            }
        } else if (!strcmp(a, "--accuracy") && i + 1 < argc) {
            if (parse_double(argv[++i], &acc) != PARSE_OK || !(acc > 0.0)) {
                diag_error("--accuracy '%s': want a positive number", argv[i]);
                return EXIT_USAGE;
            }
        } else if (!strcmp(a, "--camera") && i + 1 < argc) {
            cam = argv[++i];
        } else if (a[0] != '-' && !path) {
            path = a;
        } else {
            diag_error("unexpected argument '%s'", a);
            fputs(usage_text, stderr);
            return EXIT_USAGE;
        }
    }
    if (!path || grad == 0.0 || acc == 0.0) {
        diag_error("need SCENE, --max-gradient and --accuracy");
        fputs(usage_text, stderr);
        return EXIT_USAGE;
    }
    scene *s = NULL;
    scene_error se;
    if (scene_load(path, &s, &se) != 0) {
        scene_print_error(path, &se);
        return EXIT_RUNTIME;
    }
    char *expr = malloc(EXPR_CAP);
    if (!expr) {
        diag_error("out of memory");
        scene_free(s);
        return EXIT_RUNTIME;
    }
    printf("#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb 0 }\n"
           "#include \"%s\"\n",
           cam);
    int status = EXIT_OK;
    for (size_t k = 0; k < s->nsurfaces; k++) {
        if (povexpr_write(&s->surfaces[k].tape, expr, EXPR_CAP) < 0) {
            diag_at(path, s->surfaces[k].line, 1, "surface too large for a POV-Ray function");
            status = EXIT_RUNTIME;
            break;
        }
        printf("isosurface {\n  function { %s }\n"
               "  contained_by { box { <%.17g, %.17g, %.17g>, <%.17g, %.17g, %.17g> } }\n"
               "  open\n  threshold 0\n  max_gradient %.6g\n  accuracy %.6g\n"
               "  pigment { rgb 1 } finish { ambient 1 diffuse 0 }\n}\n",
               expr, s->lo[0], s->lo[1], s->lo[2], s->hi[0], s->hi[1], s->hi[2], grad, acc);
    }
    free(expr);
    scene_free(s);
    return status;
}
