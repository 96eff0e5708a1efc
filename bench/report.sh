#!/bin/sh
# report.sh: the README's benchmark section, written from the CSV files
# between the markers <!-- bench:begin --> and <!-- bench:end --> (appended
# at the end when absent). Nobody types figures.
# Usage: bench/report.sh RESULTS_DIR README.md
set -eu
RES=$1 README=$2
D=$(dirname "$0")
T=$(mktemp); trap 'rm -f "$T" "$T.new"' EXIT
# has NAME: RES/NAME.csv holds at least one row
has() { [ -f "$RES/$1.csv" ] && [ "$(wc -l <"$RES/$1.csv")" -gt 1 ]; }
# The awk helpers of every table: a figure or "-" when not measured, and the
# mark of a target: met or not.
AWKLIB='function num(f, x) { return (x == "" || x == "nan" || x == "-") ? "-" : sprintf(f, x) }
function mark(ok) { return ok ? " ✓" : " ✗" }'
{
echo "<!-- bench:begin -->"
echo "<!-- written by bench/report.sh from $RES/*.csv: do not edit by hand -->"
# The run a CSV's rows come from (its first row's machine, cores, date and
# commit); the header names the first of these CSVs, and a table from
# another run (SECTIONS ran a part only) says its own.
prov() { awk -F, 'NR == 2 { printf "%s (%s cores), %s, commit %s", $1, $2, $3, $4 }' "$RES/$1.csv"; }
HPROV=""
for c in render rastspeed accuracy images; do
    if has $c; then
        awk -F, 'NR == 2 { printf "Measured on %s (%s cores), %s, commit %s (`make bench`, mode %s).\n", $1, $2, $3, $4, $5 }' "$RES/$c.csv"
        HPROV=$(prov $c)
        break
    fi
done
# NAME: a line naming NAME.csv's run when it is not the header's
own_run() { p=$(prov "$1"); [ "$p" = "$HPROV" ] || echo "These rows: $p."; }
cat <<'TXT'
Times are medians of several runs of the real binaries (`bin/rasterize`, wall time
with start-up; `bin/render`, the per-frame time it prints, one mapping for all frames).
Errors are against `refcast`, the exact interval ray caster (bench/refcast.h): depth
error in voxels of the octree's level over pixels both hit, hit/miss disagreement
in % of all pixels, normal angle in degrees.

TXT
if has render && has rasterize && has refcast; then
    # Main table: per scene at the level nearest 10 that was run, standard view.
    awk -F, -v OFS=" | " '
    FILENAME ~ /rasterize.csv$/ && FNR > 1 { rs[$6, $7] = $8; rv[$6, $7] = $9; rb[$6, $7] = $11;
        rbv[$6, $7] = $12; rm[$6, $7] = $13; if (!($6 in seen)) { seen[$6] = 1; order[n++] = $6 } }
    FILENAME ~ /refcast.csv$/ && FNR > 1 && $7 == "std" { ref[$6] = $9; size = $8 }
    FILENAME ~ /render.csv$/ && FNR > 1 && $8 == "std" { k = $6 SUBSEP $7 SUBSEP $10
        ms[k] = $11; mr[k] = $12; me[k] = $13; p9[k] = $14; hm[k] = $16; nm[k] = $17; np[k] = $18; sz = $9 }
    END {
        print "| scene | levels | rasterize s | voxels | MB | bytes/voxel | peak RSS MiB | render ms (Mrays/s) | --refine ms | --exact ms (x plain) | depth err mean / p99 | --refine mean / p99 | --exact mean / p99 | hit/miss % (--refine, --exact) | normal err mean / p99 ° | --exact normal p99 ° | refcast s |"
        print "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        for (i = 0; i < n; i++) {
            s = order[i]; best = -1
            for (L = 6; L <= 12; L++) if ((s, L) in rs && (best < 0 || (L <= 10 && L > best))) best = L
            a = s SUBSEP best SUBSEP "plain"; b = s SUBSEP best SUBSEP "refine"; x = s SUBSEP best SUBSEP "exact"
            printf "| %s | %d | %.2f | %d | %.1f | %.2f | %.1f | %.1f (%.1f) | %.1f | %.1f (%.2f) | %.3g / %.3g | %.3g / %.3g | %.3g / %.3g | %.3f (%.3f, %.3f) | %.2f / %.2f | %.3g | %.1f |\n",
                s, best, rs[s, best], rv[s, best], rb[s, best] / 1e6, rbv[s, best], rm[s, best] / 1024,
                ms[a], mr[a], ms[b], ms[x], (ms[a] > 0 ? ms[x] / ms[a] : 0), me[a], p9[a], me[b], p9[b],
                me[x], p9[x], 100 * hm[a], 100 * hm[b], 100 * hm[x], nm[a], np[a], np[x], ref[s] / 1000
        }
        printf "\nRender and refcast images are %dx%d; the render columns use the default split.\n", sz, sz
    }' "$RES/rasterize.csv" "$RES/refcast.csv" "$RES/render.csv"
