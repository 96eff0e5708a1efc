/* frame_samples: the antialiasing of a frame (RENDER.md, "Antialiasing"):
 * the edge test inside each tile and across tile borders, and the pixels it
 * picks traced again with samples from their beam sub-block's start: as
 * packets under the paper's rule (trace_packet.h), else one by one from the
 * pixel's anchor. */
#include "render/frame_impl.h"
#include "render/frame_srgb.h"

#include <math.h>
#include <stdlib.h>

#include "common/big_alloc.h"
#include "render/beam.h"
#include "render/trace_packet.h"

aa_probe *frame_border_alloc(size_t n)
{
    if (n > SIZE_MAX / (FRAME_BORDER * sizeof(aa_probe)))
        return NULL;
    return big_alloc(n * FRAME_BORDER * sizeof(aa_probe)); /* a megapixel's are 3 MB */
}

void frame_border_free(aa_probe *p, size_t n)
{
    big_free(p, n * FRAME_BORDER * sizeof(aa_probe));
}

/* Where the samples of the pixel of centre probe c may start (+inf: they
 * all miss): its sub-block's start, since a sub-block's pyramid holds its
 * pixels' whole squares (beam.h); --beam 0 starts at the eye. */
static double sample_start(const frame_shared *sh, const aa_probe *c)
{
    return sh->job->beam_size ? (double)c->t_lo : 0.0;
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

/* What the samples of one pixel share: where they start, the anchor the
 * ones traced one by one start from (found when first needed), and their
 * sums so far. */
typedef struct pixel_samples {
    const trace_eye *eye;
    const aa_probe *cp; /* the centre ray's probe */
    uint32_t i, j;
    double t_lo;
    int packets;       /* the paper's rule: samples walked as packets */
    int anchor_found;
    trace_anchor an;
    float sum[3];
    unsigned hits, done;
    int uniform;       /* every sample so far agrees with the centre ray */
} pixel_samples;

/* Samples ks[0..n) (n <= TRACE_PACKET_MAX; sample q of pixel pss[q], in
 * aa.h's order), each traced from its pixel's t_lo: their directions and
 * hits. As one packet when they fit one (trace_packet.h: the same hits as
 * traced alone), else one by one from their pixel's anchor. */
static void trace_samples(const frame_shared *sh, pixel_samples *const *pss, const unsigned *ks,
                          unsigned n, double (*dir)[3], trace_hit *hits)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    const unsigned na = job->aa;
    const double w = (double)cam->width, hh = (double)cam->height;
    trace_ray r[TRACE_PACKET_MAX];
    unsigned slot[TRACE_PACKET_MAX], m = 0;
    for (unsigned q = 0; q < n; q++) {
        const pixel_samples *ps = pss[q];
        double fx, fy;
        aa_sample_offset(na, ks[q], &fx, &fy);
        const double u = (2.0 * ((double)ps->i + fx) / w - 1.0) * cam->h * w / hh;
        const double v = (1.0 - 2.0 * ((double)ps->j + fy) / hh) * cam->h;
        camera_ray_uv(cam, u, v, dir[q]);
        hits[q].hit = 0;
        hits[q].t = INFINITY;
        hits[q].steps = 0;
        if (ps->t_lo < INFINITY && trace_setup_eye(ps->eye, dir[q], &r[m]) &&
            trace_clip(&r[m], ps->t_lo, INFINITY))
            slot[m++] = q;
    }
    if (n && pss[0]->packets && trace_packet_fits(r, m)) {
        trace_hit ph[TRACE_PACKET_MAX];
        trace_packet_first(job->tree, r, m, ph);
        for (unsigned k = 0; k < m; k++)
            hits[slot[k]] = ph[k];
        return;
    }
    for (unsigned k = 0; k < m; k++) {
        pixel_samples *ps = pss[slot[k]];
        if (!ps->anchor_found) {
            sample_anchor(sh, ps->eye, ps->i, ps->j, ps->t_lo, &ps->an);
            ps->anchor_found = 1;
        }
        sh->traverse(job->tree, &job->opts, &r[k], &ps->an, &hits[slot[k]]);
    }
}

/* Shades sample k of pixel ps (hit h along dir; AO rays k * per .. of
 * per * N^2) and adds it to the pixel's sums. */
static void add_sample(const frame_shared *sh, frame_acc *acc, pixel_samples *ps, unsigned k,
                       const trace_hit *h, const double dir[3], unsigned per)
{
    const frame_job *job = sh->job;
    float rgb[3];
    aa_probe p;
    acc->rays++;
    acc->steps += h->steps;
    frame_shade_sample(sh, acc, h, dir, ps->i, ps->j, k * per, per, per * job->aa * job->aa, rgb,
                       p.n);
    p.hit = (uint8_t)h->hit;
    p.t = h->hit ? (float)h->t : INFINITY;
    p.surface = shade_surface(job->tree, h);
    ps->uniform &= !aa_differs(&p, ps->cp);
    ps->hits += p.hit;
    if (p.hit || !job->alpha)
        for (int a = 0; a < 3; a++)
            ps->sum[a] += rgb[a];
}

