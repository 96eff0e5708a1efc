#!/bin/sh
# Unbounded inputs around the outputs: views files within their limits (size,
# line length, no NUL byte), --orbit names within the file-name limits, and
# output names up to NAME_MAX bytes working (the temporary's name shortened).
set -u
. "$ROOT/tests/cli/lib.sh"

printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' > "$T/s.scene"
"$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 5 -q || fail "rasterize"

# An endless views file stops at the limit (it once read 3.9 GB).
expect_exit 2 timeout 30 "$BIN/render" "$T/s.oct" --views /dev/zero -q
expect_err "/dev/zero:1:1: file larger than 16777216 bytes"
expect_exit 2 timeout 30 "$BIN/render" "$T/s.oct" --views /dev/urandom -q
# A NUL byte is reported where it is and hides nothing after it.
printf -- '-o %s/a.png\n-o %s/b\000.png\n-o\n' "$T" "$T" > "$T/nul.views"
expect_exit 2 "$BIN/render" "$T/s.oct" --views "$T/nul.views" -q
expect_err "nul.views:2:$(( ${#T} + 6 )): NUL byte"
[ -e "$T/a.png" ] && fail "a views file with a NUL byte rendered a view"
# A line over the limit.
awk 'BEGIN { printf "-o x.png --fov 30"; for (i = 0; i < 70000; i++) printf " "; print "" }' > "$T/long.views"
expect_exit 2 "$BIN/render" "$T/s.oct" --views "$T/long.views" -q
expect_err "long.views:1:65537: line longer than 65536 bytes"

# --orbit: a width no file name can hold is refused at once (it once spun
# in snprintf), a name over the limits too, before any frame is written.
expect_exit 2 timeout 10 "$BIN/render" "$T/s.oct" --orbit 3 -o "$T/f%2147483647d.png" -q
expect_err "field width is over 255"
expect_exit 2 timeout 10 "$BIN/render" "$T/s.oct" --orbit 3 -o "$T/f%99999999999999999999d.png" -q
long=$(awk 'BEGIN { for (i = 0; i < 300; i++) printf "n" }')
expect_exit 1 "$BIN/render" "$T/s.oct" --orbit 3 -o "$T/$long%d.png" --size 8x8 -q
expect_err "name too long"
ls "$T" | grep -q '\.png' && fail "an orbit with a bad name wrote a frame"

# A 254- and a 255-byte name work: the temporary's name is shortened.
for n in 250 251; do
    name=$(awk -v n=$n 'BEGIN { for (i = 0; i < n; i++) printf "a" }').png
    expect_exit 0 "$BIN/render" "$T/s.oct" -o "$T/$name" --size 8x8 -q
    [ -s "$T/$name" ] || fail "$((n + 4))-byte name not written"
    expect_exit 0 "$BIN/rasterize" "$T/s.scene" -o "$T/${name%.png}.oct" --levels 3 -q
    [ -s "$T/${name%.png}.oct" ] || fail "$((n + 4))-byte .oct name not written"
done
ls "$T" | grep -q '\.tmp\.' && fail "temporary file left"
pass
