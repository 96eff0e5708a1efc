/* pfm: reader for the PFM images the tools write (Pf grayscale, PF colour). */
#ifndef PFM_H
#define PFM_H

#include <stdint.h>

typedef struct pfm_image {
    uint32_t width, height, channels; /* channels 1 (Pf) or 3 (PF) */
    float *data;                      /* width*height*channels, rows top to bottom */
} pfm_image;

/* Reads path into *img (free with pfm_free). Returns 0, or -1 with a static
 * reason in *why ("open", "not a PFM file", "truncated", ...; errno is
 * meaningful for "open" and "read"). Either byte order is accepted. */
int pfm_read(const char *path, pfm_image *img, const char **why);
void pfm_free(pfm_image *img);

#endif
