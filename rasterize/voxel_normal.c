/* voxel_normal: a voxel's record. The surface it belongs to, guarded Newton
 * steps from its centre onto f = 0, and the normal and plane offset packed
 * from where they stop (format/oct_normal.h). */
#include <math.h>

#include "format/oct_normal.h"
#include "rasterize/build_internal.h"
#include "rasterize/cell_geometry.h"

#define NEWTON_STEPS 4        /* guarded Newton steps from the voxel centre onto f = 0 */
#define NEWTON_TOL 0.25       /* stop once a step is below this fraction of a voxel: the
                                 linearisation error there, curvature x step^2 / 2, is far
                                 below the 1/128-voxel offset step at any level where the
                                 surface is resolved */
#define HALF_DIAGONAL 0.8660254037844386 /* sqrt(3)/2: farthest a plane can be and still cut a voxel */

static int finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* Normal and plane offset of a voxel for a surface: guarded Newton
 * steps from the centre towards f = 0, kept inside the voxel; the normal is
 * the normalised gradient there, the offset the signed distance (in voxel
 * edges) from the centre to the linearised surface along it. A gradient that
 * is zero or not finite there and at the centre falls back to +z with offset
 * 0 (counted in normal_fallbacks). */

static void newton_start(newton *nw, const double centre[3], const double fg_centre[4])
{
    memcpy(nw->p, centre, sizeof nw->p);
    memcpy(nw->fg, fg_centre, sizeof nw->fg);
    nw->f = fg_centre[0];
    memcpy(nw->g, fg_centre + 1, sizeof nw->g);
    nw->step = 0;
}

/* With f and its gradient at the iterate known: 1 when the iterate moved
 * and they are wanted at the new one, 0 when the iteration has stopped. */
static int newton_advance(newton *nw, const interval box[3], double h)
{
    double f = nw->f, *g = nw->g, *p = nw->p;
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (nw->step == NEWTON_STEPS || !(g2 > 0.0) || !isfinite(g2) || !isfinite(f) || f == 0.0)
        return 0;
    double q[3], moved = 0.0;
    for (int k = 0; k < 3; k++) {
        q[k] = min2(max2(p[k] - f / g2 * g[k], box[k].lo), box[k].hi); /* NaN gives lo */
        moved = max2(moved, fabs(q[k] - p[k]));
    }
    if (moved < NEWTON_TOL * h)
        return 0; /* the linearisation at p places the surface well enough */
    memcpy(p, q, sizeof q);
    nw->step++;
    return 1;
}

/* The voxel's record from where the iteration stopped. */
static uint32_t newton_record(worker *wk, const newton *nw, const double centre[3], double h)
{
    double p[3], g[3], f = nw->f;
    memcpy(p, nw->p, sizeof p);
    memcpy(g, nw->g, sizeof g);
    double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(g2 > 0.0) || !isfinite(g2) || !finite3(g) || !isfinite(f)) {
        memcpy(p, centre, sizeof p);
        f = nw->fg[0];
        memcpy(g, nw->fg + 1, sizeof g);
        g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
        if (!(g2 > 0.0) || !isfinite(g2) || !finite3(g)) {
            wk->st.normal_fallbacks++;
            static const double up[3] = {0.0, 0.0, 1.0};
            return oct_voxel_pack(up, 0.0);
        }
        if (!isfinite(f))
            f = 0.0;
    }
    double len = sqrt(g2), n[3], d = 0.0;
    for (int k = 0; k < 3; k++) {
        n[k] = g[k] / len;
        double s = p[k] - f / g2 * g[k]; /* surface point of the linearisation */
        d += n[k] * (s - centre[k]);
    }
    d /= h;
    if (!isfinite(d))
        d = 0.0;
    d = min2(max2(d, -HALF_DIAGONAL), HALF_DIAGONAL);
    return oct_voxel_pack(n, d);
}