fi
# --exact against the paper's rule and refcast (issue 14's speed targets):
# blobs_a and csg, standard view, from the alternating frames of
# exactratio.csv (bench/run.sh's ratio section) where it has the scene, else
# from the main table at the level nearest 10 that was run.
if has render && has refcast; then
    ratio_note=""
    has exactratio && ratio_note=" Where it has a scene, the paper's rule and \`--exact\` come
from one mapping, their frames alternating (the median of each over the pairs after a warm-up
pair), not from the main table's separate runs."
    echo
    echo "\`--exact\` against the paper's rule and the exact interval caster, standard view"
    echo "(targets: at most 1.5x the paper's rule on \`blobs_a\`, 2x on \`csg\`; ✓ met, ✗ not met).$ratio_note"
    has exactratio && own_run exactratio
    echo
    rf="$RES/exactratio.csv"; [ -f "$rf" ] || rf=/dev/null
    awk -F, "$AWKLIB"'
    FILENAME ~ /refcast.csv$/ && FNR > 1 && $7 == "std" { ref[$6] = $9 }
    FILENAME ~ /render.csv$/ && FNR > 1 && $8 == "std" { t[$6, $7, $10] = $11; sz[$6, $7] = $9; lv[$6, $7] = 1 }
    FILENAME ~ /exactratio.csv$/ && FNR > 1 { alt[$6] = $7; t[$6, $7, "plain"] = $10; t[$6, $7, "exact"] = $11; sz[$6, $7] = $8 }
    END {
        print "| scene | levels | size | paper'"'"'s rule ms | --exact ms | --exact / paper'"'"'s rule | target | refcast ms | refcast / --exact |"
        print "|---|---|---|---|---|---|---|---|---|"
        split("blobs_a csg", sc, " "); split("1.5 2", tg, " ")
        for (i = 1; i <= 2; i++) {
            s = sc[i]; best = -1
            for (L = 6; L <= 12; L++) if ((s, L) in lv && (best < 0 || (L <= 10 && L > best))) best = L
            if (s in alt) best = alt[s]
            if (best < 0 || !((s, best, "exact") in t)) continue
            p = t[s, best, "plain"]; x = t[s, best, "exact"]; r = p > 0 ? x / p : 0
            printf "| %s | %d | %d² | %.1f | %.1f | %.2f%s | %sx | %s | %s |\n", s, best, sz[s, best], p, x,
                r, mark(r <= tg[i]), tg[i], num("%.0f", ref[s]), (s in ref && x > 0) ? sprintf("%.1f", ref[s] / x) : "-"
        }
    }' "$RES/refcast.csv" "$RES/render.csv" "$rf"
