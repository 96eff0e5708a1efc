#!/bin/sh
# Messages and numbers at the edges (issue 13): the exact text of a damaged
# file's rejection, the scene limits as FILE:LINE:COL errors, the scene size
# limit, poles that are no surface, and trap mode on scenes that overflow.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 5 -q || fail "rasterize"

# A structural rejection says "corrupt:" once, with the field's offset.
cp "$T/s.oct" "$T/r.oct"
printf '\001' | dd of="$T/r.oct" bs=1 seek=100 conv=notrunc 2>/dev/null
expect_exit 1 "$BIN/render" "$T/r.oct" -o "$T/x.png"
[ "$(cat "$ERR")" = "render: $T/r.oct: corrupt: reserved field or padding not zero at offset 100" ] \
    || fail "message: $(cat "$ERR")"
head -c 300 "$T/s.oct" > "$T/cut.oct"
expect_exit 1 "$BIN/render" "$T/cut.oct" -o "$T/x.png"
grep -q "corrupt: corrupt" "$ERR" && fail "prefix twice: $(cat "$ERR")"
[ -e "$T/x.png" ] && fail "a rejected file left an output"

# bounds outside the usable range (FORMAT.md §6): a scene error at the value.
bounds_err() { # BOUNDS LEVELS MESSAGE
    printf '# limits\n  bounds %s\nsurface x\n' "$1" > "$T/b.scene"
    expect_exit 1 "$BIN/rasterize" "$T/b.scene" -o "$T/b.oct" --levels "$2" -q
    [ "$(cat "$ERR")" = "$T/b.scene:$3" ] || fail "bounds $1: $(cat "$ERR")"
    [ -e "$T/b.oct" ] && fail "bounds $1 wrote a file"
}
bounds_err '0 0 0 1e-200 1e-200 1e-200' 4 \
    "2:16: bounds: the cube's edge (1e-200, the longest side) is below the smallest, 1e-30"
bounds_err '0 0 0 1e31 1 1' 4 "2:16: bounds: the cube's edge (1e+31, the longest side) exceeds the largest, 1e+30"
bounds_err '-2e30 0 0 -1.5e30 1 1' 4 \
    "2:10: bounds: X0 (-2e+30) is farther from 0 than the largest coordinate, 1e+30"
bounds_err '1e9 0 0 1000000001 1 1' 20 \
    "2:3: bounds: at --levels 20 a voxel (9.53674e-07) is finer than 2^-48 of |X0| + edge (1e+09): use fewer levels or bounds nearer the origin"
# The smallest cube still renders.
printf 'bounds 0 0 0 1e-30 1e-30 1e-30\nsurface x+y+z-1e-30\n' > "$T/t.scene"
expect_exit 0 "$BIN/rasterize" "$T/t.scene" -o "$T/t.oct" --levels 6 -q
expect_exit 0 "$BIN/render" "$T/t.oct" -o "$T/t.png" --size 16x16 -q

# More surfaces than the format holds: the first one too many, where it is.
{ printf 'bounds 0 0 0 1 1 1\n'; i=0; while [ $i -lt 256 ]; do echo "  surface x-0.$i"; i=$((i + 1)); done; } \
    > "$T/many.scene"
expect_exit 1 "$BIN/rasterize" "$T/many.scene" -o "$T/m.oct" --levels 3 -q
[ "$(cat "$ERR")" = "$T/many.scene:257:3: surface 256: at most 255 surfaces are supported" ] \
    || fail "256 surfaces: $(cat "$ERR")"

# The scene file limit is SCENE_MAX_FILE, 64 MiB: exactly that is read, a byte more is not.
line=$(printf '#%01023d' 0)
{ printf 'bounds 0 0 0 1 1 1\nsurface x-0.5\n'; yes "$line" | head -c $((64 * 1048576 - 33)); } > "$T/big.scene"
[ "$(wc -c < "$T/big.scene")" -eq $((64 * 1048576)) ] || fail "big.scene size"
expect_exit 0 "$BIN/rasterize" "$T/big.scene" -o "$T/big.oct" --levels 2 -q
printf '\n' >> "$T/big.scene"
expect_exit 1 "$BIN/rasterize" "$T/big.scene" -o "$T/big2.oct" --levels 2 -q
[ "$(cat "$ERR")" = "$T/big.scene:1:1: file larger than 67108864 bytes (64 MiB)" ] || fail "size: $(cat "$ERR")"
rm -f "$T/big.scene"

# A pole is not a surface: no finite value anywhere keeps no voxel.
for e in '1/(x-x)' '1/(x*0)+y' 'x/(y-y)'; do
    printf 'bounds -1 -1 -1 1 1 1\nsurface %s\n' "$e" > "$T/p.scene"
    expect_exit 0 "$BIN/rasterize" "$T/p.scene" -o "$T/p.oct" --levels 6
    grep -q ' 0 voxels,' "$OUT" || fail "$e kept voxels: $(head -1 "$OUT")"
done

# Trap mode: scenes that overflow in part of their bounds (exp beyond 709)
# but are finite near their surface raise no invalid operation.
for e in 'exp(x*1000)-2' 'x*exp(x*1000)-2+y' 'exp(1000*x)/(1+exp(-1000*x))-3' 'log(1+exp(1000*y))-x'; do
    printf 'bounds -1 -1 -1 1 1 1\nsurface %s\n' "$e" > "$T/o.scene"
    DDA_FPE_TRAPS=1 timeout 60 "$BIN/rasterize" "$T/o.scene" -o "$T/o.oct" --levels 7 -q >"$OUT" 2>"$ERR" \
        || fail "trap mode: $e: exit $?"
    DDA_FPE_TRAPS=1 timeout 60 "$BIN/render" "$T/o.oct" -o "$T/o.png" --size 32x32 -q >"$OUT" 2>"$ERR" \
        || fail "trap mode render: $e: exit $?"
done
pass
