#!/bin/sh
# Renders the views of a views file or an orbit on a Slurm cluster: a job
# array of N parts that together write the frames of one whole run.
set -eu
FARM_PROG=slurm-render.sh FARM_KIND=render FARM_ENGINE=slurm
. "$(dirname "$0")/lib.sh"
. "$(dirname "$0")/slurm-lib.sh"

farm_usage() {
    cat <<'EOF'
usage: farm/slurm-render.sh FILE.oct --views VIEWS --parts N [--wait]
           [render options] [-- sbatch options]
       farm/slurm-render.sh FILE.oct --orbit K -o 'frame_%04d.png' --parts N
           [--wait] [render options] [-- sbatch options]

Submits a job array of N tasks, task I running `render FILE.oct ... --part I/N`:
views I, I+N, I+2N, ... under the names one whole run gives them, so the N
tasks write exactly the frames of `render FILE.oct ...`. Prints the array's
job id on stdout. Task I logs to render-JOBID_I.log in the current directory.

  --parts N       number of parts, the array's size (>= 1)
  --wait          return when every task has finished: exit 0 when all
                  succeeded (their logs are then removed), else the highest
                  exit status of a task
  render options  every other word goes to each render run unchanged (e.g.
                  --size, --threads, --aa, -q); paths are relative to the
                  current directory, which every node must share
  -- ...          the rest goes to sbatch, e.g. -- --partition=gpu
                  --dependency=afterok:ID (ID: a slurm-rasterize.sh merge job)

Programs: $RENDER, else bin/render of this repository, else PATH.
Exit status: 0 when submitted (with --wait: when every frame is written);
2 bad usage; 1 when sbatch fails.
EOF
}

farm_parse "$@"
farm_need sbatch slurm-client
farm_tool render RENDER
render=$FARM_TOOL
last=$((FARM_COUNT - 1))

cmd="$(farm_quote "$render") $(farm_quote "$FARM_INPUT")"
cmd="$cmd --part \"\$SLURM_ARRAY_TASK_ID\"/$FARM_COUNT $FARM_PASS"
log=render-%A_%a.log
if [ "$FARM_WAIT" -eq 0 ]; then
    array=$(farm_sbatch --array="0-$last" --job-name=render-part --output="$log" \
        --wrap="$(farm_task "$cmd")") || farm_die "sbatch of the render array failed"
    farm_note "render parts: job array $array (0-$last); logs in render-${array}_*.log"
    printf '%s\n' "$array"
    exit 0
fi

# --wait: sbatch's status is the highest of the tasks' exit statuses.
status=0
array=$(farm_sbatch --wait --array="0-$last" --job-name=render-part --output="$log" \
    --wrap="$(farm_task "$cmd")") || status=$?
[ -n "$array" ] || farm_die "sbatch of the render array failed"
printf '%s\n' "$array"
if [ "$status" -eq 0 ]; then
    i=0
    while [ "$i" -le "$last" ]; do
        rm -f "render-${array}_$i.log"
        i=$((i + 1))
    done
    exit 0
fi
farm_failed "render-${array}_%a.log" "$last"
farm_note "the render array failed (highest exit status of a task: $status)"
exit "$status"
