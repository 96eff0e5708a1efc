#!/bin/sh
# Numerical stress through the real programs (TESTPLAN 3.17, 5.23; issue 6):
# degenerate cameras, surfaces on voxel planes, features thinner than a
# voxel, deep levels. Every run has FE_INVALID traps on (DDA_FPE_TRAPS=1), so
# a NaN anywhere aborts with SIGFPE; every run is under `timeout`. Depth
# images are read back: only finite t >= 0 or +inf, and the hit mask agrees
# with an analytic ray test of the same shape outside a margin.
set -u
. "$ROOT/tests/cli/lib.sh"
DDA_FPE_TRAPS=1; export DDA_FPE_TRAPS

# run SECONDS CMD...: must exit 0 within SECONDS
run() {
    secs=$1; shift
    timeout "$secs" "$@" >"$OUT" 2>"$ERR"; got=$?
    [ "$got" -eq 124 ] && fail "hang (> ${secs} s): $*"
    [ "$got" -eq 0 ] || fail "exit $got: $*"
}

# pfm_values FILE W H: the floats of a W x H grey PFM, one a line, in the
# file's order (bottom row first); checks the header.
pfm_values() {
    hdr=$(head -n 3 "$1" | tr '\n' ' ')
    [ "$hdr" = "Pf $2 $3 -1.0 " ] || fail "$1: header '$hdr'"
    off=$(head -n 3 "$1" | wc -c)
    size=$(wc -c <"$1")
    [ "$size" -eq $((off + 4 * $2 * $3)) ] || fail "$1: size $size"
    od -An -v -f -w4 -j "$off" "$1" | tr -d ' '
}

# check_depth PFM W H EYE TARGET UP FOV SHAPE MARGIN [TMARGIN [HMARGIN]]
# SHAPE: "sphere cx cy cz r", "box x0 x1 y0 y1 z0 z1" (z0 = z1: a square) or
# "disc cx cy cz r" (horizontal, seen from above).
# A pixel whose ray passes inside the shape by more than MARGIN (world units)
# (or HMARGIN) must hit; one that passes outside by more than MARGIN must miss. A robust
# hit's t lies between the entry into the shape grown by MARGIN and the
# entry into the shape itself, each give or take TMARGIN (float32 depth).
check_depth() {
    pfm=$1 w=$2 h=$3 eye=$4 tgt=$5 up=$6 fov=$7 shape=$8 margin=$9
    tmargin=${10:-$9} hmargin=${11:-$9}
    pfm_values "$pfm" "$w" "$h" | awk -v W="$w" -v H="$h" -v eye="$eye" -v tgt="$tgt" \
        -v up="$up" -v fov="$fov" -v shape="$shape" -v m="$margin" -v tm="$tmargin" -v hm="$hmargin" '
    function norm(v,   l) { l = sqrt(v[1]^2 + v[2]^2 + v[3]^2); v[1] /= l; v[2] /= l; v[3] /= l }
    # entry t (>= 0) of the ray E + t D into the box S grown by g, or -1
    function slab(g,   a, lo, hi, t0, t1, ta, tb, x) {
        t0 = 0; t1 = 1e300
        for (a = 1; a <= 3; a++) {
            lo = S[2 * a]; hi = S[2 * a + 1]
            if (hi > lo || g > 0) { lo -= g; hi += g }
            if (D[a] == 0) { if (E[a] < lo || E[a] > hi) return -1; continue }
            ta = (lo - E[a]) / D[a]; tb = (hi - E[a]) / D[a]
            if (ta > tb) { x = ta; ta = tb; tb = x }
            if (ta > t0) t0 = ta
            if (tb < t1) t1 = tb
        }
        return t0 <= t1 ? t0 : -1
    }
    BEGIN {
        split(eye, E, ","); split(tgt, Tg, ","); split(up, U, ","); split(shape, S, " ")
        for (a = 1; a <= 3; a++) F[a] = Tg[a] - E[a]
        norm(F)
        R[1] = F[2] * U[3] - F[3] * U[2]; R[2] = F[3] * U[1] - F[1] * U[3]; R[3] = F[1] * U[2] - F[2] * U[1]
        norm(R)
        V[1] = R[2] * F[3] - R[3] * F[2]; V[2] = R[3] * F[1] - R[1] * F[3]; V[3] = R[1] * F[2] - R[2] * F[1]
        hh = sin(fov * 3.141592653589793 / 360) / cos(fov * 3.141592653589793 / 360)
        n = 0; bad = 0; hits = 0; must = 0
    }
    {
        val = $1
        if (val ~ /nan/ || val ~ /^-inf/ || (val !~ /inf/ && val + 0 < 0)) {
            print "pixel " n ": bad depth " val; bad++
        }
        i = n % W; j = H - 1 - int(n / W); n++
        u = (2 * (i + 0.5) / W - 1) * hh * W / H; v = (1 - 2 * (j + 0.5) / H) * hh
        for (a = 1; a <= 3; a++) D[a] = F[a] + u * R[a] + v * V[a]
        norm(D)
        hit = val !~ /inf/; hits += hit
        if (S[1] == "sphere") {
            b = 0; cc = 0
            for (a = 1; a <= 3; a++) { q = E[a] - S[a + 1]; b += q * D[a]; cc += q * q }
            # distance of the ray (t >= 0) from the centre
            tc = -b; if (tc < 0) tc = 0
            d2 = cc - 2 * tc * (-b) + tc * tc; if (d2 < 0) d2 = 0
            dist = sqrt(d2); r = S[5]
            inside = r - dist; tin = tc - sqrt(r * r - (dist < r ? dist * dist : r * r))
            rg = r + m; tlo = tc - sqrt(rg * rg - (dist < rg ? dist * dist : rg * rg))
        } else if (S[1] == "disc") {
            # horizontal disc (centre S[2..4], radius S[5]), seen from above
            inside = -1e300; tin = 0; tlo = 0
            if (D[3] < 0) {
                tin = (S[4] - E[3]) / D[3]; tlo = (S[4] + m - E[3]) / D[3]
                x = E[1] + tin * D[1] - S[2]; y = E[2] + tin * D[2] - S[3]
                inside = S[5] - sqrt(x * x + y * y)
            }
        } else {
            # box: must hit the box shrunk by m (flat axes kept), must miss
            # the box grown by m; tin from the box itself
            inside = slab(-m) >= 0 ? m + 1 : slab(m) < 0 ? -m - 1 : 0
            tin = slab(0); tlo = slab(m)
        }
        if (inside > hm) {
            must++
            if (!hit) { print "hole at pixel " i "," j " (inside by " inside ")"; bad++ }
            else if (val + 0 > tin + tm || val + 0 < tlo - tm) {
                printf "pixel %d,%d: t %s, analytic %.10g\n", i, j, val, tin; bad++
            }
        } else if (inside < -m && hit) { print "pixel " i "," j ": hit outside the shape (" inside ")"; bad++ }
    }
    END {
        if (n != W * H) { print "read " n " values"; bad++ }
        if (must == 0) { print "no pixel where the shape must be seen"; bad++ }
        if (bad) { print bad " bad pixels"; exit 1 }
    }' >"$T/check.log" 2>&1 || { head -20 "$T/check.log" >&2; fail "depth check: $pfm"; }
}

