/* imgcompare: depth, hit/miss and normal errors of an image against the
 * exact reference (refcast), in voxels and degrees. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>

#include "bench/compare.h"
#include "bench/pfm.h"
#include "bench/pngmask.h"
#include "common/diag.h"
#include "common/parse_num.h"

static const char usage_text[] =
    "usage: imgcompare TEST.pfm REF.pfm --voxel V [--normals TEST_N.pfm REF_N.pfm] [--csv]\n"
    "       imgcompare --mask TEST.png REF.pfm [--csv]\n"
    "Depth errors |TEST - REF| / V over pixels both hit (mean, 99th percentile,\n"
    "max), the fraction of pixels where hit and miss disagree, and the normal\n"
    "angle error in degrees (orientation ignored), and the test pixels with a\n"
    "NaN depth or normal. --mask: TEST is a PNG whose non-black pixels are\n"
    "hits; only the disagreement is measured. --csv prints mean,p99,max,\n"
    "disagree,normal_mean,normal_p99,normal_max,nan_pixels (nan where not\n"
    "measured).\n"
    "Exit status: 0 ok, 1 run-time failure, 2 bad usage.\n";

static int usage(const char *msg)
{
    diag_error("%s", msg);
    fputs(usage_text, stderr);
    return EXIT_USAGE;
}

static int load(const char *path, uint32_t channels, pfm_image *img)
{
    const char *why = NULL;
    if (pfm_read(path, img, &why) != 0) {
        if (!strcmp(why, "open"))
            diag_path_error(path, "%s", strerror(errno));
        else
            diag_path_error(path, "%s", why);
        return -1;
    }
    if (img->channels != channels) {
        diag_path_error(path, "expected a %u-channel PFM, found %u", channels, img->channels);
        pfm_free(img);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    diag_set_progname("imgcompare");
    const char *pos[2] = {NULL, NULL}, *nt = NULL, *nr = NULL, *mask = NULL;
    double voxel = NAN;
    int csv = 0, npos = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage_text, stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--csv")) {
            csv = 1;
        } else if (!strcmp(a, "--voxel") && i + 1 < argc) {
            if (parse_double(argv[++i], &voxel) != PARSE_OK || !(voxel > 0.0))
                return usage("--voxel needs a positive number");
        } else if (!strcmp(a, "--normals") && i + 2 < argc) {
            nt = argv[++i];
            nr = argv[++i];
        } else if (!strcmp(a, "--mask") && i + 1 < argc) {
            mask = argv[++i];
        } else if (a[0] == '-' && a[1] != '\0') {
            return usage("unknown option or missing value");
        } else if (npos < 2) {
            pos[npos++] = a;
        } else {
            return usage("too many files");
        }
    }
    if (mask ? npos != 1 : npos != 2)
        return usage(mask ? "--mask needs TEST.png and REF.pfm" : "need TEST.pfm and REF.pfm");
    if (!mask && isnan(voxel))
        return usage("--voxel V is required for depth errors");
    const char *ref_path = mask ? pos[0] : pos[1];
    pfm_image ref, test, ntest = {0, 0, 0, NULL}, nref = {0, 0, 0, NULL};
    if (load(ref_path, 1, &ref) != 0)
        return EXIT_RUNTIME;
    compare_stats st;
    int status = EXIT_OK;
    if (mask) {
        uint8_t *m;
        uint32_t w, h;
        const char *why;
        if (pngmask_read(mask, &m, &w, &h, &why) != 0) {
            diag_path_error(mask, "%s", why);
            pfm_free(&ref);
            return EXIT_RUNTIME;
        }
        if (w != ref.width || h != ref.height) {
            diag_path_error(mask, "%ux%u, the reference is %ux%u", w, h, ref.width, ref.height);
            free(m);
            pfm_free(&ref);
            return EXIT_RUNTIME;
        }
        compare_mask(m, ref.data, (size_t)w * h, &st);
        free(m);
    } else {
        if (load(pos[0], 1, &test) != 0) {
            pfm_free(&ref);
            return EXIT_RUNTIME;
        }
        if (nt && (load(nt, 3, &ntest) != 0 || load(nr, 3, &nref) != 0)) {
            status = EXIT_RUNTIME;
            goto done;
        }
        int same = test.width == ref.width && test.height == ref.height &&
                   (!nt || (ntest.width == ref.width && ntest.height == ref.height &&
                            nref.width == ref.width && nref.height == ref.height));
        if (!same) {
            diag_error("image sizes differ");
            status = EXIT_RUNTIME;
            goto done;
        }
        if (compare_depth(test.data, ref.data, (size_t)ref.width * ref.height, voxel,
                          nt ? ntest.data : NULL, nt ? nref.data : NULL, &st) != 0) {
            diag_error("out of memory");
            status = EXIT_RUNTIME;
            goto done;
        }
    }
    double dis = (double)st.disagree / (double)st.pixels;
    if (csv)
        printf("%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%zu\n", st.mean, st.p99, st.max, dis, st.nmean,
               st.np99, st.nmax, st.nan);
    else
        printf("pixels %zu, both hit %zu; depth error (voxels): mean %.4g, p99 %.4g, max %.4g; "
               "hit/miss disagree %.4f%%; normal error (deg): mean %.3g, p99 %.3g, max %.3g; "
               "NaN pixels %zu\n",
               st.pixels, st.both_hit, st.mean, st.p99, st.max, 100.0 * dis, st.nmean, st.np99,
               st.nmax, st.nan);
done:
    pfm_free(&ref);
    if (!mask) {
        pfm_free(&test);
        pfm_free(&ntest);
        pfm_free(&nref);
    }
    return status;
}
