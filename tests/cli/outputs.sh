#!/bin/sh
# Outputs that never destroy what they should not: devices, FIFOs, stdout
# and symlinks written where they are; one file in two roles refused before
# any work; a view's outputs committed together; no temporary left behind by
# a file-size limit.
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 7 -q || fail "rasterize"
cp "$T/s.oct" "$T/s.orig"
png_sig=89504e470d0a1a0a
sig() { head -c 8 "$1" | od -An -tx1 | tr -d ' \n'; }
no_tmp() { ls -a "$T" | grep -q '\.tmp\.' && fail "temporary file left: $1"; true; }
# A device node must still be one. A program that replaced it (as root) has
# broken the machine's /dev/null: put the node back before failing.
still_device() {
    [ -c "$1" ] && return 0
    [ "$(id -u)" -eq 0 ] && rm -f "$1" && mknod -m 666 "$1" c 1 "$2"
    fail "$1 is no longer a character device"
}

# 1. Devices are written, never replaced (as root a rename would replace the
# node with a regular file; as a user it would fail).
expect_exit 0 "$BIN/render" "$T/s.oct" -o /dev/null --size 16x16 -q
still_device /dev/null 3
expect_exit 0 "$BIN/render" "$T/s.oct" -o /dev/null --depth /dev/null --size 16x16 -q
still_device /dev/null 3
expect_exit 0 "$BIN/rasterize" "$T/s.scene" -o /dev/null --levels 3 -q
still_device /dev/null 3
expect_exit 1 "$BIN/render" "$T/s.oct" -o /dev/full --size 16x16 -q
expect_err "render: /dev/full: write: No space left on device"
expect_exit 1 "$BIN/rasterize" "$T/s.scene" -o /dev/full --levels 3 -q
expect_err "rasterize: /dev/full: write: No space left on device"
still_device /dev/full 7

# A FIFO gets the image through it and stays a FIFO.
mkfifo "$T/pipe"
timeout 20 cat "$T/pipe" > "$T/from_pipe" &
reader=$!
expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/pipe" --size 16x16 -q
wait $reader
[ -p "$T/pipe" ] || fail "the FIFO was replaced"
[ "$(sig "$T/from_pipe")" = $png_sig ] || fail "no PNG came through the FIFO"

# '-' is stdout, for both programs.
(cd "$T" && "$BIN/render" s.oct -o - --size 16x16 -q > stdout.png) || fail "render -o -"
[ "$(sig "$T/stdout.png")" = $png_sig ] || fail "render -o - wrote no PNG"
(cd "$T" && "$BIN/rasterize" s.scene -o - --levels 4 > stdout.oct 2>"$ERR") || fail "rasterize -o -"
expect_err "rasterize: -: levels 4"  # the summary went to stderr
expect_exit 0 "$BIN/render" "$T/stdout.oct" -o "$T/from_stdout.png" --size 16x16 -q
[ -e "$T/-" ] && fail "'-' created a file named -"

# A symlinked target: the file at the end of the links is replaced, the
# links stay; a dangling link creates its file.
mkdir "$T/real"
ln -s real/img.png "$T/link.png"
expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/link.png" --size 16x16 -q
[ -L "$T/link.png" ] || fail "the symlink was replaced"
[ "$(sig "$T/real/img.png")" = $png_sig ] || fail "the link's target was not written"
ln -s real/x.oct "$T/link.oct"
expect_exit 0 "$BIN/rasterize" "$T/s.scene" -o "$T/link.oct" --levels 3 -q
[ -L "$T/link.oct" ] && [ -s "$T/real/x.oct" ] || fail "rasterize through a symlink"
no_tmp "symlinks"

# 2. One file in two roles: refused, exit 2, before any work, nothing changed.
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/s.oct" -q
expect_err "the input and -o name the same file"
cmp -s "$T/s.oct" "$T/s.orig" || fail "render replaced its input"
ln "$T/s.oct" "$T/hard.oct"
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/hard.oct" -q
ln -s s.oct "$T/soft.oct"
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/soft.oct" -q
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/../$(basename "$T")/s.oct" -q
cmp -s "$T/s.oct" "$T/s.orig" || fail "render replaced its input"
cp "$T/s.scene" "$T/scene.orig"
expect_exit 2 "$BIN/rasterize" "$T/s.scene" -o "$T/s.scene" -q
expect_err "the scene and -o name the same file"
cmp -s "$T/s.scene" "$T/scene.orig" || fail "rasterize replaced its scene"
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/x.png" --depth "$T/x.png" -q
expect_err "-o and --depth name the same file"
expect_exit 2 "$BIN/render" "$T/s.oct" -o "$T/x.png" --normals "$T/./x.png" -q
expect_err "-o and --normals name the same file"
expect_exit 2 "$BIN/render" "$T/s.oct" -o - --depth - -q
[ -e "$T/x.png" ] && fail "a refused run wrote x.png"
# two views writing one file in turn: allowed, the later view's image stays
printf -- '-o %s/v1.png\n-o %s/v2.png\n-o %s/v1.png --size 8x8\n' "$T" "$T" "$T" > "$T/views"
expect_exit 0 "$BIN/render" "$T/s.oct" --views "$T/views" -q
[ "$(od -An -tx1 -j16 -N8 "$T/v1.png" | tr -d ' ')" = 0000000800000008 ] ||
    fail "v1.png is not the 8x8 image of views line 3"
