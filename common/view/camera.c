/* camera: the pinhole camera of docs/INTERFACE.md. */
#include "common/view/camera.h"

#include "common/limits.h"

#include <math.h>

const char *camera_strerror(camera_err e)
{
    switch (e) {
    case CAMERA_OK: return "no error";
    case CAMERA_ENONFINITE: return "camera values must be finite";
    case CAMERA_ESAME: return "eye and target are the same point";
    case CAMERA_EPARALLEL: return "up is parallel to the view direction";
    case CAMERA_EFOV: return "fov must be in (0, 180) degrees";
    case CAMERA_ESIZE: return "image size must be 1.." LIMIT_STR(CAMERA_MAX_SIZE) " pixels a side";
    }
    return "unknown camera error";
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

camera_err camera_init(camera *c, const double eye[3], const double target[3], const double up[3],
                       double fov_deg, long width, long height)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(eye[a]) || !isfinite(target[a]) || !isfinite(up[a]))
            return CAMERA_ENONFINITE;
    if (!isfinite(fov_deg))
        return CAMERA_ENONFINITE;
    if (!(fov_deg > 0.0 && fov_deg < 180.0))
        return CAMERA_EFOV;
    if (width < 1 || height < 1 || width > CAMERA_MAX_SIZE || height > CAMERA_MAX_SIZE)
        return CAMERA_ESIZE;
    double f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
    double fn = norm3(f);
    if (fn == 0.0)
        return CAMERA_ESAME;
    if (!isfinite(fn))
        return CAMERA_ENONFINITE;
    for (int a = 0; a < 3; a++)
        c->forward[a] = f[a] / fn;
    double r[3];
    cross3(c->forward, up, r);
    double rn = norm3(r), un = norm3(up);
    /* parallel when sin(angle) is below 1e-9: the frame would be noise */
    if (!(un > 0.0) || !(rn > 1e-9 * un))
        return CAMERA_EPARALLEL;
    for (int a = 0; a < 3; a++)
        c->right[a] = r[a] / rn;
    cross3(c->right, c->forward, c->up);
    for (int a = 0; a < 3; a++)
        c->eye[a] = eye[a];
    c->h = tan(fov_deg * M_PI / 360.0);
    c->width = (uint32_t)width;
    c->height = (uint32_t)height;
    return CAMERA_OK;
}

void camera_ray_uv(const camera *c, double u, double v, double dir[3])
{
    double d[3];
    for (int a = 0; a < 3; a++)
        d[a] = c->forward[a] + u * c->right[a] + v * c->up[a];
    double n = norm3(d);
    for (int a = 0; a < 3; a++)
        dir[a] = d[a] / n;
}

void camera_ray(const camera *c, uint32_t i, uint32_t j, double dir[3])
{
    camera_ray_uv(c, camera_u(c, i), camera_v(c, j), dir);
}
