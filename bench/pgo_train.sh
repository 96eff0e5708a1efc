#!/bin/sh
# make pgo's training run: what the benchmark and a user's batch do most
# (rasterizing every example scene with and without --shell-only, the large
# ones one level deeper; rendering with the paper's rule, --exact, --aa,
# --shadows and --ao), run by the instrumented programs so that GCC learns
# where their time goes.
#
#   sh bench/pgo_train.sh BIN WORK           train; outputs kept in WORK
#   sh bench/pgo_train.sh --check BIN WORK   the profile-guided programs
#                                            must write those outputs again,
#                                            byte for byte
set -eu
check=0
[ "${1:-}" = --check ] && { check=1; shift; }
[ $# -eq 2 ] || { echo "usage: bench/pgo_train.sh [--check] BIN WORK" >&2; exit 2; }
BIN=$1 W=$2
mkdir -p "$W"
n=0
# run NAME CMD...: CMD writes "$W/NAME.*"; with --check, into a scratch name
# that must then be the same bytes as the training's.
run() {
    name=$1; shift
    out=$name
    [ $check = 1 ] && out=check
    rm -f "$W/$out".*
    cmd=$(printf '%s\n' "$*" | sed "s|@OUT@|$W/$out|g")
    eval "$cmd" || { echo "pgo: $name failed: $cmd" >&2; exit 1; }
    if [ $check = 1 ]; then
        for f in "$W/$name".*; do
            [ -e "$f" ] || { echo "pgo: $name: no training output in $W (train first)" >&2; exit 1; }
            cmp -s "$f" "$W/check.${f##*/"$name".}" ||
                { echo "pgo: $name: ${f##*/} differs from the instrumented build's" >&2; exit 1; }
        done
        rm -f "$W/check".*
    fi
    n=$((n + 1))
}

scenes=$(for f in scenes/*.scene; do basename "$f" .scene; done)
[ $check = 1 ] && scenes="blobs_a csg gyroid multi" # a few suffice to compare
for s in $scenes; do
    run "r8.$s" "$BIN/rasterize scenes/$s.scene -o @OUT@.oct --levels 8 -q"
    run "s8.$s" "$BIN/rasterize scenes/$s.scene -o @OUT@.oct --levels 8 -q --shell-only"
    run "v8.$s" "$BIN/render $W/r8.$s.oct -o @OUT@.png --size 128x128 -q" \
        "&& $BIN/render $W/r8.$s.oct -o @OUT@.e.png --size 128x128 --exact -q --depth @OUT@.e.pfm"
done
for s in blobs_a blobs_b csg gyroid manyblobs; do
    [ $check = 1 ] && [ $s != csg ] && continue
    run "r9.$s" "$BIN/rasterize scenes/$s.scene -o @OUT@.oct --levels 9 -q"
    run "s9.$s" "$BIN/rasterize scenes/$s.scene -o @OUT@.oct --levels 9 -q --shell-only"
done
for s in blobs_a csg gyroid; do # (their r9 files come from the loop above)
    [ $check = 1 ] && [ $s != gyroid ] && continue
    run "v9.$s" "$BIN/render $W/r9.$s.oct -o @OUT@.png --size 512x512 -q" \
        "&& $BIN/render $W/r9.$s.oct -o @OUT@.e.png --size 512x512 --exact -q"
done
[ $check = 1 ] || run "s9r.csg" "$BIN/render $W/s9.csg.oct -o @OUT@.png --size 256x256 --exact -q"
run "img.blobs_a" "$BIN/render $W/r8.blobs_a.oct -o @OUT@.png --size 256x256 -q --aa 4 --shadows --ao 16" \
    "&& $BIN/render $W/r8.csg.oct -o @OUT@.e.png --size 256x256 -q --aa 4 --shadows --ao 8 --exact"
if [ $check = 1 ]; then
    echo "pgo: the profile-guided programs wrote the instrumented build's files again ($n runs)"
else
    echo "pgo: $n training runs"
fi
