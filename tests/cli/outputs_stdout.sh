#!/bin/sh
# Write errors on stdout are failures: --help, --version, --info and the
# rasterize summary into a full device exit 1 with a message.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface x-0.5\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 3 -q || fail "rasterize"
full() { "$@" >/dev/full 2>"$ERR"; }
for prog in render rasterize; do
    for opt in --help --version; do
        full "$BIN/$prog" $opt; st=$?
        [ "$st" -eq 1 ] || fail "$prog $opt >/dev/full: exit $st, want 1"
        expect_err "$prog: standard output: No space left on device"
    done
done
full "$BIN/render" --info "$T/s.oct"; st=$?
[ "$st" -eq 1 ] || fail "render --info >/dev/full: exit $st, want 1"
expect_err "render: standard output: No space left on device"
full "$BIN/rasterize" "$T/s.scene" -o "$T/t.oct" --levels 3; st=$?
[ "$st" -eq 1 ] || fail "rasterize's summary >/dev/full: exit $st, want 1"
expect_err "rasterize: standard output: No space left on device"
# The same commands into a working stdout still succeed.
expect_exit 0 "$BIN/render" --info "$T/s.oct"
[ -s "$OUT" ] || fail "--info printed nothing"
expect_exit 0 "$BIN/rasterize" --version
pass