/* Pixels whose corner samples share a packet. */
#define RUN_MAX (TRACE_PACKET_MAX / 4)

/* Pixels (i + q, j), q < n (n <= RUN_MAX; centre probes cp[q]), again with
 * samples (aa.h): the four corner samples of the N x N grid first, those
 * of the n pixels in one walk; a pixel whose corners and centre ray all
 * agree by the edge rule holds no edge and they are its colour; the others
 * get all N x N, their other samples (in increasing k) traced pixel by
 * pixel. Each sample is shaded as a pixel is; a pixel's colours are added
 * in the order of k within each of the two sets and averaged in linear
 * light. */
static void supersample(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, uint32_t i,
                        uint32_t j, unsigned n, const aa_probe *cp)
{
    const frame_job *job = sh->job;
    const camera *cam = job->cam;
    const unsigned na = job->aa, ns = na * na, ao = job->shade.ao_rays;
    const unsigned per = ao ? (ao / ns > 0 ? ao / ns : 1) : 0;
    /* the corners, then the others, each set in increasing k */
    unsigned order[AA_MAX * AA_MAX], no = 0;
    const unsigned corner[4] = {0, na - 1, ns - na, ns - 1};
    for (unsigned c = 0; c < 4; c++)
        order[no++] = corner[c];
    for (unsigned k = 0; k < ns; k++)
        if (k != corner[0] && k != corner[1] && k != corner[2] && k != corner[3])
            order[no++] = k;
    /* pss and ks zeroed: their first 4n entries are set below, which gcc
       at -O1 cannot see (-Wmaybe-uninitialized) */
    pixel_samples ps[RUN_MAX], *pss[TRACE_PACKET_MAX] = {0};
    unsigned ks[TRACE_PACKET_MAX] = {0};
    double dir[TRACE_PACKET_MAX][3];
    trace_hit h[TRACE_PACKET_MAX];
    for (unsigned q = 0; q < n; q++) {
        pixel_samples *p = &ps[q];
        p->eye = eye;
        p->cp = &cp[q];
        p->i = i + q;
        p->j = j;
        p->t_lo = sample_start(sh, &cp[q]);
        p->packets = !job->exact && !job->opts.refine && !job->no_packets;
        p->anchor_found = 0;
        p->sum[0] = p->sum[1] = p->sum[2] = 0.0f;
        p->hits = 0;
        p->done = 4;
        p->uniform = 1;
        for (unsigned c = 0; c < 4; c++) {
            pss[4 * q + c] = p;
            ks[4 * q + c] = order[c];
        }
    }
    trace_samples(sh, pss, ks, 4 * n, dir, h);
    for (unsigned s = 0; s < 4 * n; s++)
        add_sample(sh, acc, pss[s], ks[s], &h[s], dir[s], per);
    for (unsigned q = 0; q < n; q++) {
        pixel_samples *p = &ps[q];
        if (!p->uniform) {
            for (unsigned q0 = 4; q0 < ns; q0 += TRACE_PACKET_MAX) {
                const unsigned m = ns - q0 < TRACE_PACKET_MAX ? ns - q0 : TRACE_PACKET_MAX;
                for (unsigned s = 0; s < m; s++)
                    pss[s] = p;
                trace_samples(sh, pss, order + q0, m, dir, h);
                for (unsigned s = 0; s < m; s++)
                    add_sample(sh, acc, p, order[q0 + s], &h[s], dir[s], per);
            }
            p->done = ns;
        }
        const size_t px = (size_t)j * cam->width + p->i;
        const float div = job->alpha ? (float)(p->hits ? p->hits : 1) : (float)p->done;
        for (int a = 0; a < 3; a++)
            job->rgb[3 * px + (size_t)a] = frame_srgb8_ready(p->sum[a] / div);
        if (job->alpha)
            job->alpha[px] = (uint8_t)((p->hits * 255u + p->done / 2) / p->done);
        acc->aa_pixels++;
        acc->aa_full += p->done == ns;
    }
}

/* Sides of a tile's border probes (frame_impl.h). */
enum { TOP, BOTTOM, LEFT, RIGHT };

static aa_probe *border_of(const frame_shared *sh, uint32_t tx, uint32_t ty)
{
    return sh->border + ((size_t)ty * sh->tiles_x + tx) * FRAME_BORDER;
}

/* Adds the thread time since t0 (ticks) to the samples', less the
 * secondary rays' time since their sum was sec0. */
static void sample_time(const frame_shared *sh, frame_acc *acc, double t0, double sec0)
{
    if (sh->job->timing)
        acc->sample_tk += frame_ticks() - t0 - (acc->shadow_tk + acc->ao_tk - sec0);
}

