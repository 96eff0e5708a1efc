#!/bin/sh
# render: --help, usage errors (exit 2, "render: ..." + usage on stderr) and
# views-file errors (FILE:LINE:, exit 2, nothing written), none of which
# needs a readable .oct file.
set -u
R="$BIN/render"
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$R" --help >"$T/out" 2>"$T/err"; [ $? -eq 0 ] || fail "--help exit"
grep -q '^usage: render' "$T/out" || fail "--help not on stdout"
[ -s "$T/err" ] && fail "--help wrote to stderr"

expect2() { # expect2 PATTERN ARGS...: exit 2, stderr has PATTERN and the usage
    pat=$1; shift
    "$R" "$@" >"$T/out" 2>"$T/err"; rc=$?
    [ $rc -eq 2 ] || fail "$*: exit $rc, want 2"
    grep -q -- "$pat" "$T/err" || { cat "$T/err"; fail "$*: no '$pat'"; }
    [ -s "$T/out" ] && fail "$*: wrote to stdout"
    return 0
}
expect2 "render: unrecognized option '--bogus'" x.oct -o "$T/a.png" --bogus
expect2 "render: no input file" -o "$T/a.png"
expect2 "--size" x.oct -o "$T/a.png" --size 0x10
expect2 "--size" x.oct -o "$T/a.png" --size 40000x10
expect2 "--fov" x.oct -o "$T/a.png" --fov 180
expect2 "--eye" x.oct -o "$T/a.png" --eye nan,0,0
expect2 "--threads" x.oct -o "$T/a.png" --threads 0
expect2 "needs a value" x.oct -o
expect2 "no output" x.oct
expect2 "one integer conversion" x.oct -o "$T/f.png" --orbit 3
expect2 "cannot be combined" x.oct --views "$T/v" --orbit 3
grep -q 'usage: render' "$T/err" || fail "no usage after an error"
# --refine and --exact place hits each its own way: not both
expect2 "render: --refine and --exact cannot be combined" x.oct -o "$T/a.png" --refine --exact
expect2 "render: --refine and --exact cannot be combined" x.oct -o "$T/a.png" --exact --refine
[ -e "$T/a.png" ] && fail "--refine --exact wrote an image"
printf '%s\n' "-o $T/r1.png" "-o $T/r2.png --exact" > "$T/rviews"
"$R" x.oct --views "$T/rviews" --refine >"$T/out" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "--refine with a views line --exact: exit $rc"
grep -q "^$T/rviews:2: --exact and --refine (on the command line) cannot be combined" "$T/err" ||
    { cat "$T/err"; fail "no FILE:2: for --exact under --refine"; }
grep -q "^$T/rviews:1: " "$T/err" && fail "line 1 (no --exact) reported"
[ -e "$T/r1.png" ] && fail "a view was rendered despite --exact under --refine"

printf '%s\n' "-o $T/ok.png" "-o $T/b.png --eye 1,2" "# fine" "--fov 10" > "$T/views"
"$R" x.oct --views "$T/views" >"$T/out" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "bad views file: exit $rc"
grep -q "^$T/views:2: " "$T/err" || { cat "$T/err"; fail "no FILE:2:"; }
grep -q "^$T/views:4: " "$T/err" || { cat "$T/err"; fail "no FILE:4:"; }
[ -e "$T/ok.png" ] && fail "a view was rendered despite a bad line"
exit 0