# view NAME OCT W H EYE TARGET UP FOV [extra render options]: renders NAME.pfm
view() {
    name=$1 oct=$2 w=$3 h=$4 e=$5 tg=$6 u=$7 f=$8; shift 8
    run 60 "$BIN/render" "$oct" -o "$T/$name.png" --size "${w}x$h" --eye "$e" --target "$tg" \
        --up "$u" --fov "$f" --depth "$T/$name.pfm" -q "$@"
}

# ---- A sphere at level 7 (voxel 1/128), every awkward camera -------------
printf 'bounds 0 0 0 1 1 1\nsurface (x-0.5)^2+(y-0.5)^2+(z-0.5)^2-0.09\n' >"$T/s.scene"
run 60 "$BIN/rasterize" "$T/s.scene" -o "$T/s.oct" --levels 7 -q
sph="sphere 0.5 0.5 0.5 0.3"
vm=0.03 # 2 voxel diagonals: rasterized voxels lie within sqrt(3)/128 of the surface
# odd sizes: the centre pixel's ray is exactly (0,0,-1), others have zero components
for sz in "33 33" "31 17" "1 1" "3 1"; do
    set -- $sz
    for k in 0 3 7; do
        view c "$T/s.oct" "$1" "$2" 0.5,0.5,3 0.5,0.5,0.5 0,1,0 30 --split $k
        check_depth "$T/c.pfm" "$1" "$2" 0.5,0.5,3 0.5,0.5,0.5 0,1,0 30 "$sph" $vm $vm 0.0001
    done
