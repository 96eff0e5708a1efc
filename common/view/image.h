/* image: PNG (8-bit sRGB, libpng) and PFM (grayscale float depth) writers,
 * both atomic through atomic_file: the target is the old file or the whole
 * new one, never a part. */
#ifndef IMAGE_H
#define IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "common/atomic_file.h"

/* Bytes of a w x h 8-bit RGB image in *out; -1 when that overflows size_t. */
int image_rgb_size(uint32_t w, uint32_t h, size_t *out);

/* Linear [0,1] (clamped; NaN -> 0) to an 8-bit sRGB code value. */
uint8_t image_srgb8(float linear);

/* Writes rgb (w*h*3 bytes, rows top to bottom, already sRGB-encoded) as an
 * 8-bit RGB PNG with an sRGB chunk. Returns 0, or -1 with errno set and
 * *failed_op (when not NULL) naming the step ("open", "png", "write",
 * "fsync", "rename", ...); on failure no file is left. */
int image_write_png(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h,
                    const char **failed_op);

/* Writes a grayscale PFM ("Pf", scale -1.0: little-endian float32), rows
 * stored bottom to top as the format defines; `values` is w*h floats, rows
 * top to bottom (+inf allowed). Same return convention. */
int image_write_pfm(const char *path, const float *values, uint32_t w, uint32_t h,
                    const char **failed_op);

/* Writes a 3-channel PFM ("PF", scale -1.0, bottom row first); `values` is
 * w*h*3 floats, rows top to bottom, channels interleaved (used for float
 * normal images). Same return convention. */
int image_write_pfm_rgb(const char *path, const float *values, uint32_t w, uint32_t h,
                        const char **failed_op);

/* The same three images written into an open atomic_file, left for the
 * caller to commit (with others: atomic_file_commit_all) or abort. Return 0,
 * or -1 with errno (EOVERFLOW: the size). */
int image_png_to(atomic_file *af, const uint8_t *rgb, uint32_t w, uint32_t h);
/* An RGBA PNG: rgb as above, alpha w*h coverage bytes (rows top to bottom). */
int image_png_alpha_to(atomic_file *af, const uint8_t *rgb, const uint8_t *alpha, uint32_t w,
                       uint32_t h);
int image_pfm_to(atomic_file *af, const float *values, uint32_t w, uint32_t h);
int image_pfm_rgb_to(atomic_file *af, const float *values, uint32_t w, uint32_t h);

#endif
