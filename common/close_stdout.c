/* close_stdout: check that stdout was written; see close_stdout.h. */
#include "common/close_stdout.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "common/diag.h"

int close_stdout(int status)
{
    errno = 0;
    int err = 0;
    if (fflush(stdout) != 0)
        err = errno ? errno : EIO;
    else if (ferror(stdout))
        err = EIO; /* an earlier write failed; its errno is long gone */
    errno = 0;
    /* EBADF: stdout was closed from the start and nothing was written to it
     * (writing would have failed above), so there is nothing lost. */
    if (fclose(stdout) != 0 && !err && errno != EBADF)
        err = errno ? errno : EIO;
    if (!err)
        return status;
    diag_error("standard output: %s", strerror(err));
    return status == EXIT_OK ? EXIT_RUNTIME : status;
}
