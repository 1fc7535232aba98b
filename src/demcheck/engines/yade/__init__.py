"""Yade 2023.02a (Debian's ``yade``): a Python script run headless by ``yade -x -n``.

A collision deck is a Python script generated from a fixed template with only numbers substituted
(:mod:`.deck`), checked before every run by :func:`.deck.check_script` (parsed with ``ast``: only the
template's names, attributes, calls and numeric constants). It steps Yade's leap-frog NewtonIntegrator one
step at a time and writes the bodies' states as a plain table (float64, %.17g), which :meth:`Yade.read_collision`
reads into the collision record (engines/output.py), as every engine's reader does. A packing script (:mod:`.packing`) comes from a second fixed
template with its own guard; :meth:`Yade.check_deck` picks the guard by the script's first line.
"""

from __future__ import annotations

import functools
import os
import re
import shlex
import shutil
import tempfile
from pathlib import Path

import numpy as np

from .. import registry
from ..base import Native, PackageEngine, Style, traceback_errors

LAUNCHER = Path(__file__).with_name("launch.py")
# a line of Yade's logger (its colours taken off by engines/serve.plain_text): ``<WARNING> file:line function: text``
_LOGGED = re.compile(r"^<(WARNING|ERROR|FATAL ERROR)> (.*)$", re.M)
WORKER = Path(__file__).with_name("worker.py")


@functools.lru_cache(maxsize=None)
def _versioned(executable: str) -> str:
    """A wrapper of ``executable`` that answers ``-h`` with Yade's version (Yade's own ``-h`` does not name it;
    demcheck's discovery reads the version from ``<exe> -h``) and passes anything else on. Kept in the user's
    cache (one per executable, mode 0700, rewritten atomically), so runs do not leave a directory each; a private
    temporary directory, removed at exit, where the cache cannot be written."""
    import atexit
    import hashlib

    exe = shlex.quote(executable)
    text = ("#!/bin/sh\n# demcheck: Yade with its version for -h\n"
            f'if [ "$#" = 1 ] && [ "$1" = -h ]; then exec {exe} --version; fi\n'
            f'exec {exe} "$@"\n')
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "demcheck" / "yade"
    where = root / hashlib.sha256(executable.encode()).hexdigest()[:16]
    try:
        where.mkdir(parents=True, exist_ok=True, mode=0o700)
        path = where / "yade"
        if not (path.is_file() and path.read_text() == text):
            tmp = where / f".yade.{os.getpid()}"
            tmp.write_text(text)
            tmp.chmod(0o700)
            os.replace(tmp, path)
        return str(path)
    except OSError:
        where = Path(tempfile.mkdtemp(prefix="demcheck-yade-"))
        atexit.register(shutil.rmtree, where, True)
        path = where / "yade"
        path.write_text(text)
        path.chmod(0o700)
        return str(path)


class _Banner:
    """Discovery reads ``<executable> -h``. Through demcheck's launcher (:func:`_versioned`) that prints
    ``Yade version: 2023.02a``; a build named directly (``--engine yade@f128=/usr/bin/yade-float128``, whose
    executable discovery runs as it is) prints only Yade's usage line, ``usage: yade-float128 [options] [
    simulation.xml[.bz2] | script.py ...``, which names the program but not its version. Then the program it names
    is found on PATH and asked ``--version``. A match's group 1 is the version ("2023.02a")."""

    VERSION = re.compile(r"^Yade version: *(\S+)", re.M)
    USAGE = re.compile(r"^usage: (yade[A-Za-z0-9._-]*) \[options\] \[ simulation\.xml", re.M)

    def __init__(self, timeout: float = 20.0):
        self.timeout = timeout

    def search(self, text: str):
        found = self.VERSION.search(text or "")
        if found:
            return found
        usage = self.USAGE.search(text or "")
        exe = shutil.which(usage.group(1)) if usage else None
        if not exe:
            return None
        from ..discovery import output_of

        # judged by its exit, not its pipe's end: a helper the launcher leaves behind holds no wait here
        out, _ = output_of([exe, "--version"], self.timeout, "`--version`")
        return self.VERSION.search(out) if out is not None else None


