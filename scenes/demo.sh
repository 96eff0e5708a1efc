#!/bin/sh
# make demo: rasterize the paper's two scenes (and the other examples) once,
# then render each twice into demo/: NAME.plain.png with the paper's plain
# rule (one ray a pixel, Lambert + ambient) and NAME.png with antialiasing,
# shadows and ambient occlusion (NICE). Uses bin/ from `make`.
set -eu
LEVELS=${LEVELS:-10}
SIZE=${SIZE:-1024x1024}
NICE=${NICE:---aa 4 --shadows --ao 16}
mkdir -p demo
for s in blobs_a blobs_b; do
    bin/rasterize "scenes/$s.scene" -o "demo/$s.oct" --levels "$LEVELS"
    # The view of the paper's figures 5 and 6: the unit box seen from a corner.
    view="--size $SIZE --eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30"
    # shellcheck disable=SC2086 # the option lists split into words
    bin/render "demo/$s.oct" -o "demo/$s.plain.png" $view
    # shellcheck disable=SC2086
    bin/render "demo/$s.oct" -o "demo/$s.png" $view $NICE
done
for f in scenes/*.scene; do
    s=$(basename "$f" .scene)
    case $s in blobs_a|blobs_b) continue ;; esac
    bin/rasterize "$f" -o "demo/$s.oct" --levels 9 -q
    bin/render "demo/$s.oct" -o "demo/$s.plain.png" --size 512x512 -q
    # shellcheck disable=SC2086
    bin/render "demo/$s.oct" -o "demo/$s.png" --size 512x512 $NICE -q
done
echo "demo: images in demo/ (NAME.plain.png: one ray a pixel; NAME.png: $NICE)"
ls demo/*.png
