#!/bin/sh
# The farm drivers' command lines: --help, bad usage (exit 2), missing files
# and programs (exit 1), and no output left behind by a failed run.
set -u
. "$ROOT/tests/cli/lib.sh"
F=$ROOT/farm
RASTERIZE=$BIN/rasterize RENDER=$BIN/render; export RASTERIZE RENDER
scene=$ROOT/scenes/sphere.scene
"$BIN/rasterize" "$scene" -o "$T/s.oct" --levels 5 -q || fail "rasterize"
printf -- '-o %s/v.png --size 8x8\n' "$T" > "$T/v.views"

for d in parallel-rasterize parallel-render slurm-rasterize slurm-render; do
    expect_exit 0 sh "$F/$d.sh" --help
    grep -q "^usage: farm/$d.sh " "$OUT" || fail "$d --help: no usage line"
done

# usage_error TEXT DRIVER ARGS...: exit 2, TEXT on stderr, nothing written.
usage_error() {
    text=$1; shift
    expect_exit 2 sh "$@"
    expect_err "$text"
    expect_err "Try '"
    [ ! -e "$T/o.oct" ] || fail "a usage error wrote o.oct: $*"
    [ -z "$(ls -A "$T" | grep parts)" ] || fail "a usage error left a parts directory: $*"
}
for e in parallel slurm; do
    r=$F/$e-rasterize.sh
    usage_error "--shards: '0' is not a whole number" "$r" "$scene" "$T/o.oct" --levels 5 --shards 0
    usage_error "--shards: '-1' is not" "$r" "$scene" "$T/o.oct" --levels 5 --shards -1
    usage_error "--shards: 'x' is not" "$r" "$scene" "$T/o.oct" --levels 5 --shards x
    usage_error "--shards: '2x' is not" "$r" "$scene" "$T/o.oct" --levels 5 --shards 2x
    usage_error "--shards needs a value" "$r" "$scene" "$T/o.oct" --levels 5 --shards
    usage_error "needs --shards N" "$r" "$scene" "$T/o.oct" --levels 5
    usage_error "needs --levels L" "$r" "$scene" "$T/o.oct" --shards 2
    usage_error "--levels: '0' is not" "$r" "$scene" "$T/o.oct" --levels 0 --shards 2
    usage_error "needs SCENE and OUT.oct" "$r" "$scene" --levels 5 --shards 2
    usage_error "needs SCENE and OUT.oct" "$r" --levels 5 --shards 2
    usage_error "unexpected argument 'extra'" "$r" "$scene" "$T/o.oct" extra --levels 5 --shards 2
    usage_error "unknown option '--bogus'" "$r" "$scene" "$T/o.oct" --levels 5 --shards 2 --bogus
    usage_error "--shard is the driver's to set" "$r" "$scene" "$T/o.oct" --levels 5 --shards 2 --shard 0/2
    usage_error "unknown option '--parts'" "$r" "$scene" "$T/o.oct" --levels 5 --parts 2
    p=$F/$e-render.sh
    usage_error "needs one of --views FILE or --orbit N" "$p" "$T/s.oct" --parts 2
    usage_error "needs one of --views FILE or --orbit N" "$p" "$T/s.oct" --parts 2 \
        --views "$T/v.views" --orbit 3 -o "$T/f%d.png"
    usage_error "needs --parts N" "$p" "$T/s.oct" --views "$T/v.views"
    usage_error "--parts: '0' is not" "$p" "$T/s.oct" --views "$T/v.views" --parts 0
    usage_error "needs FILE.oct" "$p" --views "$T/v.views" --parts 2
    usage_error "--part is the driver's to set" "$p" "$T/s.oct" --views "$T/v.views" --parts 2 --part 0/2
    usage_error "unknown option '--shards'" "$p" "$T/s.oct" --views "$T/v.views" --shards 2
done
usage_error "--jobs: '0' is not" "$F/parallel-rasterize.sh" "$scene" "$T/o.oct" --levels 5 --shards 2 --jobs 0
usage_error "--jobs: 'all' is not" "$F/parallel-render.sh" "$T/s.oct" --views "$T/v.views" --parts 2 --jobs all
usage_error "unknown option '--wait'" "$F/parallel-rasterize.sh" "$scene" "$T/o.oct" --levels 5 --shards 2 --wait
usage_error "unknown option '--jobs'" "$F/slurm-rasterize.sh" "$scene" "$T/o.oct" --levels 5 --shards 2 --jobs 2
usage_error "unknown option '--jobs'" "$F/slurm-render.sh" "$T/s.oct" --views "$T/v.views" --parts 2 --jobs 2

# Missing inputs and programs: exit 1, named, before any job is started.
for e in parallel slurm; do
    expect_exit 1 sh "$F/$e-rasterize.sh" "$T/none.scene" "$T/o.oct" --levels 5 --shards 2
    expect_err "$T/none.scene: no such readable file"
    expect_exit 1 sh "$F/$e-rasterize.sh" "$scene" "$T/no/o.oct" --levels 5 --shards 2
    expect_err "no directory $T/no"
    RASTERIZE=$T/none expect_exit 1 sh "$F/$e-rasterize.sh" "$scene" "$T/o.oct" --levels 5 --shards 2
    expect_err "RASTERIZE=$T/none: not an executable file"
done
expect_exit 1 sh "$F/parallel-render.sh" "$T/none.oct" --views "$T/v.views" --parts 2
expect_err "$T/none.oct: no such readable file"
RENDER=no-such-render expect_exit 1 sh "$F/parallel-render.sh" "$T/s.oct" --views "$T/v.views" --parts 2
expect_err "RENDER=no-such-render: not found in PATH"
[ ! -e "$T/o.oct" ] || fail "a failed run wrote o.oct"

# local-slurm.sh: its commands, and no cluster where there is none.
expect_exit 0 sh "$F/local-slurm.sh" --help
grep -q '^usage: farm/local-slurm.sh start DIR' "$OUT" || fail "local-slurm.sh --help"
expect_exit 2 sh "$F/local-slurm.sh"
expect_exit 2 sh "$F/local-slurm.sh" begin "$T/c"
expect_err "unknown command 'begin'"
expect_exit 2 sh "$F/local-slurm.sh" start
expect_exit 1 sh "$F/local-slurm.sh" stop "$T"
expect_err "$T: no cluster here"
expect_exit 1 sh "$F/local-slurm.sh" start "$T"
expect_err "$T: not a new or empty directory"

# Options rasterize rejects fail in every shard: the first failure's status,
# OUT.oct as it was, no parts left.
command -v parallel >/dev/null || fail "GNU parallel is not installed (sh tests/deps.sh test)"
printf 'old' > "$T/o.oct"
expect_exit 2 sh "$F/parallel-rasterize.sh" "$scene" "$T/o.oct" --levels 5 --shards 3 --jobs 2 \
    --method bogus
expect_err "a shard failed (exit 2); $T/o.oct left as it was"
[ "$(cat "$T/o.oct")" = old ] || fail "a failed run changed o.oct"
[ -z "$(ls -A "$T" | grep parts)" ] || fail "a failed run left its parts: $(ls -A "$T")"
pass
