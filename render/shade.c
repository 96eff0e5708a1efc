/* shade: two-sided Lambert + ambient. */
#include "render/shade.h"

#include <math.h>

#include "format/oct_normal.h"

void shade_default_light(const camera *cam, double light[3])
{
    double l[3];
    for (int a = 0; a < 3; a++)
        l[a] = -cam->forward[a] + 0.7 * cam->up[a] - 0.5 * cam->right[a];
    double n = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    for (int a = 0; a < 3; a++)
        light[a] = l[a] / n;
}

int shade_set_light(shade_params *p, const double light[3])
{
    double n = sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
    if (!(n > 0.0) || !isfinite(n)) {
        /* zero, NaN or infinite; or finite but its square overflows: scaled first */
        double m = fmax(fabs(light[0]), fmax(fabs(light[1]), fabs(light[2])));
        if (!(m > 0.0) || !isfinite(m) || isnan(light[0] + light[1] + light[2]))
            return -1;
        double l[3] = {light[0] / m, light[1] / m, light[2] / m};
        return shade_set_light(p, l);
    }
    for (int a = 0; a < 3; a++)
        p->light[a] = light[a] / n;
    return 0;
}

double shade_normal(const oct_tree *tree, const shade_params *p, const trace_hit *hit,
                    const double dir[3], float n[3])
{
    if (!hit->hit) {
        n[0] = n[1] = n[2] = 0.0f;
        return 0.0;
    }
    if (!hit->exact) {
        float ns[3];
        oct_normal_decode(tree->voxels[hit->voxel] & OCT_VOXEL_NORMAL_MASK, ns);
        return shade_normal_stored(p, ns, dir, n);
    }
    for (int a = 0; a < 3; a++) /* the gradient, already facing the viewer */
        n[a] = (float)hit->normal[a];
    double lam = n[0] * p->light[0] + n[1] * p->light[1] + n[2] * p->light[2];
    return lam < 0.0 ? 0.0 : lam;
}

double shade_normal_stored(const shade_params *p, const float ns[3], const double dir[3],
                           float n[3])
{
    double facing = ns[0] * dir[0] + ns[1] * dir[1] + ns[2] * dir[2];
    for (int a = 0; a < 3; a++) /* two-sided: face the viewer */
        n[a] = facing > 0.0 ? -ns[a] : ns[a];
    double lam = n[0] * p->light[0] + n[1] * p->light[1] + n[2] * p->light[2];
    return lam < 0.0 ? 0.0 : lam;
}

unsigned shade_surface(const oct_tree *tree, const trace_hit *hit)
{
    if (!hit->hit)
        return 0;
    unsigned s = hit->exact ? hit->surface : tree->surfaces ? tree->surfaces[hit->voxel] : 0;
    return s < tree->surface_count ? s : 0;
}

void shade_color(const oct_tree *tree, const shade_params *p, const trace_hit *hit, double lam,
                 float ao, float rgb[3])
{
    if (!hit->hit) {
        for (int a = 0; a < 3; a++)
            rgb[a] = p->background[a];
        return;
    }
    const float *col = tree->palette + 3 * shade_surface(tree, hit);
    float k = p->ambient * ao + (1.0f - p->ambient) * (float)lam;
    for (int a = 0; a < 3; a++)
        rgb[a] = col[a] * k;
}

void shade_hit(const oct_tree *tree, const shade_params *p, const trace_hit *hit,
               const double dir[3], float rgb[3], float n[3])
{
    shade_color(tree, p, hit, shade_normal(tree, p, hit, dir, n), 1.0f, rgb);
}
