#!/bin/sh
# make demo: rasterize the paper's two scenes (and the other examples) once,
# then render them into demo/*.png. Uses bin/ from `make`.
set -eu
LEVELS=${LEVELS:-10}
SIZE=${SIZE:-1024x1024}
mkdir -p demo
for s in blobs_a blobs_b; do
    bin/rasterize "scenes/$s.scene" -o "demo/$s.oct" --levels "$LEVELS"
    # The view of the paper's figures 5 and 6: the unit box seen from a corner.
    bin/render "demo/$s.oct" -o "demo/$s.png" --size "$SIZE" \
        --eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30
done
for f in scenes/*.scene; do
    s=$(basename "$f" .scene)
    case $s in blobs_a|blobs_b) continue ;; esac
    bin/rasterize "$f" -o "demo/$s.oct" --levels 9 -q
    bin/render "demo/$s.oct" -o "demo/$s.png" --size 512x512 -q
done
echo "demo: images in demo/"
ls demo/*.png
