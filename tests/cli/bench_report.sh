#!/bin/sh
# bench/report.sh writes the README's benchmark tables from fixture CSV files:
# every column where its header says (a table's rows have as many cells as
# its header), the targets marked, the text outside the markers kept; and
# bench/vline.awk reads render -v lines by name, whatever fields follow.
. "$ROOT/tests/cli/lib.sh"
R="$T/res"; mkdir -p "$R"
P="cpu,2,2026-12-01T22:17Z,abc1234,full"
H="machine,cores,date,commit,mode"
cat >"$R/images.csv" <<CSV
$H,scene,levels,size,option,ms_per_frame,time_ratio,supersampled_pct,primary_mrays_s,shadow_mrays_s,ao_mrays_s,secondary_mrays_s
$P,blobs_a,10,1024,plain,39.2,1.00,0,26.96,,,
$P,blobs_a,10,1024,aa,81.8,2.09,0.17,13.33,,,
$P,blobs_a,10,1024,shadows,71.9,1.50,0,25.57,14.1,,14.1
$P,blobs_a,10,1024,all,402.9,10.28,0.2,2.5,,,7.06
CSV
cat >"$R/rastspeed.csv" <<CSV
$H,scene,levels,seconds,voxels,mvox_s,cpu_pct,shell_only_seconds,shell_only_mvox_s,shell_only_cpu_pct,portable_mvox_s,portable_shell_only_mvox_s,portable_same
$P,gyroid,12,95.5,1000000000,10.47,190,30.1,33.2,195,9.8,26.1,1
$P,blobs_a,10,0.2,2792804,13.96,190,0.12,23.27,188,10.2,24.5,0
$P,csg,10,0.53,4446496,8.39,189,,,
CSV
cat >"$R/shell.csv" <<CSV
$H,scene,levels,kept,real,ratio,lost,voxels_near,voxels_missed,normal_mean_deg,normal_p99_deg,normal_max_deg,offset_mean_vox,offset_p99_vox,offset_max_vox
cpu,2,2026-12-05T10:00Z,def5678,full,blobs_b,9,954671,828476,1.4,0,927041,27630,0.0317,0.1719,0.5380,0.00196,0.00388,0.00594
CSV
cat >"$R/accuracy.csv" <<CSV
$H,scene,levels,size,exact_ms,depth_mean_vox,depth_p99_vox,depth_max_vox,hitmiss_frac,normal_mean_deg,normal_p99_deg,normal_max_deg,nan_pixels,refcast_ms
$P,cube,9,256,10.8,0,0,0,0,7e-07,1.2e-06,1.2e-06,0,23.7
$P,plate,10,256,15.6,0.002,0.5,1,0.001,0.1,0.2,3,2,43.1
CSV
cat >"$R/sweep.csv" <<CSV
$H,scene,levels,size,rasterize_s,exact_ms
$P,a,8,1024,0.1,300
$P,a,9,1024,0.2,200
$P,a,10,1024,0.4,250
$P,b,8,1024,0.1,100
$P,b,9,1024,0.2,150
$P,b,10,1024,0.4,120
CSV
cat >"$R/render.csv" <<CSV
$H,scene,levels,view,size,refine,ms_per_frame,mrays_s,depth_mean_vox,depth_p99_vox,depth_max_vox,hitmiss_frac,normal_mean_deg,normal_p99_deg,normal_max_deg,nan_pixels
$P,blobs_a,10,std,1024,plain,41.6,25.2,3.74,13.2,20,0.00163,0.41,2.25,3,0
$P,blobs_a,10,std,1024,exact,82.3,12.7,0,0,0,0,2e-07,2.09e-06,3e-06,0
$P,csg,10,std,1024,plain,84.7,12.4,2.13,8.67,9,0.00223,0.53,1.55,2,0
$P,csg,10,std,1024,exact,145.5,7.2,0,0,0,0,1e-07,1.21e-06,2e-06,0
CSV
cat >"$R/refcast.csv" <<CSV
$H,scene,view,size,ms,mrays_s
$P,blobs_a,std,1024,1410,0.74
$P,csg,std,1024,936,1.12
CSV
# the ratio section's alternating frames replace the main table's for blobs_a
cat >"$R/exactratio.csv" <<CSV
$H,scene,levels,size,pairs,plain_ms,exact_ms,ratio
$P,blobs_a,10,1024,9,40.0,70.0,1.750
CSV
printf 'before\n<!-- bench:begin -->\nold\n<!-- bench:end -->\nafter\n' >"$T/README.md"
expect_exit 0 sh "$ROOT/bench/report.sh" "$R" "$T/README.md"
M="$T/README.md"
has() { grep -qxF -- "$1" "$M" || fail "README lacks the line: $1"; }
[ "$(head -n 1 "$M")" = before ] && [ "$(tail -n 1 "$M")" = after ] || fail "text outside the markers changed"
grep -q '^old$' "$M" && fail "the old section stayed"
has "Measured on cpu (2 cores), 2026-12-01T22:17Z, commit abc1234 (\`make bench\`, mode full)."
has "| one ray a pixel | 10 | 1024² | 39.2 | 1.00 | 0.00 | 26.96 | - | - |"
has "| --aa 4 | 10 | 1024² | 81.8 | 2.09 ✗ (≤ 1.6) | 0.17 | 13.33 | - | - |"
has "| --shadows | 10 | 1024² | 71.9 | 1.50 ✓ (≤ 1.6) | 0.00 | 25.57 | 14.10 ✓ | - |"
has "| --aa 4 --shadows --ao 16 --exact | 10 | 1024² | 402.9 | 10.28 | 0.20 | 2.50 | - | - (shadow + AO: 7.06) |"
has "| gyroid | 12 | 95.50 | 1000000000 | 10.47 ✓ | 190 | 30.10 | 33.20 ✓ | 195 | 9.80 ✗ | 26.10 ✓ | ✓ |"
has "| blobs_a | 10 | 0.20 | 2792804 | 13.96 ✓ | 190 | 0.12 | 23.27 ✗ | 188 | 10.20 ✓ | 24.50 ✗ | ✗ |"
has "| csg | 10 | 0.53 | 4446496 | 8.39 ✗ | 189 | - | - | - | - | - | - |"
has "Runs over a minute: gyroid levels 12 96 s."
# a table from another run than the header's names its own; the others do not
has "These rows: cpu (2 cores), 2026-12-05T10:00Z, commit def5678."
[ "$(grep -c '^These rows:' "$M")" = 1 ] || fail "a table of the header's run named its run"
has "| blobs_b | 9 | 954671 | 828476 | 1.400 ✗ | 0 ✓ | 0.032 / 0.172 / 0.54 | 0.0020 / 0.0039 |"
has "| cube | 9 | 0 / 0 | 0.000 | 7e-07 / 1.2e-06 / 1.2e-06 | 0 | 10.8 | 24 | all met ✓ |"
has "| plate | 10 | 0.002 / 0.5 | 0.100 | 0.1 / 0.2 / 3 | 2 | 15.6 | 43 | ✗ mean p99 hit/miss normal NaN |"
has "| blobs_a | 10 | 1024² | 40.0 | 70.0 | 1.75 ✗ | 1.5x | 1410 | 20.1 |"
has "| csg | 10 | 1024² | 84.7 | 145.5 | 1.72 ✓ | 2x | 936 | 6.4 |"
has "| a | 300.0 | 200.0 | 250.0 | 9 |"
has "| b | 100.0 | 150.0 | 120.0 | 8 |"
grep -qF "The fastest level is 9 for a and 8 for b; at \`--levels 10\` a frame takes on average 1.23x" "$M" ||
    fail "no default level sentence"
