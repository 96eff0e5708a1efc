/* frame_samples: the antialiasing pass of a frame (RENDER.md,
 * "Antialiasing"): the pixels the edge test picks, traced again with
 * samples from their beam sub-block's start and anchor. */
#include "render/frame_impl.h"

#include <math.h>

#include "render/beam.h"

/* Where the samples of pixel (i, j) may start (+inf: they all miss): its
 * sub-block's start, since a sub-block's pyramid holds its pixels' whole
 * squares (beam.h); --beam 0 starts at the eye. */
static double sample_start(const frame_shared *sh, uint32_t i, uint32_t j)
{
    if (!sh->job->beam_size)
        return 0.0;
    return sh->probes[(size_t)j * sh->job->cam->width + i].t_lo;
}

/* The anchor of pixel (i, j)'s samples, which all start at t_lo: the
 * deepest occupied cell holding their start points (the pixel's square at
 * t_lo), as for a sub-block's centre rays. */
static void sample_anchor(const frame_shared *sh, const trace_eye *eye, uint32_t i, uint32_t j,
                          double t_lo, trace_anchor *an)
{
    const camera *cam = sh->job->cam;
    an->depth = 0;
    if (!eye->ok || !sh->job->beam_size || !(t_lo < INFINITY))
        return;
    const double w = (double)cam->width, hh = (double)cam->height;
    const double u0 = (2.0 * (double)i / w - 1.0) * cam->h * w / hh;
    const double u1 = (2.0 * (double)(i + 1) / w - 1.0) * cam->h * w / hh;
    const double v0 = (1.0 - 2.0 * (double)(j + 1) / hh) * cam->h;
    const double v1 = (1.0 - 2.0 * (double)j / hh) * cam->h;
    double lo[3], hi[3];
    beam_start_box_uv(cam, eye->o, eye->scale, u0, u1, v0, v1, t_lo, lo, hi);
    trace_anchor_find(sh->job->tree, lo, hi, an);
}

/* Sample k of pixel (i, j) (aa.h's order), traced from t_lo and shaded
 * with AO rays k * per .. of per * N^2; its colour in rgb, what the edge
 * test keeps of it in p. */
static void trace_sample(const frame_shared *sh, frame_acc *acc, const trace_eye *eye,
                         const trace_anchor *an, uint32_t i, uint32_t j, unsigned k, double t_lo,
                         unsigned per, float rgb[3], aa_probe *p)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    const unsigned na = job->aa;
    const double w = (double)cam->width, hh = (double)cam->height;
    double fx, fy, dir[3];
    aa_sample_offset(na, k, &fx, &fy);
    const double u = (2.0 * ((double)i + fx) / w - 1.0) * cam->h * w / hh;
    const double v = (1.0 - 2.0 * ((double)j + fy) / hh) * cam->h;
    camera_ray_uv(cam, u, v, dir);
    trace_ray r;
    trace_hit h;
    if (t_lo < INFINITY && trace_setup_eye(eye, dir, &r) && trace_clip(&r, t_lo, INFINITY)) {
        sh->traverse(job->tree, &job->opts, &r, an, &h);
    } else {
        h.hit = 0;
        h.t = INFINITY;
        h.steps = 0;
    }
    acc->rays++;
    acc->steps += h.steps;
    frame_shade_sample(sh, acc, &h, dir, i, j, k * per, per, per * na * na, rgb, p->n);
    p->hit = (uint8_t)h.hit;
    p->t = h.hit ? (float)h.t : INFINITY;
    p->surface = shade_surface(job->tree, &h);
}

/* Pixel (i, j) again with samples (aa.h): the four corner samples of the
 * N x N grid first; when they and the centre ray all agree by the edge
 * rule, the pixel holds no edge and they are its colour; otherwise all
 * N x N. Colours averaged in linear light; AO rays shared out. */
static void supersample(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, uint32_t i,
                        uint32_t j)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    const unsigned na = job->aa, ns = na * na, ao = job->shade.ao_rays;
    const unsigned per = ao ? (ao / ns > 0 ? ao / ns : 1) : 0;
    const size_t px = (size_t)j * cam->width + i;
    const unsigned corner[4] = {0, na - 1, ns - na, ns - 1};
    float sum[3] = {0.0f, 0.0f, 0.0f};
    unsigned hits = 0, done = 0;
    int uniform = 1;
    const double t_lo = sample_start(sh, i, j);
    trace_anchor an;
    sample_anchor(sh, eye, i, j, t_lo, &an);
    for (unsigned k = 0; k < ns; k++) {
        int is_corner = 0;
        for (unsigned c = 0; c < 4; c++)
            is_corner |= k == corner[c];
        const int pass = done < 4 ? 0 : 1; /* corners, then the rest */
        if (pass == 0 ? !is_corner : is_corner)
            continue;
        float rgb[3];
        aa_probe p;
        trace_sample(sh, acc, eye, &an, i, j, k, t_lo, per, rgb, &p);
        uniform &= !aa_differs(&p, &sh->probes[px]);
        hits += p.hit;
        if (p.hit || !job->alpha)
            for (int a = 0; a < 3; a++)
                sum[a] += rgb[a];
        if (++done == 4) {
            if (uniform)
                break;
            k = (unsigned)-1; /* the rest, from the start */
        }
    }
    const float div = job->alpha ? (float)(hits ? hits : 1) : (float)done;
    for (int a = 0; a < 3; a++)
        job->rgb[3 * px + (size_t)a] = frame_srgb8_ready(sum[a] / div);
    if (job->alpha)
        job->alpha[px] = (uint8_t)((hits * 255u + done / 2) / done);
    acc->aa_pixels++;
    acc->aa_full += done == ns;
}

/* The antialiasing pass over [i0, i1) x [j0, j1): samples where needed. */
void frame_supersample_tile(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, int any,
                            uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1)
{
    const camera *cam = sh->job->cam;
    for (uint32_t j = j0; j < j1; j++) {
        /* a tile without hits or marks: only its border pixels have a
           neighbour that may differ (in the next tile) */
        const uint32_t step = any || j == j0 || j + 1 == j1 || i1 - i0 < 2 ? 1 : i1 - i0 - 1;
        for (uint32_t i = i0; i < i1; i += step)
            if (aa_needs(sh->probes, cam->width, cam->height, i, j))
                supersample(sh, acc, eye, i, j);
    }
}

