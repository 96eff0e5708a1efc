#!/bin/sh
# make bench (full) / make bench-quick (quick): rasterize and render against
# the exact reference (refcast), the paper's Figure 4, the POV-Ray peer.
# Results: CSV files, plots and the Figure 4 table in $RES (bench/results),
# then the README's benchmark section (bench/report.sh). Scratch in $WORK.
# Knobs (environment): SCENES, LEVELS, LEVELS_BLOBS, SIZE, REPS, RAST_REPS.
set -eu
MODE=${1:-quick}
BIN=${BIN:-bin}
TOOLS=${TOOLS:-build/rel/bin}
RES=${RES:-bench/results}
WORK=${WORK:-build/bench}
case $MODE in
quick) # manyblobs' reference alone would take a minute
    SCENES=${SCENES:-"blobs_a blobs_b thin csg"}
    LEVELS=${LEVELS:-"6 8"}; LEVELS_BLOBS=${LEVELS_BLOBS:-"6 7 8"}
    SIZE=${SIZE:-512}; NVIEWS=${NVIEWS:-1}; REPS=${REPS:-3}; RAST_REPS=${RAST_REPS:-1}
    FIG_LEVELS=${FIG_LEVELS:-8}; FIG_SIZES=${FIG_SIZES:-"256 512"}; POV_SIZE=${POV_SIZE:-256} ;;
full)
    SCENES=${SCENES:-"blobs_a blobs_b thin csg manyblobs"}
    LEVELS=${LEVELS:-"6 7 8 9 10"}; LEVELS_BLOBS=${LEVELS_BLOBS:-"6 7 8 9 10 11 12"}
    SIZE=${SIZE:-1024}; NVIEWS=${NVIEWS:-3}; REPS=${REPS:-3}; RAST_REPS=${RAST_REPS:-3}
    FIG_LEVELS=${FIG_LEVELS:-10}; FIG_SIZES=${FIG_SIZES:-"256 512 1024"}
    POV_SIZE=${POV_SIZE:-1024} ;;
*)
    echo "usage: bench/run.sh quick|full" >&2; exit 2 ;;
esac
D=$(dirname "$0")
for t in "$BIN/rasterize" "$BIN/render" "$TOOLS/refcast" "$TOOLS/imgcompare" "$TOOLS/gradmax" \
         "$TOOLS/scene2pov"; do
    [ -x "$t" ] || { echo "bench: $t missing: run 'make all tools' first" >&2; exit 1; }
done
sh "$D/deps.sh" "$MODE"
have() { command -v "$1" >/dev/null 2>&1; }
mkdir -p "$RES" "$WORK"
T0=$(date +%s)

# ---- Provenance: every CSV row carries machine, cores, date and commit. ----
CPU=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1 | tr -s ' ,' ' ')
CORES=$(nproc)
DATE=$(date -u +%Y-%m-%dT%H:%MZ)
COMMIT=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
[ -n "$(git status --porcelain --untracked-files=no 2>/dev/null | grep -v "^.. $RES/" || true)" ] &&
    COMMIT="$COMMIT-dirty"
PROV="$CPU,$CORES,$DATE,$COMMIT,$MODE"
PROVH="machine,cores,date,commit,mode"
echo "bench: $MODE on $CPU ($CORES cores), commit $COMMIT"

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "nan";
    else if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# Views of a scene, one a line: NAME EYE TARGET UP. The standard view is the
# paper's for the unit box (eye 2.2,1.6,1.9 target 0.5,0.5,0.5), scaled to
# the cube around any other bounds; two more from other sides.
views() {
    awk -v n="$NVIEWS" '$1 == "bounds" {
        e = $5 - $2; if ($6 - $3 > e) e = $6 - $3; if ($7 - $4 > e) e = $7 - $4
        c1 = $2 + e / 2; c2 = $3 + e / 2; c3 = $4 + e / 2
        split("std side top", name, " ")
        split("1.7 1.1 1.4  -1.9 1.3 0.6  0.5 -0.9 2.1", o, " ")
        for (k = 0; k < n && k < 3; k++)
            printf "%s %.6g,%.6g,%.6g %.6g,%.6g,%.6g 0,0,1\n", name[k + 1],
                c1 + e * o[3*k + 1], c2 + e * o[3*k + 2], c3 + e * o[3*k + 3], c1, c2, c3
        exit }' "$1"
}
edge() { awk '$1 == "bounds" { e = $5 - $2; if ($6 - $3 > e) e = $6 - $3;
    if ($7 - $4 > e) e = $7 - $4; printf "%.17g\n", e; exit }' "$1"; }

