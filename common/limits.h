/* limits: the numeric limits of the command lines, each defined once and
 * used by the code, its messages and the usage text (LIMIT_STR turns one
 * into a string literal for the texts). Limits a file format or a module
 * owns stay with it and are stringified the same way: OCT_MAX_LEVELS
 * (format/oct.h, --levels 1..20) and CAMERA_MAX_SIZE (common/view/camera.h,
 * --size 1..32768 a side). */
#ifndef DDA_LIMITS_H
#define DDA_LIMITS_H

#define LIMIT_STR_(x) #x
#define LIMIT_STR(x) LIMIT_STR_(x)

/* --threads N accepts 1..THREADS_MAX in both programs. */
#define THREADS_MAX 256
/* Without --threads: the number of online processors, at most this. */
#define THREADS_DEFAULT_MAX 64

#endif
