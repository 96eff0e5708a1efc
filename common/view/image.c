/* image: atomic PNG and PFM writers. */
#include "common/view/image.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "common/atomic_file.h"

int image_rgb_size(uint32_t w, uint32_t h, size_t *out)
{
    if (w == 0 || h == 0 || (size_t)w > SIZE_MAX / 3 / (size_t)h)
        return -1;
    *out = (size_t)w * h * 3;
    return 0;
}

uint8_t image_srgb8(float linear)
{
    double x = linear;
    if (!(x > 0.0))
        return 0;
    if (x >= 1.0)
        return 255;
    double s = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    return (uint8_t)(s * 255.0 + 0.5);
}

static void png_fail(png_structp png, png_const_charp msg)
{
    (void)msg;
    png_longjmp(png, 1);
}

static void png_warn(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void png_write_cb(png_structp png, png_bytep data, size_t n)
{
    atomic_file *af = png_get_io_ptr(png);
    if (atomic_file_write(af, data, n) != 0)
        png_longjmp(png, 2);
}

static void png_flush_cb(png_structp png)
{
    (void)png;
}

int image_png_to(atomic_file *af, const uint8_t *rgb, uint32_t w, uint32_t h)
{
    return image_png_alpha_to(af, rgb, NULL, w, h);
}

int image_png_alpha_to(atomic_file *af, const uint8_t *rgb, const uint8_t *alpha, uint32_t w,
                       uint32_t h)
{
    size_t bytes;
    if (image_rgb_size(w, h, &bytes) != 0 || w > PNG_UINT_31_MAX / 4 || h > PNG_UINT_31_MAX) {
        errno = EOVERFLOW;
        return -1;
    }
    /* RGBA rows, interleaved; volatile: live across setjmp, which gcc without
     * LTO flags (-Wclobbered) although it is never changed after it */
    uint8_t *volatile row = alpha ? malloc(4 * (size_t)w) : NULL;
    if (alpha && !row) {
        errno = ENOMEM;
        return -1;
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png_fail, png_warn);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    volatile int err = 0;
    if (!png || !info) {
        err = ENOMEM;
        goto fail;
    }
    if (setjmp(png_jmpbuf(png))) {
        /* 2: our write callback failed and set errno; 1: libpng's own error */
        err = errno ? errno : EIO;
        goto fail;
    }
    errno = 0;
    png_set_write_fn(png, af, png_write_cb, png_flush_cb);
    png_set_IHDR(png, info, w, h, 8, alpha ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    /* Rendered frames are flat background and smooth shading: the SUB filter
     * and run-length deflate keep them within a fifth of the default size
     * for a fifteenth of the time (47 -> 3 ms a 1024^2 frame, 85 -> 100 KB),
     * which matters when an orbit writes hundreds of them. */
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_strategy(png, Z_RLE);
    png_write_info(png, info);
    for (uint32_t j = 0; j < h; j++) {
        const uint8_t *src = rgb + (size_t)j * w * 3;
        if (!alpha) {
            png_write_row(png, src);
            continue;
        }
        for (uint32_t i = 0; i < w; i++) {
            memcpy(row + 4 * (size_t)i, src + 3 * (size_t)i, 3);
            row[4 * (size_t)i + 3] = alpha[(size_t)j * w + i];
        }
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(row);
    return 0;
fail:
    png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
    free(row);
    errno = err;
    return -1;
}

/* Opens path, writes through `to` and commits; shared by the path writers. */
static int write_path(const char *path, int (*to)(atomic_file *, const void *, uint32_t, uint32_t),
                      const void *data, uint32_t w, uint32_t h, const char **failed_op)
{
    atomic_file *af = atomic_file_open(path);
    if (!af) {
        if (failed_op)
            *failed_op = "open";
        return -1;
    }
    if (to(af, data, w, h) != 0) {
        int e = errno;
        atomic_file_abort(af);
        errno = e;
        if (failed_op)
            *failed_op = e == EOVERFLOW ? "size" : "write";
        return -1;
    }
    return atomic_file_commit(af, failed_op);
}

static int png_to(atomic_file *af, const void *rgb, uint32_t w, uint32_t h)
{
    return image_png_to(af, rgb, w, h);
}

int image_write_png(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h,
                    const char **failed_op)
{
    return write_path(path, png_to, rgb, w, h, failed_op);
}

/* PFM with `ch` channels (1: "Pf", 3: "PF"), bottom row first. */
static int pfm_to(atomic_file *af, const float *values, uint32_t w, uint32_t h, unsigned ch)
{
    if (w == 0 || h == 0 || (size_t)w > SIZE_MAX / 4 / ch / (size_t)h) {
        errno = EOVERFLOW;
        return -1;
    }
    char head[64];
    int hn = snprintf(head, sizeof head, "%s\n%u %u\n-1.0\n", ch == 3 ? "PF" : "Pf", (unsigned)w,
                      (unsigned)h);
    if (atomic_file_write(af, head, (size_t)hn) != 0)
        return -1;
    uint8_t row[4096];
    const size_t n = (size_t)w * ch;
    for (uint32_t jj = h; jj-- > 0;) { /* bottom row first */
        const float *src = values + (size_t)jj * n;
        size_t fill = 0;
        for (size_t i = 0; i < n; i++) {
            uint32_t u;
            memcpy(&u, &src[i], 4);
            row[fill++] = (uint8_t)u;
            row[fill++] = (uint8_t)(u >> 8);
            row[fill++] = (uint8_t)(u >> 16);
            row[fill++] = (uint8_t)(u >> 24);
            if (fill == sizeof row) {
                if (atomic_file_write(af, row, fill) != 0)
                    return -1;
                fill = 0;
            }
        }
        if (fill && atomic_file_write(af, row, fill) != 0)
            return -1;
    }
    return 0;
}

int image_pfm_to(atomic_file *af, const float *values, uint32_t w, uint32_t h)
{
    return pfm_to(af, values, w, h, 1);
}

int image_pfm_rgb_to(atomic_file *af, const float *values, uint32_t w, uint32_t h)
{
    return pfm_to(af, values, w, h, 3);
}

static int pfm1_to(atomic_file *af, const void *values, uint32_t w, uint32_t h)
{
    return pfm_to(af, values, w, h, 1);
}

static int pfm3_to(atomic_file *af, const void *values, uint32_t w, uint32_t h)
{
    return pfm_to(af, values, w, h, 3);
}

int image_write_pfm(const char *path, const float *values, uint32_t w, uint32_t h,
                    const char **failed_op)
{
    return write_path(path, pfm1_to, values, w, h, failed_op);
}

int image_write_pfm_rgb(const char *path, const float *values, uint32_t w, uint32_t h,
                        const char **failed_op)
{
    return write_path(path, pfm3_to, values, w, h, failed_op);
}