RAST="$RES/rasterize.csv" REND="$RES/render.csv" REF="$RES/refcast.csv"
FIG="$RES/figure4.csv" POV="$RES/povray.csv"
echo "$PROVH,scene,levels,seconds,voxels,nodes,bytes,bytes_per_voxel,peak_rss_kib" >"$RAST"
echo "$PROVH,scene,levels,view,size,refine,ms_per_frame,mrays_s,depth_mean_vox,depth_p99_vox,depth_max_vox,hitmiss_frac,normal_mean_deg,normal_p99_deg" >"$REND"
echo "$PROVH,scene,view,size,ms,mrays_s" >"$REF"

# ---- rasterize: median wall time of RAST_REPS runs, RSS from /usr/bin/time ----
rasterize() { # SCENE LEVELS OUT.oct: one CSV row
    s=$1 L=$2 o=$3 reps=$RAST_REPS
    # one run where a run takes long: above level 10, and at 10 but for the paper's scenes
    [ "$L" -gt 10 ] && reps=1
    case $s.$L in blobs_a.10|blobs_b.10) ;; *.10) reps=1 ;; esac
    : >"$WORK/rt"
    r=0
    while [ $r -lt "$reps" ]; do
        if [ -x /usr/bin/time ]; then
            /usr/bin/time -f "time %e %M" "$BIN/rasterize" "scenes/$s.scene" -o "$o" --levels "$L" \
                >"$WORK/rlog" 2>&1
            sed -n 's/^time \([0-9.]*\) [0-9]*$/\1/p' "$WORK/rlog" >>"$WORK/rt"
        else # the time rasterize reports (no start-up)
            "$BIN/rasterize" "scenes/$s.scene" -o "$o" --levels "$L" >"$WORK/rlog" 2>&1
            sed -n 's/.*; \([0-9.]*\) s, peak memory.*/\1/p' "$WORK/rlog" >>"$WORK/rt"
        fi
        r=$((r + 1))
    done
    # summary: "levels L (..), V voxels, N nodes, B bytes (x bytes/voxel)"
    v=$(sed -n 's/.* \([0-9]*\) voxels, \([0-9]*\) nodes, \([0-9]*\) bytes (\([0-9.]*\) bytes\/voxel).*/\1,\2,\3,\4/p' "$WORK/rlog")
    rss=$(sed -n 's/^time [0-9.]* \([0-9]*\)$/\1/p' "$WORK/rlog")
    [ -n "$rss" ] || rss=$(sed -n 's/.*peak memory \([0-9.]*\) MiB.*/\1/p' "$WORK/rlog" |
        awk '{ printf "%d\n", $1 * 1024 }')
    sec=$(median <"$WORK/rt")
    echo "$PROV,$s,$L,$sec,$v,$rss" >>"$RAST"
    echo "  rasterize $s levels $L: $sec s, $v (voxels,nodes,bytes,bytes/voxel), $rss KiB"
}

