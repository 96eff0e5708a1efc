#!/bin/sh
# deps.sh: the benchmark's optional tools. Says what is missing; for `full`
# on Debian/Ubuntu installs it with apt-get (saying so) unless
# BENCH_NO_INSTALL=1. Nothing is installed for `quick`.
# Usage: bench/deps.sh quick|full
set -u
need=""
command -v gnuplot >/dev/null 2>&1 || need="$need gnuplot-nox"
command -v povray >/dev/null 2>&1  || need="$need povray"
[ -x /usr/bin/time ]               || need="$need time"
[ -z "$need" ] && exit 0
echo "bench: missing:$need (plots, the POV-Ray peer, peak RSS)" >&2
if [ "${1:-quick}" != full ] || [ "${BENCH_NO_INSTALL:-0}" = 1 ] || ! command -v apt-get >/dev/null; then
    echo "bench: going on without them; install them for the whole benchmark" >&2
    exit 0
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo=sudo
echo "bench: installing$need with apt-get (BENCH_NO_INSTALL=1 to skip)" >&2
$sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $need >/dev/null ||
    echo "bench: apt-get failed; going on without$need" >&2
exit 0
