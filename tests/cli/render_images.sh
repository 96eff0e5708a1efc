#!/bin/sh
# render --aa, --alpha, --shadows, --ao, --ao-distance, -v: bad values (exit 2, a message,
# no output), RGBA output, per-view options in views files, the same bytes
# whatever the thread count.
. "$ROOT/tests/cli/lib.sh"
R="$BIN/render"
"$BIN/rasterize" "$ROOT/scenes/torus.scene" -o "$T/t.oct" --levels 6 -q || fail "rasterize"

bad() { # bad TEXT ARGS...: exit 2, TEXT on stderr, no image
    text=$1; shift
    expect_exit 2 "$R" "$T/t.oct" "$@"
    expect_err "$text"
    [ -e "$T/o.png" ] && fail "$*: wrote an image"
    [ -e "$T/o.ppm" ] && fail "$*: wrote an image"
    return 0
}
bad "--aa: '0'" -o "$T/o.png" --aa 0
bad "--aa: '17'" -o "$T/o.png" --aa 17
bad "--aa: 'x'" -o "$T/o.png" --aa x
bad "(1..16)" -o "$T/o.png" --aa 17
bad "--ao: '-1'" -o "$T/o.png" --ao -1
bad "--ao: '100000'" -o "$T/o.png" --ao 100000
bad "--ao: '1e9'" -o "$T/o.png" --ao 1e9
bad "--ao-distance: 0: must be in (0, 2] cube edges" -o "$T/o.png" --ao 4 --ao-distance 0
bad "--ao-distance: -0.1: must be in (0, 2] cube edges" -o "$T/o.png" --ao 4 --ao-distance -0.1
bad "--ao-distance: 2.5: must be in (0, 2] cube edges" -o "$T/o.png" --ao 4 --ao-distance 2.5
bad "--ao-distance: 'x': not a number" -o "$T/o.png" --ao 4 --ao-distance x
bad "--ao-distance: 'nan': not a number" -o "$T/o.png" --ao 4 --ao-distance nan
bad "--alpha: " -o "$T/o.ppm" --alpha
bad "--light: 0,0,0" -o "$T/o.png" --light 0,0,0
bad "--light: 'nan,0,1'" -o "$T/o.png" --light nan,0,1
bad "--light: 'inf,0,1'" -o "$T/o.png" --light inf,0,1
printf '%s\n' "-o $T/o.png --aa 2" "-o $T/o2.png --ao -3" "-o $T/o.ppm --alpha" \
    "-o $T/o3.png --ao 2 --ao-distance 3" >"$T/bad.views"
expect_exit 2 "$R" "$T/t.oct" --views "$T/bad.views"
expect_err "bad.views:2: --ao"
expect_err "bad.views:3: --alpha"
expect_err "bad.views:4: --ao-distance: 3: must be in (0, 2] cube edges"
[ -e "$T/o.png" ] && fail "a view of a bad views file was rendered"
[ -e "$T/o3.png" ] && fail "a view of a bad views file was rendered"

# a finite light whose square overflows is still a direction
expect_exit 0 "$R" "$T/t.oct" -o "$T/big.png" --size 32x32 --light 1e300,1e300,1e300 --shadows -q

# RGBA: colour type 6 in the IHDR (byte 26); RGB: 2
ctype() { od -An -tu1 -j25 -N1 "$1" | tr -d ' '; }
expect_exit 0 "$R" "$T/t.oct" -o "$T/a.png" --size 64x48 --aa 4 --alpha
[ "$(ctype "$T/a.png")" = 6 ] || fail "--alpha: not an RGBA PNG"
expect_err "supersampled"
expect_exit 0 "$R" "$T/t.oct" -o "$T/p.png" --size 64x48 --aa 4
[ "$(ctype "$T/p.png")" = 2 ] || fail "no --alpha: not an RGB PNG"

