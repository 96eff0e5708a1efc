/* evalbench: point, gradient and interval evaluations per second of the
 * first surface of each scene given, over random points and random boxes the
 * size of a level-10 voxel inside the scene's bounds. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/diag.h"
#include "common/expr/scene.h"
#include "common/expr/tape.h"
#include "bench/rng.h"

#define LEVEL 10
#define MIN_SECONDS 0.5 /* per measurement */
#define WINDOWS 5
#define BATCH 4096

static uint64_t rng = 0x853c49e6748fea9bull;
static double unit(void) { return rng_unit(rng_xorshift64(&rng)); }

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum kind { POINT, GRAD, IVAL, IGRAD, PRUNE };
static const char *kind_name[] = {"point", "gradient", "interval", "interval+gradient",
                                  "interval+prune"};

/* Evaluations per second of one kind; inputs are precomputed so that only
 * the evaluator is timed. */
static double measure(const scene *s, const tape *t, enum kind k, void *scratch, void *scratch2,
                      double *sink)
{
    static double pts[BATCH][3];
    static interval boxes[BATCH][3];
    double edge = 0;
    for (int a = 0; a < 3; a++)
        if (s->hi[a] - s->lo[a] > edge)
            edge = s->hi[a] - s->lo[a];
    edge /= (double)(1 << LEVEL);
    for (int i = 0; i < BATCH; i++)
        for (int a = 0; a < 3; a++) {
            pts[i][a] = s->lo[a] + unit() * (s->hi[a] - s->lo[a]);
            double lo = s->lo[a] + unit() * (s->hi[a] - s->lo[a] - edge);
            boxes[i][a].lo = lo;
            boxes[i][a].hi = lo + edge;
        }
    /* Best of WINDOWS short windows: on a shared machine the fastest window
     * is the one least disturbed by other processes. */
    double best = 0, acc = 0;
    for (int win = 0; win < WINDOWS; win++) {
        long n = 0;
        double t0 = now(), t1;
        do {
            for (int i = 0; i < BATCH; i++) {
                unsigned f;
                interval g[3];
                double gd[3];
                tape pt;
                switch (k) {
                case POINT: acc += tape_eval(t, pts[i][0], pts[i][1], pts[i][2], scratch); break;
                case GRAD: acc += tape_eval_grad(t, pts[i], gd, scratch) + gd[0]; break;
                case IVAL: acc += tape_eval_interval(t, boxes[i], scratch, &f).hi; break;
                case IGRAD:
                    acc += tape_eval_interval_grad(t, boxes[i], g, scratch, &f).hi + g[0].lo;
                    break;
                case PRUNE:
                    acc += tape_eval_interval(t, boxes[i], scratch, &f).hi;
                    acc += tape_prune(t, scratch, f, scratch2, (uint32_t *)scratch2 + 3 * t->n, &pt);
                    break;
                }
            }
            n += BATCH;
            t1 = now();
        } while (t1 - t0 < MIN_SECONDS / WINDOWS);
        if ((double)n / (t1 - t0) > best)
            best = (double)n / (t1 - t0);
    }
    *sink += acc;
    return best;
}

int main(int argc, char **argv)
{
    diag_set_progname("evalbench");
    if (argc >= 2 && strcmp(argv[1], "--help") == 0) {
        printf("usage: evalbench SCENE...\n"
               "Prints point, gradient and interval evaluations per second of each scene's\n"
               "first surface (random points; random boxes of a level-%d voxel).\n", LEVEL);
        return EXIT_OK;
    }
    if (argc < 2) {
        fprintf(stderr, "usage: evalbench SCENE...\n");
        return EXIT_USAGE;
    }
    int status = EXIT_OK;
    double sink = 0;
    for (int i = 1; i < argc; i++) {
        scene *s = NULL;
        scene_error e;
        if (scene_load(argv[i], &s, &e) != 0) {
            scene_print_error(argv[i], &e);
            status = EXIT_RUNTIME;
            continue;
        }
        const tape *t = &s->surfaces[0].tape;
        /* One buffer big enough for every evaluator's slots. */
        void *scratch = malloc((size_t)t->n * sizeof(tape_idual));
        void *scratch2 = malloc((size_t)t->n * (sizeof(tape_insn) + sizeof(uint32_t)));
        if (!scratch || !scratch2) {
            diag_error("out of memory");
            free(scratch);
            free(scratch2);
            scene_free(s);
            return EXIT_RUNTIME;
        }
        printf("%s: tape of %u instructions (%u requested before sharing, folding and "
               "dead-code removal), %u constants\n", argv[i], t->n, t->ntree, t->nconst);
        for (int k = POINT; k <= PRUNE; k++)
            printf("  %-18s %8.2f M/s\n", kind_name[k],
                   measure(s, t, (enum kind)k, scratch, scratch2, &sink) / 1e6);
        free(scratch);
        free(scratch2);
        scene_free(s);
    }
    if (sink == 12345.678)
        printf("(sink)\n"); /* keeps the evaluations from being optimized away */
    return status;
}
