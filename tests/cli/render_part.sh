#!/bin/sh
# render --part I/N: N parts of a --views or --orbit run write exactly the
# frames of the whole run, byte for byte; bad values are usage errors.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds -1 -1 -1 1 1 1\nsurface (sqrt(x^2+y^2)-0.6)^2+z^2-0.09\n' > "$T/t.scene"
expect_exit 0 "$BIN/rasterize" "$T/t.scene" -o "$T/t.oct" --levels 6 -q

# --orbit: 7 frames, as 1, 3 and 8 parts (parts past the last frame render nothing).
mkdir "$T/whole"
expect_exit 0 "$BIN/render" "$T/t.oct" -o "$T/whole/f_%02d.png" --orbit 7 --size 40x30 -q
for n in 1 3 8; do
    rm -rf "$T/parts"; mkdir "$T/parts"
    i=0
    while [ "$i" -lt "$n" ]; do
        expect_exit 0 "$BIN/render" "$T/t.oct" -o "$T/parts/f_%02d.png" --orbit 7 --size 40x30 \
            --part "$i/$n" --threads 1
        i=$((i + 1))
    done
    diff -r "$T/whole" "$T/parts" >/dev/null || fail "--orbit 7 as $n parts differs from the whole run"
done
# Each part writes its own frames only: part 1/3 is frames 1 and 4.
rm -rf "$T/parts"; mkdir "$T/parts"
expect_exit 0 "$BIN/render" "$T/t.oct" -o "$T/parts/f_%02d.png" --orbit 7 --size 40x30 --part 1/3 -q
[ "$(ls "$T/parts" | tr '\n' ' ')" = "f_01.png f_04.png " ] || fail "part 1/3 wrote $(ls "$T/parts")"

# --views: depth and normal images too.
cat > "$T/views" <<V
-o $T/v0.png --size 32x24
-o $T/v1.png --size 24x32 --eye 3,1,1 --depth $T/v1.pfm
-o $T/v2.png --size 16x16 --eye 1,3,2 --normals $T/v2n.png
V
expect_exit 0 "$BIN/render" "$T/t.oct" --views "$T/views" -q
mkdir "$T/keep"; mv "$T"/v0.png "$T"/v1.png "$T"/v1.pfm "$T"/v2.png "$T"/v2n.png "$T/keep/"
for i in 0 1; do
    expect_exit 0 "$BIN/render" "$T/t.oct" --views "$T/views" --part "$i/2" -q
done
for f in v0.png v1.png v1.pfm v2.png v2n.png; do
    cmp -s "$T/$f" "$T/keep/$f" || fail "--views as 2 parts: $f differs"
done

# Bad values: usage errors, nothing written.
rm -rf "$T/parts"; mkdir "$T/parts"
for bad in 3/3 -1/4 0/0 x/y 1 1/ /2 1/2/3; do
    expect_exit 2 "$BIN/render" "$T/t.oct" -o "$T/parts/f_%02d.png" --orbit 3 --part "$bad"
    expect_err "render: --part: '$bad':"
done
expect_exit 2 "$BIN/render" "$T/t.oct" -o "$T/parts/f_%02d.png" --orbit 3 --part
expect_err "option '--part' needs a value"
expect_exit 2 "$BIN/render" "$T/t.oct" -o "$T/parts/one.png" --part 0/2
expect_err "render: --part needs --views or --orbit"
[ -z "$(ls "$T/parts")" ] || fail "a bad --part wrote $(ls "$T/parts")"
# A views file that fails leaves nothing, whatever the part.
printf -- '-o %s --size 0x1\n' "$T/parts/bad.png" > "$T/bad.views"
expect_exit 2 "$BIN/render" "$T/t.oct" --views "$T/bad.views" --part 0/2
[ -z "$(ls "$T/parts")" ] || fail "a bad views file wrote $(ls "$T/parts")"
pass
