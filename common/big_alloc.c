/* big_alloc: see big_alloc.h. */
#include "common/big_alloc.h"

#include <stdlib.h>
#include <sys/mman.h>

void *big_alloc(size_t bytes)
{
#if defined(MAP_ANONYMOUS) && defined(MADV_HUGEPAGE)
    if (bytes >= BIG_ALLOC_MAPPED) {
        void *p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED)
            return NULL;
        (void)madvise(p, bytes, MADV_HUGEPAGE); /* a hint: no huge pages is fine */
        return p;
    }
#endif
    return malloc(bytes ? bytes : 1);
}

void big_free(void *p, size_t bytes)
{
    if (!p)
        return;
#if defined(MAP_ANONYMOUS) && defined(MADV_HUGEPAGE)
    if (bytes >= BIG_ALLOC_MAPPED) {
        munmap(p, bytes);
        return;
    }
#endif
    free(p);
}
