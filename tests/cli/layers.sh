#!/bin/sh
# Every #include "..." in the tree points down the layer matrix of the
# Makefile's comment (a program links only the layers it may use, so a
# wrong-way include would otherwise show up only as a link error, or not at
# all for header-only use). Also: every quoted include names a file that
# exists, relative to the repository root.
. "$ROOT/tests/cli/lib.sh"
cd "$ROOT" || fail "no ROOT"

# layer of a path: its folder, with common/expr and common/view separate
# and tests/fuzz part of tests.
layer() {
    case $1 in
        common/expr/*) echo common/expr ;;
        common/view/*) echo common/view ;;
        tests/*) echo tests ;;
        */*) echo "${1%%/*}" ;;
        *) echo top ;;
    esac
}
# allowed FROM TO: may layer FROM include layer TO?
allowed() {
    [ "$1" = "$2" ] && return 0
    case "$1:$2" in
        common/expr:common | common/view:common) return 0 ;;
        rasterize:common/expr | rasterize:common | rasterize:format) return 0 ;;
        render:common/view | render:common/expr | render:common | render:format) return 0 ;;
        bench:render | bench:common/expr | bench:common/view | bench:common | bench:format) return 0 ;;
        tests:bench | tests:render | tests:rasterize | tests:common/expr | tests:common/view \
            | tests:common | tests:format) return 0 ;;
    esac
    return 1
}

bad=0; n=0
find format common rasterize render bench tests -name '*.[ch]' | sort >"$T/files"
while read -r f; do
    from=$(layer "$f")
    sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f" >"$T/inc"
    while read -r inc; do
        n=$((n + 1))
        case $inc in
            */*) ;;
            *) echo "$f: #include \"$inc\": name the path from the repository root" >&2
               bad=1; continue ;;
        esac
        [ -f "$inc" ] || { echo "$f: #include \"$inc\": no such file" >&2; bad=1; continue; }
        to=$(layer "$inc")
        if ! allowed "$from" "$to"; then
            echo "$f: #include \"$inc\": $from may not use $to (Makefile, layers)" >&2
            bad=1
        fi
    done <"$T/inc"
done <"$T/files"
[ "$n" -gt 100 ] || fail "only $n includes found; is the tree there?"
[ "$bad" -eq 0 ] || fail "includes against the layer matrix"
pass
