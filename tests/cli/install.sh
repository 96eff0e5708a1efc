#!/bin/sh
# make install / make uninstall into a temporary DESTDIR: the release
# programs and the four man pages land under PREFIX, every page formats
# without a warning, the installed programs run, and uninstall removes
# every file it installed.
. "$ROOT/tests/cli/lib.sh"
: "${RELBIN:?RELBIN (the release programs) is set by tests/run.sh}"
command -v groff >/dev/null || fail "groff is missing (tests/deps.sh installs it)"
# The build that made RELBIN: build/rel, build/san, or build/rel-march-X
# for `make ARCHFLAGS=-march=X`.
case $RELBIN in
    */san*/bin) san=1 ;;
    *) san=0 ;;
esac
arch=""
case $RELBIN in
    */build/*-march-*/bin) a=${RELBIN%/bin}; arch="ARCHFLAGS=-march=${a##*-march-}" ;;
esac
D="$T/dest"; P=/opt/dda
# A make of its own: not the caller's job server or variables.
mk() { env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s -C "$ROOT" SANITIZE=$san $arch \
           DESTDIR="$D" PREFIX=$P "$@" >"$OUT" 2>"$ERR"; }
mk install || fail "make install"
v=$(cat "$ROOT/VERSION")
for p in rasterize render; do
    f="$D$P/bin/$p"
    [ -x "$f" ] || fail "$f not installed"
    cmp -s "$f" "$RELBIN/$p" || fail "$f is not the release build's $p"
    expect_exit 0 "$f" --version
    case $(cat "$OUT") in
        "$p $v"*) ;;
        *) fail "installed $p --version: '$(cat "$OUT")'" ;;
    esac
done
for m in man1/rasterize.1 man1/render.1 man5/oct.5 man5/scene.5; do
    f="$D$P/share/man/$m"
    [ -f "$f" ] || fail "$f not installed"
    groff -ww -mandoc -z "$f" >"$OUT" 2>"$ERR" || fail "groff failed on $m"
    [ -s "$ERR" ] && fail "groff warns on $m"
done
mk uninstall || fail "make uninstall"
left=$(find "$D" -type f | head -5)
[ -z "$left" ] || fail "left after uninstall: $left"
pass
