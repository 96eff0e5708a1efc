#!/bin/sh
# make bench (full) / make bench-quick (quick): rasterize and render against
# the exact reference (refcast), the paper's Figure 4, the POV-Ray peer.
# Results: CSV files, plots and the Figure 4 table in $RES (bench/results),
# then the README's benchmark section (bench/report.sh). Scratch in $WORK.
# Knobs (environment, bench/README.md): SCENES, LEVELS, LEVELS_BLOBS, SIZE,
# REPS, RAST_REPS, ..., SECTIONS (which parts run).
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
    FIG_LEVELS=${FIG_LEVELS:-8}; FIG_SIZES=${FIG_SIZES:-"256 512"}; POV_SIZE=${POV_SIZE:-256}
    SPEED_SCENES=${SPEED_SCENES:-"blobs_a csg"}; SPEED_LEVELS=${SPEED_LEVELS:-8}; SPEED_REPS=${SPEED_REPS:-1}
    SHELL_LEVELS=${SHELL_LEVELS:-7}; RATIO_LEVELS=${RATIO_LEVELS:-8}; RATIO_PAIRS=${RATIO_PAIRS:-3}
    ACC_SCENES=${ACC_SCENES:-"sphere torus crease csg cube heart plate thin gyroid_ball"}
    ACC_LEVELS=${ACC_LEVELS:-9}; ACC_SIZE=${ACC_SIZE:-128}
    SWEEP_SCENES=${SWEEP_SCENES:-"blobs_a csg"}; SWEEP_LEVELS=${SWEEP_LEVELS:-"6 7 8 9"}
    SWEEP_SIZE=${SWEEP_SIZE:-512} ;;