# Shape: in each table, every row has the header's number of cells.
awk '/^\|/ { n = gsub(/\|/, "|"); if (!intable) { want = n; intable = 1 } else if (n != want) { print "row " NR ": " n " bars, header " want; bad = 1 }; next }
    { intable = 0 } END { exit bad }' "$M" || fail "a table row has the wrong number of cells"

# vline.awk: by name; a field added after the others shifts nothing.
cat >"$T/log" <<'LOG'
render: a.png: 1024x1024, 71.9 ms, 14.6 Mrays/s, 40.1% hit; primary 1.05 Mrays 25.57 Mrays/s, shadow 0.42 Mrays, ao 0.00 Mrays, 4.67 Mrays/s
render: b.png: 1024x1024, 81.8 ms, 12.8 Mrays/s, 40.1% hit, 1.20% edge pixels, 0.17% supersampled, 3 new things; primary 1.10 Mrays 13.33 Mrays/s, shadow 0.42 Mrays 9.5 Mrays/s, ao 16.8 Mrays 7.5 Mrays/s, extra 2 things
render: c.png: 8x8, 5.0 ms, 1.0 Mrays/s, 50.0% hit; primary 0.01 Mrays 2.00 Mrays/s, shadow 0.01 Mrays, ao 0.02 Mrays, 1.50 Mrays/s
render: 3 views, 2.2 Mrays in 158.7 ms, 13.9 Mrays/s, 2 threads
LOG
awk -f "$ROOT/bench/vline.awk" "$T/log" >"$OUT"
printf '%s\n' "71.9 0 25.57 4.67 - 4.67" "81.8 0.17 13.33 9.5 7.5 -" "5.0 0 2.00 - - 1.50" | cmp -s - "$OUT" ||
    { sed 's/^/  got: /' "$OUT" >&2; fail "vline.awk output"; }
pass
