/* pngmask: libpng's simplified reader, thresholded. */
#include "bench/pngmask.h"

#include <png.h>
#include <stdlib.h>
#include <string.h>

int pngmask_read(const char *path, uint8_t **mask, uint32_t *w, uint32_t *h, const char **why)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) {
        *why = "cannot read PNG";
        return -1;
    }
    img.format = PNG_FORMAT_GRAY;
    size_t n = (size_t)img.width * img.height;
    uint8_t *buf = malloc(n ? n : 1);
    if (!buf) {
        png_image_free(&img);
        *why = "out of memory";
        return -1;
    }
    if (!png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        free(buf);
        *why = "cannot decode PNG";
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        buf[i] = buf[i] != 0;
    *mask = buf;
    *w = img.width;
    *h = img.height;
    return 0;
}
