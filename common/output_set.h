/* output_set: the files of one run, checked together before any work, so
 * that a run refuses at once what would otherwise fail (or destroy
 * something) after minutes of work:
 *   - one file in two roles: an output that is also an input, or two
 *     outputs of one view naming the same file (same path after resolving
 *     the directory and symlinks, or same inode): EXIT_USAGE. Two views may
 *     write one file in turn (a benchmark's repeated frames): the later
 *     view's stays. Character
 *     devices are exempt (any number of outputs may go to /dev/null); "-"
 *     (stdout) is not.
 *   - an output that cannot be written: a name over NAME_MAX / PATH_MAX, a
 *     directory, a missing or unwritable directory: EXIT_RUNTIME. */
#ifndef OUTPUT_SET_H
#define OUTPUT_SET_H

#include <stddef.h>

typedef struct output_use {
    const char *path;
    const char *role; /* as the user wrote it: "-o", "--depth", "the input", ... */
    unsigned line;    /* the views-file line that names it, 0: the command line */
    int is_input;
} output_use;

/* Checks n uses. Returns 0 (EXIT_OK), or EXIT_RUNTIME / EXIT_USAGE (see
 * above) with a message "PATH: what" in msg (size msg_size) about the first
 * problem found. -1 on allocation failure. */
int output_set_check(const output_use *uses, size_t n, char *msg, size_t msg_size);

#endif
