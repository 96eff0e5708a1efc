#!/bin/sh
# images.sh (called by run.sh): the cost of --aa 4, --shadows, --ao 16 and
# of all of them with --exact against one ray a pixel, on blobs_a at
# FIG_LEVELS, SIZE², the standard view, REPS frames each in one mapping
# (median), with the supersampled share and the rate of each kind of ray
# from render -v (bench/vline.awk reads its fields by name); and a picture
# grid of the five at 256² for the README. Writes $RES/images.csv and
# $RES/images/*.png.
# Environment: BIN RES WORK PROV PROVH REPS SIZE FIG_LEVELS.
set -eu
D=$(dirname "$0")
. "$D/lib.sh"
CSV="$RES/images.csv"
oct="$WORK/blobs_a.$FIG_LEVELS.oct"
[ -f "$oct" ] || "$BIN/rasterize" scenes/blobs_a.scene -o "$oct" --levels "$FIG_LEVELS" -q
view="--eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30"
mkdir -p "$RES/images"
echo "$PROVH,scene,levels,size,option,ms_per_frame,time_ratio,supersampled_pct,primary_mrays_s,shadow_mrays_s,ao_mrays_s,secondary_mrays_s" >"$CSV"
col() { awk -v c="$1" '$c != "-" { print $c }' "$WORK/ifig" | median | sed 's/^nan$//'; }
base=""
for opt in plain aa shadows ao all; do
    case $opt in
    plain) flags="" ;; aa) flags="--aa 4" ;; shadows) flags="--shadows" ;; ao) flags="--ao 16" ;;
    all) flags="--aa 4 --shadows --ao 16 --exact" ;;
    esac
    vf="$WORK/views"; : >"$vf"
    r=0
    while [ "$r" -lt "$REPS" ]; do
        echo "-o $WORK/img.png --size ${SIZE}x$SIZE $view" >>"$vf"
        r=$((r + 1))
    done
    # shellcheck disable=SC2086 # flags split into words
    "$BIN/render" "$oct" --views "$vf" -v $flags 2>"$WORK/ilog"
    awk -f "$D/vline.awk" "$WORK/ilog" >"$WORK/ifig"
    ms=$(col 1) ss=$(col 2) pr=$(col 3) sh=$(col 4) ao=$(col 5) sec=$(col 6)
    # one kind of secondary ray: the combined rate is its own
    case $opt in shadows) sh=${sh:-$sec} ;; ao) ao=${ao:-$sec} ;; esac
    [ -n "$base" ] || base=$ms
    ratio=$(awk -v a="$ms" -v b="$base" 'BEGIN { printf "%.2f", a / b }')
    echo "$PROV,blobs_a,$FIG_LEVELS,$SIZE,$opt,$ms,$ratio,${ss:-0},$pr,$sh,$ao,$sec" >>"$CSV"
    echo "  images blobs_a levels $FIG_LEVELS ${SIZE}² $opt: $ms ms (x$ratio), supersampled ${ss:-0}%, Mrays/s primary $pr, shadow ${sh:--}, ao ${ao:--}, secondary ${sec:--}"
    # shellcheck disable=SC2086
    "$BIN/render" "$oct" -o "$RES/images/$opt.png" --size 256x256 $view $flags -q
done
