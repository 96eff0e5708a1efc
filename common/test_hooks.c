#include "common/test_hooks.h"

#ifdef DDA_TEST_HOOKS
#include <fenv.h>
#include <stdlib.h>
#include <string.h>

void test_hooks_init(void)
{
    const char *v = getenv("DDA_FPE_TRAPS");
    if (v && strcmp(v, "1") == 0)
        feenableexcept(FE_INVALID);
}
#else
void test_hooks_init(void) {}
#endif
