/* oct_sink: see oct_sink.h. */
#include "format/oct_sink.h"

#include <errno.h>

#include "format/oct_layout.h"

int oct_sink_put(oct_sink *s, const void *data, size_t n)
{
    if (n == 0)
        return 0;
    if (!s->no_crc)
        s->crc = crc32_z(s->crc, data, n);
    s->bytes += n;
    /* glibc may report a failed flush inside fwrite only through the error
     * flag, so both are checked: the caller stops at the first failure. */
    if (s->f && (fwrite(data, 1, n, s->f) != n || ferror(s->f))) {
        if (errno == 0)
            errno = EIO;
        return -1;
    }
    return 0;
}

int oct_sink_pad_to(oct_sink *s, uint64_t target)
{
    static const unsigned char zero[OCT_ALIGN];
    while (s->bytes < target) {
        uint64_t n = target - s->bytes;
        if (oct_sink_put(s, zero, n < sizeof zero ? (size_t)n : sizeof zero) != 0)
            return -1;
    }
    return 0;
}
