/* frame_shade: a traced sample's shading (frame_impl.h): its shadow ray,
 * its AO rays and its colour, each kind of secondary ray timed apart. */
#include "render/frame_impl.h"

#include "format/oct_normal.h"
#include "render/ao.h"
#include "render/shade.h"
#include "render/shadow.h"

/* Shades a traced sample of pixel (i, j) seen along `dir`: the shadow ray,
 * AO rays k0 .. k0 + ao_count - 1 of ao_total, the colour; n gets the
 * facing normal. */
void frame_shade_sample(const frame_shared *sh, frame_acc *acc, const trace_hit *h,
                        const double dir[3], uint32_t i, uint32_t j, unsigned ao_k0,
                        unsigned ao_count, unsigned ao_total, float rgb[3], float n[3])
{
    const frame_job *job = sh->job;
    float ns[3]; /* a voxel hit's stored normal, decoded once for both uses */
    const int stored = h->hit && !h->exact;
    if (stored)
        oct_normal_decode(job->tree->voxels[h->voxel] & OCT_VOXEL_NORMAL_MASK, ns);
    double lam = stored ? shade_normal_stored(&job->shade, ns, dir, n)
                        : shade_normal(job->tree, &job->shade, h, dir, n);
    float ao = 1.0f;
    const int shadow = job->shade.shadows && lam > 0.0;
    if (h->hit && (shadow || ao_count)) {
        /* timed per kind: the shared start goes to the shadow ray when
           there is one */
        const double t0 = job->timing ? frame_ticks() : 0.0;
        double t1 = t0;
        double p[3];
        for (int a = 0; a < 3; a++)
            p[a] = job->cam->eye[a] + h->t * dir[a];
        shadow_start *const st = &acc->start;
        if (shadow && !ao_count && sh->shadow_map &&
            (h->exact ? shadow_lit_at(job->tree, p, n, sh->shadow_map, job->shade.light)
                      : shadow_lit_stored(job->tree, h, ns, n, sh->shadow_map,
                                          job->shade.light))) {
            acc->shadow_rays++; /* answered by the map where it starts */
            goto lit;
        }
        if (!(h->exact ? shadow_start_at(job->tree, p, n, st)
                       : shadow_start_stored(job->tree, h, ns, n, st)))
            goto lit; /* no start off the surface: lit and open */
        if (shadow) {
            acc->shadow_rays++;
            if (shadow_blocked_from(job->tree, &job->opts, sh->traverse, st, sh->shadow_map,
                                    job->shade.light, INFINITY, &acc->secondary_steps))
                lam = 0.0;
            if (job->timing)
                t1 = frame_ticks();
        }
        if (ao_count) {
            ao = ao_factor_from(job->tree, &job->opts, sh->traverse, st, n, ao_k0, ao_count,
                                ao_total, ao_seed(i, j), job->shade.ao_distance, sh->ao_grid,
                                &acc->secondary_steps);
            acc->ao_rays += ao_count;
        }
    lit:
        if (job->timing) {
            /* no AO rays: the shadow ray's end is the end */
            const double t2 = ao_count || t1 == t0 ? frame_ticks() : t1;
            if (shadow) {
                if (t1 == t0) /* no start: all of it the shadow's */
                    t1 = t2;
                acc->shadow_tk += t1 - t0;
                acc->ao_tk += t2 - t1;
            } else {
                acc->ao_tk += t2 - t0;
            }
        }
    }
    if (!h->hit && job->alpha)
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
    else
        shade_color(job->tree, &job->shade, h, lam, ao, rgb);
}
