# Helpers for CLI tests (sourced). Needs $BIN (programs) and $ROOT (repo).
# Each test gets a fresh temporary directory $T, removed on exit.
T=$(mktemp -d); OUT="$T/.out"; ERR="$T/.err"
trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*" >&2; [ -s "$ERR" ] && sed 's/^/  stderr: /' "$ERR" >&2; exit 1; }
pass() { exit 0; }
# expect_exit CODE CMD...: runs CMD, stdout to $OUT, stderr to $ERR.
expect_exit() {
    want=$1; shift
    "$@" >"$OUT" 2>"$ERR"; got=$?
    [ "$got" -eq "$want" ] || fail "exit $got, want $want: $*"
}
# expect_err TEXT: stderr of the last command contains TEXT (fixed string).
expect_err() { grep -qF -- "$1" "$ERR" || fail "stderr lacks '$1'"; }