full)
    SCENES=${SCENES:-"blobs_a blobs_b thin csg manyblobs"}
    LEVELS=${LEVELS:-"6 7 8 9 10"}; LEVELS_BLOBS=${LEVELS_BLOBS:-"6 7 8 9 10 11 12"}
    SIZE=${SIZE:-1024}; NVIEWS=${NVIEWS:-3}; REPS=${REPS:-3}; RAST_REPS=${RAST_REPS:-3}
    FIG_LEVELS=${FIG_LEVELS:-10}; FIG_SIZES=${FIG_SIZES:-"256 512 1024"}
    POV_SIZE=${POV_SIZE:-1024}
    SPEED_SCENES=${SPEED_SCENES:-"blobs_a blobs_b csg gyroid manyblobs"}
    SPEED_LEVELS=${SPEED_LEVELS:-"10 12"}; SPEED_REPS=${SPEED_REPS:-3}; SHELL_LEVELS=${SHELL_LEVELS:-9}
    RATIO_LEVELS=${RATIO_LEVELS:-10}; RATIO_PAIRS=${RATIO_PAIRS:-9}
    ACC_SCENES=${ACC_SCENES:-$(for f in scenes/*.scene; do basename "$f" .scene; done)}
    ACC_LEVELS=${ACC_LEVELS:-"9 10"}; ACC_SIZE=${ACC_SIZE:-256}
    SWEEP_SCENES=${SWEEP_SCENES:-"blobs_a blobs_b thin csg gyroid manyblobs"}
    SWEEP_LEVELS=${SWEEP_LEVELS:-"6 7 8 9 10 11 12"}; SWEEP_SIZE=${SWEEP_SIZE:-1024} ;;
*)
    echo "usage: bench/run.sh quick|full" >&2; exit 2 ;;
esac
SECTIONS=${SECTIONS:-"main ratio speed accuracy sweep fig4 images pov shard eval"}
REPORT=${REPORT:-README.md}
want() { case " $SECTIONS " in *" $1 "*) return 0 ;; esac; return 1; }
D=$(dirname "$0")
. "$D/lib.sh"
for t in "$BIN/rasterize" "$BIN/render" "$TOOLS/refcast" "$TOOLS/imgcompare" "$TOOLS/gradmax" \
         "$TOOLS/scene2pov" "$TOOLS/shellratio" "$TOOLS/normalerr"; do
    [ -x "$t" ] || { echo "bench: $t missing: run 'make pgo tools' (or 'make all tools') first" >&2; exit 1; }
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

if want main; then
    RAST="$RES/rasterize.csv" REND="$RES/render.csv" REF="$RES/refcast.csv"
    echo "$PROVH,scene,levels,seconds,voxels,nodes,bytes,bytes_per_voxel,peak_rss_kib" >"$RAST"
    echo "$PROVH,scene,levels,view,size,refine,ms_per_frame,mrays_s,depth_mean_vox,depth_p99_vox,depth_max_vox,hitmiss_frac,normal_mean_deg,normal_p99_deg,normal_max_deg,nan_pixels" >"$REND"
    echo "$PROVH,scene,view,size,ms,mrays_s" >"$REF"
fi

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
render_views() { # OCT SCENE LEVELS MODE(plain|refine|exact) [--split K]: CSV rows
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
    flag=""; [ "$mode" = refine ] && flag=--refine; [ "$mode" = exact ] && flag=--exact
    "$BIN/render" "$oct" --views "$vf" $flag "$@" 2>"$WORK/vlog"
    vox=$(voxel "scenes/$s.scene" "$L")
    views "scenes/$s.scene" | while read -r name eye target up; do
        ms=$(sed -n "s|^render: $WORK/$name.png: [0-9x]*, \([0-9.]*\) ms,.*|\1|p" "$WORK/vlog" | median)
        err=$("$TOOLS/imgcompare" "$WORK/$name.pfm" "$WORK/ref.$s.$name.pfm" --voxel "$vox" \
              --normals "$WORK/$name.n.pfm" "$WORK/ref.$s.$name.n.pfm" --csv)
        mr=$(awk -v ms="$ms" -v n="$SIZE" 'BEGIN { printf "%.3f", n * n / ms / 1e3 }')
        echo "$PROV,$s,$L,$name,$SIZE,$mode,$ms,$mr,$err" >>"$REND"
        echo "  render $s levels $L $name $mode: $ms ms ($mr Mrays/s); mean,p99,max,hitmiss,nmean,np99,nmax,nan = $err"
    done
}

if want main; then
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
            render_views "$oct" "$s" "$L" exact
            case $s.$L in blobs_a.$FIG_LEVELS|blobs_b.$FIG_LEVELS) ;; *) rm -f "$oct" ;; esac
        done
    done
fi

# ---- issue 14's ratio: --exact against the paper's rule on the standard view,
# frames of the two alternating in one mapping (the same file, machine state
# and warmed caches for both), RATIO_PAIRS pairs after one warm-up pair, the
# median of each ----
if want ratio; then
    RAT="$RES/exactratio.csv"
    echo "$PROVH,scene,levels,size,pairs,plain_ms,exact_ms,ratio" >"$RAT"
    for s in blobs_a csg; do
        oct="$WORK/ratio.oct" L=$RATIO_LEVELS
        "$BIN/rasterize" "scenes/$s.scene" -o "$oct" --levels "$L" -q
        set -- $(views "scenes/$s.scene" | head -n 1) # the standard view
        vf="$WORK/ratio.views"; : >"$vf"
        i=0
        while [ $i -le "$RATIO_PAIRS" ]; do
            for m in plain exact; do
                flag=""; [ $m = exact ] && flag=--exact
                echo "-o $WORK/ratio.$m.$i.png --size ${SIZE}x$SIZE --eye $2 --target $3 --up $4 --fov 30 $flag" >>"$vf"
            done
            i=$((i + 1))
        done
        "$BIN/render" "$oct" --views "$vf" 2>"$WORK/vlog"
        rm -f "$oct" "$WORK"/ratio.*.png
        for m in plain exact; do # (pair 0, the warm-up, left out)
            sed -n "s|^render: $WORK/ratio\.$m\.[0-9]*\.png: [0-9x]*, \([0-9.]*\) ms,.*|\1|p" "$WORK/vlog" |
                tail -n "$RATIO_PAIRS" | median >"$WORK/ratio.$m"
        done
        p=$(cat "$WORK/ratio.plain") x=$(cat "$WORK/ratio.exact")
        r=$(awk -v p="$p" -v x="$x" 'BEGIN { printf "%.3f", (p > 0 ? x / p : 0) }')
        echo "$PROV,$s,$L,$SIZE,$RATIO_PAIRS,$p,$x,$r" >>"$RAT"
        echo "  ratio $s levels $L std: plain $p ms, --exact $x ms: ${r}x ($RATIO_PAIRS pairs)"
    done
fi

# ---- rasterize speed: M voxels kept a second and CPU use (user + system over
# wall, 200 % = both cores busy to the end), the median of SPEED_REPS runs, full records and
# --shell-only, each on both paths of the lane evaluators' dispatch (the AVX2
# build where the processor has it, and DDA_SIMD=portable); the shell: voxels
# kept over the voxels the surface really passes through (bench/shellratio),
# and the records' errors (bench/normalerr) ----
speed_run() { # SCENE LEVELS OUT [FLAGS]: prints "seconds voxels mvox_s cpu_pct"; $SIMD: the path
    s=$1 L=$2 o=$3; shift 3
    set -- env ${SIMD:+DDA_SIMD=$SIMD} "$BIN/rasterize" "scenes/$s.scene" -o "$o" --levels "$L" "$@"
    if [ -x /usr/bin/time ]; then
        # the run of median wall time among SPEED_REPS (a shared machine's load comes and goes)
        : >"$WORK/st"
        r=0
        while [ $r -lt "$SPEED_REPS" ]; do
            /usr/bin/time -f "time %e %U %S" "$@" >"$WORK/rlog" 2>&1
            sed -n 's/^time \([0-9.]*\) \([0-9.]*\) \([0-9.]*\)$/\1 \2 \3/p' "$WORK/rlog" >>"$WORK/st"
            r=$((r + 1))
        done
        set -- $(sort -g "$WORK/st" | sed -n "$(((SPEED_REPS + 1) / 2))p")
        sec=$1 cpu=$(awk -v w="$1" -v u="$2" -v k="$3" 'BEGIN { printf "%.0f", (w > 0 ? 100 * (u + k) / w : 0) }')
    else
        "$@" >"$WORK/rlog" 2>&1
        sec=$(sed -n 's/.*; \([0-9.]*\) s, peak memory.*/\1/p' "$WORK/rlog") cpu=nan
    fi
    v=$(sed -n 's/.* \([0-9]*\) voxels, [0-9]* nodes.*/\1/p' "$WORK/rlog")
    echo "$sec $v $(awk -v v="$v" -v t="$sec" 'BEGIN { printf "%.2f", (t > 0 ? v / t / 1e6 : 0) }') $cpu"
}
if want speed; then
    SPEED="$RES/rastspeed.csv" SHELL="$RES/shell.csv"
    echo "$PROVH,scene,levels,seconds,voxels,mvox_s,cpu_pct,shell_only_seconds,shell_only_mvox_s,shell_only_cpu_pct,portable_mvox_s,portable_shell_only_mvox_s,portable_same" >"$SPEED"
    echo "$PROVH,scene,levels,kept,real,ratio,lost,voxels_near,voxels_missed,normal_mean_deg,normal_p99_deg,normal_max_deg,offset_mean_vox,offset_p99_vox,offset_max_vox" >"$SHELL"
    for s in $SPEED_SCENES; do
        for L in $SPEED_LEVELS; do
            SIMD=
            set -- $(speed_run "$s" "$L" "$WORK/speed.oct")
            sec=$1 v=$2 mv=$3 cpu=$4
            # the level sweep uses this file again rather than rasterize it twice
            set -- $(speed_run "$s" "$L" "$WORK/shell.$s.$L.oct" --shell-only)
            ssec=$1 smv=$3 scpu=$4
            # the portable path: its speed, and its files the same bytes
            SIMD=portable
            set -- $(speed_run "$s" "$L" "$WORK/speed.p.oct")
            pmv=$3
            set -- $(speed_run "$s" "$L" "$WORK/shell.p.oct" --shell-only)
            psmv=$3 SIMD=
            same=1
            cmp -s "$WORK/speed.oct" "$WORK/speed.p.oct" && cmp -s "$WORK/shell.$s.$L.oct" "$WORK/shell.p.oct" ||
                { same=0; echo "bench: $s levels $L: the portable path wrote other bytes" >&2; }
            rm -f "$WORK/speed.oct" "$WORK/speed.p.oct" "$WORK/shell.p.oct"
            echo "$PROV,$s,$L,$sec,$v,$mv,$cpu,$ssec,$smv,$scpu,$pmv,$psmv,$same" >>"$SPEED"
            echo "  rasterize speed $s levels $L: $sec s, $v voxels, $mv M voxels/s, CPU $cpu %; --shell-only $ssec s, $smv M voxels/s, CPU $scpu %; portable path $pmv / $psmv M voxels/s, same bytes: $same"
        done
        for L in $SHELL_LEVELS; do
            o="$WORK/shell.oct"
            "$BIN/rasterize" "scenes/$s.scene" -o "$o" --levels "$L" -q
            r=$("$TOOLS/shellratio" "scenes/$s.scene" "$o" --csv) || echo "bench: $s levels $L: shellratio failed" >&2
            ne=$("$TOOLS/normalerr" "scenes/$s.scene" "$o" --csv)
            rm -f "$o"
            echo "$PROV,$s,$L,$r,$ne" >>"$SHELL"
            echo "  shell $s levels $L: kept,real,ratio,lost = $r; records against the exact surface: $ne"
        done
    done
fi

# ---- Exactness: --exact against refcast on many scenes (bench/accuracy.sh),
# and the --exact time against the octree's level (bench/sweep.sh) ----
export BIN TOOLS RES WORK PROV PROVH REPS NVIEWS
want accuracy && ACC_SCENES=$ACC_SCENES ACC_LEVELS=$ACC_LEVELS ACC_SIZE=$ACC_SIZE sh "$D/accuracy.sh"
want sweep && SWEEP_SCENES=$SWEEP_SCENES SWEEP_LEVELS=$SWEEP_LEVELS SWEEP_SIZE=$SWEEP_SIZE sh "$D/sweep.sh"
rm -f "$WORK"/shell.*.oct

# ---- Figure 4: both blobs at FIG_LEVELS, sizes x splits 4..7 ----
if want fig4; then
    FIG="$RES/figure4.csv"
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
                ms=$(frame_ms "$WORK/vlog" | median)
                paper=$(awk -v s="$s" -v n="$n" -v k="$k" -f "$D/paper_fig4.awk")
                echo "$PROV,$s,$FIG_LEVELS,$n,$k,$ms,$paper" >>"$FIG"
                echo "  figure 4 $s ${n}x$n split $k: $ms ms (paper $paper s)"
            done
        done
    done
fi

# ---- Images: --aa 4, --shadows, --ao 16 against one ray a pixel ----
if want images; then
    SIZE=$SIZE FIG_LEVELS=$FIG_LEVELS sh "$D/images.sh"
fi

# ---- POV-Ray: blobs_a and blobs_b, standard view, two accuracies ----
if want pov; then
    POV="$RES/povray.csv"
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
                ms=$(frame_ms "$WORK/vlog" | median)
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
fi

# ---- Sharded rasterization (bench/shard.sh): overhead, merge, projection ----
if want shard; then
    case $MODE in
    quick) BIN="$BIN" RES="$RES" WORK="$WORK/shard" sh "$D/shard.sh" blobs_a 8 8 ;;
    full) BIN="$BIN" RES="$RES" WORK="$WORK/shard" sh "$D/shard.sh" blobs_a 12 64 ;;
    esac
fi

# ---- Plots and the report ----
if ! [ -f "$RES/render.csv" ] || ! [ -f "$RES/rasterize.csv" ]; then
    echo "bench: no render.csv or rasterize.csv: no plots"
elif have gnuplot; then
    gnuplot -e "res='$RES'" "$D/plots.gp" && echo "bench: plots in $RES/*.png"
else
    echo "bench: gnuplot not installed: no plots (apt-get install gnuplot)"
fi
want fig4 && sh "$D/fig4.sh" "$RES/figure4.csv" >"$RES/figure4.md"
if want eval; then
    BIN=$TOOLS sh "$D/eval.sh" >"$RES/eval.txt" 2>&1 || echo "bench: eval.sh failed (see $RES/eval.txt)"
fi
[ "$MODE" = full ] && [ "$REPORT" != none ] && sh "$D/report.sh" "$RES" "$REPORT"
echo "bench: $MODE done in $(( $(date +%s) - T0 )) s; results in $RES"
