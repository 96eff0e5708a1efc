/* oct_alloc: the one place format/ allocates, so tests can make the Nth
 * allocation fail (STYLE.md: allocation failure must be testable). */
#include "format/oct_layout.h"

#include <stdlib.h>

static long fail_at;     /* fail the fail_at-th allocation from the arming; 0 = never */
static int fail_sticky;  /* and every one after it */
static long alloc_calls;

void oct__alloc_fail_after(long n, int sticky)
{
    fail_at = n;
    fail_sticky = sticky;
    alloc_calls = 0;
}

static int should_fail(void)
{
    if (fail_at <= 0)
        return 0;
    long c = ++alloc_calls;
    return c == fail_at || (fail_sticky && c > fail_at);
}

void *oct__calloc(size_t n, size_t size) { return should_fail() ? NULL : calloc(n, size); }
void *oct__realloc(void *p, size_t size) { return should_fail() ? NULL : realloc(p, size); }
void *oct__aligned_alloc(size_t align, size_t size)
{
    return should_fail() ? NULL : aligned_alloc(align, size);
}
