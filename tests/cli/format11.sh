#!/bin/sh
# Format 1.1 end to end: rasterize stores the function; --shell-only keeps
# the tree (same nodes, voxels and surfaces, whatever the thread count) and
# drops the records; render refuses a shell-only file without --exact and a
# damaged function section, writing nothing; --info shows the 1.1 fields.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\ncolor 0.9 0.4 0.2\nsurface z - 0.3 - 0.1*x\n' \
    > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/full.oct" --levels 7 -q || fail "rasterize"
expect_exit 0 "$BIN/rasterize" "$T/s.scene" -o "$T/shell.oct" --levels 7 --shell-only --threads 1
expect_exit 0 "$BIN/rasterize" "$T/s.scene" -o "$T/shell3.oct" --levels 7 --shell-only --threads 3 -q
cmp -s "$T/shell.oct" "$T/shell3.oct" || fail "--shell-only output depends on the thread count"

expect_exit 0 "$BIN/render" --info "$T/full.oct"
grep -q '^format: *\.oct 1\.1$' "$OUT" || fail "--info format: $(cat "$OUT")"
grep -q '^flags: *none$' "$OUT" || fail "--info flags"
grep -q '^function: *2 tapes, [0-9]* instructions' "$OUT" || fail "--info function"
grep -v -e '^flags' -e '^file bytes' -e '^bytes/voxel' "$OUT" > "$T/full.info"
expect_exit 0 "$BIN/render" --info "$T/shell.oct"
grep -q '^flags: *shell-only' "$OUT" || fail "--info shell-only"
grep -v -e '^flags' -e '^file bytes' -e '^bytes/voxel' "$OUT" > "$T/shell.info"
cmp -s "$T/full.info" "$T/shell.info" || fail "--shell-only changed the tree: $(diff "$T/full.info" "$T/shell.info")"
# ... byte for byte: the NODES (entry at 136) and SURFACES (entry at 184) sections
section() { # FILE ENTRY_OFFSET -> the section's bytes on stdout
    off=$(od -An -tu8 -j "$2" -N 8 "$1" | tr -d ' '); len=$(od -An -tu8 -j $(($2 + 8)) -N 8 "$1" | tr -d ' ')
    tail -c +$((off + 1)) "$1" | head -c "$len"
}
for e in 136 184; do
    section "$T/full.oct" $e > "$T/a.sec"; section "$T/shell.oct" $e > "$T/b.sec"
    [ -s "$T/a.sec" ] && cmp -s "$T/a.sec" "$T/b.sec" || fail "--shell-only changed the section at entry $e"
done
# well under a byte a voxel: the nodes, the surface indices (two surfaces), the function
voxels=$(sed -n 's/^voxels: *//p' "$OUT")
bytes=$(wc -c < "$T/shell.oct")
[ "$bytes" -lt $((voxels * 2)) ] || fail "shell-only file of $bytes bytes for $voxels voxels"
[ "$bytes" -lt $(($(wc -c < "$T/full.oct") / 3)) ] || fail "shell-only file not smaller"

# Without --exact a shell-only file cannot be drawn.
expect_exit 1 "$BIN/render" "$T/shell.oct" -o "$T/x.png" --size 8x8
expect_err "render: $T/shell.oct: stores no normals (rasterized with --shell-only): use --exact"
[ -e "$T/x.png" ] && fail "a refused shell-only file left an output"

# A damaged function section: the first broken rule and where, nothing written.
F=$(od -An -tu8 -j 232 -N 8 "$T/full.oct" | tr -d ' ')
cp "$T/full.oct" "$T/bad.oct"
printf '\007' | dd of="$T/bad.oct" bs=1 seek="$F" conv=notrunc 2>/dev/null
expect_exit 1 "$BIN/render" "$T/bad.oct" -o "$T/x.png" --size 8x8
expect_err "render: $T/bad.oct: corrupt: function: tape count is not the surface count at offset $F"
[ -e "$T/x.png" ] && fail "a corrupt function section left an output"
# The full file still renders as before.
expect_exit 0 "$BIN/render" "$T/full.oct" -o "$T/ok.png" --size 8x8 -q
[ -s "$T/ok.png" ] || fail "full file did not render"
pass
