"""A toy third engine, registered from outside demcheck (``DEMCHECK_ENGINE_PLUGINS=tests.toy_engine``), to
show that an engine is a one-package addition: nothing outside this package names it.

Its "binary" is demcheck's own reference verlet method run in a subprocess (runner.py), reading a JSON
deck and writing a LAMMPS-style dump. Its vocabulary expresses every seed model exactly (the twin is the
seed model), with the seed's kinematic rules.
"""

from __future__ import annotations

import json
import os
import re
import stat
import sys
import tempfile
from pathlib import Path

from demcheck.engines import registry
from demcheck.engines.base import EXACT, Engine, Mapping, Native, Style

ROOT = Path(__file__).resolve().parents[2]


def check_toy_deck(text: str, files: dict | None = None) -> None:
    """The toy's guard: a deck is one JSON object with exactly the keys the toy writes."""
    from demcheck.errors import DemcheckError

    try:
        d = json.loads(text)
    except ValueError as exc:
        raise DemcheckError(f"refusing to run a toy deck that is not JSON: {exc}") from None
    if not isinstance(d, dict) or set(d) != {"case", "dt", "steps"}:
        raise DemcheckError("refusing to run a toy deck with other keys than case, dt, steps")


class Toy(Engine):
    name = "toy"
    title = "Toy"
    release = "toy 1.0"
    how_to_install = "a test engine: DEMCHECK_ENGINE_PLUGINS=tests.toy_engine"
    banner = re.compile(r"^toy engine (\S+)", re.M)
    rules = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact", "rotation": "rescale"}
    style = Style(colour="#9467bd", marker="P", linestyle="-")

    def default_candidates(self) -> list[str]:
        """A wrapper script that runs runner.py with this Python (written once per process)."""
        path = Path(tempfile.gettempdir()) / f"demcheck-toy-engine-{os.getuid()}-{os.getpid()}"
        if not path.exists():
            # the demcheck of this source tree (the engines' environment may not carry PYTHONPATH)
            path.write_text(f"#!/bin/sh\nPYTHONPATH={ROOT}:{ROOT / 'src'}${{PYTHONPATH:+:$PYTHONPATH}} exec {sys.executable} "
                            f"-m tests.toy_engine.runner \"$@\"\n")
            path.chmod(path.stat().st_mode | stat.S_IXUSR)
        return [str(path)]

    def argv(self, executable: str, deck: str) -> list[str]:
        return [executable, "-in", deck, "-log", "log.txt", "-screen", "screen.txt"]

    def check_deck(self, text: str, files: dict | None = None) -> None:
        check_toy_deck(text, files)

    log_files = ("log.txt", "screen.txt")

    def errors(self, log: str) -> list[str]:
        """runner.py's errors: a Python exception."""
        from demcheck.engines.base import traceback_errors

        return traceback_errors(log)

    def read_collision(self, workdir, log: str = ""):
        """runner.py's dump (its own states in the dump custom layout) as the collision record."""
        from pathlib import Path

        from demcheck.engines.dumps import read_dump
        from demcheck.engines.output import STATE_COLUMNS, CollisionOutput
        from demcheck.inputs.common import DUMP_FILE

        return CollisionOutput(read_dump(Path(workdir) / DUMP_FILE, columns=STATE_COLUMNS), log)

    def map(self, model, contact_params: dict) -> Mapping:
        native = Native("toy", normal=model.normal.id, tangential=model.tangential.id, limit=model.limit_force,
                        props={"laws": (model.normal_law, model.tangential_law)})
        return Mapping("toy", EXACT, [], native)

    def twin(self, native: Native, m_eff: float, r_eff: float):
        return native.props["laws"]

    def summary(self, native: Native) -> str:
        return f"{native.normal} × {native.tangential}"

    def collision_deck(self, case, dt=None, length=1.0, native=None, **options):
        from demcheck.inputs import common

        sc = common.scene(case, dt, length)
        text = json.dumps({"case": case.raw, "dt": sc.dt, "steps": sc.steps}, default=list)
        return common.Deck("toy", text, {}, dt=sc.dt, check=check_toy_deck)


registry.register(Toy())
