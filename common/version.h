/* version: the project's one version string, for --version. */
#ifndef VERSION_H
#define VERSION_H

/* "1.1.0-dev (abc1234)" when built from a git checkout, "1.1.0-dev" when
 * not. The Makefile defines DDA_VERSION (from the VERSION file) and
 * DDA_COMMIT (`git describe --always --dirty`, empty outside a checkout). */
const char *version_string(void);

/* Prints "PROG VERSION (COMMIT)" and a newline on stdout. */
void version_print(const char *prog);

#endif
