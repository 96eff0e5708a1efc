/* atomic_file: write an output file so that readers only ever see the old
 * file or the complete new one. A temporary file is created in the target's
 * directory (O_EXCL, unique name, shortened to fit NAME_MAX), written through
 * a FILE *, flushed, fsynced and renamed over the target, then the directory
 * is fsynced. A symlinked target is written where the links end (the links
 * stay). On failure, on atomic_file_abort, and on every terminating signal
 * the program does not cause itself (SIGINT, SIGTERM, SIGHUP, SIGQUIT,
 * SIGPIPE, SIGXFSZ, SIGUSR1/2, ...: the handler unlinks, restores the default
 * and re-raises), the temporary file is removed and the target is untouched.
 *
 * Only regular files are replaced: "-" (stdout) and an existing device, FIFO
 * or socket are written directly, without a temporary (output_path.h); a
 * failure there cannot be undone, and is still reported.
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

/* Creates the temporary file (or, for "-", a device or a FIFO, opens the
 * target itself). Returns NULL with errno set on failure: EISDIR for a
 * directory, ELOOP for a symlink loop, open's or mkstemp's errors. */
atomic_file *atomic_file_open(const char *target_path);

/* The stream to write to (seekable, except when the target is "-", a FIFO
 * or a device that cannot seek); valid until commit or abort. */
FILE *atomic_file_stream(atomic_file *af);

/* Writes n bytes, honouring the fault hook; returns 0 or -1 with errno. */
int atomic_file_write(atomic_file *af, const void *data, size_t n);

/* Flush, fsync, close, rename, fsync the directory; frees af. Returns 0, or
 * -1 with errno set and the temporary removed (target untouched). On error
 * *failed_op (if not NULL) names the step: "write", "fsync", "close", ... */
int atomic_file_commit(atomic_file *af, const char **failed_op);

/* Commits n files together: all are flushed, fsynced and closed first, and
 * only when every one of those steps succeeded are they renamed, one right
 * after the other. So either all are replaced or (a failure before the
 * renames) none; only a failing rename itself (rare: the directory's own
 * I/O) leaves the ones before it replaced. Every file not renamed has its
 * temporary removed; all are freed. Returns 0, or -1 with errno, *failed
 * (if not NULL) the index of the file that failed and *failed_op its step. */
int atomic_file_commit_all(atomic_file **afs, size_t n, size_t *failed, const char **failed_op);

/* Removes the temporary and frees af. Accepts NULL. */
void atomic_file_abort(atomic_file *af);

#endif
