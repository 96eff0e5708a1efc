#!/bin/sh
# fig4.sh: the paper's Figure 4 as a markdown table from figure4.csv: our
# median time per frame beside the paper's (100 MHz workstation).
# Usage: bench/fig4.sh figure4.csv
set -eu
awk -F, 'function ms(m) { return m >= 1000 ? sprintf("%.2f s", m / 1000) : sprintf("%.1f ms", m) }
function mmss(s) { return s == "nan" ? "-" : sprintf("%d'"'"'%02d\"", int(s / 60), s % 60) }
NR == 1 { next }
{
    key = $6 SUBSEP $8; if (!(key in seen)) { seen[key] = 1; order[n++] = key }
    cell[key, $9] = ms($10) " (" mmss($11) ")"; lv = $7; machine = $1; cores = $2; date = $3; commit = $4
}
END {
    printf "Figure 4 of the paper: render time per image, splits K+(%d-K) (`render --split K`), octree levels %d.\n", lv, lv
    printf "Ours: median of the runs on %s (%s cores), %s, commit %s; in brackets the paper'"'"'s time on its 100 MHz workstation.\n\n", machine, cores, date, commit
    printf "| image | size | %d+%d | %d+%d | %d+%d | %d+%d |\n", 4, lv - 4, 5, lv - 5, 6, lv - 6, 7, lv - 7
    print "|---|---|---|---|---|---|"
    for (i = 0; i < n; i++) {
        split(order[i], p, SUBSEP)
        img = p[1] == "blobs_a" ? "1 (blobs_a)" : p[1] == "blobs_b" ? "2 (blobs_b)" : p[1]
        printf "| %s | %d² | %s | %s | %s | %s |\n", img, p[2], cell[order[i], 4], cell[order[i], 5], cell[order[i], 6], cell[order[i], 7]
    }
}' "$1"