done
# eye on a voxel plane and on the cube's face (z = 1), on an edge and a corner,
# inside the cube (outside the sphere), inside the sphere, on a voxel corner
for e in 0.5,0.5,1 0.5,1,1 1,1,1 0,0,0 0.5,0.5,0.9 0.5,0.5,0.5 0.25,0.75,0.125 0.9,0.1,0.5; do
    view e "$T/s.oct" 21 19 "$e" 0.5,0.5,0.4 0,1,0 100
    pfm_values "$T/e.pfm" 21 19 >"$T/e.txt"
    grep -q nan "$T/e.txt" && fail "NaN depth, eye $e"
    grep -q -- '-' "$T/e.txt" && fail "negative depth, eye $e"
done
# from the cube's face looking in: the sphere straight ahead fills the middle
view f "$T/s.oct" 21 21 0.5,0.5,1 0.5,0.5,0.5 0,1,0 60
check_depth "$T/f.pfm" 21 21 0.5,0.5,1 0.5,0.5,0.5 0,1,0 60 "$sph" $vm
# eye inside the sphere's voxels' region is a hit at t = 0 or on the far wall:
# from the centre every ray hits within r + margin
view i "$T/s.oct" 15 15 0.5,0.5,0.5 0.5,0.5,1 0,1,0 120
pfm_values "$T/i.pfm" 15 15 | awk '$1 ~ /inf|nan/ || $1 > 0.33 || $1 < 0.27 { bad = 1 } END { exit bad }' \
    || fail "from the sphere's centre every ray must hit the wall at t ~ 0.3"
# eye inside an occupied voxel (on the sphere itself): trace.h's start rule,
# every ray hits that voxel at t = 0
view ov "$T/s.oct" 9 7 0.5,0.5,0.8 0.5,0.5,0.5 0,1,0 90
pfm_values "$T/ov.pfm" 9 7 | awk '$1 != 0 { bad = 1 } END { exit bad }' \
    || fail "an eye inside an occupied voxel must give t = 0 everywhere"
# far away with a tiny fov (the sphere fills about half the frame)
view far "$T/s.oct" 17 17 0.5,0.5,1000000 0.5,0.5,0.5 0,1,0 0.00005
# (t near 10^6 in float32 has an ulp of 1/16)
check_depth "$T/far.pfm" 17 17 0.5,0.5,1000000 0.5,0.5,0.5 0,1,0 0.00005 "$sph" $vm 0.1
# an eye at 1e30 and at -1e30: finite or +inf, no hang
view huge "$T/s.oct" 9 9 1e30,1e30,1e30 0.5,0.5,0.5 0,0,1 1e-20
pfm_values "$T/huge.pfm" 9 9 | grep -q nan && fail "NaN at 1e30"

# ---- Surfaces exactly on voxel planes -------------------------------------
# z = 0.5 (a voxel plane at every level) and a box whose faces are planes
printf 'bounds 0 0 0 1 1 1\nsurface z-0.5\n' >"$T/p.scene"
run 60 "$BIN/rasterize" "$T/p.scene" -o "$T/p.oct" --levels 6 -q
for k in 0 2 6; do
    view p "$T/p.oct" 25 25 0.5,0.5,2 0.5,0.5,0.5 0,1,0 50 --split $k
    check_depth "$T/p.pfm" 25 25 0.5,0.5,2 0.5,0.5,0.5 0,1,0 50 "box 0 1 0 1 0.5 0.5" 0.02 0.04
    # grazing: the eye in the plane itself, looking along it
    view g "$T/p.oct" 25 25 -1,0.5,0.5 0.5,0.5,0.5 0,0,1 50 --split $k
    pfm_values "$T/g.pfm" 25 25 | grep -q nan && fail "NaN, eye in the plane"
    # the middle row looks exactly along z = 0.5: it lies in the plane's voxels
    pfm_values "$T/g.pfm" 25 25 | sed -n '301,325p' | grep -q inf \
        && fail "rays lying in the surface plane z = 0.5 missed it (K=$k)"
done
printf 'bounds 0 0 0 1 1 1\nsurface max(abs(x-0.5),abs(y-0.5),abs(z-0.5))-0.25\n' >"$T/b.scene"
run 60 "$BIN/rasterize" "$T/b.scene" -o "$T/b.oct" --levels 5 -q
view b "$T/b.oct" 27 27 0.5,0.5,3 0.5,0.5,0.5 0,1,0 20
check_depth "$T/b.pfm" 27 27 0.5,0.5,3 0.5,0.5,0.5 0,1,0 20 "box 0.25 0.75 0.25 0.75 0.25 0.75" 0.04 0.04