unsigned voxel_surface(worker *wk, unsigned idx, const double centre[3], newton *nw)
{
    const unsigned ns = wk->c->nsurf;
    unsigned best = wk->act[(size_t)idx * ns];
    if (wk->nact[idx] > 1) {
        double best_dist = INFINITY;
        for (unsigned k = 0; k < wk->nact[idx]; k++) {
            unsigned s = wk->act[(size_t)idx * ns + k];
            const double *fg = centre_fg(wk, s, centre);
            const double *g = fg + 1;
            double dist = fabs(fg[0]) / sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            if (isnan(dist))
                dist = INFINITY;
            if (k == 0 || dist < best_dist) {
                best_dist = dist;
                best = s;
            }
        }
    }
    newton_start(nw, centre, centre_fg(wk, best, centre));
    for (unsigned k = 0; k < wk->nact[idx]; k++)
        wk->cf_ok[wk->act[(size_t)idx * ns + k]] = 0;
    return best;
}

static int push_voxel(worker *wk, uint32_t rec, unsigned surface)
{
    uint8_t surf = (uint8_t)surface;
    if (buf_push(&wk->out->voxels, &rec, sizeof rec) ||
        (wk->c->nsurf > 1 && buf_push(&wk->out->surfaces, &surf, 1))) {
        wk->failed = 1;
        return 0;
    }
    wk->st.voxels++;
    return 1;
}

unsigned shell_surface(worker *wk, unsigned idx, const double centre[3])
{
    newton nw;
    if (wk->nact[idx] > 1)
        return voxel_surface(wk, idx, centre, &nw);
    unsigned s = wk->act[(size_t)idx * wk->c->nsurf];
    wk->cf_ok[s] = 0;
    return s;
}

int emit_voxel(worker *wk, const interval box[3], const double centre[3])
{
    const build_ctx *c = wk->c;
    unsigned idx = c->levels + 1;
    if (c->par->shell_only) /* --shell-only: the writer stores no record */
        return push_voxel(wk, 0, shell_surface(wk, idx, centre));
    newton nw;
    unsigned best = voxel_surface(wk, idx, centre, &nw);
    const tape *t = c->full[best];
    double h = c->cell_edge[c->levels];
    while (newton_advance(&nw, box, h)) {
        nw.f = tape_eval_grad(t, nw.p, nw.g, wk->dslots);
        wk->st.point_evals++;
    }
    return push_voxel(wk, newton_record(wk, &nw, centre, h), best);
}

void emit_voxels(worker *wk, const child_boxes *cb, const uint8_t *child,
                 const uint8_t *surf, newton *nw, unsigned np)
{
    const build_ctx *c = wk->c;
    double h = c->cell_edge[c->levels];
    uint8_t live[8];
    if (c->par->shell_only) { /* --shell-only: the writer stores no record */
        for (unsigned j = 0; j < np && !wk->failed; j++)
            push_voxel(wk, 0, surf[j]);
        return;
    }
    for (unsigned j = 0; j < np; j++)
        live[j] = (uint8_t)newton_advance(&nw[j], cb->box[child[j]], h);
    for (;;) {
        unsigned first = 0;
        while (first < np && !live[first])
            first++;
        if (first == np)
            break;
        unsigned s = surf[first], n = 0, lane[8];
        double x[TAPE_LANES], y[TAPE_LANES], z[TAPE_LANES], f[TAPE_LANES], g[3][TAPE_LANES];
        for (unsigned j = first; j < np; j++)
            if (live[j] && surf[j] == s) {
                x[n] = nw[j].p[0];
                y[n] = nw[j].p[1];
                z[n] = nw[j].p[2];
                lane[n++] = j;
            }
        tape_eval_grad_lanes(c->full[s], n, x, y, z, f, g, wk->lslots);
        wk->st.point_evals += n;
        for (unsigned l = 0; l < n; l++) {
            newton *w = &nw[lane[l]];
            w->f = f[l];
            w->g[0] = g[0][l];
            w->g[1] = g[1][l];
            w->g[2] = g[2][l];
            live[lane[l]] = (uint8_t)newton_advance(w, cb->box[child[lane[l]]], h);
        }
    }
    for (unsigned j = 0; j < np && !wk->failed; j++)
        push_voxel(wk, newton_record(wk, &nw[j], cb->centre[child[j]], h), surf[j]);
}