void frame_aa_tile(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, int any,
                   uint32_t tx, uint32_t ty, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1)
{
    const double t0 = sh->job->timing ? frame_ticks() : 0.0, sec0 = acc->shadow_tk + acc->ao_tk;
    aa_probe *const tp = sh->tile->p;
    const uint32_t w = i1 - i0, h = j1 - j0;
    if (any) {
        aa_mark_inside(tp, FRAME_TILE, w, h);
        for (uint32_t j = 0; j < h; j++) {
            const aa_probe *row = &tp[(size_t)j * FRAME_TILE];
            for (uint32_t i = 0; i < w;) {
                if (!row[i].need) {
                    i++;
                    continue;
                }
                unsigned n = 1; /* a run of pixels that need samples */
                while (n < RUN_MAX && i + n < w && row[i + n].need)
                    n++;
                supersample(sh, acc, eye, i0 + i, j0 + j, n, &row[i]);
                i += n;
            }
        }
    }
    aa_probe *b = border_of(sh, tx, ty);
    unsigned hit[4] = {0, 0, 0, 0};
    for (uint32_t k = 0; k < w; k++) {
        hit[TOP] |= (b[TOP * FRAME_TILE + k] = tp[k]).hit;
        hit[BOTTOM] |= (b[BOTTOM * FRAME_TILE + k] = tp[(size_t)(h - 1) * FRAME_TILE + k]).hit;
    }
    for (uint32_t k = 0; k < h; k++) {
        hit[LEFT] |= (b[LEFT * FRAME_TILE + k] = tp[(size_t)k * FRAME_TILE]).hit;
        hit[RIGHT] |= (b[RIGHT * FRAME_TILE + k] = tp[(size_t)k * FRAME_TILE + w - 1]).hit;
    }
    sh->border_hit[(size_t)ty * sh->tiles_x + tx] =
        (uint8_t)(hit[TOP] << TOP | hit[BOTTOM] << BOTTOM | hit[LEFT] << LEFT | hit[RIGHT] << RIGHT);
    sample_time(sh, acc, t0, sec0);
}

void frame_aa_border(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, uint32_t tx,
                     uint32_t ty, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1)
{
    const double t0 = sh->job->timing ? frame_ticks() : 0.0, sec0 = acc->shadow_tk + acc->ao_tk;
    const camera *cam = sh->job->cam;
    const aa_probe *b = border_of(sh, tx, ty);
    /* the facing sides of the four neighbouring tiles, where there are and
       one of the two sides has a hit (two misses never differ) */
    const uint8_t *bh = sh->border_hit, mine = bh[(size_t)ty * sh->tiles_x + tx];
    const size_t t = (size_t)ty * sh->tiles_x + tx;
    const aa_probe *up = ty > 0 && (mine >> TOP & 1u || bh[t - sh->tiles_x] >> BOTTOM & 1u)
                             ? border_of(sh, tx, ty - 1) + BOTTOM * FRAME_TILE
                             : NULL;
    const aa_probe *down = j1 < cam->height && (mine >> BOTTOM & 1u || bh[t + sh->tiles_x] >> TOP & 1u)
                               ? border_of(sh, tx, ty + 1) + TOP * FRAME_TILE
                               : NULL;
    const aa_probe *left = tx > 0 && (mine >> LEFT & 1u || bh[t - 1] >> RIGHT & 1u)
                               ? border_of(sh, tx - 1, ty) + RIGHT * FRAME_TILE
                               : NULL;
    const aa_probe *right = i1 < cam->width && (mine >> RIGHT & 1u || bh[t + 1] >> LEFT & 1u)
                                ? border_of(sh, tx + 1, ty) + LEFT * FRAME_TILE
                                : NULL;
    if (!up && !down && !left && !right)
        return;
    for (uint32_t j = j0; j < j1; j++) {
        const uint32_t m = j - j0;
        /* the outer rows whole, of the others the two outer columns */
        const uint32_t step = j == j0 || j + 1 == j1 || i1 - i0 < 2 ? 1 : i1 - i0 - 1;
        for (uint32_t i = i0; i < i1; i += step) {
            const uint32_t k = i - i0;
            const aa_probe *p = j == j0       ? &b[TOP * FRAME_TILE + k]
                                : j + 1 == j1 ? &b[BOTTOM * FRAME_TILE + k]
                                : i == i0     ? &b[LEFT * FRAME_TILE + m]
                                              : &b[RIGHT * FRAME_TILE + m];
            if (p->need) /* sampled by the first pass */
                continue;
            if ((j == j0 && up && aa_differs(p, &up[k])) ||
                (j + 1 == j1 && down && aa_differs(p, &down[k])) ||
                (i == i0 && left && aa_differs(p, &left[m])) ||
                (i + 1 == i1 && right && aa_differs(p, &right[m])))
                supersample(sh, acc, eye, i, j, 1, p);
        }
    }
    sample_time(sh, acc, t0, sec0);
}
