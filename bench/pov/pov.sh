#!/bin/sh
# pov.sh: the POV-Ray peer: our scenes and camera as POV-Ray isosurfaces.
#   pov.sh check TOOLS_DIR           the camera mapping on an off-centre sphere
#   pov.sh render TOOLS_DIR SCENE OUT.png WxH EYE TARGET UP FOV MAXGRAD ACCURACY
#                                    flat silhouette; prints wall seconds
# Needs povray (Debian's povray, 3.7). Run from the repository root.
set -eu
D=$(dirname "$0")
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT

now() { date +%s.%N; }

camera() { # W H EYE TARGET UP FOV
    awk -v w="$1" -v hgt="$2" -v eye="$3" -v target="$4" -v up="$5" -v fov="$6" \
        -f "$D/camera.awk"
}


povrun() { # POV OUT W H: quiet, no display, no antialiasing, all cores;
    # run in the include's folder (POV-Ray restricts reading elsewhere)
    (cd "$(dirname "$1")" && povray +I"$(basename "$1")" +O"$2" +W"$3" +H"$4" -D -V -GA +FN -A +WT"$(nproc)") >"$T/log" 2>&1 ||
        { cat "$T/log" >&2; echo "pov.sh: povray failed on $1" >&2; exit 1; }
}

case ${1:-} in
check)
    TOOLS=$2
    eye=2.2,1.6,1.9 target=0.5,0.5,0.5 up=0,0,1 fov=30 w=160 h=120
    # a sphere of radius 0.03 on the ray of pixel (50, 30), 2.5 from the eye
    c=$(awk -v eye=$eye -v target=$target -v up=$up -v fov=$fov -v w=$w -v hgt=$h 'BEGIN {
        split(eye, E, ","); split(target, T, ","); split(up, U, ",")
        for (a = 1; a <= 3; a++) F[a] = T[a] - E[a]
        n = sqrt(F[1]^2 + F[2]^2 + F[3]^2); for (a = 1; a <= 3; a++) F[a] /= n
        R[1] = F[2]*U[3] - F[3]*U[2]; R[2] = F[3]*U[1] - F[1]*U[3]; R[3] = F[1]*U[2] - F[2]*U[1]
        n = sqrt(R[1]^2 + R[2]^2 + R[3]^2); for (a = 1; a <= 3; a++) R[a] /= n
        V[1] = R[2]*F[3] - R[3]*F[2]; V[2] = R[3]*F[1] - R[1]*F[3]; V[3] = R[1]*F[2] - R[2]*F[1]
        hh = sin(fov * 3.141592653589793 / 360) / cos(fov * 3.141592653589793 / 360)
        u = (2 * 50.5 / w - 1) * hh * w / hgt; v = (1 - 2 * 30.5 / hgt) * hh
        for (a = 1; a <= 3; a++) d[a] = F[a] + u * R[a] + v * V[a]
        n = sqrt(d[1]^2 + d[2]^2 + d[3]^2)
        printf "%.12f %.12f %.12f", E[1] + 2.5*d[1]/n, E[2] + 2.5*d[2]/n, E[3] + 2.5*d[3]/n }')
    set -- $c
    printf 'bounds -1 -1 -1 3 3 3\nsurface (x-%s)^2+(y-%s)^2+(z-%s)^2-0.03^2\n' "$1" "$2" "$3" >"$T/s.scene"
    camera $w $h $eye $target $up $fov >"$T/camera.inc"
    "$TOOLS/scene2pov" "$T/s.scene" --max-gradient 10 --accuracy 1e-6 >"$T/s.pov"
    povrun "$T/s.pov" "$T/s.png" $w $h
    "$TOOLS/refcast" "$T/s.scene" --depth "$T/s.pfm" --size ${w}x$h --eye $eye --target $target \
        --up $up --fov $fov -q
    r=$("$TOOLS/imgcompare" --mask "$T/s.png" "$T/s.pfm")
    echo "pov.sh: camera check (off-centre sphere at pixel 50,30 of 160x120): $r"
    case $r in
    *"both hit 0;"*) echo "pov.sh: camera check failed: no pixel in common" >&2; exit 1 ;;
    *"disagree 0.0000%"*) ;;
    *) echo "pov.sh: camera check failed: the sphere lands elsewhere" >&2; exit 1 ;;
    esac ;;
render)
    TOOLS=$2 scene=$3 out=$4 size=$5 eye=$6 target=$7 up=$8 fov=$9; shift 9; maxgrad=$1 acc=$2
    w=${size%x*} h=${size#*x}
    out=$(cd "$(dirname "$out")" && pwd)/$(basename "$out") # povrun changes folder
    camera "$w" "$h" "$eye" "$target" "$up" "$fov" >"$T/camera.inc"
    "$TOOLS/scene2pov" "$scene" --max-gradient "$maxgrad" --accuracy "$acc" >"$T/s.pov"
    t0=$(now)
    povrun "$T/s.pov" "$out" "$w" "$h"
    t1=$(now)
    awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f\n", b - a }' ;;
*)
    sed -n '2,6s/^# \{0,1\}//p' "$0" >&2; exit 2 ;;
esac
