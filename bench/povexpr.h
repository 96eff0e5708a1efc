/* povexpr: a tape written out as a POV-Ray function expression. */
#ifndef POVEXPR_H
#define POVEXPR_H

#include <stddef.h>

#include "common/expr/tape.h"

/* Writes the expression of t's root into buf (NUL-terminated), shared
 * sub-expressions repeated (POV-Ray functions have no local names): x^n as
 * pow, log as ln (POV's log is base 10), constants with 17 digits. Returns
 * the length, or -1 when it does not fit in cap bytes. */
long povexpr_write(const tape *t, char *buf, size_t cap);

#endif
