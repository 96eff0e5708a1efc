/* big_alloc: see big_alloc.h. */
#include "common/big_alloc.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>

#if defined(MAP_ANONYMOUS) && defined(MADV_HUGEPAGE)
#define BIG_ALLOC_HUGE 1
/* bytes rounded up to whole huge pages (the mapped length), 0 on overflow */
static size_t huge_length(size_t bytes)
{
    const size_t huge = BIG_ALLOC_MAPPED;
    return bytes > SIZE_MAX - huge ? 0 : (bytes + huge - 1) & ~(huge - 1);
}
#else
#define BIG_ALLOC_HUGE 0
#endif

void *big_alloc(size_t bytes)
{
#if BIG_ALLOC_HUGE
    if (bytes >= BIG_ALLOC_MAPPED) {
        /* huge pages only fill aligned 2 MiB ranges: map one more, keep the
           aligned whole pages, return the ends */
        const size_t len = huge_length(bytes), huge = BIG_ALLOC_MAPPED;
        if (!len || len > SIZE_MAX - huge)
            return NULL;
        char *m = mmap(NULL, len + huge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1,
                       0);
        if (m == MAP_FAILED)
            return NULL;
        char *p = (char *)(((uintptr_t)m + huge - 1) & ~(uintptr_t)(huge - 1));
        if (p > m)
            munmap(m, (size_t)(p - m));
        if (p + len < m + len + huge)
            munmap(p + len, (size_t)(m + len + huge - (p + len)));
        (void)madvise(p, len, MADV_HUGEPAGE); /* a hint: no huge pages is fine */
        return p;
    }
#endif
    return malloc(bytes ? bytes : 1);
}

void big_free(void *p, size_t bytes)
{
    if (!p)
        return;
#if BIG_ALLOC_HUGE
    if (bytes >= BIG_ALLOC_MAPPED) {
        munmap(p, huge_length(bytes));
        return;
    }
#endif
    free(p);
}
