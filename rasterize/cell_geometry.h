/* cell_geometry: world boxes of grid cells and of a node's children,
 * rounded outward exactly as the cell tests need them (private to
 * rasterize/; static inline, the recursion runs them per cell). */
#ifndef CELL_GEOMETRY_H
#define CELL_GEOMETRY_H

#include "rasterize/build_internal.h"

/* Axis k of the cell with integer coordinate ck at depth: its span rounded
 * outward and clipped to the bounds. 0 when it lies beyond them. */
static inline int cell_span(const build_ctx *c, unsigned depth, uint64_t ck, int k,
                            interval *span)
{
    double h = c->cell_edge[depth];
    /* Coordinates are below 2^OCT_MAX_LEVELS: the signed conversion is
     * exact, like the unsigned one, and cheaper on x86. */
    span->lo = interval_next_down(c->origin[k] + (double)(int64_t)ck * h);
    span->hi = interval_next_up(c->origin[k] + (double)(int64_t)(ck + 1) * h);
    if (span->hi > c->bmax[k])
        span->hi = c->bmax[k];
    return span->lo <= span->hi;
}

/* World box of a cell, rounded outward and clipped to bounds. 0 if empty. */
static inline int cell_box(const build_ctx *c, unsigned depth, const uint64_t cell[3],
                           interval box[3], double centre[3])
{
    for (int k = 0; k < 3; k++) {
        if (!cell_span(c, depth, cell[k], k, &box[k]))
            return 0;
        centre[k] = 0.5 * (box[k].lo + box[k].hi);
    }
    return 1;
}

/* The boxes of a node's children, made lazily: a child's box is its lower
 * or upper half on each axis, each half a cell_span. */
struct child_boxes {
    interval half[3][2];
    double mid[3][2];
    uint8_t half_ok[3][2]; /* that half lies inside the bounds */
    int8_t have[8];        /* child's box made (1), outside the bounds (0), not yet (-1) */
    interval box[8][3];
    double centre[8][3];
};

/* The halves' outer ends are the node's own (pbox): cell_span rounds the
 * same value there, 2c * h/2 being c * h exactly. Only the middle face is
 * rounded here, both ways, as cell_span rounds it. */
static inline void child_boxes_init(const build_ctx *c, unsigned depth, const uint64_t cell[3],
                                    const interval pbox[3], child_boxes *cb)
{
    double h = c->cell_edge[depth + 1];
    for (int k = 0; k < 3; k++) {
        double m = c->origin[k] + (double)(int64_t)(2 * cell[k] + 1) * h;
        interval *lo = &cb->half[k][0], *hi = &cb->half[k][1];
        lo->lo = pbox[k].lo;
        lo->hi = min2(interval_next_up(m), c->bmax[k]);
        hi->lo = interval_next_down(m);
        hi->hi = pbox[k].hi;
        for (unsigned b = 0; b < 2; b++) {
            interval *span = &cb->half[k][b];
            cb->half_ok[k][b] = span->lo <= span->hi;
            cb->mid[k][b] = 0.5 * (span->lo + span->hi);
        }
    }
    memset(cb->have, -1, sizeof cb->have);
}

/* 1 when child i lies (in part) inside the bounds; then its box is made. */
static inline int child_box(child_boxes *cb, unsigned i)
{
    if (cb->have[i] < 0) {
        const unsigned bx = i & 1, by = (i >> 1) & 1, bz = i >> 2;
        cb->have[i] = (int8_t)(cb->half_ok[0][bx] & cb->half_ok[1][by] & cb->half_ok[2][bz]);
        cb->box[i][0] = cb->half[0][bx];
        cb->box[i][1] = cb->half[1][by];
        cb->box[i][2] = cb->half[2][bz];
        cb->centre[i][0] = cb->mid[0][bx];
        cb->centre[i][1] = cb->mid[1][by];
        cb->centre[i][2] = cb->mid[2][bz];
    }
    return cb->have[i];
}

#endif
