/* trace_packet: the first occupied voxel of each of a few rays, found in one
 * walk of the octree shared by all of them (RENDER.md, "Antialiasing": the
 * samples of a pixel pass through nearly the same nodes).
 *
 * The walk is depth first from the root, children front to back in the
 * order the rays' direction signs give (child k ^ flip, k = 0..7), and a
 * node is opened only for the rays that meet it. Whether a ray meets a cell
 * is the tie rule of trace.h read on the cell: its interval
 * [max(t_start, entry times), min(t_end, exit times)) is not empty, with
 * the traversal's plane times T_a(k) = (k - zo_a) * zi_a; a child's
 * interval is its parent's narrowed by the parent's mid-plane time on each
 * axis (the far half starts there, the near half ends there), as the
 * traversal's `enter` chooses. Every ray moves monotonically along each
 * axis, so the front-to-back order restricted to the voxels one ray meets is
 * that ray's own order: the first occupied voxel the walk finds a ray in is
 * the one the traversal stops in, and its t is the start of its interval,
 * the same T of the same planes (the traversal's entry time). So a packet
 * hit is trace_ray_prepared's hit, voxel, xyz and t, bit for bit
 * (tests/test_trace_packet.c), with the paper's rule only: --refine and
 * --exact keep the ray-by-ray traversal. */
#ifndef TRACE_PACKET_H
#define TRACE_PACKET_H

#include "format/oct.h"
#include "render/trace.h"

#define TRACE_PACKET_MAX 16 /* rays a packet */

/* 1 when trace_packet_first takes each node's steps two lanes at a time
 * (SSE2); trace_packet_first_portable is the plain C walk, the same bits. */
#if defined(__SSE2__)
#define TRACE_PACKET_HAVE_SSE2 1
#else
#define TRACE_PACKET_HAVE_SSE2 0
#endif

/* 1 when rays r[0..n) (n <= TRACE_PACKET_MAX, each from trace_setup or
 * trace_setup_eye, possibly clipped) can share a walk: on every axis their
 * directions agree in sign (a zero axis agrees with either). */
int trace_packet_fits(const trace_ray *r, unsigned n);

/* For each ray k of a packet that fits, hits[k] as trace_ray_prepared fills
 * it under the paper's rule (hit, voxel, xyz of a hit, t), except steps:
 * 0, the walk takes no DDA steps of its own. Thread-safe (reads the tree
 * only), no allocation. */
void trace_packet_first(const oct_tree *tree, const trace_ray *r, unsigned n, trace_hit *hits);

/* The same walk in plain C whatever the target (the tests compare it). */
void trace_packet_first_portable(const oct_tree *tree, const trace_ray *r, unsigned n,
                                 trace_hit *hits);

#endif
