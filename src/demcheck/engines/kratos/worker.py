"""A Kratos worker: one process that imports Kratos once and runs runner script after runner script
(engines/serve.py's protocol).

``python -m demcheck.engines.kratos.worker --parent PID`` (this Python: the one with Kratos beside demcheck)
imports KratosMultiphysics and the DEM application once — a process per run spends about half a second on
that — then executes each run's ``in.deck`` (the template of :mod:`.deck`, checked by its guard in run.py) as
``python in.deck`` does, in its work directory.

Kratos keeps state for the life of a process; what a run leaves behind, and why the next run does not see it:

* the script's own names (``CASE``, its ``DemcheckRun`` stage, its ``K.Model()``): each run executes in a
  fresh ``__main__`` namespace, dropped afterwards, and ``gc.collect()`` then destroys that run's Model (its
  model parts, nodes, elements, search structures, strategy) before the next run builds its own;
* what Kratos registers on import (variables, elements, conditions, constitutive laws, applications): done
  once, read-only afterwards, the same objects a fresh process registers;
* parallel utilities: the thread count is read from ``OMP_NUM_THREADS`` (1, set by run.py for workers as for
  processes) when Kratos is imported; no run changes it;
* the logger: every runner sets the default output's severity (WARNING) itself; Kratos's import banners go to
  the worker's start, so a run's screen lacks them (a process's has them) — the only difference in its output;
* the working directory: the stage creates its output folders in the run's directory, and the worker returns
  to its own after every run.

Runs are checked, not trusted, to be independent: a case run after other cases gives the bytes of a fresh
process (tests/test_engine_workers.py). The worker also times each run's solution loop (the stage's
``RunSolutionLoop``: the steps and the dump, not the start-up of the stage) for the benchmark's loop time.

This module imports only the standard library at module level: ``serves`` is asked by the engine object
without loading Kratos.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from ..serve import Server as _Server, run_script, serve

MODULE = "demcheck.engines.kratos.worker"


def version_words(kratos: str, dem: str) -> str:
    """The engine's version from its two distributions' (KratosMultiphysics first), as discovery reads it from
    the Python and results record it: "10.4.4 (DEMApplication 10.4.4)"."""
    return f"{kratos} (DEMApplication {dem})"


def serves(executable: str) -> bool:
    """Whether ``executable`` (the kratos engine discovery found) is this Python (the same interpreter in the
    same environment), whose Kratos the worker imports. Any other Python runs a process per run."""
    exe, here = Path(executable), Path(sys.executable)
    try:
        return exe.parent.resolve() == here.parent.resolve() and os.path.samefile(exe, here)
    except OSError:
        return False


class Server(_Server):
    """This Python's Kratos and DEM application."""

    def __init__(self):
        self.loop = 0.0

    def start(self) -> str:
        from importlib.metadata import version

        import KratosMultiphysics  # noqa: F401 - imported once, for every run
        import KratosMultiphysics.DEMApplication  # noqa: F401
        from KratosMultiphysics.DEMApplication.DEM_analysis_stage import DEMAnalysisStage

        solution_loop = DEMAnalysisStage.RunSolutionLoop

        def timed_solution_loop(stage):
            started = time.perf_counter()
            try:
                solution_loop(stage)
            finally:
                self.loop += time.perf_counter() - started

        DEMAnalysisStage.RunSolutionLoop = timed_solution_loop
        return version_words(version("KratosMultiphysics"), version("KratosDEMApplication"))

    def run(self, deck: str) -> float:
        import builtins

        self.loop = 0.0
        run_script(deck, {"__name__": "__main__", "__file__": deck, "__builtins__": builtins})
        return self.loop

    def reset(self, failed: bool) -> None:
        import gc

        gc.collect()


if __name__ == "__main__":
    sys.exit(serve(Server()))
