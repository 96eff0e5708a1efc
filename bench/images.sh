#!/bin/sh
# images.sh (called by run.sh): the cost of --aa 4, --shadows and --ao 16
# against one ray a pixel, on blobs_a at FIG_LEVELS, SIZE², the standard
# view, REPS frames each in one mapping (median), with the supersampled
# share and the rates of each kind of ray (-v); and a picture grid of the
# four at 256² for the README. Writes $RES/images.csv and $RES/images/*.png.
# Environment: BIN RES WORK PROV PROVH REPS SIZE FIG_LEVELS.
set -eu
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "";
    else if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
CSV="$RES/images.csv"
oct="$WORK/blobs_a.$FIG_LEVELS.oct"
[ -f "$oct" ] || "$BIN/rasterize" scenes/blobs_a.scene -o "$oct" --levels "$FIG_LEVELS" -q
view="--eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30"
mkdir -p "$RES/images"
echo "$PROVH,scene,levels,size,option,ms_per_frame,time_ratio,supersampled_pct,primary_mrays_s,secondary_mrays_s" >"$CSV"
base=""
for opt in plain aa shadows ao; do
    case $opt in
    plain) flags="" ;; aa) flags="--aa 4" ;; shadows) flags="--shadows" ;; ao) flags="--ao 16" ;;
    esac
    vf="$WORK/views"; : >"$vf"
    r=0
    while [ "$r" -lt "$REPS" ]; do
        echo "-o $WORK/img.png --size ${SIZE}x$SIZE $view" >>"$vf"
        r=$((r + 1))
    done
    # shellcheck disable=SC2086 # flags split into words
    "$BIN/render" "$oct" --views "$vf" -v $flags 2>"$WORK/ilog"
    ms=$(sed -n 's|^render: .*: [0-9x]*, \([0-9.]*\) ms,.*|\1|p' "$WORK/ilog" | median)
    ss=$(sed -n 's|.*, \([0-9.]*\)% supersampled.*|\1|p' "$WORK/ilog" | median)
    pr=$(sed -n 's|.*; primary [0-9.]* Mrays \([0-9.]*\) Mrays/s.*|\1|p' "$WORK/ilog" | median)
    sr=$(sed -n 's|.*, ao [0-9.]* Mrays, \([0-9.]*\) Mrays/s.*|\1|p' "$WORK/ilog" | median)
    [ -n "$base" ] || base=$ms
    ratio=$(awk -v a="$ms" -v b="$base" 'BEGIN { printf "%.2f", a / b }')
    echo "$PROV,blobs_a,$FIG_LEVELS,$SIZE,$opt,$ms,$ratio,${ss:-0},$pr,$sr" >>"$CSV"
    echo "  images blobs_a levels $FIG_LEVELS ${SIZE}² $opt: $ms ms (x$ratio), supersampled ${ss:-0}%, primary $pr Mrays/s, secondary ${sr:-none} Mrays/s"
    # shellcheck disable=SC2086
    "$BIN/render" "$oct" -o "$RES/images/$opt.png" --size 256x256 $view $flags -q
done
