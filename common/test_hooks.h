/* test_hooks: behaviour only the test builds have. Compiled with
 * DDA_TEST_HOOKS defined (tests and build/.../testbin programs), the
 * environment switches on:
 *     DDA_FPE_TRAPS=1   trap invalid operations (NaN from 0*inf, inf-inf,
 *                       sqrt(-1) ...) with SIGFPE, so a stray NaN stops the
 *                       run instead of reaching an output
 *     ATOMIC_FAULT=...  fail atomic_file's I/O on purpose (atomic_file.h)
 * Without the macro, the release programs never read those variables. */
#ifndef TEST_HOOKS_H
#define TEST_HOOKS_H

/* Call first in main(); threads inherit the trap mask. A no-op in release
 * builds. */
void test_hooks_init(void);

#endif
