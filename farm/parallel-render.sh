#!/bin/sh
# Renders the views of a views file or an orbit as N parts run by GNU parallel
# (here or over ssh); together they write the frames of one whole run.
set -eu
FARM_PROG=parallel-render.sh FARM_KIND=render FARM_ENGINE=parallel
. "$(dirname "$0")/lib.sh"

farm_usage() {
    cat <<'EOF'
usage: farm/parallel-render.sh FILE.oct --views VIEWS --parts N [--jobs J]
           [render options] [-- parallel options]
       farm/parallel-render.sh FILE.oct --orbit K -o 'frame_%04d.png' --parts N
           [--jobs J] [render options] [-- parallel options]

Runs `render FILE.oct ... --part I/N` for I = 0..N-1 through GNU parallel:
part I renders views I, I+N, I+2N, ... under the names one whole run gives
them, so the N parts write exactly the frames of `render FILE.oct ...`.

  --parts N       number of parts (>= 1)
  --jobs J        parts run at once (default: parallel's, one per core)
  render options  every other word goes to each render run unchanged
                  (e.g. --size, --threads, --aa, -q); output paths are
                  relative to the current directory
  -- ...          the rest goes to parallel, e.g. -- --sshloginfile FILE

Programs: $RENDER, else bin/render of this repository, else PATH.
Exit status: that of the first failing part (the others are stopped);
0 when every part succeeded; 2 bad usage.
EOF
}

farm_parse "$@"
farm_need parallel parallel
farm_tool render RENDER
render=$FARM_TOOL

# -q: parallel quotes each word of the command; {} is the part number.
eval "set -- $FARM_EXTRA"
status=0
seq 0 $((FARM_COUNT - 1)) |
    eval "parallel --will-cite -q --halt now,fail=1 ${FARM_JOBS:+--jobs $FARM_JOBS}" '"$@"' \
        '"$render" "$FARM_INPUT" --part "{}/$FARM_COUNT"' "$FARM_PASS" || status=$?
if [ "$status" -ne 0 ]; then
    farm_note "a part failed (exit $status)"
    exit "$status"
fi