# ---- render: REPS frames of every view in one mapping, median per view ----
render_views() { # OCT SCENE LEVELS MODE(plain|refine) [--split K]: CSV rows
    oct=$1 s=$2 L=$3 mode=$4; shift 4
    vf="$WORK/views" ; : >"$vf"
    views "scenes/$s.scene" | while read -r name eye target up; do
        r=0
        while [ $r -lt "$REPS" ]; do
            extra=""
            [ $r -eq 0 ] && extra="--depth $WORK/$name.pfm --normals $WORK/$name.n.pfm"
            echo "-o $WORK/$name.png --size ${SIZE}x$SIZE --eye $eye --target $target --up $up --fov 30 $extra" >>"$vf"
            r=$((r + 1))
        done
    done
    flag=""; [ "$mode" = refine ] && flag=--refine
    "$BIN/render" "$oct" --views "$vf" $flag "$@" 2>"$WORK/vlog"
    vox=$(awk -v e="$(edge "scenes/$s.scene")" -v L="$L" 'BEGIN { printf "%.17g", e / 2 ^ L }')
    views "scenes/$s.scene" | while read -r name eye target up; do
        ms=$(sed -n "s|^render: $WORK/$name.png: [0-9x]*, \([0-9.]*\) ms,.*|\1|p" "$WORK/vlog" | median)
        err=$("$TOOLS/imgcompare" "$WORK/$name.pfm" "$WORK/ref.$s.$name.pfm" --voxel "$vox" \
              --normals "$WORK/$name.n.pfm" "$WORK/ref.$s.$name.n.pfm" --csv)
        mr=$(awk -v ms="$ms" -v n="$SIZE" 'BEGIN { printf "%.3f", n * n / ms / 1e3 }')
        echo "$PROV,$s,$L,$name,$SIZE,$mode,$ms,$mr,$err" >>"$REND"
        echo "  render $s levels $L $name $mode: $ms ms ($mr Mrays/s); mean,p99,max,hitmiss,nmean,np99 = $err"
    done
}

for s in $SCENES; do
    f="scenes/$s.scene"
    echo "bench: $s"
    views "$f" | while read -r name eye target up; do
        "$TOOLS/refcast" "$f" -o "$WORK/ref.$s.$name.png" --depth "$WORK/ref.$s.$name.pfm" \
            --normals "$WORK/ref.$s.$name.n.pfm" --size "${SIZE}x$SIZE" --eye "$eye" \
            --target "$target" --up "$up" --fov 30 2>"$WORK/flog"
        ms=$(sed -n 's/.*: [0-9x]*, \([0-9.]*\) ms,.*/\1/p' "$WORK/flog")
        mr=$(awk -v ms="$ms" -v n="$SIZE" 'BEGIN { printf "%.4f", n * n / ms / 1e3 }')
        echo "$PROV,$s,$name,$SIZE,$ms,$mr" >>"$REF"
        echo "  refcast $s $name: $ms ms"
    done
    lv=$LEVELS
    case $s in blobs_a|blobs_b) lv=$LEVELS_BLOBS ;; esac
    for L in $lv; do
        oct="$WORK/$s.$L.oct"
        rasterize "$s" "$L" "$oct"
        render_views "$oct" "$s" "$L" plain
        render_views "$oct" "$s" "$L" refine
        case $s.$L in blobs_a.$FIG_LEVELS|blobs_b.$FIG_LEVELS) ;; *) rm -f "$oct" ;; esac
    done
done

# ---- Figure 4: both blobs at FIG_LEVELS, sizes x splits 4..7 ----
echo "$PROVH,scene,levels,size,split,ms_per_frame,paper_s" >"$FIG"
for s in blobs_a blobs_b; do
    oct="$WORK/$s.$FIG_LEVELS.oct"
    [ -f "$oct" ] || "$BIN/rasterize" "scenes/$s.scene" -o "$oct" --levels "$FIG_LEVELS" -q
    for n in $FIG_SIZES; do
        for k in 4 5 6 7; do
            vf="$WORK/views"; : >"$vf"
            r=0
            while [ $r -lt "$REPS" ]; do
                echo "-o $WORK/fig4.png --size ${n}x$n --eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30" >>"$vf"
                r=$((r + 1))
            done
            "$BIN/render" "$oct" --views "$vf" --split "$k" 2>"$WORK/vlog"
            ms=$(sed -n 's|^render: .*: [0-9x]*, \([0-9.]*\) ms,.*|\1|p' "$WORK/vlog" | median)
            paper=$(awk -v s="$s" -v n="$n" -v k="$k" -f "$D/paper_fig4.awk")
            echo "$PROV,$s,$FIG_LEVELS,$n,$k,$ms,$paper" >>"$FIG"
            echo "  figure 4 $s ${n}x$n split $k: $ms ms (paper $paper s)"
        done
    done
done

