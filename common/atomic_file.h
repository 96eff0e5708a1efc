/* atomic_file: write an output file so that readers only ever see the old
 * file or the complete new one. A temporary file is created in the target's
 * directory (O_EXCL, unique name), written through a FILE *, flushed, fsynced
 * and renamed over the target, then the directory is fsynced. On failure, on
 * atomic_file_abort, and on SIGINT/SIGTERM/SIGHUP (the handler only unlinks
 * and re-raises), the temporary file is removed and the target is untouched.
 *
 * Test hook, compiled only with DDA_TEST_HOOKS (common/test_hooks.h): the
 * environment variable ATOMIC_FAULT=OP:N[:ERRNO][:sticky] (OP =
 * write|fsync|close|rename, ERRNO = ENOSPC|EIO|...) makes the Nth such call
 * fail with that errno (default EIO), and every later one with :sticky. */
#ifndef ATOMIC_FILE_H
#define ATOMIC_FILE_H

#include <stdio.h>
#include <stddef.h>

typedef struct atomic_file atomic_file;

/* Creates the temporary file. Returns NULL with errno set on failure. */
atomic_file *atomic_file_open(const char *target_path);

/* The stream to write to (seekable); valid until commit or abort. */
FILE *atomic_file_stream(atomic_file *af);

/* Writes n bytes, honouring the fault hook; returns 0 or -1 with errno. */
int atomic_file_write(atomic_file *af, const void *data, size_t n);

/* Flush, fsync, close, rename, fsync the directory; frees af. Returns 0, or
 * -1 with errno set and the temporary removed (target untouched). On error
 * *failed_op (if not NULL) names the step: "write", "fsync", "close", ... */
int atomic_file_commit(atomic_file *af, const char **failed_op);

/* Removes the temporary and frees af. Accepts NULL. */
void atomic_file_abort(atomic_file *af);

#endif