class Yade(PackageEngine):
    name = "yade"
    title = "Yade"
    release = "Yade 2023.02a"
    how_to_install = "apt-get install yade (Debian), or scripts/install-engines.sh as root"
    banner = _Banner()
    # slip velocity and torques at the contact point (R − δ/2 for a pair); the history's rotation is Yade's
    # first-order ScGeom::rotate, which the twin's "project" matches where the normal does not turn (walls,
    # head-on pairs); on a wall both arms are R − δ, the point on the wall's plane (measured: these rules, and
    # no other combination of R, R − δ/2 and R − δ, meet a spinning oblique wall impact to round-off)
    rules = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "surface", "rotation": "project",
             "wall_slip_arm": "surface"}
    style = Style(colour="#e377c2", marker="X", linestyle=":")
    # Debian's builds of the same 2023.02a code in extended precision (docs/yade.md)
    precisions = {"float128": "yade-float128", "mpfr150": "yade-mpfr150"}

    def executables(self) -> tuple[str, ...]:
        return ("yade",)

    def candidates(self) -> list[str]:
        env = os.environ.get("DEMCHECK_YADE")
        if env and not Path(env).exists():
            return [env]  # discovery names it: it does not start
        found = [env] if env else [shutil.which(e) for e in self.executables()]
        return [_versioned(str(Path(e).resolve())) for e in found if e]

    def build_executable(self, path: str) -> str:
        return _versioned(str(Path(path).resolve()))  # the version of this very binary, asked through the wrapper

    def argv(self, executable: str, deck: str) -> list[str]:
        return [executable, "-x", "-n", str(LAUNCHER), deck]

    def worker_argv(self, executable: str) -> list[str] | None:
        """The worker (worker.py) in this very executable: one Yade process, script after script."""
        return [executable, "-x", "-n", str(WORKER)]

    def check_deck(self, text: str, files: dict | None = None) -> None:
        """The guard of the template the script opens as: a packing script's (its first line), else the
        collision script's; both refuse anything their template does not write."""
        from . import deck, packing, scenario

        if scenario.is_scenario_script(text):
            return scenario.check_script(text, files)
        (packing.check_script if packing.is_packing_script(text) else deck.check_script)(text, files)

    def errors(self, log: str) -> list[str]:
        """The script's Python exception (Yade prints its traceback and ends)."""
        return traceback_errors(log)

    def warnings(self, log: str) -> list[str]:
        """The lines of Yade's logger at WARNING, ERROR or FATAL ERROR level (``<WARNING> file:line function:
        message``): a run they appear in is judged by its output, as Yade goes on past them."""
        return [f"{level}: {text.strip()}" for level, text in _LOGGED.findall(log)]

    def read_collision(self, workdir, log: str = ""):
        """The collision script's state table (deck.py, :func:`.deck.read_states`)."""
        from ..output import CollisionOutput
        from .deck import read_states

        return CollisionOutput(read_states(workdir), log)

    def read_packing(self, workdir, log: str, box=None):
        """The packing script's final state, contacts and kinetic energy lines (:func:`.packing.read`)."""
        from .packing import read

        return read(self, workdir, log, box)

    def summary(self, native: Native) -> str:
        return f"{native.normal} + {native.tangential}"

    def twin_rules(self, native: Native) -> dict:
        return self._part("mapping").twin_rules(native, self.rules)

    def own_twin(self, native: Native) -> bool:
        return native.normal == self._part("mapping").LUDING

    def twin_collide(self, case, model, native: Native, dt: float):
        """The Luding law's twin steps its own hysteresis (reference/twins_luding.py); the others are the shared
        verlet twin with :meth:`twin_rules`."""
        if not self.own_twin(native):
            return super().twin_collide(case, model, native, dt)
        mapping = self._part("mapping")
        from ...reference import twins_luding

        return twins_luding.collide(case, model, mapping.twin_law_array(native, case), dt)


registry.register(Yade())