# ---- POV-Ray: blobs_a and blobs_b, standard view, two accuracies ----
echo "$PROVH,scene,size,accuracy,max_gradient,pov_s,pov_hitmiss_frac,ours_ms,ours_refine_ms,ours_hitmiss_frac,pov_over_ours" >"$POV"
if have povray; then
    sh "$D/pov/pov.sh" check "$TOOLS"
    for s in blobs_a blobs_b; do
        f="scenes/$s.scene" oct="$WORK/$s.$FIG_LEVELS.oct" n=$POV_SIZE
        set -- $(views "$f" | head -n 1)
        eye=$2 target=$3 up=$4
        "$TOOLS/refcast" "$f" --depth "$WORK/pref.pfm" --size "${n}x$n" --eye "$eye" --target "$target" \
            --up "$up" --fov 30 -q
        g=$("$TOOLS/gradmax" "$f" --grid 96)
        mg=$(awk -v g="$g" 'BEGIN { printf "%.4g", 1.5 * g }') # safety factor 1.5
        for mode in plain refine; do
            vf="$WORK/views"; : >"$vf"
            r=0
            while [ $r -lt "$REPS" ]; do
                echo "-o $WORK/p.png --size ${n}x$n --eye $eye --target $target --up $up --fov 30 --depth $WORK/p.pfm" >>"$vf"
                r=$((r + 1))
            done
            flag=""; [ $mode = refine ] && flag=--refine
            "$BIN/render" "$oct" --views "$vf" $flag 2>"$WORK/vlog"
            ms=$(sed -n 's|^render: .*: [0-9x]*, \([0-9.]*\) ms,.*|\1|p' "$WORK/vlog" | median)
            [ $mode = plain ] && { ours=$ms; ohm=$("$TOOLS/imgcompare" "$WORK/p.pfm" "$WORK/pref.pfm" --voxel 1 --csv | cut -d, -f4); }
            [ $mode = refine ] && oursr=$ms
        done
        for acc in 0.001 0.00001; do
            : >"$WORK/pt"
            r=0
            while [ $r -lt 3 ]; do
                sh "$D/pov/pov.sh" render "$TOOLS" "$f" "$WORK/pov.png" "${n}x$n" "$eye" "$target" "$up" 30 \
                    "$mg" "$acc" >>"$WORK/pt"
                r=$((r + 1))
            done
            ps=$(median <"$WORK/pt")
            phm=$("$TOOLS/imgcompare" --mask "$WORK/pov.png" "$WORK/pref.pfm" --csv | cut -d, -f4)
            ratio=$(awk -v p="$ps" -v o="$ours" 'BEGIN { printf "%.1f", p * 1000 / o }')
            echo "$PROV,$s,$n,$acc,$mg,$ps,$phm,$ours,$oursr,$ohm,$ratio" >>"$POV"
            echo "  povray $s ${n}x$n accuracy $acc: $ps s, hit/miss $phm; ours $ours ms (hit/miss $ohm): x$ratio"
        done
    done
else
    echo "bench: povray not installed: no peer comparison (apt-get install povray)"
fi

# ---- Sharded rasterization (bench/shard.sh): overhead, merge, projection ----
case $MODE in
quick) BIN="$BIN" RES="$RES" WORK="$WORK/shard" sh "$D/shard.sh" blobs_a 8 8 ;;
full) BIN="$BIN" RES="$RES" WORK="$WORK/shard" sh "$D/shard.sh" blobs_a 12 64 ;;
esac

# ---- Plots and the report ----
if have gnuplot; then
    gnuplot -e "res='$RES'" "$D/plots.gp" && echo "bench: plots in $RES/*.png"
else
    echo "bench: gnuplot not installed: no plots (apt-get install gnuplot)"
fi
sh "$D/fig4.sh" "$FIG" >"$RES/figure4.md"
sh "$D/eval.sh" >"$RES/eval.txt" 2>&1 || echo "bench: eval.sh failed (see $RES/eval.txt)"
[ "$MODE" = full ] && sh "$D/report.sh" "$RES" README.md
echo "bench: $MODE done in $(( $(date +%s) - T0 )) s; results in $RES"
