/* aa: the edge test of adaptive antialiasing inside a rectangle of pixels. */
#include "render/aa.h"

void aa_mark_inside(aa_probe *p, size_t stride, uint32_t w, uint32_t h)
{
    for (uint32_t j = 0; j < h; j++) {
        aa_probe *row = p + (size_t)j * stride;
        const int down = j + 1 < h;
        for (uint32_t i = 0; i < w; i++) {
            aa_probe *a = row + i;
            /* misses all round, the common case, at the cost of two loads */
            if (!a->hit && (i + 1 >= w || !a[1].hit) && (!down || !a[stride].hit))
                continue;
            if (i + 1 < w && aa_differs(a, a + 1))
                a->need = a[1].need = 1;
            if (down && aa_differs(a, a + stride))
                a->need = a[stride].need = 1;
        }
    }
}
