/* test_hooks: behaviour only the test builds have. Compiled with
 * DDA_TEST_HOOKS defined (tests and build/.../testbin programs), the
 * environment switches on:
 *     DDA_FPE_TRAPS=1   trap invalid operations (NaN from 0*inf, inf-inf,
 *                       sqrt(-1) ...) with SIGFPE, so a stray NaN stops the
 *                       run instead of reaching an output
 *     ATOMIC_FAULT=...  fail atomic_file's I/O on purpose (atomic_file.h)
 *     DDA_RENDER_HOOK=VIEW:TILE:COMMAND
 *                       render runs COMMAND (system(3)) once, when its view
 *                       VIEW (from 1) has TILE tiles done (0: before the
 *                       view's first ray), on the thread that called
 *                       frame_render: with --threads 1 a fixed point of the
 *                       run, to change the mapped file under it
 *     DDA_SIMD=portable the lane evaluators run their portable build even
 *                       where the processor has AVX2 (common/expr/tape.h),
 *                       so the tests cover every dispatched path
 * Without the macro, the release programs never read those variables. */
#ifndef TEST_HOOKS_H
#define TEST_HOOKS_H

/* Call first in main(); threads inherit the trap mask. A no-op in release
 * builds. */
void test_hooks_init(void);

/* DDA_RENDER_HOOK's points: the view about to be rendered (runs a TILE 0
 * hook), then each count of tiles done. No-ops in release builds. */
void test_hooks_view(unsigned view);
void test_hooks_tile(unsigned long long done);

/* 1 when DDA_SIMD=portable is set (test builds); 0 in release builds. */
int test_hooks_portable_simd(void);

#endif