fi
# Accuracy of --exact (issue 14's accuracy targets), bench/accuracy.sh.
if has accuracy; then
    echo
    awk -F, 'NR == 2 { printf "Accuracy of `--exact` against refcast, standard view at %d² (smaller than the tables above:\n", $8 }' "$RES/accuracy.csv"
    echo "refcast is slow on large expressions); depth error in voxels of the level over pixels both hit,"
    echo "normal angle to the exact gradient in degrees, NaN = pixels with a NaN depth or normal."
    echo "Targets: mean ≤ 0.001 voxel, p99 ≤ 0.01 voxel, hit/miss ≤ 0.05 %, normal max ≤ 0.01°, no NaN;"
    echo "the last column lists the ones not met:"
    echo
    awk -F, "$AWKLIB"'
    NR == 1 { next }
    {
        miss = ""
        if (!($10 <= 0.001)) miss = miss " mean"
        if (!($11 <= 0.01)) miss = miss " p99"
        if (!($13 <= 0.0005)) miss = miss " hit/miss"
        if ($16 != "nan" && !($16 <= 0.01)) miss = miss " normal"
        if ($17 + 0 > 0) miss = miss " NaN"
        printf "| %s | %d | %s / %s | %s | %s / %s / %s | %d | %.1f | %.0f | %s |\n", $6, $7,
            num("%.2g", $10), num("%.2g", $11), num("%.3f", 100 * $13), num("%.2g", $14), num("%.2g", $15),
            num("%.2g", $16), $17, $9, $18, miss == "" ? "all met ✓" : "✗" miss
    }
    BEGIN {
        print "| scene | levels | depth err mean / p99 (voxels) | hit/miss % | normal err mean / p99 / max ° | NaN | --exact ms | refcast ms | targets |"
        print "|---|---|---|---|---|---|---|---|---|"
    }' "$RES/accuracy.csv"
fi
# --exact time against the octree's level, bench/sweep.sh; the default it
# suggests: the level with the least mean slowdown against each scene's
# fastest, over the scenes that ran it.
if has sweep; then
    echo
    awk -F, 'NR == 2 { printf "`--exact` time (ms a frame, standard view, %d²) against the octree'"'"'s level (`bench/sweep.sh`,\n", $8 }' "$RES/sweep.csv"
    echo "files from \`rasterize --shell-only\`): with exact hits the level is a speed knob, not an accuracy one."
    echo
    awk -F, 'NR > 1 { t[$6, $7] = $10; have[$7] = 1; if (!($6 in seen)) { seen[$6] = 1; order[n++] = $6 } }
    END {
        printf "| scene |"; for (L = 1; L <= 20; L++) if (L in have) printf " %d |", L; print " fastest level |"
        printf "|---|"; for (L = 1; L <= 20; L++) if (L in have) printf "---|"; print "---|"
        for (i = 0; i < n; i++) {
            s = order[i]; best[s] = -1; printf "| %s |", s
            for (L = 1; L <= 20; L++) {
                if (!(L in have)) continue
                if ((s, L) in t) { printf " %.1f |", t[s, L]; if (best[s] < 0 || t[s, L] < t[s, best[s]]) best[s] = L }
                else printf " |"
            }
            printf " %d |\n", best[s]
        }
        pick = -1
        for (L = 1; L <= 20; L++) {
            if (!(L in have)) continue
            sum = 0; k = 0; worst = 0
            for (i = 0; i < n; i++) {
                s = order[i]
                if (!((s, L) in t)) { k = -1; break }
                r = t[s, L] / t[s, best[s]]; sum += r; k++; if (r > worst) { worst = r; ws = s }
            }
            if (k > 0 && (pick < 0 || sum / k < mean)) { pick = L; mean = sum / k; pw = worst; pws = ws }
        }
        if (pick < 0) exit
        printf "\nThe fastest level is"
        for (i = 0; i < n; i++) printf "%s %d for %s", (i ? (i == n - 1 ? " and" : ",") : ""), best[order[i]], order[i]
        printf "; at `--levels %d` a frame takes on average %.2fx the fastest time of each scene (at worst %.2fx, on %s), which suggests `--levels %d` as the default for files rendered with `--exact`.\n", pick, mean, pw, pws, pick
    }' "$RES/sweep.csv"
