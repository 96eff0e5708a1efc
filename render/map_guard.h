/* map_guard: notices when the mapped .oct file changes under the renderer
 * (format/FORMAT.md §10, "Mapping"). The file's identity (device, inode,
 * size, modification time) is taken once it is mapped and compared between
 * views and after each; a SIGBUS or SIGSEGV raised while a thread runs under
 * map_guard_run, at a moment when that identity has changed (a truncation:
 * lost pages; an overwrite in place: indices from foreign bytes), abandons
 * that thread's work instead of killing the process. Any other fault keeps
 * its default action: a bug still crashes. One mapped file per process. */
#ifndef MAP_GUARD_H
#define MAP_GUARD_H

#include <stdint.h>

/* Opens `path` (after the mapping was made from it) and records its
 * identity; `mapped_size` is the size that was mapped. Installs the fault
 * handlers. Returns 0; -1 with errno set when it cannot be opened, or with
 * errno 0 when the file already differs from what was mapped. */
int map_guard_open(const char *path, uint64_t mapped_size);

/* 1 when the file's identity differs from the recorded one (or can no
 * longer be read), else 0. Always 0 before map_guard_open. */
int map_guard_changed(void);

/* Runs fn(arg) on the calling thread. Returns 0 when it returned, -1 when a
 * fault caused by a changed file abandoned it. */
int map_guard_run(void (*fn)(void *), void *arg);

/* Restores the default fault actions and closes the file. */
void map_guard_close(void);

#endif
