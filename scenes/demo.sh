#!/bin/sh
# make demo: rasterize the paper's two scenes (and the other examples) once,
# then render each twice into demo/: NAME.plain.png with the paper's plain
# rule (one ray a pixel, Lambert + ambient, the voxel's plane) and NAME.png
# with antialiasing, shadows, ambient occlusion and exact hits (NICE). Uses
# bin/ from `make`. Knobs (environment): LEVELS and SIZE of the paper's
# scenes, NICE, and DOCS=1 to render the README's side-by-side pictures
# (256², docs/images/) as well.
set -eu
LEVELS=${LEVELS:-10}
SIZE=${SIZE:-1024x1024}
NICE=${NICE:---aa 4 --shadows --ao 16 --exact}
T0=$(date +%s)
mkdir -p demo
# both looks of one file: OCT OUT_PREFIX VIEW_OPTIONS...
both() {
    oct=$1 out=$2; shift 2
    bin/render "$oct" -o "$out.plain.png" "$@" -q
    # shellcheck disable=SC2086 # NICE splits into words
    bin/render "$oct" -o "$out.png" "$@" $NICE -q
}
# The view of the paper's figures 5 and 6: the unit box seen from a corner.
paper="--eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30"
for s in blobs_a blobs_b; do
    bin/rasterize "scenes/$s.scene" -o "demo/$s.oct" --levels "$LEVELS"
    # shellcheck disable=SC2086 # the view splits into words
    both "demo/$s.oct" "demo/$s" --size "$SIZE" $paper
done
for f in scenes/*.scene; do
    s=$(basename "$f" .scene)
    case $s in blobs_a|blobs_b) continue ;; esac
    bin/rasterize "$f" -o "demo/$s.oct" --levels 9 -q
    both "demo/$s.oct" "demo/$s" --size 512x512
done
if [ "${DOCS:-0}" = 1 ]; then # the README's pictures: blobs_a at LEVELS, the others at 9
    mkdir -p docs/images
    # shellcheck disable=SC2086
    both demo/blobs_a.oct docs/images/blobs_a --size 256x256 $paper
    for s in csg gyroid torus; do
        both "demo/$s.oct" "docs/images/$s" --size 256x256
    done
fi
echo "demo: images in demo/ (NAME.plain.png: the paper's plain rule; NAME.png: $NICE) in $(( $(date +%s) - T0 )) s"
ls demo/*.png
