#!/bin/sh
# --version: one line "PROG VERSION (COMMIT)" (no commit outside a checkout),
# VERSION from the VERSION file, exit 0, nothing on stderr; --help lists it.
. "$ROOT/tests/cli/lib.sh"
v=$(cat "$ROOT/VERSION") || fail "no VERSION file"
for p in rasterize render; do
    expect_exit 0 "$BIN/$p" --version
    [ -s "$ERR" ] && fail "$p --version wrote to stderr"
    [ "$(wc -l <"$OUT")" -eq 1 ] || fail "$p --version: not one line"
    line=$(cat "$OUT")
    case $line in
        "$p $v" | "$p $v ("?*")") ;;
        *) fail "$p --version: '$line', want '$p $v (COMMIT)'" ;;
    esac
    expect_exit 0 "$BIN/$p" --help
    grep -q -- '--version' "$OUT" || fail "$p --help does not list --version"
done
pass
