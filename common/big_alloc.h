/* big_alloc: memory for large arrays filled once and read a lot (render's
 * per-frame buffers): from a size of 2 MiB, an anonymous mapping with a
 * hint for huge pages, so that the first touch of a megabyte costs one or
 * two page faults instead of 256 (each some 15-20 us of CPU on virtual
 * machines); below it, malloc. */
#ifndef BIG_ALLOC_H
#define BIG_ALLOC_H

#include <stddef.h>

#define BIG_ALLOC_MAPPED ((size_t)1 << 21) /* from this size on: mapped */

/* bytes of uninitialised memory (zeroed when mapped), or NULL. */
void *big_alloc(size_t bytes);
/* Releases p (NULL accepted); bytes as given to big_alloc. */
void big_free(void *p, size_t bytes);

#endif
