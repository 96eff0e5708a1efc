#!/bin/sh
# sweep.sh (called by run.sh): the time of render --exact against the
# octree's level. With exact hits the level no longer sets the accuracy, only
# the speed: coarse trees send the root finder through large voxels, fine ones
# walk many voxels. Each scene of SWEEP_SCENES at each level of SWEEP_LEVELS
# is rasterized with --shell-only (the records are not needed; a file the
# speed table left in WORK as shell.SCENE.LEVELS.oct is used again), then REPS
# frames of the standard view at SWEEP_SIZE² in one mapping (median).
# Writes $RES/sweep.csv.
# Environment: BIN RES WORK PROV PROVH REPS SWEEP_SCENES SWEEP_LEVELS SWEEP_SIZE.
set -eu
D=$(dirname "$0")
. "$D/lib.sh"
CSV="$RES/sweep.csv"
n=$SWEEP_SIZE
echo "$PROVH,scene,levels,size,rasterize_s,exact_ms" >"$CSV"
for s in $SWEEP_SCENES; do
    f="scenes/$s.scene"
    set -- $(NVIEWS=1 views "$f")
    vf="$WORK/sweep.views"; : >"$vf"
    r=0
    while [ "$r" -lt "$REPS" ]; do
        echo "-o $WORK/sweep.png --size ${n}x$n --eye $2 --target $3 --up $4 --fov 30" >>"$vf"
        r=$((r + 1))
    done
    for L in $SWEEP_LEVELS; do
        oct="$WORK/shell.$s.$L.oct" rs="" # the speed table's file when it kept one
        if ! [ -f "$oct" ]; then
            t0=$(date +%s.%N)
            "$BIN/rasterize" "$f" -o "$oct" --levels "$L" --shell-only -q
            rs=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
        fi
        "$BIN/render" "$oct" --views "$vf" --exact 2>"$WORK/slog"
        ms=$(frame_ms "$WORK/slog" | median)
        rm -f "$oct"
        echo "$PROV,$s,$L,$n,$rs,$ms" >>"$CSV"
        how="rasterize --shell-only $rs s"; [ -n "$rs" ] || how="the speed table's file"
        echo "  sweep $s levels $L ${n}²: --exact $ms ms ($how)"
    done
done
