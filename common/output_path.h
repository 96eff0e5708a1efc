/* output_path: what an output path names before anything is written to it.
 * atomic_file (writing) and output_set (checking a run's outputs up front)
 * both take their answers from here, so they agree on every path.
 *
 * An output is one of:
 *   "-"                      standard output, written directly;
 *   an existing non-regular  a device, FIFO or socket (after following
 *   file                     symbolic links), written directly, never replaced;
 *   a regular file or        replaced atomically: a temporary beside the file
 *   nothing (yet)            a symlink chain ends at, then renamed over it,
 *                            so the links stay links. */
#ifndef OUTPUT_PATH_H
#define OUTPUT_PATH_H

#include <stddef.h>

typedef enum output_kind {
    OUTPUT_STDOUT,  /* "-" */
    OUTPUT_DIRECT,  /* an existing device, FIFO or socket */
    OUTPUT_REPLACE, /* a regular file or a name not taken yet */
} output_kind;

/* 1 when path means standard output. */
int output_path_is_stdout(const char *path);

/* Classifies path. For OUTPUT_REPLACE, *resolved (if not NULL) is a
 * malloc'ed copy of the path the symlink chain of the last component ends at
 * (path itself when it is not a link); otherwise it is set to NULL. Returns
 * 0, or -1 with errno: EISDIR for a directory, ELOOP for more than 40 links,
 * ENOMEM, or stat's error. */
int output_path_classify(const char *path, output_kind *kind, char **resolved);

/* The directory part of path ("." when there is none), malloc'ed. */
char *output_path_dir(const char *path);

/* The temporary's name for target: "<target>.tmp.XXXXXX" (a mkstemp
 * template), its last component shortened so that it stays within NAME_MAX
 * bytes. malloc'ed, NULL on allocation failure. */
char *output_path_temp_template(const char *target);

/* 0 when every component of path is at most NAME_MAX bytes and the whole
 * shorter than PATH_MAX; -1 with errno = ENAMETOOLONG otherwise. */
int output_path_check_length(const char *path);

#endif
