/* outputs: render's output checks and a view's all-or-nothing write; see
 * outputs.h. */
#include "render/outputs.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "common/atomic_file.h"
#include "common/diag.h"
#include "common/output_set.h"
#include "common/view/image.h"

int outputs_is_pfm(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcmp(path + n - 4, ".pfm") == 0;
}

int outputs_check(const char *oct_path, const char *views_path, const views_view *list,
                  size_t nviews)
{
    if (nviews > (SIZE_MAX - 2) / 3) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    output_use *uses = malloc((2 + 3 * nviews) * sizeof *uses);
    if (!uses) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    size_t n = 0;
    uses[n++] = (output_use){oct_path, "the input", 0, 1};
    if (views_path)
        uses[n++] = (output_use){views_path, "--views", 0, 1};
    for (size_t k = 0; k < nviews; k++) {
        const views_view *v = &list[k];
        uses[n++] = (output_use){v->out, "-o", v->line, 0};
        if (v->depth)
            uses[n++] = (output_use){v->depth, "--depth", v->line, 0};
        if (v->normals)
            uses[n++] = (output_use){v->normals, "--normals", v->line, 0};
    }
    char msg[2 * 4096 + 256];
    int rc = output_set_check(uses, n, msg, sizeof msg);
    free(uses);
    if (rc < 0) {
        diag_error("out of memory");
        return EXIT_RUNTIME;
    }
    if (rc != EXIT_OK)
        diag_error("%s", msg);
    return rc;
}

int outputs_write_view(const views_view *v, const outputs_images *img)
{
    enum { COLOUR, DEPTH, NORMALS } kind[3];
    const char *paths[3];
    atomic_file *af[3];
    size_t n = 0;
    paths[n] = v->out;
    kind[n++] = COLOUR;
    if (v->depth) {
        paths[n] = v->depth;
        kind[n++] = DEPTH;
    }
    if (v->normals) {
        paths[n] = v->normals;
        kind[n++] = NORMALS;
    }
    const uint32_t w = img->width, h = img->height;
    for (size_t i = 0; i < n; i++) {
        af[i] = atomic_file_open(paths[i]);
        int rc = -1;
        const char *op = "write";
        if (!af[i])
            op = "open";
        else if (kind[i] == COLOUR)
            rc = image_png_alpha_to(af[i], img->rgb, img->alpha, w, h);
        else if (kind[i] == DEPTH)
            rc = image_pfm_to(af[i], img->depth, w, h);
        else if (outputs_is_pfm(v->normals))
            rc = image_pfm_rgb_to(af[i], img->nrm_f, w, h);
        else
            rc = image_png_to(af[i], img->nrm, w, h);
        if (rc != 0) {
            int e = errno;
            diag_path_error(paths[i], "%s: %s", op, strerror(e));
            for (size_t j = 0; j <= i; j++)
                atomic_file_abort(af[j]);
            return EXIT_RUNTIME;
        }
    }
    size_t failed = 0;
    const char *op = NULL;
    if (atomic_file_commit_all(af, n, &failed, &op) != 0) {
        diag_path_error(paths[failed], "%s: %s", op ? op : "write", strerror(errno));
        return EXIT_RUNTIME;
    }
    return EXIT_OK;
}
