# shard.gp: speed-up of a sharded rasterization against the number of
# workers, from the measured shard times (bench/shard.sh).
#   gnuplot -e "res='bench/results'" bench/shard.gp
set datafile separator ","
set terminal pngcairo size 900,600 noenhanced font ",10"
set grid
set key left top
set output res."/shard_scale.png"
set title "Sharded rasterization: makespan speed-up on W workers (measured shard CPU times, longest first)"
set xlabel "workers W"
set ylabel "speed-up over one worker"
set logscale xy 2
plot res."/shard_scale.csv" using 1:3 every ::1 with linespoints title "speed-up", \
     x with lines dashtype 2 title "ideal"
