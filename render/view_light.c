/* view_light: see view_light.h. */
#include "render/view_light.h"

#include <string.h>

#include "render/shade.h"

void view_light(int has_light, const double light[3], const camera *cam, double out[3])
{
    if (has_light) {
        shade_params sp;
        shade_set_light(&sp, light);
        for (int a = 0; a < 3; a++)
            out[a] = sp.light[a];
    } else {
        shade_default_light(cam, out);
    }
}

void view_shadow_pixels(int has_light, const double light[3], const views_view *list,
                        const camera *cams, size_t n, size_t first, size_t step, uint64_t *ahead)
{
    if (first >= n || step == 0)
        return;
    size_t k = first + (n - 1 - first) / step * step; /* the last view of the run */
    double next_light[3] = {0, 0, 0};
    uint64_t next = 0; /* ahead[] of the next shadow view after k, 0: none */
    for (;; k -= step) {
        ahead[k] = 0;
        if (list[k].shadows) {
            double l[3];
            view_light(has_light, light, &cams[k], l);
            const uint64_t px = (uint64_t)list[k].width * (uint64_t)list[k].height;
            ahead[k] = px + (next && memcmp(l, next_light, sizeof l) == 0 ? next : 0);
            next = ahead[k];
            memcpy(next_light, l, sizeof l);
        }
        if (k == first)
            break;
    }
}
