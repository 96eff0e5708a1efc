# plots.gp: the benchmark's plots from the CSV files in `res` (PNG).
#   gnuplot -e "res='bench/results'" bench/plots.gp
set datafile separator ","
set terminal pngcairo size 900,600 noenhanced font ",10"
set key outside right top
set grid
rend = res."/render.csv"
rast = res."/rasterize.csv"
# rows of one series, so that its points join into a line
sel(f, s, extra) = sprintf("< awk -F, '$6 == \"%s\" %s' %s", s, extra, f)
std(m) = sprintf("&& $8 == \"std\" && $10 == \"%s\"", m)
scenes = system("cut -d, -f6 ".rast." | tail -n +2 | uniq | tr '\\n' ' '")
slope(c, s) = system("awk -F, -v c=".c." -v min=8 -f bench/slopes.awk ".rast." | awk '$1 == \"".s."\" { print $2 }'")

# 1. depth error against render time, standard view, one point per level
set output res."/error_vs_time.png"
set title "Mean |depth error| against render time (standard view, one point per octree level, blobs_a's labelled)"
set xlabel "render time per frame (ms)"
set ylabel "mean |depth error| (voxels of that level)"
set logscale xy
plot for [i = 1:words(scenes)] sel(rend, word(scenes, i), std("plain")) using 11:13 \
        with linespoints linecolor i title word(scenes, i)." (entry point)", \
     for [i = 1:words(scenes)] sel(rend, word(scenes, i), std("refine")) using 11:13 \
        with linespoints linecolor i dashtype 2 title word(scenes, i)." (--refine)", \
     sel(rend, "blobs_a", std("plain")) using 11:13:7 with labels offset 0,0.8 notitle

# 2. the same with the 99th percentile
set output res."/p99_vs_time.png"
set title "99th percentile |depth error| against render time (standard view)"
set ylabel "p99 |depth error| (voxels)"
plot for [i = 1:words(scenes)] sel(rend, word(scenes, i), std("plain")) using 11:14 \
        with linespoints linecolor i title word(scenes, i)." (entry point)", \
     for [i = 1:words(scenes)] sel(rend, word(scenes, i), std("refine")) using 11:14 \
        with linespoints linecolor i dashtype 2 title word(scenes, i)." (--refine)"

# 3. rasterize time and file size against the grid side 2^levels, log-log
set xlabel "grid side 2^levels"
set logscale x 2
set output res."/rasterize_time.png"
set title "rasterize time against grid side (slope: least squares over levels >= 8; 2 = surface, 3 = volume)"
set ylabel "seconds"
plot for [s in scenes] sel(rast, s, "") using (2**$7):8 with linespoints \
        title sprintf("%s (slope %s)", s, slope(8, s))
set output res."/rasterize_bytes.png"
set title "file size against grid side (slope fitted over levels >= 8)"
set ylabel "bytes"
plot for [s in scenes] sel(rast, s, "") using (2**$7):11 with linespoints \
        title sprintf("%s (slope %s)", s, slope(11, s))
