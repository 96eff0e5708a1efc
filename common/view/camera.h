/* camera: the pinhole camera of docs/INTERFACE.md, pixel centre -> unit ray. */
#ifndef CAMERA_H
#define CAMERA_H

#include <stdint.h>

#define CAMERA_MAX_SIZE 32768 /* pixels a side */

typedef struct camera {
    double eye[3];
    double forward[3], right[3], up[3]; /* orthonormal: right x up' = -forward */
    double h;                           /* tan(fov * pi / 360) */
    uint32_t width, height;
} camera;

typedef enum camera_err {
    CAMERA_OK = 0,
    CAMERA_ENONFINITE, /* a NaN or infinite coordinate or fov */
    CAMERA_ESAME,      /* eye == target */
    CAMERA_EPARALLEL,  /* up parallel to the view direction (or zero) */
    CAMERA_EFOV,       /* fov not in (0, 180) degrees */
    CAMERA_ESIZE,      /* width or height not in 1..CAMERA_MAX_SIZE */
} camera_err;

const char *camera_strerror(camera_err e); /* static text, never NULL */

/* Sets up c for the view (world coordinates, fov in degrees, size in
 * pixels). Returns CAMERA_OK or why the view is rejected (c then undefined). */
camera_err camera_init(camera *c, const double eye[3], const double target[3], const double up[3],
                       double fov_deg, long width, long height);

/* Unit direction through the centre of pixel (i, j), i left to right, j top
 * to bottom, exactly as docs/INTERFACE.md writes it. */
void camera_ray(const camera *c, uint32_t i, uint32_t j, double dir[3]);

/* camera_ray in pieces, for renderers that reuse u along a column and v
 * along a row: camera_ray(c, i, j, d) is camera_ray_uv(c, camera_u(c, i),
 * camera_v(c, j), d), bit for bit. */
static inline double camera_u(const camera *c, uint32_t i)
{
    const double w = (double)c->width, h = (double)c->height;
    return (2.0 * ((double)i + 0.5) / w - 1.0) * c->h * w / h;
}

static inline double camera_v(const camera *c, uint32_t j)
{
    const double h = (double)c->height;
    return (1.0 - 2.0 * ((double)j + 0.5) / h) * c->h;
}

void camera_ray_uv(const camera *c, double u, double v, double dir[3]);

#endif
