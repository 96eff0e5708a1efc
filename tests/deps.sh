#!/bin/sh
# Installs the libraries the build needs when they are missing (Debian/Ubuntu).
# Usage: tests/deps.sh build|test
# `make test` (and `make check`) run it first; it says what it will install
# before it calls apt-get.
set -u
need=""
pkg-config --exists libpng 2>/dev/null || need="$need libpng-dev"
pkg-config --exists zlib 2>/dev/null   || need="$need zlib1g-dev"
command -v pkg-config >/dev/null       || need="$need pkg-config"
command -v cc >/dev/null               || need="$need gcc"
command -v gcc-ar >/dev/null           || need="$need gcc"  # the release build's LTO archives
if [ "${1:-build}" = test ]; then
    pkg-config --exists cmocka 2>/dev/null || need="$need libcmocka-dev"
    [ -f /usr/include/mpfr.h ]             || need="$need libmpfr-dev"  # interval tests check against MPFR
    command -v groff >/dev/null            || need="$need groff"        # install.sh formats the man pages
fi

# farm/: the engines tests/cli/farm_*.sh run (GNU parallel; a local Slurm cluster)
if [ "${1:-build}" = test ]; then
    command -v parallel >/dev/null                       || need="$need parallel"
    command -v slurmctld >/dev/null && command -v slurmd >/dev/null || need="$need slurm-wlm"
    command -v munged >/dev/null                         || need="$need munge"
fi

[ -z "$need" ] && exit 0
if ! command -v apt-get >/dev/null; then
    echo "deps: missing:$need; install them with your package manager" >&2
    exit 1
fi
sudo=""
[ "$(id -u)" -ne 0 ] && sudo=sudo
# Said before anything runs, so nobody is surprised by a password prompt.
echo "deps: missing:$need" >&2
echo "deps: installing them now with ${sudo:+sudo }apt-get update and apt-get install" >&2
$sudo apt-get update -qq || exit 1
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $need >/dev/null || exit 1
