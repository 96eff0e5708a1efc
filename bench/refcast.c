/* refcast: front-to-back interval bisection along each ray, Illinois refinement. */
#include "bench/refcast.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

#include "common/expr/interval.h"

#define MAX_DEPTH 64 /* bisections of one segment: 2^-64 is below any tolerance */

struct refcast_scratch {
    double *slots;
    interval *islots;
    tape_idual *gslots;
    tape_dual *dslots;
};

refcast_scratch *refcast_scratch_new(const scene *s)
{
    uint32_t n = 1;
    for (size_t k = 0; k < s->nsurfaces; k++)
        if (s->surfaces[k].tape.n > n)
            n = s->surfaces[k].tape.n;
    refcast_scratch *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->slots = malloc(n * sizeof *w->slots);
    w->islots = malloc(n * sizeof *w->islots);
    w->gslots = malloc(n * sizeof *w->gslots);
    w->dslots = malloc(n * sizeof *w->dslots);
    if (!w->slots || !w->islots || !w->gslots || !w->dslots) {
        refcast_scratch_free(w);
        return NULL;
    }
    return w;
}

void refcast_scratch_free(refcast_scratch *w)
{
    if (!w)
        return;
    free(w->slots);
    free(w->islots);
    free(w->gslots);
    free(w->dslots);
    free(w);
}

/* Ray parameter interval inside the box lo..hi (slab test); 0 when missed. */
static int clip_box(const double lo[3], const double hi[3], const double eye[3],
                    const double dir[3], double *t0, double *t1)
{
    double a = 0.0, b = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (dir[k] == 0.0) {
            if (eye[k] < lo[k] || eye[k] > hi[k])
                return 0;
            continue;
        }
        double ta = (lo[k] - eye[k]) / dir[k], tb = (hi[k] - eye[k]) / dir[k];
        if (ta > tb) {
            double x = ta;
            ta = tb;
            tb = x;
        }
        if (ta > a)
            a = ta;
        if (tb < b)
            b = tb;
    }
    if (!(a <= b))
        return 0;
    *t0 = a;
    *t1 = b;
    return 1;
}

/* The box spanned by the ray's points for t in [a, b], rounded outward. */
static void segment_box(const double eye[3], const double dir[3], double a, double b,
                        interval box[3])
{
    for (int k = 0; k < 3; k++) {
        double pa = eye[k] + a * dir[k], pb = eye[k] + b * dir[k];
        double l = pa < pb ? pa : pb, h = pa < pb ? pb : pa;
        /* two roundings (product, sum) each side: two ulps out */
        box[k].lo = interval_next_down(interval_next_down(l));
        box[k].hi = interval_next_up(interval_next_up(h));
    }
}

static double f_at(const tape *tp, refcast_scratch *w, const double eye[3], const double dir[3],
                   double t, refcast_stats *st)
{
    st->point_evals++;
    return tape_eval(tp, eye[0] + t * dir[0], eye[1] + t * dir[1], eye[2] + t * dir[2],
                     w->slots);
}

/* Root of f in [a, b] where fa and fb have opposite signs (or one is 0):
 * Illinois regula falsi, with a bisection whenever it stalls. */
static double refine(const tape *tp, refcast_scratch *w, const double eye[3],
                     const double dir[3], double a, double b, double fa, double fb,
                     refcast_stats *st)
{
    if (fa == 0.0)
        return a;
    if (fb == 0.0)
        return b;
    int side = 0;
    for (int it = 0; it < 200; it++) {
        double tol = REFCAST_REL_TOL * 0.5 * fabs(a + b);
        if (b - a <= tol)
            break;
        double c = (a * fb - b * fa) / (fb - fa);
        if (!(c > a && c < b) || it % 8 == 7) /* outside or slow: bisect */
            c = 0.5 * (a + b);
        double fc = f_at(tp, w, eye, dir, c, st);
        if (fc == 0.0)
            return c;
        if (fc != fc) { /* undefined between: keep bisecting towards the near end */
            b = c;
            fb = fa > 0 ? -1.0 : 1.0;
            side = 0;
            continue;
        }
        if ((fc < 0.0) == (fa < 0.0)) {
            a = c;
            fa = fc;
            if (side == -1)
                fb *= 0.5;
            side = -1;
        } else {
            b = c;
            fb = fc;
            if (side == 1)
                fa *= 0.5;
            side = 1;
        }
    }
    return 0.5 * (a + b);
}

