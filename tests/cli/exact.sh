#!/bin/sh
# render --exact end to end: on the command line and in views lines, with
# the beam and without (same image), on a full and a shell-only file (same
# image: only the function places the hits, and these tapes are too short
# for a model to start at a stored plane, RENDER.md); a 1.0 file (no stored
# function) is refused with the contract's message and writes nothing.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\ncolor 0.9 0.4 0.2\nsurface z - 0.3 - 0.1*x\n' \
    > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/full.oct" --levels 7 -q || fail "rasterize"
"$BIN/rasterize" "$T/s.scene" -o "$T/shell.oct" --levels 7 --shell-only -q || fail "rasterize --shell-only"

V="--size 48x40 --eye 2.2,1.6,1.9 --target 0.5,0.5,0.5"
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/a.png" --depth "$T/a.pfm" --normals "$T/a.n.pfm" $V --exact -q
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/b.png" --depth "$T/b.pfm" --normals "$T/b.n.pfm" $V --exact --beam 0 -q
expect_exit 0 "$BIN/render" "$T/shell.oct" -o "$T/c.png" --depth "$T/c.pfm" $V --exact -q
for f in png pfm; do
    cmp -s "$T/a.$f" "$T/b.$f" || fail "--exact: the beam changed the $f"
    cmp -s "$T/a.$f" "$T/c.$f" || fail "--exact: the shell-only file gives another $f"
done
cmp -s "$T/a.n.pfm" "$T/b.n.pfm" || fail "--exact: the beam changed the normals"
# the exact depth differs from the paper's rule
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/p.png" --depth "$T/p.pfm" $V -q
cmp -s "$T/a.pfm" "$T/p.pfm" && fail "--exact depth is the paper's"

# --exact in a views line (and a line without it on a full file)
printf -- '-o %s %s --depth %s --exact\n-o %s %s --depth %s\n' "$T/v1.png" "$V" "$T/v1.pfm" \
    "$T/v2.png" "$V" "$T/v2.pfm" > "$T/views"
expect_exit 0 "$BIN/render" "$T/full.oct" --views "$T/views" -q
cmp -s "$T/v1.pfm" "$T/a.pfm" || fail "--exact in a views line"
cmp -s "$T/v2.pfm" "$T/p.pfm" || fail "a views line without --exact"
# on a shell-only file every view needs --exact
expect_exit 1 "$BIN/render" "$T/shell.oct" --views "$T/views" -q
expect_err "use --exact"
printf -- '-o %s %s --exact\n' "$T/w.png" "$V" > "$T/views2"
expect_exit 0 "$BIN/render" "$T/shell.oct" --views "$T/views2" -q
[ -s "$T/w.png" ] || fail "views --exact on a shell-only file"

# -v with --exact: the exact test's counts, some voxels tested; none without
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/v.png" $V --exact -v
grep -q '; exact: [1-9][0-9]* voxel tests ([0-9]* by bisection), [0-9]* voxels passed root-free, [0-9]* hits past their voxel$' "$ERR" \
    || fail "-v --exact lacks the exact test's counts"
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/v.png" $V -v
grep -q 'exact:' "$ERR" && fail "-v without --exact reports exact counts"

# A 1.0 file has no stored function.
OLD="$ROOT/tests/fuzz/corpus/fuzz_oct/ok-l4-v2.oct"
expect_exit 0 "$BIN/render" --info "$OLD"
grep -q '^format: *\.oct 1\.0$' "$OUT" || fail "the fixture is not a 1.0 file"
expect_exit 1 "$BIN/render" "$OLD" -o "$T/old.png" --size 8x8 --exact
expect_err "render: $OLD: no stored function (rasterize it again)"
[ -e "$T/old.png" ] && fail "a refused 1.0 file left an output"
printf -- '-o %s --size 8x8 --exact\n' "$T/old2.png" > "$T/views3"
expect_exit 1 "$BIN/render" "$OLD" --views "$T/views3"
expect_err "render: $OLD: no stored function (rasterize it again)"
[ -e "$T/old2.png" ] && fail "a refused 1.0 file left an output (views)"
grep -qF '.B \-\-exact' "$ROOT/docs/man/render.1" || fail "render.1 lacks --exact"
expect_exit 0 "$BIN/render" --help
grep -q -- "--exact" "$OUT" || fail "--help lacks --exact"
pass
