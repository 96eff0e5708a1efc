#!/bin/sh
# farm/parallel-*.sh with GNU parallel on this machine: shards merged into the
# bytes of a whole run, render parts writing the frames of one run, failures.
set -u
. "$ROOT/tests/cli/lib.sh"
command -v parallel >/dev/null || fail "GNU parallel is not installed (sh tests/deps.sh test)"
F=$ROOT/farm
RASTERIZE=$BIN/rasterize RENDER=$BIN/render; export RASTERIZE RENDER
scene=$ROOT/scenes/sphere.scene
no_parts() { [ -z "$(ls -A "$1" | grep parts)" ] || fail "parts left in $1: $(ls -A "$1")"; }

# 5 shards, 2 at a time, merge to the bytes of one whole run.
"$BIN/rasterize" "$scene" -o "$T/whole.oct" --levels 7 -q || fail "whole rasterize"
expect_exit 0 sh "$F/parallel-rasterize.sh" "$scene" "$T/s5.oct" --levels 7 --shards 5 --jobs 2
cmp "$T/whole.oct" "$T/s5.oct" >&2 || fail "5 shards merged differ from the whole run"
no_parts "$T"

# One shard; parts in --tmpdir; options after -- reach parallel (its job log).
mkdir "$T/tmp"
expect_exit 0 sh "$F/parallel-rasterize.sh" "$scene" "$T/s1.oct" --levels 7 --shards 1 \
    --tmpdir "$T/tmp" -- --joblog "$T/jobs.log"
cmp "$T/whole.oct" "$T/s1.oct" >&2 || fail "1 shard differs from the whole run"
[ -z "$(ls -A "$T/tmp")" ] || fail "--tmpdir: parts left: $(ls -A "$T/tmp")"
[ "$(wc -l < "$T/jobs.log")" -eq 2 ] || fail "-- --joblog: $(cat "$T/jobs.log")"

# A scene every shard rejects: the first failure's status, OUT.oct as it was.
printf 'bounds 0 0 0 1 1 1\nsurface x +\n' > "$T/bad.scene"
cp "$T/whole.oct" "$T/keep.oct"
expect_exit 1 sh "$F/parallel-rasterize.sh" "$T/bad.scene" "$T/keep.oct" --levels 7 --shards 3
expect_err "$T/bad.scene:2:"
expect_err "a shard failed (exit 1)"
cmp -s "$T/whole.oct" "$T/keep.oct" || fail "a failed run changed OUT.oct"
no_parts "$T"

# Render parts: 7 views (colour and depth) as 3 parts, 2 at a time, write the
# files of one whole run, byte for byte; output paths are the views file's,
# relative to the current directory.
view="--target 0.5,0.5,0.5 --up 0,0,1 --fov 35"
: > "$T/v.views"
for i in 0 1 2 3 4 5 6; do
    printf -- '-o v%d.png --depth v%d.pfm --size %dx24 --eye %d.5,-2,1.%d %s\n' \
        "$i" "$i" $((20 + i)) "$i" "$i" "$view" >> "$T/v.views"
done
mkdir "$T/a" "$T/b" "$T/oa" "$T/ob"
(cd "$T/a" && "$BIN/render" "$T/whole.oct" --views "$T/v.views" -q) || fail "whole render"
(cd "$T/b" && sh "$F/parallel-render.sh" "$T/s5.oct" --views "$T/v.views" --parts 3 --jobs 2 -q) \
    >"$OUT" 2>"$ERR" || fail "parallel-render.sh --views"
same_dirs() {
    [ "$(ls "$1")" = "$(ls "$2")" ] || fail "$3: files $(ls "$2" | tr '\n' ' '), want $(ls "$1" | tr '\n' ' ')"
    for f in $(ls "$1"); do cmp "$1/$f" "$2/$f" >&2 || fail "$3: $f differs from the whole run"; done
}
[ "$(ls "$T/a" | wc -l)" -eq 14 ] || fail "whole render: $(ls "$T/a")"
same_dirs "$T/a" "$T/b" "views in 3 parts"

# An orbit of 5 frames as 2 parts.
"$BIN/render" "$T/whole.oct" --orbit 5 -o "$T/oa/f_%02d.png" --size 24x16 $view -q || fail "orbit"
expect_exit 0 sh "$F/parallel-render.sh" "$T/whole.oct" --orbit 5 -o "$T/ob/f_%02d.png" \
    --size 24x16 $view -q --parts 2
same_dirs "$T/oa" "$T/ob" "orbit in 2 parts"

# More parts than views: the extra parts render nothing and succeed.
mkdir "$T/c"
(cd "$T/c" && sh "$F/parallel-render.sh" "$T/s5.oct" --views "$T/v.views" --parts 9 -q) \
    >"$OUT" 2>"$ERR" || fail "parallel-render.sh --parts 9"
same_dirs "$T/a" "$T/c" "views in 9 parts"

# A part that fails stops the run with its status.
expect_exit 1 sh "$F/parallel-render.sh" "$T/none.oct" --views "$T/v.views" --parts 2
expect_err "$T/none.oct: no such readable file"
expect_exit 1 sh "$F/parallel-render.sh" "$T/s5.oct" --views "$T/none.views" --parts 2
expect_err "a part failed (exit 1)"
pass
