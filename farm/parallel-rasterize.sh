#!/bin/sh
# Rasterizes a scene as N shards run by GNU parallel (here or over ssh), then
# merges them into the file one whole run writes, byte for byte.
set -eu
FARM_PROG=parallel-rasterize.sh FARM_KIND=rasterize FARM_ENGINE=parallel
. "$(dirname "$0")/lib.sh"

farm_usage() {
    cat <<'EOF'
usage: farm/parallel-rasterize.sh SCENE OUT.oct --levels L --shards N [--jobs J]
           [--tmpdir DIR] [--method M] [--threads T] [--shell-only] [-- parallel options]

Runs `rasterize SCENE --levels L --shard I/N` for I = 0..N-1 through GNU parallel,
then `rasterize --merge` of the N parts into OUT.oct: the same bytes as
`rasterize SCENE -o OUT.oct --levels L` run whole.

  --levels L      octree levels (as rasterize)
  --shards N      number of shards (>= 1)
  --jobs J        shards run at once (default: parallel's, one per core)
  --tmpdir DIR    where the parts go, in a fresh directory removed at the end
                  (default: OUT.oct's directory; every machine must see it)
  --method M, --threads T, --shell-only
                  passed to every rasterize run
  -- ...          the rest goes to parallel, e.g. -- --sshloginfile FILE

Programs: $RASTERIZE, else bin/rasterize of this repository, else PATH.
Exit status: that of the first failing shard or of the merge; 0 when OUT.oct
is written; 2 bad usage. On failure OUT.oct is left as it was.
EOF
}

farm_parse "$@"
farm_need parallel parallel
farm_tool rasterize RASTERIZE
rasterize=$FARM_TOOL

parts=$(mktemp -d "$FARM_TMPDIR/.$(basename "$FARM_OUT").parts.XXXXXX")
trap 'rm -rf "$parts"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# -q: parallel quotes each word of the command; {} is the shard number.
eval "set -- $FARM_EXTRA"
status=0
seq 0 $((FARM_COUNT - 1)) |
    eval "parallel --will-cite -q --halt now,fail=1 ${FARM_JOBS:+--jobs $FARM_JOBS}" '"$@"' \
        '"$rasterize" "$FARM_INPUT" -o "$parts/part-{}.oct" --shard "{}/$FARM_COUNT" -q' \
        "$FARM_PASS" || status=$?
if [ "$status" -ne 0 ]; then
    farm_note "a shard failed (exit $status); $FARM_OUT left as it was"
    exit "$status"
fi

i=0
set --
while [ "$i" -lt "$FARM_COUNT" ]; do
    set -- "$@" "$parts/part-$i.oct"
    i=$((i + 1))
done
"$rasterize" --merge -o "$FARM_OUT" "$@"
