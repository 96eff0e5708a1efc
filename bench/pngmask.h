/* pngmask: a PNG read as a hit mask (any non-black pixel is a hit). */
#ifndef PNGMASK_H
#define PNGMASK_H

#include <stdint.h>

/* Reads path; *mask receives w*h bytes (1 hit, 0 background), rows top to
 * bottom; free it with free(). Returns 0 or -1 with a static reason. */
int pngmask_read(const char *path, uint8_t **mask, uint32_t *w, uint32_t *h, const char **why);

#endif
