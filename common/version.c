#include "common/version.h"

#include <stdio.h>

#ifndef DDA_VERSION
#define DDA_VERSION "unknown"
#endif
#ifndef DDA_COMMIT
#define DDA_COMMIT ""
#endif

const char *version_string(void)
{
    return sizeof DDA_COMMIT > 1 ? DDA_VERSION " (" DDA_COMMIT ")" : DDA_VERSION;
}

void version_print(const char *prog) { printf("%s %s\n", prog, version_string()); }
