#!/bin/sh
# report.sh: the README's benchmark section, written from the CSV files
# between the markers <!-- bench:begin --> and <!-- bench:end --> (appended
# at the end when absent). Nobody types figures.
# Usage: bench/report.sh RESULTS_DIR README.md
set -eu
RES=$1 README=$2
T=$(mktemp); trap 'rm -f "$T" "$T.new"' EXIT
{
echo "<!-- bench:begin -->"
echo "<!-- written by bench/report.sh from $RES/*.csv: do not edit by hand -->"
awk -F, 'NR == 2 { printf "Measured on %s (%s cores), %s, commit %s (`make bench`, mode %s).\n", $1, $2, $3, $4, $5 }' "$RES/render.csv"
cat <<'TXT'
Times are medians of several runs of the real binaries (`bin/rasterize`, wall time
with start-up; `bin/render`, the per-frame time it prints, one mapping for all frames).
Errors are against `refcast`, the exact interval ray caster (bench/refcast.h): depth
error in voxels of the octree's level over pixels both hit, hit/miss disagreement
in % of all pixels, normal angle in degrees.

TXT
# Main table: per scene at the level nearest 10 that was run, standard view.
awk -F, -v OFS=" | " '
FILENAME ~ /rasterize.csv$/ && FNR > 1 { rs[$6, $7] = $8; rv[$6, $7] = $9; rb[$6, $7] = $11;
    rbv[$6, $7] = $12; rm[$6, $7] = $13; if (!($6 in seen)) { seen[$6] = 1; order[n++] = $6 } }
FILENAME ~ /refcast.csv$/ && FNR > 1 && $7 == "std" { ref[$6] = $9; size = $8 }
FILENAME ~ /render.csv$/ && FNR > 1 && $8 == "std" { k = $6 SUBSEP $7 SUBSEP $10
    ms[k] = $11; mr[k] = $12; me[k] = $13; p9[k] = $14; hm[k] = $16; nm[k] = $17; np[k] = $18; sz = $9 }
END {
    print "| scene | levels | rasterize s | voxels | MB | bytes/voxel | peak RSS MiB | render ms (Mrays/s) | --refine ms | depth err mean / p99 | --refine mean / p99 | hit/miss % (--refine) | normal err mean / p99 ° | refcast s |"
    print "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    for (i = 0; i < n; i++) {
        s = order[i]; best = -1
        for (L = 6; L <= 12; L++) if ((s, L) in rs && (best < 0 || (L <= 10 && L > best))) best = L
        a = s SUBSEP best SUBSEP "plain"; b = s SUBSEP best SUBSEP "refine"
        printf "| %s | %d | %.2f | %d | %.1f | %.2f | %.1f | %.1f (%.1f) | %.1f | %.3g / %.3g | %.3g / %.3g | %.3f (%.3f) | %.2f / %.2f | %.1f |\n",
            s, best, rs[s, best], rv[s, best], rb[s, best] / 1e6, rbv[s, best], rm[s, best] / 1024,
            ms[a], mr[a], ms[b], me[a], p9[a], me[b], p9[b], 100 * hm[a], 100 * hm[b], nm[a], np[a], ref[s] / 1000
    }
    printf "\nRender and refcast images are %dx%d; the render columns use the default split.\n", sz, sz
}' "$RES/rasterize.csv" "$RES/refcast.csv" "$RES/render.csv"
echo
echo "Rasterize cost against octree levels (slope of log time / log bytes against log 2^levels, levels >= 8):"
echo
echo "| scene | levels run | time slope | bytes slope |"
echo "|---|---|---|---|"
awk -F, -v c=8 -v min=8 -f bench/slopes.awk "$RES/rasterize.csv" | sort >"$T"
awk -F, -v c=11 -v min=8 -f bench/slopes.awk "$RES/rasterize.csv" | sort | join "$T" - |
while read -r s ts bs; do
    lv=$(awk -F, -v s="$s" 'NR > 1 && $6 == s { printf "%s%s", sep, $7; sep = " " }' "$RES/rasterize.csv")
    echo "| $s | $lv | $ts | $bs |"
done
if [ "$(wc -l <"$RES/povray.csv")" -gt 1 ]; then
    echo
    echo "The peer, POV-Ray 3.7 \`isosurface\` (max_gradient = 1.5 x the largest |grad f| sampled on a 96³ grid),"
    echo "standard view, against ours at the same size in the same run (hit/miss against refcast):"
    echo
    echo "| scene | size | accuracy | POV-Ray s | POV-Ray hit/miss % | ours ms | ours --refine ms | ours hit/miss % | POV-Ray time / ours |"
    echo "|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { printf "| %s | %d² | %s | %.2f | %.3f | %.1f | %.1f | %.3f | %s |\n", $6, $7, $8, $10, 100 * $11, $12, $13, 100 * $14, $15 }' "$RES/povray.csv"
fi
if [ -f "$RES/shard_summary.txt" ]; then
    echo
    echo "Sharded rasterization (\`bench/shard.sh\`: the shards run two at a time on this machine, then \`--merge\`;"
    echo "the merged file is the whole run's byte for byte; the projection is the longest-first makespan"
    echo "of the measured shard CPU times on W workers):"
    echo
    sed 's/^/    /' "$RES/shard_summary.txt"
fi
echo
cat "$RES/figure4.md"
echo
for p in error_vs_time p99_vs_time rasterize_time rasterize_bytes shard_scale; do
    [ -f "$RES/$p.png" ] && echo "![$p]($RES/$p.png)"
done
echo
echo "CSV files: \`$RES/\` (rasterize, render, refcast, figure4, povray, shard, shard_scale)."
echo "<!-- bench:end -->"
} >"$T.new"
if grep -q '<!-- bench:begin -->' "$README"; then
    awk -v f="$T.new" '/<!-- bench:begin -->/ { while ((getline l < f) > 0) print l; skip = 1; next }
        /<!-- bench:end -->/ { skip = 0; next } !skip' "$README" >"$T"
else
    { cat "$README"; printf '\n## Benchmark\n\n'; cat "$T.new"; } >"$T"
fi
cat "$T" >"$README"
echo "report: $README updated from $RES"
