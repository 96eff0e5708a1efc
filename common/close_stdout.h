/* close_stdout: the last thing a program does. Output on stdout (--help,
 * --version, --info, summaries, an image written to "-") that could not be
 * written, because of a full disk or a broken device, is a failure like any
 * other write error, not a silent exit 0. */
#ifndef CLOSE_STDOUT_H
#define CLOSE_STDOUT_H

/* Flushes and closes stdout. Returns status when that worked; otherwise
 * prints "prog: standard output: <reason>" and returns EXIT_RUNTIME (or
 * status, when it already says failure). */
int close_stdout(int status);

#endif
