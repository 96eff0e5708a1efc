#!/bin/sh
# The mapped file changes while render reads it (issue 13): truncated or
# overwritten in place, between views or in the middle of one, render says
# so and exits 1, leaving the views done before and nothing of the failed
# one; a file replaced by rename changes nothing. DDA_RENDER_HOOK (test
# builds, common/test_hooks.h) runs the change at a fixed point of a
# one-thread run: 64x64 views are 4 tiles each.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 7 -q || fail "rasterize"
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2-0.04\n' > "$T/c.scene"
"$BIN/rasterize" "$T/c.scene" -o "$T/c.oct" --levels 5 -q || fail "rasterize"
orbit="--orbit 5 --size 64x64 --threads 1 -q"
mkdir "$T/ref"
expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/ref/f%d.png" $orbit

# changed HOOK: the run fails at view 3 with the message; views 1-2 are
# written and identical to the undisturbed run; view 3 on is not; no
# temporary is left.
changed() {
    cp "$T/s.oct" "$T/v.oct"
    rm -rf "$T/o"; mkdir "$T/o"
    DDA_RENDER_HOOK="$1" timeout 60 "$BIN/render" "$T/v.oct" -o "$T/o/f%d.png" $orbit >"$OUT" 2>"$ERR"
    got=$?
    [ "$got" -eq 1 ] || fail "$1: exit $got"
    [ "$(cat "$ERR")" = "render: $T/v.oct: changed while being read" ] || fail "$1: message"
    [ "$(ls "$T/o")" = "$(printf 'f0.png\nf1.png')" ] || fail "$1: outputs $(ls "$T/o")"
    for f in f0 f1; do cmp -s "$T/o/$f.png" "$T/ref/$f.png" || fail "$1: $f.png differs"; done
}
changed "3:0:truncate -s 1000 $T/v.oct"   # between views
changed "3:0:truncate -s 0 $T/v.oct"
changed "3:1:truncate -s 1000 $T/v.oct"   # during one: the first page reads as zeros past the end
changed "3:1:truncate -s 4096 $T/v.oct"   # during one: later pages gone, SIGBUS
# Overwritten in place with other bytes of the file (shifted): foreign masks
# and bases, indices far outside the mapping, SIGSEGV during a view.
shifted="dd if=$T/s.oct bs=1 skip=3000 count=60000 2>/dev/null | dd of=$T/v.oct bs=1 seek=256 conv=notrunc 2>/dev/null"
changed "3:0:$shifted"
changed "3:0:cat $T/c.oct > $T/v.oct"     # rewritten in place, shorter
# During a view, the foreign indices make pointer arithmetic overflow, which
# UBSan without recovery (make SANITIZE=1) stops at before any fault: these
# run in the plain build only.
case $BIN in
*/build/san*) ;;
*)
    changed "3:1:$shifted"
    changed "3:2:cat $T/c.oct > $T/v.oct"
    ;;
esac

# Replaced by rename (as rasterize writes): the mapping keeps the old file.
cp "$T/s.oct" "$T/v.oct"
rm -rf "$T/o"; mkdir "$T/o"
DDA_RENDER_HOOK="2:1:cp $T/c.oct $T/n.oct && mv $T/n.oct $T/v.oct" \
    timeout 60 "$BIN/render" "$T/v.oct" -o "$T/o/f%d.png" $orbit >"$OUT" 2>"$ERR" || fail "rename: exit $?"
for k in 0 1 2 3 4; do cmp -s "$T/o/f$k.png" "$T/ref/f$k.png" || fail "rename: f$k.png differs"; done
pass
