#!/bin/sh
# rasterize through its command line: exit codes, messages, atomic output.
set -u
. "$ROOT/tests/cli/lib.sh"

s="$T/s.scene"
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$s"

expect_exit 0 "$BIN/rasterize" --help
grep -q '^usage: rasterize SCENE -o OUT.oct' "$OUT" || fail "--help prints usage to stdout"
expect_exit 2 "$BIN/rasterize" "$s"
expect_err 'rasterize: missing -o OUT.oct'
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --levels 0
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --levels 21
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --levels 3x
expect_err "rasterize: --levels: '3x' is not an integer from 1 to 20"
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --threads 0
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --method newton
expect_exit 2 "$BIN/rasterize" "$s" -o "$T/a.oct" --bogus
expect_err "rasterize: unrecognized option '--bogus'"
[ -e "$T/a.oct" ] && fail "usage errors must not create the output"

# A good run, with its summary.
expect_exit 0 "$BIN/rasterize" "$s" -o "$T/a.oct" --levels 6
grep -q 'voxels' "$OUT" || fail "summary names the voxel count"
[ -s "$T/a.oct" ] || fail "output written"
cp "$T/a.oct" "$T/a.keep"

# A bad scene leaves an existing output byte-identical and adds no file.
printf 'bounds 0 0 0 1 1 1\nsurface x +* y\n' > "$T/bad.scene"
before=$(ls "$T" | wc -l)
expect_exit 1 "$BIN/rasterize" "$T/bad.scene" -o "$T/a.oct" --levels 6
expect_err "$T/bad.scene:2:"
cmp -s "$T/a.oct" "$T/a.keep" || fail "bad scene changed the output"
[ "$(ls "$T" | wc -l)" -eq "$before" ] || fail "bad scene left a file behind"
expect_exit 1 "$BIN/rasterize" "$T/missing.scene" -o "$T/a.oct"
expect_exit 1 "$BIN/rasterize" "$T" -o "$T/a.oct"

# Unwritable destination.
expect_exit 1 "$BIN/rasterize" "$s" -o "$T/no/such/dir/a.oct" --levels 4 -q
expect_err "rasterize: $T/no/such/dir/a.oct: No such file or directory"

# Fault loop: fail the Nth write/fsync/close/rename, once and from N on. Each
# failure exits 1 naming the path and the reason, leaves the old file intact
# and no temporary behind; the loop ends when the run succeeds.
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.16\n' > "$T/s2.scene"
for op in write fsync close rename; do
    for mode in "" ":sticky"; do
        n=1
        while :; do
            spec="$op:$n:ENOSPC$mode"
            if ATOMIC_FAULT="$spec" "$BIN/rasterize" "$T/s2.scene" -o "$T/a.oct" --levels 6 -q \
                   >"$OUT" 2>"$ERR"; then
                break
            fi
            grep -q "rasterize: $T/a.oct: .*No space left on device" "$ERR" \
                || fail "$spec: message: $(cat "$ERR")"
            cmp -s "$T/a.oct" "$T/a.keep" || fail "$spec: old file changed"
            ls "$T" | grep -q '\.tmp\.' && fail "$spec: temporary file left"
            n=$((n + 1))
            [ "$n" -le 64 ] || fail "$spec: never succeeded"
        done
        cmp -s "$T/a.oct" "$T/a.keep" && fail "$op$mode: final run did not replace the file"
        cp "$T/a.keep" "$T/a.oct"
    done
done

# Output is identical whatever the thread count.
"$BIN/rasterize" "$T/s2.scene" -o "$T/t1.oct" --levels 7 --threads 1 -q || fail "threads 1"
"$BIN/rasterize" "$T/s2.scene" -o "$T/t2.oct" --levels 7 --threads 2 -q || fail "threads 2"
cmp -s "$T/t1.oct" "$T/t2.oct" || fail "thread count changed the output"

# ... and wherever the voxel records wait: a scratch file in $TMPDIR, or
# memory when there is no such directory; no scratch file is left behind.
mkdir "$T/spool"
TMPDIR="$T/spool" "$BIN/rasterize" "$T/s2.scene" -o "$T/t3.oct" --levels 7 -q || fail "spooled"
TMPDIR="$T/none" "$BIN/rasterize" "$T/s2.scene" -o "$T/t4.oct" --levels 7 -q || fail "no TMPDIR"
cmp -s "$T/t1.oct" "$T/t3.oct" || fail "the spool changed the output"
cmp -s "$T/t1.oct" "$T/t4.oct" || fail "the memory fallback changed the output"
[ -z "$(ls -A "$T/spool")" ] || fail "scratch file left in TMPDIR"
# (with several surfaces their indices wait there too; --shell-only keeps
# only those)
for flag in "" --shell-only; do
    "$BIN/rasterize" "$ROOT/scenes/multi.scene" -o "$T/m1.oct" --levels 7 -q $flag \
        || fail "multi $flag"
    TMPDIR="$T/spool" "$BIN/rasterize" "$ROOT/scenes/multi.scene" -o "$T/m2.oct" --levels 7 -q \
        $flag || fail "multi $flag: spooled"
    cmp -s "$T/m1.oct" "$T/m2.oct" || fail "multi $flag: the spool changed the output"
done
[ -z "$(ls -A "$T/spool")" ] || fail "scratch file left in TMPDIR (several surfaces)"

# ... and whatever build of the lane evaluators runs (AVX2 where the
# processor has it, or the portable one): levels 8, where the voxels'
# re-tests run on lanes, on scenes with and without kinks and several
# surfaces.
for sc in blobs_a csg gyroid_ball multi heart; do
    "$BIN/rasterize" "$ROOT/scenes/$sc.scene" -o "$T/d.oct" --levels 8 -q || fail "$sc: default path"
    DDA_SIMD=portable "$BIN/rasterize" "$ROOT/scenes/$sc.scene" -o "$T/p.oct" --levels 8 -q \
        || fail "$sc: portable path"
    cmp -s "$T/d.oct" "$T/p.oct" || fail "$sc: the lane evaluators' build changed the output"
done
pass
