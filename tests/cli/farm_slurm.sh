#!/bin/sh
# farm/slurm-*.sh on a single-node Slurm cluster this test starts (munged,
# slurmctld, slurmd on localhost, all state in the test's directory) and
# stops: a sharded rasterization and a render array, byte-identical to whole
# runs. A cluster that does not start is a failure, with the reason.
set -u
. "$ROOT/tests/cli/lib.sh"
F=$ROOT/farm
C=$T/cluster
chmod 755 "$T"   # munged wants the directories above its socket searchable
trap 'sh "$F/local-slurm.sh" stop "$C" >/dev/null 2>&1; rm -rf "$T"' EXIT
for c in munged slurmctld slurmd sbatch; do
    command -v $c >/dev/null || fail "$c is not installed (sh tests/deps.sh test installs slurm-wlm, munge)"
done
sh "$F/local-slurm.sh" start "$C" >"$OUT" 2>"$ERR" || fail "cannot start the local Slurm cluster"
eval "$(cat "$OUT")"
[ "$SLURM_CONF" = "$C/slurm.conf" ] || fail "local-slurm.sh start printed: $(cat "$OUT")"
RASTERIZE=$BIN/rasterize RENDER=$BIN/render; export RASTERIZE RENDER
bound="timeout 60"   # a waited job that never ends fails (exit 124), never hangs the suite
scene=$ROOT/scenes/sphere.scene
no_parts() { [ -z "$(ls -A "$1" | grep parts)" ] || fail "parts left in $1: $(ls -A "$1")"; }
same_dirs() {
    [ "$(ls "$1")" = "$(ls "$2")" ] || fail "$3: files $(ls "$2" | tr '\n' ' '), want $(ls "$1" | tr '\n' ' ')"
    for f in $(ls "$1"); do cmp "$1/$f" "$2/$f" >&2 || fail "$3: $f differs from the whole run"; done
}

# A job array of 5 shards and the merge after it, waited for.
"$BIN/rasterize" "$scene" -o "$T/whole.oct" --levels 7 -q || fail "whole rasterize"
expect_exit 0 $bound sh "$F/slurm-rasterize.sh" "$scene" "$T/s5.oct" --levels 7 --shards 5 --wait
cmp "$T/whole.oct" "$T/s5.oct" >&2 || fail "5 shards merged by Slurm differ from the whole run"
no_parts "$T"

# Without --wait: the merge job's id on stdout; a render array of 3 parts
# that depends on it (-- sbatch options) renders the merged file once written.
mkdir "$T/a" "$T/b"
: > "$T/v.views"
for i in 0 1 2 3 4; do
    printf -- '-o v%d.png --depth v%d.pfm --size %dx20 --eye %d.5,-2,1 --target 0.5,0.5,0.5\n' \
        "$i" "$i" $((16 + i)) "$i" >> "$T/v.views"
done
(cd "$T/a" && "$BIN/render" "$T/whole.oct" --views "$T/v.views" -q) || fail "whole render"
expect_exit 0 sh "$F/slurm-rasterize.sh" "$scene" "$T/s3.oct" --levels 7 --shards 3
merge=$(cat "$OUT")
case $merge in '' | *[!0-9]*) fail "slurm-rasterize.sh printed '$merge', not a job id" ;; esac
(cd "$T/b" && $bound sh "$F/slurm-render.sh" "$T/s3.oct" --views "$T/v.views" --parts 3 --wait -q \
    -- --dependency="afterok:$merge") >"$OUT" 2>"$ERR" || fail "slurm-render.sh --wait"
cmp "$T/whole.oct" "$T/s3.oct" >&2 || fail "3 shards merged by Slurm differ from the whole run"
no_parts "$T"
same_dirs "$T/a" "$T/b" "a render array of 3 parts"

# A scene every shard rejects: the merge never runs; --wait reports the first
# failed shard with its status and log; OUT.oct as it was, no parts left.
printf 'bounds 0 0 0 1 1 1\nsurface x +\n' > "$T/bad.scene"
cp "$T/whole.oct" "$T/keep.oct"
expect_exit 1 $bound sh "$F/slurm-rasterize.sh" "$T/bad.scene" "$T/keep.oct" --levels 7 --shards 2 --wait
expect_err "task 0 of the job array failed (exit 1)"
expect_err "task 0: $T/bad.scene:2:"
expect_err "the merge did not run"
cmp -s "$T/whole.oct" "$T/keep.oct" || fail "a failed run changed OUT.oct"
no_parts "$T"

# A failing render task: --wait returns its status.
mkdir "$T/c"
(cd "$T/c" && $bound sh "$F/slurm-render.sh" "$T/none.oct" --views "$T/v.views" --parts 2 --wait) \
    >"$OUT" 2>"$ERR" && fail "a render array of a missing file succeeded"
expect_err "task 0 of the job array failed (exit 1)"

# Stopped: every daemon it started is gone (local-slurm.sh stop checks by pid).
pids=$(cat "$C/munged.pid" "$C/slurmctld.pid" "$C/slurmd.pid")
sh "$F/local-slurm.sh" stop "$C" >"$OUT" 2>"$ERR" || fail "cannot stop the local Slurm cluster"
for p in $pids; do
    ! kill -0 "$p" 2>/dev/null || [ "$(ps -o stat= -p "$p")" = Z ] || fail "pid $p still runs after stop"
done
pass
