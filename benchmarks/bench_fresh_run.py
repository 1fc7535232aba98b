"""A fresh clone's ``make run``, part by part, and a pip-installed ``demcheck verify --engines none`` from cold.

    python benchmarks/bench_fresh_run.py [--part clone|pip|both] [--out FILE]

``clone``: ``git clone`` of this checkout's HEAD into a temporary directory, then the parts of ``make run`` one at a
time, each timed (wall clock): the venv and Python packages (``make .venv/.demcheck-installed``), the engines
and the compiled kernels side by side (``make -j2 engines-available warmup``, as make run does) and the default
suite (``demcheck verify``).
``pip``: ``pip wheel .`` and a new venv with that wheel, then ``demcheck verify --engines none`` from an empty
directory with an empty kernel cache (``XDG_CACHE_HOME`` in the temporary directory). Every part runs with an
empty ``XDG_CACHE_HOME``, so pip downloads every package as on a new machine.

What "fresh" means is the machine's: the script states what it found before it started (the pip cache, which
engines were already installed, the Debian release), because a second run on the same machine finds them warm. To
measure from nothing, first ``apt-get remove -y yade liggghts && apt-get autoremove -y && apt-get clean`` and
``pip cache purge``. Output: a table of the parts, and the exit status of each.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# make run's parts, as its recipe runs them (the engines install while the kernels compile)
PARTS = ("venv and Python packages", "engines and warm-up, side by side (make -j2)", "default suite (demcheck verify)")


def sh(cmd: list[str] | str, cwd: Path, env: dict | None = None, log: Path | None = None) -> tuple[float, int]:
    t0 = time.perf_counter()
    with open(log, "ab") if log else open(os.devnull, "wb") as out:
        rc = subprocess.run(cmd, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT, shell=isinstance(cmd, str)).returncode
    return time.perf_counter() - t0, rc


def state() -> list[str]:
    pip_cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "pip"
    size = sum(f.stat().st_size for f in pip_cache.rglob("*") if f.is_file()) if pip_cache.exists() else 0
    release = "unknown"
    if Path("/etc/os-release").exists():
        release = next((ln.split("=", 1)[1].strip('"\n') for ln in open("/etc/os-release") if ln.startswith("PRETTY_NAME=")), release)
    found = [p for p in ("liggghts", "yade", "yade-float128", "chromium") if shutil.which(p)]
    load = os.getloadavg()
    return [f"machine: {release}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} (other work on the machine slows every part)",
            f"before: pip cache {size / 2**20:.0f} MiB (not used: each part runs with an empty XDG_CACHE_HOME); "
            f"on PATH: {', '.join(found) or 'none of liggghts, yade, chromium'}"]


def clone_part(tmp: Path) -> list[tuple[str, float, int]]:
    work = tmp / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(work)], check=True)
    log = tmp / "make-run.log"
    # empty caches: pip's and the kernels' (XDG_CACHE_HOME) and the engine runs' (DEMCHECK_CACHE)
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp / "cache"), DEMCHECK_CACHE=str(tmp / "cache" / "runs"))
    rows = []
    for name, cmd in zip(PARTS, [["make", ".venv/.demcheck-installed"],
                                 ["make", "--no-print-directory", "-j2", "--output-sync=target", "engines-available",
                                  "warmup"],
                                 [".venv/bin/demcheck", "verify"]]):
        dt, rc = sh(cmd, work, env, log)
        rows.append((name, dt, rc))
        print(f"  {name}: {dt:.1f} s (exit {rc})", flush=True)
    print(f"  log: {log}")
    return rows


def pip_part(tmp: Path) -> list[tuple[str, float, int]]:
    rows = []
    wheels, venv, empty = tmp / "wheels", tmp / "venv", tmp / "empty"
    empty.mkdir()
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp / "pcache"))
    env.pop("NUMBA_CACHE_DIR", None)
    log = tmp / "pip.log"
    for name, cmd, cwd in [
            ("venv + pip wheel . (build)", f"{sys.executable} -m venv {venv} && "
                                           f"{venv}/bin/pip wheel -q --no-deps -w {wheels} {ROOT}", tmp),
            ("pip install the wheel (with its dependencies)", f"{venv}/bin/pip install -q {wheels}/demcheck-*.whl", tmp),
            ("demcheck verify --engines none (cold)", [str(venv / "bin" / "demcheck"), "verify", "--engines", "none"], empty),
            ("demcheck verify --engines none (warm)", [str(venv / "bin" / "demcheck"), "verify", "--engines", "none"], empty)]:
        dt, rc = sh(cmd, cwd, env, log)
        rows.append((name, dt, rc))
        print(f"  {name}: {dt:.1f} s (exit {rc})", flush=True)
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=["clone", "pip", "both"], default="both")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory (its logs)")
    a = ap.parse_args()
    lines = state()
    print("\n".join(lines), flush=True)
    tmp = Path(tempfile.mkdtemp(prefix="demcheck-fresh-"))
    rows: list[tuple[str, float, int]] = []
    try:
        if a.part in ("clone", "both"):
            print("a fresh clone's make run:", flush=True)
            rows += clone_part(tmp)
        if a.part in ("pip", "both"):
            print("a pip-installed demcheck:", flush=True)
            rows += pip_part(tmp)
    finally:
        if not a.keep:
            shutil.rmtree(tmp, ignore_errors=True)
    print("\n| part | wall time | exit |\n|---|---|---|")
    for name, dt, rc in rows:
        print(f"| {name} | {dt:.1f} s | {rc} |")
    clone = [r for r in rows if r[0] in PARTS]
    if clone:
        print(f"| **make run, total** | **{sum(r[1] for r in clone):.1f} s** ({sum(r[1] for r in clone) / 60:.1f} min) | |")
    return max((r[2] for r in rows), default=0) and 1


if __name__ == "__main__":
    sys.exit(main())
