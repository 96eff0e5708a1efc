#include "common/test_hooks.h"

#ifdef DDA_TEST_HOOKS
#include <fenv.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void test_hooks_init(void)
{
    const char *v = getenv("DDA_FPE_TRAPS");
    if (v && strcmp(v, "1") == 0)
        feenableexcept(FE_INVALID);
}

static unsigned hook_view;

/* Runs DDA_RENDER_HOOK's command when (view, done) is its point, once. */
static void render_hook(unsigned view, unsigned long long done)
{
    static int ran;
    const char *v = getenv("DDA_RENDER_HOOK");
    if (ran || !v)
        return;
    unsigned want_view;
    unsigned long long want_tile;
    int n = 0;
    if (sscanf(v, "%u:%llu:%n", &want_view, &want_tile, &n) != 2 || n == 0)
        return;
    if (view != want_view || done != want_tile)
        return;
    ran = 1;
    if (system(v + n) != 0)
        fprintf(stderr, "DDA_RENDER_HOOK: '%s' failed\n", v + n);
}

void test_hooks_view(unsigned view)
{
    hook_view = view;
    render_hook(view, 0);
}

void test_hooks_tile(unsigned long long done) { render_hook(hook_view, done); }

int test_hooks_portable_simd(void)
{
    const char *v = getenv("DDA_SIMD");
    return v && strcmp(v, "portable") == 0;
}
#else
void test_hooks_init(void) {}
void test_hooks_view(unsigned view) { (void)view; }
void test_hooks_tile(unsigned long long done) { (void)done; }
int test_hooks_portable_simd(void) { return 0; }
#endif