typedef struct seg {
    double a, b;
    unsigned depth;
} seg;

/* First root of one surface in [t0, t1]; +inf when none. *touch is set for
 * a tangential touch. */
static double first_root(const tape *tp, refcast_scratch *w, const double eye[3],
                         const double dir[3], double t0, double t1, int *touch,
                         refcast_stats *st)
{
    seg stack[MAX_DEPTH + 2];
    int top = 0;
    stack[top++] = (seg){t0, t1, 0};
    const double minw = REFCAST_REL_TOL * (t1 > 1.0 ? t1 : 1.0);
    while (top > 0) {
        seg s = stack[--top];
        interval box[3];
        segment_box(eye, dir, s.a, s.b, box);
        unsigned flags = 0;
        st->interval_evals++;
        interval F = tape_eval_interval(tp, box, w->islots, &flags);
        if (!flags && !interval_is_nan(F) && (F.lo > 0.0 || F.hi < 0.0))
            continue; /* no root in this segment */
        int last = s.depth >= MAX_DEPTH || s.b - s.a <= minw;
        if (!flags && !last) {
            interval g[3];
            unsigned gf = 0;
            st->grad_evals++;
            tape_eval_interval_grad(tp, box, g, w->gslots, &gf);
            interval D = interval_mul(g[0], (interval){dir[0], dir[0]}, &gf);
            D = interval_add(D, interval_mul(g[1], (interval){dir[1], dir[1]}, &gf), &gf);
            D = interval_add(D, interval_mul(g[2], (interval){dir[2], dir[2]}, &gf), &gf);
            if (!gf && !interval_is_nan(D) && (D.lo > 0.0 || D.hi < 0.0)) {
                /* monotone: one root at most, there iff the ends differ in sign */
                double fa = f_at(tp, w, eye, dir, s.a, st), fb = f_at(tp, w, eye, dir, s.b, st);
                if (fa == 0.0 || fb == 0.0 || (fa < 0.0) != (fb < 0.0))
                    return refine(tp, w, eye, dir, s.a, s.b, fa, fb, st);
                continue;
            }
        }
        if (last) {
            double fa = f_at(tp, w, eye, dir, s.a, st), fb = f_at(tp, w, eye, dir, s.b, st);
            if (fa != fa && fb != fb)
                continue; /* undefined here: not a surface point */
            if (fa == fa && fb == fb && (fa == 0.0 || fb == 0.0 || (fa < 0.0) != (fb < 0.0)))
                return refine(tp, w, eye, dir, s.a, s.b, fa, fb, st);
            if (flags)
                continue; /* NaN at one end, no evidence of a crossing */
            *touch = 1;
            st->touches++;
            return 0.5 * (s.a + s.b);
        }
        double m = 0.5 * (s.a + s.b);
        stack[top++] = (seg){m, s.b, s.depth + 1}; /* far half below */
        stack[top++] = (seg){s.a, m, s.depth + 1};
    }
    return INFINITY;
}

