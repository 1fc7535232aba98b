"""Kratos DEM 10.4.4 (PyPI KratosMultiphysics + KratosDEMApplication): DEM_D_*_viscous_Coulomb laws, driven
by a runner script that the Python with Kratos installed executes (one subprocess a run, like the others, or
script after script in this Python's worker: worker.py)."""

from __future__ import annotations

import re
import sys

from .. import registry
from ..base import Native, PackageEngine, Style

# what the engine's Python answers for its installed distributions (no Kratos import: that takes a second)
VERSION_QUERY = ("from importlib.metadata import version; "
                 "print('KratosMultiphysics', version('KratosMultiphysics'), "
                 "'KratosDEMApplication', version('KratosDEMApplication'))")
VERSION = re.compile(r"^KratosMultiphysics (\S+) KratosDEMApplication (\S+)\s*$", re.M)
USAGE = re.compile(r"^usage: (\S+) \[option\]", re.M)


class _Banner:
    """Discovery reads ``<executable> -h``; the executable is a Python, whose help names itself
    (``usage: /path/python [option] ...``) but not Kratos. This pattern asks that Python for the versions of
    its KratosMultiphysics and KratosDEMApplication distributions; a match's group 1 is
    "10.4.4 (DEMApplication 10.4.4)" (KratosMultiphysics first). No match when they are not installed there."""

    def __init__(self, timeout: float = 20.0):
        self.timeout = timeout

    def search(self, text: str):
        usage = USAGE.search(text or "")
        if not usage:
            return None
        from ..discovery import output_of

        out, _ = output_of([usage.group(1), "-c", VERSION_QUERY], self.timeout, "its version query")
        m = VERSION.search(out) if out is not None else None
        if not m:
            return None
        from .worker import version_words

        return re.match(r"(.+)", version_words(m.group(1), m.group(2)))


class Kratos(PackageEngine):
    name = "kratos"
    title = "Kratos DEM"
    release = "Kratos 10.4.4"
    how_to_install = ("pip install 'KratosMultiphysics==10.4.4' 'KratosDEMApplication==10.4.4' (or 'demcheck[kratos]'), "
                      "or `make engines` in a clone of demcheck")
    banner = _Banner()
    # only frictionless contacts are mapped (no tangential law maps): the arms never act; recorded as Kratos'
    # SphericParticle computes them, the slip velocity and the torque at the contact point
    rules = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact", "rotation": "project"}
    style = Style(colour="#ff7f0e", marker="s", linestyle=":")

    def executables(self) -> tuple[str, ...]:
        return ("python",)

    def argv(self, executable: str, deck: str) -> list[str]:
        return [executable, deck]

    def worker_argv(self, executable: str) -> list[str] | None:
        """The worker (worker.py) when ``executable`` is this Python: it imports Kratos once and runs script
        after script in one process. Another Python (``$DEMCHECK_KRATOS``, ``kratos@LABEL=PATH``) runs a process
        per run."""
        from . import worker

        return [sys.executable, "-m", worker.MODULE] if worker.serves(executable) else None

    def check_deck(self, text: str, files: dict | None = None) -> None:
        from .deck import check

        check(text, files)

    def summary(self, native: Native) -> str:
        return f"{native.normal} E*={native.normal_args[0]:.6g} DAMPING_GAMMA={native.damping_coeff:.6g} no friction"


registry.register(Kratos())
