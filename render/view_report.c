/* view_report: render's per-view line (view_report.h). */
#include "render/view_report.h"

#include <inttypes.h>
#include <stdio.h>

/* " N Mrays R Mrays/s" of one kind of ray: n rays in ns of thread time
 * over th threads. */
static void report_kind(double n, double ns, double th)
{
    fprintf(stderr, " %.2f Mrays %.2f Mrays/s", n / 1e6, ns > 0 ? n * th / ns * 1e3 : 0.0);
}

void view_report(const views_view *v, const frame_stats *st, double ms, int verbose,
                 unsigned threads)
{
    const uint64_t px = (uint64_t)v->width * (uint64_t)v->height;
    fprintf(stderr, "render: %s: %ldx%ld, %.1f ms, %.2f Mrays/s, %.1f%% hit", v->out, v->width,
            v->height, ms, ms > 0 ? (double)st->rays / ms / 1e3 : 0.0,
            100.0 * (double)st->hits / (double)px);
    if (v->aa > 1)
        fprintf(stderr, ", %.2f%% edge pixels, %.2f%% supersampled",
                100.0 * (double)st->aa_pixels / (double)px, 100.0 * (double)st->aa_full / (double)px);
    if (verbose) {
        const double th = (double)threads;
        fprintf(stderr, "; primary %.2f Mrays %.2f Mrays/s", (double)st->rays / 1e6,
                st->primary_ns > 0 ? (double)st->rays * th / st->primary_ns * 1e3 : 0.0);
        const double sec = (double)(st->shadow_rays + st->ao_rays);
        if (sec > 0)
            fprintf(stderr, ", shadow %.2f Mrays, ao %.2f Mrays, %.2f Mrays/s",
                    (double)st->shadow_rays / 1e6, (double)st->ao_rays / 1e6,
                    st->secondary_ns > 0 ? sec * th / st->secondary_ns * 1e3 : 0.0);
        /* then one rate per kind, each over its own thread time */
        fprintf(stderr, "; by kind: centre");
        report_kind((double)px, st->centre_ns, th);
        if (v->aa > 1) {
            fprintf(stderr, ", aa samples");
            report_kind((double)st->samples, st->sample_ns, th);
        }
        if (st->shadow_rays) {
            fprintf(stderr, ", shadow");
            report_kind((double)st->shadow_rays, st->shadow_ns, th);
        }
        if (st->ao_rays) {
            fprintf(stderr, ", ao");
            report_kind((double)st->ao_rays, st->ao_ns, th);
        }
        if (st->exact_tests || st->exact_passed)
            fprintf(stderr,
                    "; exact: %" PRIu64 " voxel tests (%" PRIu64 " by bisection), %" PRIu64
                    " voxels passed root-free, %" PRIu64 " hits past their voxel",
                    st->exact_tests, st->exact_bisected, st->exact_passed, st->exact_beyond);
    }
    fputc('\n', stderr);
}

