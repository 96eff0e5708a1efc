#!/bin/sh
# rasterize --shard I/N: bad values are usage errors that write nothing; a
# shard is a valid file that renders on its own; its summary names its piece.
set -u
. "$ROOT/tests/cli/lib.sh"

s="$T/s.scene"
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$s"

for bad in 3/3 -1/4 0/0 x/y 1 2/ /2 1/2/3 0/4097; do
    expect_exit 2 "$BIN/rasterize" "$s" -o "$T/p.oct" --levels 6 --shard "$bad"
    expect_err "rasterize: --shard: '$bad' is not I/N with 0 <= I < N <= 4096"
done
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/p.oct" --shard
expect_err "option '--shard' needs a value"
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/p.oct" --shard 0/2 --merge
expect_err "rasterize: --merge and --shard do not go together"
[ -e "$T/p.oct" ] && fail "usage errors must not create the output"

# Shards of a 3-way split: each valid, each renders, together all the voxels
# (levels 9: the partition's depth 4 lies above this smooth scene's five
# mean-value levels).
total=0
for i in 0 1 2; do
    expect_exit 0 "$BIN/rasterize" "$s" -o "$T/p$i.oct" --levels 9 --shard "$i/3"
    grep -q "^rasterize: shard $i/3: cells \[[0-9]*, [0-9]*) of depth 4, " "$OUT" \
        || fail "shard summary: $(cat "$OUT")"
    n=$(sed -n 's/.* levels 9 (512^3), \([0-9]*\) voxels,.*/\1/p' "$OUT")
    [ -n "$n" ] || fail "no voxel count in: $(cat "$OUT")"
    total=$((total + n))
    expect_exit 0 "$BIN/render" "$T/p$i.oct" -o "$T/p$i.png" --size 32x32 -q
done
expect_exit 0 "$BIN/rasterize" "$s" -o "$T/whole.oct" --levels 9
whole=$(sed -n 's/.* levels 9 (512^3), \([0-9]*\) voxels,.*/\1/p' "$OUT")
[ "$total" -eq "$whole" ] || fail "shards hold $total voxels, the whole run $whole"
pass
