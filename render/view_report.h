/* view_report: the per-view line render prints on stderr: size, time,
 * rate, hits; the edge and supersampled shares with --aa; with -v the rays
 * of each kind and their rates over thread time, first as they have always
 * been printed (primary; shadow and ao sharing one rate), then one rate a
 * kind ("; by kind: centre ..., aa samples ..., shadow ..., ao ..."). */
#ifndef VIEW_REPORT_H
#define VIEW_REPORT_H

#include "render/frame.h"
#include "render/views.h"

/* The line for view v rendered in ms milliseconds with stats st on
 * `threads` threads; verbose: with the rates. */
void view_report(const views_view *v, const frame_stats *st, double ms, int verbose,
                 unsigned threads);

#endif
