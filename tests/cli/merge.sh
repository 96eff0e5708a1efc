#!/bin/sh
# rasterize --merge: the shards of a split, in any order, merge into the
# whole run's file byte for byte; parts that do not belong together are
# refused by name with exit 1 and no output; no parts is a usage error.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\ncolor 1 0.5 0.25\nsurface (x-0.3)^2+(y-0.6)^2+(z-0.5)^2-0.04\n' > "$T/a.scene"
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.1\n' > "$T/b.scene"
expect_exit 0 "$BIN/rasterize" "$T/a.scene" -o "$T/whole.oct" --levels 7 -q --threads 2
for i in 0 1 2; do
    expect_exit 0 "$BIN/rasterize" "$T/a.scene" -o "$T/a$i.oct" --levels 7 -q --shard "$i/3" --threads 1
    expect_exit 0 "$BIN/rasterize" "$T/b.scene" -o "$T/b$i.oct" --levels 7 -q --shard "$i/3"
done
expect_exit 0 "$BIN/rasterize" "$T/a.scene" -o "$T/c0.oct" --levels 7 -q --shard 0/2

expect_exit 0 "$BIN/rasterize" --merge -o "$T/m.oct" "$T/a2.oct" "$T/a0.oct" "$T/a1.oct"
grep -q "^rasterize: $T/m.oct: merged 3 shards, [0-9]* bytes, .* MB/s)$" "$OUT" || fail "summary: $(cat "$OUT")"
cmp -s "$T/m.oct" "$T/whole.oct" || fail "merged file differs from the whole run"
# The parts may come before --merge too.
expect_exit 0 "$BIN/rasterize" "$T/a1.oct" "$T/a0.oct" --merge "$T/a2.oct" -o "$T/m2.oct" -q
cmp -s "$T/m2.oct" "$T/whole.oct" || fail "merged file (parts before --merge) differs"
[ -s "$OUT" ] && fail "-q printed: $(cat "$OUT")"
# --shell-only shards merge into the --shell-only whole run; mixed with full ones they are refused.
expect_exit 0 "$BIN/rasterize" "$T/a.scene" -o "$T/shell.oct" --levels 7 -q --shell-only
for i in 0 1 2; do
    expect_exit 0 "$BIN/rasterize" "$T/a.scene" -o "$T/s$i.oct" --levels 7 -q --shard "$i/3" --shell-only
done
expect_exit 0 "$BIN/rasterize" --merge -o "$T/ms.oct" "$T/s1.oct" "$T/s2.oct" "$T/s0.oct" -q
cmp -s "$T/ms.oct" "$T/shell.oct" || fail "merged shell-only file differs from the whole run"
expect_exit 1 "$BIN/rasterize" --merge -o "$T/mix.oct" "$T/a0.oct" "$T/s1.oct" "$T/a2.oct"
expect_err "rasterize: $T/s1.oct: has a different format version or flags from $T/a0.oct"
[ -e "$T/mix.oct" ] && fail "a refused merge wrote its output"
# render --info says which shard it is.
expect_exit 0 "$BIN/render" --info "$T/a1.oct"
grep -q "^shard: *1 of 3" "$OUT" || fail "--info on a shard: $(cat "$OUT")"

# Usage errors.
expect_exit 2 "$BIN/rasterize" --merge -o "$T/x.oct"
expect_err "rasterize: --merge needs the parts to merge"
expect_exit 2 "$BIN/rasterize" --merge "$T/a0.oct"
expect_err "rasterize: missing -o OUT.oct"

# Run-time refusals: exit 1, the file named, no output, an old output kept.
cp "$T/whole.oct" "$T/keep.oct"
refuse() { # WHAT PARTS...: the message must hold WHAT
    what=$1; shift
    expect_exit 1 "$BIN/rasterize" --merge -o "$T/keep.oct" "$@"
    expect_err "$what"
    cmp -s "$T/keep.oct" "$T/whole.oct" || fail "a refused merge changed the output"
    ls "$T" | grep -q '\.tmp\.' && fail "a refused merge left a temporary file"
    expect_exit 1 "$BIN/rasterize" --merge -o "$T/new.oct" "$@"
    [ -e "$T/new.oct" ] && fail "a refused merge wrote its output"
    return 0
}
refuse "rasterize: --merge: shard 1/3 is missing (2 of 3 parts given)" "$T/a0.oct" "$T/a2.oct"
refuse "rasterize: --merge: shard 0/3 is missing (1 of 3 parts given)" "$T/a1.oct"
refuse "rasterize: $T/a1.oct: is shard 1/3, as $T/a1.oct is" "$T/a0.oct" "$T/a1.oct" "$T/a1.oct" "$T/a2.oct"
refuse "rasterize: $T/b1.oct: has a different scene" "$T/a0.oct" "$T/b1.oct" "$T/a2.oct"
refuse "rasterize: $T/c0.oct: has a different partition" "$T/a1.oct" "$T/c0.oct"
refuse "rasterize: $T/whole.oct: is not a shard (a whole file)" "$T/a0.oct" "$T/whole.oct"
refuse "rasterize: $T/none.oct: open: No such file or directory" "$T/a0.oct" "$T/none.oct"
head -c 1000 "$T/a1.oct" > "$T/cut.oct"
refuse "rasterize: $T/cut.oct: truncated file" "$T/a0.oct" "$T/cut.oct" "$T/a2.oct"
printf 'not an oct file at all' > "$T/text.oct"
refuse "rasterize: $T/text.oct: not an .oct file" "$T/text.oct" "$T/a0.oct"

# Unwritable destination, and write faults: exit 1 naming the output, old file kept.
expect_exit 1 "$BIN/rasterize" --merge -o "$T/no/dir/m.oct" "$T/a0.oct" "$T/a1.oct" "$T/a2.oct"
expect_err "rasterize: $T/no/dir/m.oct: No such file or directory"
for op in write fsync rename; do
    n=1
    while :; do
        if ATOMIC_FAULT="$op:$n:ENOSPC" "$BIN/rasterize" --merge -o "$T/keep.oct" -q \
               "$T/a0.oct" "$T/a1.oct" "$T/a2.oct" >"$OUT" 2>"$ERR"; then
            break
        fi
        grep -q "rasterize: $T/keep.oct: .*No space left on device" "$ERR" || fail "$op:$n: $(cat "$ERR")"
        cmp -s "$T/keep.oct" "$T/whole.oct" || fail "$op:$n: old file changed"
        ls "$T" | grep -q '\.tmp\.' && fail "$op:$n: temporary file left"
        n=$((n + 1))
        [ "$n" -lt 200 ] || fail "$op: no end to the fault loop"
    done
    cmp -s "$T/keep.oct" "$T/whole.oct" || fail "$op: the final merge differs"
done
pass