void refcast_ray(const scene *s, refcast_scratch *w, const double eye[3], const double dir[3],
                 refcast_hit *hit, refcast_stats *st)
{
    hit->t = INFINITY;
    hit->normal[0] = hit->normal[1] = hit->normal[2] = 0.0;
    hit->surface = 0;
    hit->touch = 0;
    double t0, t1;
    if (!clip_box(s->lo, s->hi, eye, dir, &t0, &t1))
        return;
    for (size_t k = 0; k < s->nsurfaces; k++) {
        const tape *tp = &s->surfaces[k].tape;
        int touch = 0;
        double t = first_root(tp, w, eye, dir, t0, t1, &touch, st);
        if (t < hit->t) {
            hit->t = t;
            hit->surface = (uint32_t)k;
            hit->touch = touch;
            t1 = t; /* a later surface must be nearer to win */
        }
    }
    if (isinf(hit->t))
        return;
    const tape *tp = &s->surfaces[hit->surface].tape;
    double p[3], g[3];
    for (int a = 0; a < 3; a++)
        p[a] = eye[a] + hit->t * dir[a];
    st->point_evals++;
    tape_eval_grad(tp, p, g, w->dslots);
    double n = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(n > 0.0) || !isfinite(n)) { /* singular point: face the viewer */
        for (int a = 0; a < 3; a++)
            hit->normal[a] = -dir[a];
        return;
    }
    double facing = g[0] * dir[0] + g[1] * dir[1] + g[2] * dir[2];
    double sgn = facing > 0.0 ? -1.0 : 1.0;
    for (int a = 0; a < 3; a++)
        hit->normal[a] = sgn * g[a] / n;
}

/* ---- Whole images --------------------------------------------------------- */

typedef struct image_job {
    const scene *s;
    const camera *cam;
    float *depth, *normals;
    uint8_t *surface;
    atomic_uint next_row;
    atomic_int failed;
    pthread_mutex_t lock;
    refcast_stats st;
} image_job;

static void *image_worker(void *arg)
{
    image_job *job = arg;
    refcast_scratch *w = refcast_scratch_new(job->s);
    if (!w) {
        atomic_store(&job->failed, 1);
        return NULL;
    }
    refcast_stats st = {0, 0, 0, 0};
    const uint32_t W = job->cam->width, H = job->cam->height;
    for (;;) {
        uint32_t j = atomic_fetch_add(&job->next_row, 1);
        if (j >= H)
            break;
        for (uint32_t i = 0; i < W; i++) {
            double dir[3];
            camera_ray(job->cam, i, j, dir);
            refcast_hit h;
            refcast_ray(job->s, w, job->cam->eye, dir, &h, &st);
            size_t px = (size_t)j * W + i;
            if (job->depth)
                job->depth[px] = (float)h.t;
            if (job->normals)
                for (int a = 0; a < 3; a++)
                    job->normals[3 * px + (size_t)a] = (float)h.normal[a];
            if (job->surface)
                job->surface[px] = isinf(h.t) ? 255 : (uint8_t)(h.surface > 254 ? 254 : h.surface);
        }
    }
    refcast_scratch_free(w);
    pthread_mutex_lock(&job->lock);
    job->st.interval_evals += st.interval_evals;
    job->st.grad_evals += st.grad_evals;
    job->st.point_evals += st.point_evals;
    job->st.touches += st.touches;
    pthread_mutex_unlock(&job->lock);
    return NULL;
}

int refcast_image(const scene *s, const camera *cam, unsigned threads, float *depth,
                  float *normals, uint8_t *surface, refcast_stats *st)
{
    image_job job;
    job.s = s;
    job.cam = cam;
    job.depth = depth;
    job.normals = normals;
    job.surface = surface;
    atomic_init(&job.next_row, 0);
    atomic_init(&job.failed, 0);
    pthread_mutex_init(&job.lock, NULL);
    job.st = (refcast_stats){0, 0, 0, 0};
    if (threads < 1)
        threads = 1;
    pthread_t *tid = calloc(threads, sizeof *tid);
    unsigned started = 0;
    if (tid)
        for (; started + 1 < threads; started++)
            if (pthread_create(&tid[started], NULL, image_worker, &job) != 0)
                break;
    image_worker(&job);
    for (unsigned k = 0; k < started; k++)
        pthread_join(tid[k], NULL);
    free(tid);
    pthread_mutex_destroy(&job.lock);
    if (st)
        *st = job.st;
    return atomic_load(&job.failed) ? -1 : 0;
}
