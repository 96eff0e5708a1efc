#!/bin/sh
# Rasterizes a scene on a Slurm cluster: a job array of N shards and a merge
# job that runs once every shard has succeeded (--dependency=afterok).
set -eu
FARM_PROG=slurm-rasterize.sh FARM_KIND=rasterize FARM_ENGINE=slurm
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/slurm-lib.sh"

farm_usage() {
    cat <<'EOF'
usage: farm/slurm-rasterize.sh SCENE OUT.oct --levels L --shards N [--wait]
           [--tmpdir DIR] [--method M] [--threads T] [--shell-only] [-- sbatch options]

Submits a job array of N tasks, task I running `rasterize SCENE --levels L
--shard I/N`, and a merge job (--dependency=afterok on the array) running
`rasterize --merge` of the N parts into OUT.oct: the same bytes as
`rasterize SCENE -o OUT.oct --levels L` run whole. Prints the merge job's id
on stdout (for a later --dependency=afterok:ID).

  --levels L      octree levels (as rasterize)
  --shards N      number of shards, the array's size (>= 1)
  --wait          return when the merge has finished, with its exit status
                  (or that of the first failed shard)
  --tmpdir DIR    where the parts and the jobs' logs go, in a fresh directory
                  the merge removes once OUT.oct is written (default:
                  OUT.oct's directory); it must be on a filesystem every
                  node shares, like SCENE, OUT.oct and the programs
  --method M, --threads T, --shell-only
                  passed to every rasterize run
  -- ...          the rest goes to both sbatch calls, e.g. -- --partition=batch
                  --time=1:00:00 --cpus-per-task=8

Programs: $RASTERIZE, else bin/rasterize of this repository, else PATH.
Exit status: 0 when submitted (with --wait: when OUT.oct is written); 2 bad
usage; with --wait, the merge's status or the first failed shard's. On
failure OUT.oct is left as it was; without --wait the parts directory is left
for its logs.
EOF
}

farm_parse "$@"
farm_need sbatch slurm-client
farm_tool rasterize RASTERIZE
rasterize=$FARM_TOOL

parts=$(mktemp -d "$FARM_TMPDIR/.$(basename "$FARM_OUT").parts.XXXXXX")
submitted=0
trap '[ "$submitted" -eq 1 ] || rm -rf "$parts"' EXIT
last=$((FARM_COUNT - 1))
q_parts=$(farm_quote "$parts")

shard_cmd="$(farm_quote "$rasterize") $(farm_quote "$FARM_INPUT")"
shard_cmd="$shard_cmd -o $q_parts/part-\"\$SLURM_ARRAY_TASK_ID\".oct"
shard_cmd="$shard_cmd --shard \"\$SLURM_ARRAY_TASK_ID\"/$FARM_COUNT -q $FARM_PASS"
array=$(farm_sbatch --array="0-$last" --job-name=rasterize-shard \
    --output="$parts/shard-%a.log" --wrap="$(farm_task "$shard_cmd")") ||
    farm_die "sbatch of the shard array failed"
submitted=1

# The merge removes the parts once OUT.oct is written: a parts directory that
# is still there after the merge job ended means the merge never ran.
merge_cmd="$(farm_quote "$rasterize") --merge -o $(farm_quote "$FARM_OUT")"
i=0
while [ "$i" -le "$last" ]; do
    merge_cmd="$merge_cmd $q_parts/part-$i.oct"
    i=$((i + 1))
done
merge_cmd="$merge_cmd && rm -rf $q_parts"
merge_opts="--dependency=afterok:$array --kill-on-invalid-dep=yes --job-name=rasterize-merge"
if [ "$FARM_WAIT" -eq 0 ]; then
    merge=$(farm_sbatch $merge_opts --output="$parts/merge.log" --wrap="$merge_cmd") || {
        scancel "$array" 2>/dev/null || :
        farm_die "sbatch of the merge job failed; shard array $array cancelled"
    }
    farm_note "shards: job array $array (0-$last), merge: job $merge; parts and logs in $parts"
    printf '%s\n' "$merge"
    exit 0
fi

# --wait: sbatch returns the merge's exit status, or 0 when the merge was
# cancelled because a shard failed (the parts directory then still exists).
status=0
merge=$(farm_sbatch --wait $merge_opts --output="$parts/merge.log" --wrap="$merge_cmd") ||
    status=$?
if [ -z "$merge" ]; then
    scancel "$array" 2>/dev/null || :
    farm_die "sbatch of the merge job failed; shard array $array cancelled"
fi
printf '%s\n' "$merge"
[ -d "$parts" ] || exit "$status"
submitted=0   # every job has ended: the trap removes the parts
if [ "$status" -ne 0 ]; then
    [ -f "$parts/merge.log" ] && sed 's/^/  merge: /' "$parts/merge.log" >&2
    farm_note "the merge failed (exit $status); $FARM_OUT left as it was"
    exit "$status"
fi
farm_failed "$parts/shard-%a.log" "$last"
farm_note "the merge did not run; $FARM_OUT left as it was"
exit "$farm_failed_status"