rm -f "$T/v1.png" "$T/v2.png"
# one view naming a file twice, in a views line: refused
printf -- '-o %s/v1.png --normals %s/v1.png\n' "$T" "$T" > "$T/views"
expect_exit 2 "$BIN/render" "$T/s.oct" --views "$T/views" -q
expect_err "-o (views line 1) and --normals (views line 1) name the same file"
printf -- '-o %s/v1.png --depth %s/views2\n' "$T" "$T" > "$T/views2"
expect_exit 2 "$BIN/render" "$T/s.oct" --views "$T/views2" -q
printf -- '-o %s/views3\n' "$T" > "$T/views3"
expect_exit 2 "$BIN/render" "$T/s.oct" --views "$T/views3" -q
expect_err "--views and -o (views line 1) name the same file"
[ -e "$T/v1.png" ] && fail "a refused views file wrote v1.png"

# 3. No partial set: a bad directory anywhere is found before the first
# ray; a failure while committing a view's outputs replaces none of them.
printf 'old' > "$T/a.png"
expect_exit 1 "$BIN/render" "$T/s.oct" -o "$T/a.png" --depth "$T/nodir/d.pfm" --size 16x16 -q
expect_err "$T/nodir/d.pfm: No such file or directory"
[ "$(cat "$T/a.png")" = old ] || fail "a failed run replaced a.png"
printf -- '-o %s/w1.png\n-o %s/nodir/w2.png\n' "$T" "$T" > "$T/views4"
expect_exit 1 "$BIN/render" "$T/s.oct" --views "$T/views4" --size 16x16 -q
[ -e "$T/w1.png" ] && fail "view 1 written although view 2 cannot be"
ATOMIC_FAULT=fsync:2:EIO expect_exit 1 "$BIN/render" "$T/s.oct" -o "$T/a.png" --depth "$T/a.pfm" --size 16x16 -q
[ "$(cat "$T/a.png")" = old ] || fail "a.png replaced although its --depth failed"
[ -e "$T/a.pfm" ] && fail "a.pfm written although the view failed"
no_tmp "failed commit"
# View k fails: the views before it are complete, view k and later untouched.
printf 'old' > "$T/w2.png"
printf -- '-o %s/w1.png\n-o %s/w2.png\n-o %s/w3.png\n' "$T" "$T" "$T" > "$T/views5"
ATOMIC_FAULT=rename:2:EIO expect_exit 1 "$BIN/render" "$T/s.oct" --views "$T/views5" --size 16x16 -q
[ "$(sig "$T/w1.png")" = $png_sig ] || fail "view 1 not complete"
[ "$(cat "$T/w2.png")" = old ] || fail "the failed view 2 replaced its output"
[ -e "$T/w3.png" ] && fail "view 3 written after view 2 failed"
no_tmp "failed view"

# 5. A file-size limit (SIGXFSZ) leaves no temporary behind, and the
# process still ends by that signal.
(ulimit -c 0; ulimit -f 8; exec "$BIN/rasterize" "$T/s.scene" -o "$T/big.oct" --levels 7 -q) 2>"$ERR"
st=$?
[ "$st" -gt 128 ] || fail "rasterize under a 4 kB file-size limit: exit $st, want a signal"
(ulimit -c 0; ulimit -f 1; exec "$BIN/render" "$T/s.oct" -o "$T/big.png" --size 256x256 -q) 2>"$ERR"
st=$?
[ "$st" -gt 128 ] || fail "render under a 512-byte file-size limit: exit $st, want a signal"
[ -e "$T/big.oct" ] || [ -e "$T/big.png" ] && fail "an output appeared under the limit"
no_tmp "SIGXFSZ"
pass
