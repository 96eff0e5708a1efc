/* tape_io: tapes as the bytes of an .oct FUNCTION section (format/FORMAT.md
 * §8) and back. The op codes in those bytes are FORMAT.md's numbers, mapped
 * here explicitly to tape_op; this file does not include format/ (the
 * format layer knows nothing of tapes, and the expression engine nothing of
 * files: render and rasterize join the two). */
#ifndef TAPE_IO_H
#define TAPE_IO_H

#include <stddef.h>
#include <stdint.h>

#include "common/expr/tape.h"

#define TAPE_IO_EINVALID (-10) /* the stored tape breaks a rule of FORMAT.md §8 */

/* The FUNCTION section holding `count` tapes, in order, in a malloc'd
 * buffer (*out, *size bytes): the whole tape each, byte for byte what
 * FORMAT.md prescribes, so identical tapes give identical bytes. Returns
 * TAPE_OK, TAPE_ENOMEM, or TAPE_ETOOBIG for a tape over TAPE_MAX_INSNS
 * instructions or constants. */
int tape_io_encode(const tape *const *tapes, unsigned count, unsigned char **out, size_t *size);

/* An owned tape (free with tape_free) from one stored tape: n instructions
 * as words insn[3i..3i+2] = op (FORMAT.md's code), a, b; m constants as
 * konst[3j..3j+2] = v, lo, hi; output slot root. Checks every rule again
 * (TAPE_IO_EINVALID, *out zeroed) so that it is safe on any input; TAPE_OK
 * or TAPE_ENOMEM otherwise. */
int tape_io_decode(const uint32_t *insn, uint32_t n, const double *konst, uint32_t m, uint32_t root,
                   tape *out);

/* The file's op code of a tape_op, and the tape_op of a file's code (-1
 * when the code is unknown). */
uint32_t tape_io_file_op(tape_op op);
int tape_io_tape_op(uint32_t code);

#endif
