/* outputs: render's files, checked before the first ray and written a view
 * at a time, all of a view's images committed together. */
#ifndef RENDER_OUTPUTS_H
#define RENDER_OUTPUTS_H

#include <stddef.h>
#include <stdint.h>

#include "render/views.h"

/* 1 when path ends in ".pfm": --normals then writes float normals. */
int outputs_is_pfm(const char *path);

/* Every output of every view against the inputs and each other
 * (common/output_set.h). Prints the problem; returns EXIT_OK, EXIT_RUNTIME
 * or EXIT_USAGE. */
int outputs_check(const char *oct_path, const char *views_path, const views_view *list,
                  size_t nviews);

/* A view's rendered images, as the frame left them. */
typedef struct outputs_images {
    const uint8_t *rgb, *nrm;
    const uint8_t *alpha; /* coverage, for an RGBA colour image; NULL: RGB */
    const float *depth, *nrm_f;
    uint32_t width, height;
} outputs_images;

/* Writes the colour image and, when asked, depth and normals of view v, all
 * to temporaries first, then renames them in a row: either all of them
 * replace their targets or none does. Prints the failure; returns EXIT_OK or
 * EXIT_RUNTIME. */
int outputs_write_view(const views_view *v, const outputs_images *img);

#endif