fi
if has rasterize; then
    echo
    echo "Rasterize cost against octree levels (slope of log time / log bytes against log 2^levels, levels >= 8):"
    echo
    echo "| scene | levels run | time slope | bytes slope |"
    echo "|---|---|---|---|"
    awk -F, -v c=8 -v min=8 -f "$D/slopes.awk" "$RES/rasterize.csv" | sort >"$T"
    awk -F, -v c=11 -v min=8 -f "$D/slopes.awk" "$RES/rasterize.csv" | sort | join "$T" - |
    while read -r s ts bs; do
        lv=$(awk -F, -v s="$s" 'NR > 1 && $6 == s { printf "%s%s", sep, $7; sep = " " }' "$RES/rasterize.csv")
        echo "| $s | $lv | $ts | $bs |"
    done
fi
if has rastspeed; then
    echo
    echo "Rasterize speed (issue 17), the run of median wall time of SPEED_REPS (full: 3): M voxels kept a second (wall time with start-up) with"
    echo "the records (normals and planes) and with \`--shell-only\`, and the CPU use (user + system over"
    echo "wall: 200 % keeps both cores busy). Targets: ≥ 10 M voxels/s, ≥ 25 with \`--shell-only\`"
    echo "(✓ met, ✗ not met)."
    awk -F, 'NR > 1 && $8 > 60 { printf "%s%s levels %d %.0f s", n++ ? ", " : "Runs over a minute: ", $6, $7, $8 }
        END { if (n) print "." }' "$RES/rastspeed.csv"
    own_run rastspeed
    echo
    echo "The portable columns time the same runs with \`DDA_SIMD=portable\` (the lane evaluators'"
    echo "build without AVX2), whose files must be the same bytes (same: ✓)."
    echo
    echo "| scene | levels | seconds | voxels | M voxels/s (≥ 10) | CPU % | --shell-only s | M voxels/s (≥ 25) | CPU % | portable M voxels/s | portable --shell-only | same |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
    awk -F, "$AWKLIB"'NR > 1 { printf "| %s | %d | %.2f | %d | %.2f%s | %s | %s | %s%s | %s | %s%s | %s%s | %s |\n", $6, $7, $8, $9, $10,
        mark($10 >= 10), $11, num("%.2f", $12), num("%.2f", $13), ($13 == "" ? "" : mark($13 >= 25)), num("%s", $14),
        num("%.2f", $15), ($15 == "" ? "" : mark($15 >= 10)), num("%.2f", $16), ($16 == "" ? "" : mark($16 >= 25)),
        ($17 == "" ? "-" : substr(mark($17 == 1), 2)) }' \
        "$RES/rastspeed.csv"
fi
if has shell; then
    echo
    echo "The shell: voxels kept over the voxels the surface really passes through (\`bench/shellratio\`:"
    echo "its interval test at the voxel's own size and a sign change on a 5³ lattice per voxel; target"
    echo "≤ 1.3), the real ones lost (must be 0), and the stored records against the exact surface"
    echo "(\`bench/normalerr\`: normal against the gradient at the foot point of the voxel centre, plane"
    echo "offset against the distance to it):"
    own_run shell
    echo
    echo "| scene | levels | kept | real | kept / real (≤ 1.3) | real ones lost (0) | normal err mean / p99 / max ° | offset err mean / p99 voxel |"
    echo "|---|---|---|---|---|---|---|---|"
    awk -F, "$AWKLIB"'NR > 1 { printf "| %s | %d | %d | %d | %.3f%s | %d%s | %s / %s / %s | %s / %s |\n", $6, $7, $8, $9,
        $10, mark($10 <= 1.3), $11, mark($11 == 0), num("%.3f", $14), num("%.3f", $15), num("%.2f", $16),
        num("%.4f", $17), num("%.4f", $18) }' "$RES/shell.csv"
