#!/bin/sh
# accuracy.sh (called by run.sh): render --exact against the exact interval
# ray caster (refcast) on each scene of ACC_SCENES at each level of
# ACC_LEVELS, the standard view at ACC_SIZE² (smaller than the main tables:
# refcast is slow on large expressions): depth error in voxels of the level,
# hit/miss disagreement, normal angle error, NaN pixels; the time of one
# --exact frame and of refcast. Writes $RES/accuracy.csv.
# Environment: BIN TOOLS RES WORK PROV PROVH ACC_SCENES ACC_LEVELS ACC_SIZE.
set -eu
D=$(dirname "$0")
. "$D/lib.sh"
CSV="$RES/accuracy.csv"
n=$ACC_SIZE
echo "$PROVH,scene,levels,size,exact_ms,depth_mean_vox,depth_p99_vox,depth_max_vox,hitmiss_frac,normal_mean_deg,normal_p99_deg,normal_max_deg,nan_pixels,refcast_ms" >"$CSV"
for s in $ACC_SCENES; do
    f="scenes/$s.scene"
    set -- $(NVIEWS=1 views "$f")
    view="--size ${n}x$n --eye $2 --target $3 --up $4 --fov 30"
    # shellcheck disable=SC2086 # the view splits into words
    "$TOOLS/refcast" "$f" --depth "$WORK/aref.pfm" --normals "$WORK/aref.n.pfm" $view 2>"$WORK/alog"
    rms=$(sed -n 's/.*: [0-9x]*, \([0-9.]*\) ms,.*/\1/p' "$WORK/alog")
    for L in $ACC_LEVELS; do
        oct="$WORK/acc.oct"
        "$BIN/rasterize" "$f" -o "$oct" --levels "$L" -q
        # shellcheck disable=SC2086
        "$BIN/render" "$oct" -o "$WORK/acc.png" --depth "$WORK/acc.pfm" --normals "$WORK/acc.n.pfm" \
            $view --exact 2>"$WORK/alog"
        ms=$(frame_ms "$WORK/alog" | median)
        err=$("$TOOLS/imgcompare" "$WORK/acc.pfm" "$WORK/aref.pfm" --voxel "$(voxel "$f" "$L")" \
              --normals "$WORK/acc.n.pfm" "$WORK/aref.n.pfm" --csv)
        rm -f "$oct"
        echo "$PROV,$s,$L,$n,$ms,$err,$rms" >>"$CSV"
        echo "  accuracy $s levels $L ${n}²: --exact $ms ms, refcast $rms ms; mean,p99,max,hitmiss,nmean,np99,nmax,nan = $err"
    done
done
