"""Kratos DEM 10.4.4 (PyPI KratosMultiphysics + KratosDEMApplication): DEM_D_*_viscous_Coulomb laws, driven
by a runner script that the Python with Kratos installed executes (one subprocess a run, like the others, or
script after script in this Python's worker: worker.py)."""

from __future__ import annotations

import re
import sys

from .. import registry
from ..base import Native, PackageEngine, Style, traceback_errors

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

        # judged by its exit, not its pipe's end (discovery.output_of), as the banner itself is
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
    # the frictionless contacts' twin (the arms never act there); a frictional law's twin steps with Kratos' own
    # rules (reference/twins_kratos.py: the contact point at R − δ/2 for a pair, R − δ on a wall; twin_collide)
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

    def errors(self, log: str) -> list[str]:
        """The runner script's Python exception (Kratos's own errors are raised into it)."""
        return traceback_errors(log)

    def read_collision(self, workdir, log: str = ""):
        """The runner script's state table (deck.py, :func:`.deck.read_states`)."""
        from ..output import CollisionOutput
        from .deck import read_states

        return CollisionOutput(read_states(workdir), log)

    def own_twin(self, native: Native) -> bool:
        from .mapping import FRICTION

        return native.tangential == FRICTION

    def twin_collide(self, case, model, native: Native, dt: float):
        """A frictional law's twin steps as Kratos does (reference/twins_kratos.py); a frictionless one is the
        shared verlet twin."""
        from .mapping import twin_law_array

        if not self.own_twin(native):
            return super().twin_collide(case, model, native, dt)
        from ...reference import twins_kratos

        kp = twin_law_array(native, model.pair.m_eff, model.pair.r_eff)
        return twins_kratos.collide(case, model, kp, dt)

    def summary(self, native: Native) -> str:
        head = f"{native.normal} E*={native.normal_args[0]:.6g} DAMPING_GAMMA={native.damping_coeff:.6g}"
        p = native.props
        if native.tangential == "none":
            return head + " no friction"
        return (f"{head} POISSON_RATIO={p['poisson']:.6g} STATIC_FRICTION={p['mu_s']:.6g} "
                f"DYNAMIC_FRICTION={p['mu_d']:.6g} FRICTION_DECAY={p.get('decay', 0.0):.6g}")


registry.register(Kratos())