fi
if has povray; then
    echo
    echo "The peer, POV-Ray 3.7 \`isosurface\` (max_gradient = 1.5 x the largest |grad f| sampled on a 96³ grid),"
    echo "standard view, against ours at the same size in the same run (hit/miss against refcast):"
    echo
    echo "| scene | size | accuracy | POV-Ray s | POV-Ray hit/miss % | ours ms | ours --refine ms | ours hit/miss % | POV-Ray time / ours |"
    echo "|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { printf "| %s | %d² | %s | %.2f | %.3f | %.1f | %.1f | %.3f | %s |\n", $6, $7, $8, $10, 100 * $11, $12, $13, 100 * $14, $15 }' "$RES/povray.csv"
fi
if has images; then
    echo
    echo "Images people want to look at (issue 15): \`blobs_a\`, standard view, against one ray a pixel;"
    echo "rays a second of each kind over thread time (\`render -v\`). Targets: \`--aa 4\` and \`--shadows\`"
    echo "at most 1.6x the time of one ray a pixel, \`--ao 16\` at most 8x; shadow and AO rays at no less"
    echo "than half the primary rate, the higher of the row's own and the plain run's (✓ met, ✗ not met):"
    own_run images
    echo
    echo "| option | levels | size | ms | time / plain (target) | supersampled % | primary Mrays/s | shadow Mrays/s (≥ ½ primary) | AO Mrays/s (≥ ½ primary) |"
    echo "|---|---|---|---|---|---|---|---|---|"
    awk -F, "$AWKLIB"'
    function rate(x, p) { return x == "" ? "-" : sprintf("%.2f%s", x, mark(x >= p / 2)) }
    # the plain row comes first; a row with --exact has a lower primary rate of its own
    NR == 2 { p0 = $13 }
    NR > 1 {
        p = $13 > p0 ? $13 : p0
        o = $9; tg = ""
        if (o == "plain") o = "one ray a pixel"
        else if (o == "aa") { o = "--aa 4"; tg = 1.6 }
        else if (o == "shadows") { o = "--shadows"; tg = 1.6 }
        else if (o == "ao") { o = "--ao 16"; tg = 8 }
        else if (o == "all") o = "--aa 4 --shadows --ao 16 --exact"
        else o = "--" o
        r = sprintf("%.2f", $11); if (tg != "") r = r mark($11 <= tg) " (≤ " tg ")"
        sec = ($14 == "" && $15 == "" && $16 != "") ? " (shadow + AO: " sprintf("%.2f", $16) ")" : ""
        printf "| %s | %d | %d² | %.1f | %s | %s | %s | %s | %s%s |\n", o, $7, $8, $10, r, num("%.2f", $12),
            num("%.2f", $13), rate($14, p), rate($15, p), sec
    }' "$RES/images.csv"
    echo
    echo "| plain | --aa 4 | --shadows | --ao 16 | all, with --exact |"
    echo "|---|---|---|---|---|"
    echo "| ![plain]($RES/images/plain.png) | ![aa]($RES/images/aa.png) | ![shadows]($RES/images/shadows.png) | ![ao]($RES/images/ao.png) | ![all]($RES/images/all.png) |"
fi
if [ -f "$RES/shard_summary.txt" ]; then
    echo
    echo "Sharded rasterization (\`bench/shard.sh\`: the shards run two at a time on this machine, then \`--merge\`;"
    echo "the merged file is the whole run's byte for byte; the projection is the longest-first makespan"
    echo "of the measured shard CPU times on W workers):"
    echo
    sed 's/^/    /' "$RES/shard_summary.txt"
fi
if [ -f "$RES/figure4.md" ]; then
    echo
    cat "$RES/figure4.md"
fi
echo
for p in error_vs_time p99_vs_time rasterize_time rasterize_bytes shard_scale; do
    [ -f "$RES/$p.png" ] && echo "![$p]($RES/$p.png)"
done
echo
echo "CSV files: \`$RES/\` (rasterize, rastspeed, shell, render, refcast, accuracy, sweep, figure4, povray, shard, shard_scale, images)."
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
