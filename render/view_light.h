/* view_light: the light of each view of a run, and what a shadow map made
 * for a view will serve (the views after it under the same light). */
#ifndef VIEW_LIGHT_H
#define VIEW_LIGHT_H

#include <stddef.h>
#include <stdint.h>

#include "common/view/camera.h"
#include "render/views.h"

/* The unit light of a view: `light` (has_light; a direction the command
 * line has checked) normalized, else over the camera's shoulder. */
void view_light(int has_light, const double light[3], const camera *cam, double out[3]);

/* For the views k = first, first + step, ... < n of a run, in order, ahead[k]:
 * the pixels of view k and of the views after it that cast shadows under
 * its light with no shadow view under another light between (which would
 * make the kept map again): the frames the shadow map made for view k
 * serves (shadow_map_up_for). 0 for a view without shadows. One pass. */
void view_shadow_pixels(int has_light, const double light[3], const views_view *list,
                        const camera *cams, size_t n, size_t first, size_t step, uint64_t *ahead);

#endif
