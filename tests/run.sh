#!/bin/sh
# Runs every test of one build variant and prints one closing line:
#   "tests: N passed, N failed"
# Usage: tests/run.sh BUILD_DIR    (e.g. build/rel or build/san)
# cmocka suites count each test case; CLI scripts and fuzz replays count once each.
# CLI tests run $BIN = BUILD_DIR/testbin, the programs built with the test
# hooks (ATOMIC_FAULT, DDA_FPE_TRAPS); $RELBIN = BUILD_DIR/bin are the
# release programs (install.sh installs and runs those).
set -u
B=${1:?usage: tests/run.sh BUILD_DIR}
mkdir -p "$B/bin" "$B/testbin"
BIN=$(cd "$B/testbin" && pwd); RELBIN=$(cd "$B/bin" && pwd); export BIN RELBIN
ROOT=$(pwd); export ROOT
passed=0; failed=0; failures=""
log=$(mktemp); trap 'rm -f "$log"' EXIT

for t in "$B"/tests/test_*; do
    [ -x "$t" ] || continue
    name=$(basename "$t")
    if "$t" >"$log" 2>&1; then status=0; else status=$?; fi
    p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | awk '{s+=$1} END {print s+0}')
    f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | awk '{s+=$1} END {print s+0}')
    if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi   # crashed or aborted
    passed=$((passed + p)); failed=$((failed + f))
    if [ "$f" -ne 0 ]; then failures="$failures $name"; cat "$log"; fi
    echo "$name: $p passed, $f failed"
done

# The suites of the lane evaluators and the rasterizer again on the portable
# build of the lane evaluators (DDA_SIMD=portable), so every dispatched path
# is tested where the processor has AVX2.
for name in test_tape_ilanes test_tape test_build; do
    t="$B/tests/$name"
    [ -x "$t" ] || continue
    if DDA_SIMD=portable "$t" >"$log" 2>&1; then status=0; else status=$?; fi
    p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log" | awk '{s+=$1} END {print s+0}')
    f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$log" | awk '{s+=$1} END {print s+0}')
    if [ "$status" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    passed=$((passed + p)); failed=$((failed + f))
    if [ "$f" -ne 0 ]; then failures="$failures $name(portable)"; cat "$log"; fi
    echo "$name (DDA_SIMD=portable): $p passed, $f failed"
done

for t in "$B"/tests/replay_*; do
    [ -x "$t" ] || continue
    name=$(basename "$t"); target=${name#replay_}
    if "$t" tests/fuzz/corpus/"$target" tests/fuzz/crashers >"$log" 2>&1; then
        passed=$((passed + 1)); echo "$name: ok"
    else
        failed=$((failed + 1)); failures="$failures $name"; cat "$log"
    fi
done

for t in tests/cli/*.sh; do
    [ -f "$t" ] || continue
    name=$(basename "$t" .sh)
    if sh "$t" >"$log" 2>&1; then
        passed=$((passed + 1)); echo "cli/$name: ok"
    else
        failed=$((failed + 1)); failures="$failures cli/$name"; cat "$log"; echo "cli/$name: FAILED"
    fi
done

[ -n "$failures" ] && echo "failed:$failures"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