# ---- Thinner than a voxel, off the grid ------------------------------------
# a disc 0.002 thick at z = 0.1 (a level-8 voxel is 0.0078), seen from above
printf 'bounds -1 -1 -1 1 1 1\nsurface max(abs(z-0.1)-0.001,x^2+y^2-0.64)\n' >"$T/d.scene"
run 60 "$BIN/rasterize" "$T/d.scene" -o "$T/d.oct" --levels 8 -q
view d "$T/d.oct" 41 41 0.013,-0.007,3 0.013,-0.007,0 0,1,0 40
check_depth "$T/d.pfm" 41 41 0.013,-0.007,3 0.013,-0.007,0 0,1,0 40 "disc 0 0 0.101 0.8" 0.03 0.03
# a shell 0.003 thick (the thin.scene one, closed) seen from outside
printf 'bounds -1 -1 -1 1 1 1\nsurface abs(sqrt(x^2+y^2+z^2)-0.5)-0.0015\n' >"$T/sh.scene"
run 60 "$BIN/rasterize" "$T/sh.scene" -o "$T/sh.oct" --levels 8 -q
view sh "$T/sh.oct" 33 33 0.01,0.02,2.5 0,0,0 0,1,0 30
check_depth "$T/sh.pfm" 33 33 0.01,0.02,2.5 0,0,0 0,1,0 30 "sphere 0 0 0 0.5015" 0.02

# ---- Scenes with poles and undefined regions -------------------------------
# The interval evaluator meets 0*inf, inf-inf and sqrt(<0) on purpose here and
# handles them by flag (common/expr/interval.h), so rasterize runs without traps;
# the renderer must still produce no NaN, with traps on.
for e in 'sqrt(x)' '1/x' '1/(x-x)' 'log(x+1)' 'sqrt(x)-0.5+0*y' 'x/(y-y)'; do
    printf 'bounds -1 -1 -1 1 1 1\nsurface %s\n' "$e" >"$T/u.scene"
    DDA_FPE_TRAPS=0 run 60 "$BIN/rasterize" "$T/u.scene" -o "$T/u.oct" --levels 6 -q
    for e2 in 2,1.5,1.2 0,0,0 0.5,0.5,-3; do
        view u "$T/u.oct" 19 19 "$e2" 0.1,0.05,0.1 0,1,0 60 --refine
        pfm_values "$T/u.pfm" 19 19 | grep -q nan && fail "NaN depth: $e, eye $e2"
    done
done

# ---- Deep levels: a sphere of radius 2^-14 (32 voxels at level 20) --------
printf 'bounds -1 -1 -1 1 1 1\nsurface (x-0.1234)^2+(y+0.05)^2+(z-0.3)^2-0.0000000037252902984619140625\n' \
    >"$T/tiny.scene"
r=0.00006103515625
for L in 16 18 20; do
    start=$(date +%s)
    run 30 "$BIN/rasterize" "$T/tiny.scene" -o "$T/t$L.oct" --levels "$L" -q
    [ $(($(date +%s) - start)) -le 10 ] || fail "level $L: rasterizing a tiny sphere took too long"
    vox=$(awk -v L="$L" 'BEGIN { printf "%.17g", 2 / 2^L }')
    m=$(awk -v v="$vox" 'BEGIN { printf "%.17g", 4 * v }')    # may be seen (voxel slack)
    hm=$(awk -v v="$vox" 'BEGIN { printf "%.17g", v / 64 }')  # must be seen: any crossing
    for k in "$L" $((L - 6)); do
        view t "$T/t$L.oct" 31 31 0.1234,-0.05,0.3006 0.1234,-0.05,0.3 0,1,0 30 --split "$k"
        check_depth "$T/t.pfm" 31 31 0.1234,-0.05,0.3006 0.1234,-0.05,0.3 0,1,0 30 "sphere 0.1234 -0.05 0.3 $r" "$m" "$m" "$hm"
        # from far away, tiny fov
        view tf "$T/t$L.oct" 23 23 0.1234,-0.05,1000 0.1234,-0.05,0.3 0,1,0 0.00001 --split "$k"
        check_depth "$T/tf.pfm" 23 23 0.1234,-0.05,1000 0.1234,-0.05,0.3 0,1,0 0.00001 "sphere 0.1234 -0.05 0.3 $r" "$m" 0.001 "$hm"
    done
done
# deeper than the format allows is refused up front
expect_exit 2 "$BIN/rasterize" "$T/tiny.scene" -o "$T/t21.oct" --levels 21
expect_err "--levels: '21' is not an integer from 1 to 20"
[ -e "$T/t21.oct" ] && fail "--levels 21 created a file"

pass
