#!/bin/sh
# render end to end on a real rasterized file: outputs, PFM layout, thread
# independence, views files, orbits, and failures that leave nothing behind.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\ncolor 0.9 0.4 0.2\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 7 -q || fail "rasterize"
view="--eye 2.2,1.6,1.9 --target 0.5,0.5,0.5 --up 0,0,1 --fov 30"

# One view with every output; the PFM is exactly W x H little-endian floats.
expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/a.png" --size 33x17 $view \
    --depth "$T/a.pfm" --normals "$T/n.png"
expect_err "33x17"
for f in a.png n.png a.pfm; do [ -s "$T/$f" ] || fail "$f not written"; done
[ "$(head -c 8 "$T/a.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "PNG signature"
[ "$(head -c 14 "$T/a.pfm")" = "$(printf 'Pf\n33 17\n-1.0\n')" ] || fail "PFM header"
[ "$(wc -c < "$T/a.pfm")" -eq $((14 + 33 * 17 * 4)) ] || fail "PFM size"

# The centre pixel of a centred view hits the sphere at its exact distance
# (entry of the first voxel: within one voxel edge, 1/128, of the sphere).
expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/c.png" --size 1x1 --eye 0.5,0.5,3 \
    --target 0.5,0.5,0.5 --up 0,1,0 --depth "$T/c.pfm"
t=$(tail -c 4 "$T/c.pfm" | od -An -tf4 | tr -d ' ')
awk -v t="$t" 'BEGIN { exit !(t > 2.2 - 1/128 && t <= 2.2 + 1e-6) }' || fail "centre depth $t, want 2.2"

# Byte-identical whatever the thread count.
"$BIN/render" "$T/s.oct" -o "$T/t1.png" --size 64x48 $view --depth "$T/t1.pfm" --threads 1 -q
"$BIN/render" "$T/s.oct" -o "$T/t3.png" --size 64x48 $view --depth "$T/t3.pfm" --threads 3 -q
cmp -s "$T/t1.png" "$T/t3.png" && cmp -s "$T/t1.pfm" "$T/t3.pfm" || fail "thread count changed the image"

# The beam test only skips what no ray can hit: the same bytes with it off,
# at the default and at odd block sizes, plain and refined.
for flags in "" "--refine"; do
    "$BIN/render" "$T/s.oct" -o "$T/b0.png" --size 71x53 $view --depth "$T/b0.pfm" --beam 0 $flags -q
    for b in 16 5 32; do
        "$BIN/render" "$T/s.oct" -o "$T/b.png" --size 71x53 $view --depth "$T/b.pfm" --beam $b $flags -q
        cmp -s "$T/b0.png" "$T/b.png" && cmp -s "$T/b0.pfm" "$T/b.pfm" || fail "--beam $b $flags changed the image"
    done
done
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/x.png" --beam 33
expect_err "--beam: '33'"
[ ! -e "$T/x.png" ] || fail "--beam 33 wrote a file"

# A views file renders every line from one mapping.
printf '# two views\n-o %s/v1.png --size 16x16\n\n-o %s/v2.png --eye 0.5,-3,0.5 --depth %s/v2.pfm\n' \
    "$T" "$T" "$T" > "$T/v.views"
expect_exit 0 "$BIN/render" "$T/s.oct" --views "$T/v.views" -q
for f in v1.png v2.png v2.pfm; do [ -s "$T/$f" ] || fail "views: $f missing"; done

# An orbit names its frames from the pattern.
mkdir "$T/orbit"
expect_exit 0 "$BIN/render" "$T/s.oct" --orbit 3 -o "$T/orbit/f_%02d.png" --size 8x8 $view -q
[ "$(ls "$T/orbit")" = "$(printf 'f_00.png\nf_01.png\nf_02.png')" ] || fail "orbit frames: $(ls "$T/orbit")"

# A corrupt file is refused before any output, with where it is damaged.
head -c 300 "$T/s.oct" > "$T/cut.oct"
expect_exit 1 "$BIN/render" "$T/cut.oct" -o "$T/x.png"
expect_err "render: $T/cut.oct: corrupt: "
[ -e "$T/x.png" ] && fail "corrupt input left an output"
expect_exit 1 "$BIN/render" "$T/missing.oct" -o "$T/x.png"
expect_err "render: $T/missing.oct: No such file or directory"
expect_exit 1 "$BIN/render" "$T" -o "$T/x.png"

# An unwritable output fails cleanly and leaves no temporary file.
expect_exit 1 "$BIN/render" "$T/s.oct" -o "$T/no/dir/x.png" --size 8x8
expect_err "$T/no/dir/x.png"
ATOMIC_FAULT=write:1:ENOSPC "$BIN/render" "$T/s.oct" -o "$T/a.png" --size 8x8 >"$OUT" 2>"$ERR" \
    && fail "a failed write must fail the run"
grep -q "No space left on device" "$ERR" || fail "ENOSPC reported: $(cat "$ERR")"
ls "$T" | grep -q '\.tmp\.' && fail "temporary file left"
[ "$(head -c 8 "$T/a.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "old PNG damaged"

# --info summarises the file.
expect_exit 0 "$BIN/render" --info "$T/s.oct"
grep -q 'levels: *7' "$OUT" || fail "--info levels"
pass
