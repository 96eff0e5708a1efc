#!/bin/sh
# Evaluator throughput on the paper's two scenes. Builds nothing: run
# `make tools` first. BIN defaults to build/rel/bin.
set -eu
BIN=${BIN:-build/rel/bin}
echo "machine: $(uname -m), $(nproc) cpus, $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)"
set -- "$BIN/evalbench" scenes/blobs_a.scene scenes/blobs_b.scene
echo "command: $*"
"$@"