# --ao-distance: the default's own value changes nothing, a much shorter one
# changes the image (test_ao.c checks it lightens ray by ray); per view too
expect_exit 0 "$R" "$T/t.oct" -o "$T/ao.png" --size 64x48 --ao 16 -q
expect_exit 0 "$R" "$T/t.oct" -o "$T/ao8.png" --size 64x48 --ao 16 --ao-distance 0.125 -q
cmp -s "$T/ao.png" "$T/ao8.png" || fail "--ao-distance 0.125 is not the default"
expect_exit 0 "$R" "$T/t.oct" -o "$T/ao1.png" --size 64x48 --ao 16 --ao-distance 0.01 -q
cmp -s "$T/ao.png" "$T/ao1.png" && fail "--ao-distance 0.01 changed nothing"
printf '%s\n' "-o $T/vd1.png --ao 16 --ao-distance 0.01" "-o $T/vd2.png --ao 16" >"$T/d.views"
expect_exit 0 "$R" "$T/t.oct" --views "$T/d.views" --size 64x48 -q
cmp -s "$T/vd1.png" "$T/ao1.png" || fail "views: --ao-distance not per view"
cmp -s "$T/vd2.png" "$T/ao.png" || fail "views: --ao-distance leaked to the next line"

# -v: rays of each kind
expect_exit 0 "$R" "$T/t.oct" -o "$T/v.png" --size 64x48 --shadows --ao 4 -v
expect_err "primary"
expect_err "shadow"
expect_err "ao "

# the same bytes on 1 and 3 threads, every option on
for th in 1 3; do
    expect_exit 0 "$R" "$T/t.oct" -o "$T/th$th.png" --depth "$T/th$th.pfm" --size 70x50 \
        --aa 3 --alpha --shadows --ao 8 --threads "$th" -q
done
cmp -s "$T/th1.png" "$T/th3.png" || fail "image differs with the thread count"
cmp -s "$T/th1.pfm" "$T/th3.pfm" || fail "depth differs with the thread count"
# depth stays the centre ray's
expect_exit 0 "$R" "$T/t.oct" -o "$T/c.png" --depth "$T/c.pfm" --size 70x50 -q
cmp -s "$T/c.pfm" "$T/th1.pfm" || fail "--aa changed the depth image"

# per-view options: a views line's own, or the command line's
printf '%s\n' "-o $T/v1.png --aa 2 --alpha" "-o $T/v2.png --shadows --ao 2" "-o $T/v3.png" >"$T/ok.views"
expect_exit 0 "$R" "$T/t.oct" --views "$T/ok.views" --size 40x30 --aa 3
[ "$(ctype "$T/v1.png")" = 6 ] || fail "views: --alpha ignored"
[ "$(ctype "$T/v2.png")" = 2 ] || fail "views: --alpha leaked to the next line"
grep -c "supersampled" "$ERR" | grep -qx 3 || fail "views: --aa not per view"
expect_exit 0 "$R" "$T/t.oct" -o "$T/v2b.png" --size 40x30 --aa 3 --shadows --ao 2 -q
cmp -s "$T/v2.png" "$T/v2b.png" || fail "views line differs from the same command line"

# shadows under one light over many views (a shadow map of voxels, made once
# and asked where the rays start) give the images of each view alone (a
# map of coarser cells): four 88x88 views are over one pixel a voxel here,
# one is under (shadow_map_up_for)
nvox=$("$BIN/rasterize" "$ROOT/scenes/torus.scene" -o "$T/t2.oct" --levels 6 2>&1 |
    sed -n 's/.*), \([0-9]*\) voxels,.*/\1/p')
[ -n "$nvox" ] && [ "$nvox" -gt 7744 ] && [ "$nvox" -le 30976 ] ||
    fail "shadows: $nvox voxels: the views below do not choose both maps"
printf '%s\n' "-o $T/s1.png" "-o $T/s2.png --eye 2,-1.5,1" "-o $T/s3.png --exact" \
    "-o $T/s4.png --eye -1,2,1.5 --exact" >"$T/sh.views"
expect_exit 0 "$R" "$T/t.oct" --views "$T/sh.views" --size 88x88 --shadows --light 0.3,0.4,0.85 -q
for v in "1:" "2:--eye 2,-1.5,1" "3:--exact" "4:--eye -1,2,1.5 --exact"; do
    k=${v%%:*}
    # shellcheck disable=SC2086 # the view's options split into words
    expect_exit 0 "$R" "$T/t.oct" -o "$T/s${k}b.png" ${v#*:} --size 88x88 --shadows \
        --light 0.3,0.4,0.85 -q
    cmp -s "$T/s$k.png" "$T/s${k}b.png" || fail "shadows: view $k of a run differs from it alone"
done
pass
