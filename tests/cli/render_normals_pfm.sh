#!/bin/sh
# render --normals NAME.pfm: float normals as a 3-channel PFM ("PF", w*h*3
# little-endian floats, unit length where the ray hits, 0 where it misses);
# any other name still gets the PNG.
set -u
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$BIN/rasterize" "$ROOT/scenes/sphere.scene" -o "$T/s.oct" --levels 5 -q || fail "rasterize"
"$BIN/render" "$T/s.oct" -o "$T/s.png" --size 8x6 --normals "$T/n.pfm" -q || fail "render"
[ "$(head -c 12 "$T/n.pfm" | od -An -c | tr -d ' ')" = 'PF\n86\n-1.0\n' ] || fail "header"
[ "$(wc -c <"$T/n.pfm")" -eq $((12 + 8 * 6 * 12)) ] || fail "size"
# every pixel: |n| is 1 (a hit) or 0 (a miss); the centre pixel hits
tail -c $((8 * 6 * 12)) "$T/n.pfm" | od -An -v -f -w12 | awk '
    { l = $1 * $1 + $2 * $2 + $3 * $3; if (l > 1e-6 && (l < 0.999 || l > 1.001)) bad++; if (l > 0.5) hit++ }
    END { exit !(bad == 0 && hit > 0) }' || fail "normals not unit or no hit"
"$BIN/render" "$T/s.oct" -o "$T/s.png" --size 8x6 --normals "$T/n.png" -q || fail "render png"
head -c 4 "$T/n.png" | od -An -c | grep -q 'P   N   G' || fail "PNG normals"
exit 0
