#!/bin/sh
# shard.sh: sharded rasterization on this machine against one whole run.
#   bench/shard.sh [SCENE [LEVELS [N]]]      (default blobs_a 12 64)
# Runs the whole file once (--threads JOBS), then the N shards JOBS at a
# time (--threads 1 each) and the merge, checks the merged file is the whole
# run's byte for byte, and writes:
#   $RES/shard.csv        one row per shard: estimated share of the work,
#                         wall and CPU (user + system) seconds, voxels, bytes,
#                         peak RSS
#   $RES/shard_scale.csv  makespan of the measured shard CPU times on 1, 2, 4, ...
#                         N workers (longest processing time first) and the
#                         speed-up over one worker
#   $RES/shard_summary.txt  overhead ratio, merge MB/s, balance, estimate error
#   $RES/shard_scale.png  the speed-up plot (when gnuplot is installed)
# Knobs (environment): BIN (bin), RES (bench/results), WORK (build/bench/shard), JOBS (2).
# On a shared machine wall times include other people's work: the summary
# gives CPU times beside them, and the projection uses CPU times.
set -eu
SCENE=${1:-blobs_a} LEVELS=${2:-12} N=${3:-64}
BIN=${BIN:-bin} RES=${RES:-bench/results} WORK=${WORK:-build/bench/shard} JOBS=${JOBS:-2}
D=$(dirname "$0")
S=scenes/$SCENE.scene
[ -x "$BIN/rasterize" ] || { echo "shard: $BIN/rasterize missing: run 'make' first" >&2; exit 1; }
[ -f "$S" ] || { echo "shard: no scene $S" >&2; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK" "$RES"
now() { date +%s.%N; }
echo "shard: $SCENE levels $LEVELS as $N shards, $JOBS at a time"

/usr/bin/time -f "%e %U %S %M" -o "$WORK/whole.time" \
    "$BIN/rasterize" "$S" -o "$WORK/whole.oct" --levels "$LEVELS" --threads "$JOBS" -q
read -r whole wu ws wrss <"$WORK/whole.time"

# One shard: its summary and /usr/bin/time's seconds and peak RSS, in a file.
i=0; while [ "$i" -lt "$N" ]; do echo "$i"; i=$((i + 1)); done >"$WORK/list"
export BIN S LEVELS N WORK
t2=$(now)
xargs -P "$JOBS" -I{} sh -c '/usr/bin/time -f "%e %U %S %M" -o "$WORK/{}.time" "$BIN/rasterize" "$S" \
    -o "$WORK/part{}.oct" --levels "$LEVELS" --shard "{}/$N" --threads 1 >"$WORK/{}.out"' <"$WORK/list"
t3=$(now)
parts=$(awk -v w="$WORK" '{ printf "%s/part%s.oct ", w, $1 }' "$WORK/list")
# shellcheck disable=SC2086 # the list of parts is meant to split
/usr/bin/time -f "%e %U %S %M" -o "$WORK/merge.time" "$BIN/rasterize" --merge -o "$WORK/merged.oct" $parts >"$WORK/merge.out"
t4=$(now)
read -r mwall mu ms mrss <"$WORK/merge.time"
cmp -s "$WORK/whole.oct" "$WORK/merged.oct" || { echo "shard: merged file differs from the whole run" >&2; exit 1; }

echo "shard,estimate_share,seconds,cpu_seconds,voxels,bytes,peak_rss_kib" >"$RES/shard.csv"
while read -r i; do
    share=$(sed -n 's/.* of depth [0-9]*, \([0-9.]*\)% of the estimated work.*/\1/p' "$WORK/$i.out")
    vox=$(sed -n 's/.*), \([0-9]*\) voxels, .*/\1/p' "$WORK/$i.out")
    read -r sec us ss rss <"$WORK/$i.time"
    echo "$i,$share,$sec,$(echo "$us $ss" | awk '{ printf "%.2f", $1 + $2 }'),$vox,$(wc -c <"$WORK/part$i.oct"),$rss"
done <"$WORK/list" >>"$RES/shard.csv"

# Makespan on W workers, longest processing time first, from the measured times.
awk -F, 'NR > 1 { t[n++] = $4 } END {
    for (i = 0; i < n; i++) for (j = i + 1; j < n; j++) if (t[j] > t[i]) { x = t[i]; t[i] = t[j]; t[j] = x }
    for (i = 0; i < n; i++) one += t[i]
    print "workers,makespan_s,speedup"
    for (w = 1; w <= n; w *= 2) {
        for (k = 0; k < w; k++) load[k] = 0
        for (i = 0; i < n; i++) { m = 0; for (k = 1; k < w; k++) if (load[k] < load[m]) m = k; load[m] += t[i] }
        span = 0; for (k = 0; k < w; k++) if (load[k] > span) span = load[k]
        printf "%d,%.3f,%.2f\n", w, span, one / span
    } }' "$RES/shard.csv" >"$RES/shard_scale.csv"

bytes=$(wc -c <"$WORK/merged.oct")
{
    echo "$SCENE levels $LEVELS, $N shards, $JOBS at a time, on $(nproc) cores, commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
    echo "$t2 $t3 $t4 $whole $wrss" | awk '{ s = $2 - $1; m = $3 - $2
        printf "wall: whole run %.2f s (%.1f MiB); shards %.2f s + merge %.2f s = %.2f s: %.2f x the whole run\n", $4, $5 / 1024, s, m, s + m, (s + m) / $4 }'
    awk -F, -v wu="$wu" -v ws="$ws" -v mu="$mu" -v ms="$ms" 'NR > 1 { c += $4 } END {
        printf "CPU: whole run %.2f s; shards %.2f s + merge %.2f s = %.2f s: %.2f x the whole run\n", wu + ws, c, mu + ms, c + mu + ms, (c + mu + ms) / (wu + ws) }' "$RES/shard.csv"
    echo "$mwall $bytes $mrss" | awk '{ printf "merge: %.1f MB in %.2f s, %.0f MB/s, peak RSS %.1f MiB\n", $2 / 1e6, $1, $2 / 1e6 / ($1 > 0 ? $1 : 0.01), $3 / 1024 }'
    awk -F, 'NR > 1 { t[n] = $4; e[n++] = $2; s += $4; if ($4 > mx) mx = $4; if ($7 > r) r = $7 } END {
        printf "shard CPU times: mean %.3f s, max %.3f s (%.2f x the mean); peak RSS per worker %.1f MiB at most\n", s / n, mx, mx / (s / n), r / 1024
        for (i = 0; i < n; i++) { d = 100 * t[i] / s - e[i]; ad += d < 0 ? -d : d; if ((d < 0 ? -d : d) > md) md = d < 0 ? -d : d }
        printf "estimate against measured share of the time: mean |difference| %.2f, max %.2f percentage points (1/N = %.2f)\n", ad / n, md, 100 / n }' "$RES/shard.csv"
    awk -F, 'NR > 1 { printf "%s%d workers %.2f s (%.1f x)", (NR > 2 ? "; " : "makespan: "), $1, $2, $3 } END { print "" }' "$RES/shard_scale.csv"
} | tee "$RES/shard_summary.txt"

if command -v gnuplot >/dev/null 2>&1; then
    gnuplot -e "res='$RES'" "$D/shard.gp" && echo "shard: plot in $RES/shard_scale.png"
else
    echo "shard: gnuplot not installed: no plot"
fi
rm -f "$WORK"/part*.oct
