# lib.sh (sourced by the benchmark scripts): the views of a scene, its cube's
# edge and the median of a column of numbers.

# median: the median of the numbers on stdin, one a line ("nan" when none).
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "nan";
    else if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# views SCENE: its views, one a line: NAME EYE TARGET UP (at most $NVIEWS).
# The standard view is the paper's for the unit box (eye 2.2,1.6,1.9 target
# 0.5,0.5,0.5), scaled to the cube around any other bounds; two more from
# other sides.
views() {
    awk -v n="${NVIEWS:-1}" '$1 == "bounds" {
        e = $5 - $2; if ($6 - $3 > e) e = $6 - $3; if ($7 - $4 > e) e = $7 - $4
        c1 = $2 + e / 2; c2 = $3 + e / 2; c3 = $4 + e / 2
        split("std side top", name, " ")
        split("1.7 1.1 1.4  -1.9 1.3 0.6  0.5 -0.9 2.1", o, " ")
        for (k = 0; k < n && k < 3; k++)
            printf "%s %.6g,%.6g,%.6g %.6g,%.6g,%.6g 0,0,1\n", name[k + 1],
                c1 + e * o[3*k + 1], c2 + e * o[3*k + 2], c3 + e * o[3*k + 3], c1, c2, c3
        exit }' "$1"
}

# edge SCENE: the edge of the cube around its bounds.
edge() { awk '$1 == "bounds" { e = $5 - $2; if ($6 - $3 > e) e = $6 - $3;
    if ($7 - $4 > e) e = $7 - $4; printf "%.17g\n", e; exit }' "$1"; }

# voxel SCENE LEVELS: the edge of a voxel of the octree.
voxel() { awk -v e="$(edge "$1")" -v L="$2" 'BEGIN { printf "%.17g", e / 2 ^ L }'; }

# frame_ms LOG: the per-frame times render printed, one a line.
frame_ms() { sed -n 's|^render: .*: [0-9]*x[0-9]*, \([0-9.]*\) ms,.*|\1|p' "$1"; }
