# slopes.awk: least-squares slope of log(y) against log(2^levels) per scene
# from rasterize.csv, over levels >= min (small grids are dominated by fixed
# costs), or over all levels when fewer than two reach min; column c is y
# (8 seconds, 11 bytes). Prints "scene slope".
# Usage: awk -F, -v c=8 -v min=8 -f slopes.awk rasterize.csv
function add(k, x, y) { n[k]++; sx[k] += x; sy[k] += y; sxx[k] += x * x; sxy[k] += x * y }
function slope(k) { return (n[k] * sxy[k] - sx[k] * sy[k]) / (n[k] * sxx[k] - sx[k] * sx[k]) }
NR > 1 && $c > 0 {
    x = $7 * log(2); y = log($c); s[$6] = 1
    add($6 SUBSEP "all", x, y)
    if ($7 >= min)
        add($6 SUBSEP "min", x, y)
}
END {
    for (k in s)
        if (n[k, "min"] >= 2)
            printf "%s %.2f\n", k, slope(k SUBSEP "min")
        else if (n[k, "all"] >= 2)
            printf "%s %.2f\n", k, slope(k SUBSEP "all")
}
