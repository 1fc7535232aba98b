"""A Yade worker: one Yade process that runs script after script (engines/serve.py's protocol).

``yade -x -n worker.py --parent PID`` (the executable discovery found: ``yade``, or ``yade-float128`` /
``yade-mpfr150`` for ``--precision``, through demcheck's version wrapper) starts Yade once and serves runs: each
deck, a script :mod:`.deck` or :mod:`.packing` wrote and the engine's guard checked (run.py, before the
request), is executed as ``launch.py`` executes it in a process of its own — in Yade's own namespace, here a
fresh copy of it as this script found it, so no name a script sets reaches the next one. After each run
``O.reset()`` gives the next one a new scene: bodies, materials, interactions, engines, ``dt``, time and
iteration count, periodic cell, everything a script sets on ``O``. The scripts set nothing else that outlives
them (their dump file is closed by them, or with their namespace), so a run gives the bytes a fresh process
gives (tests/test_engine_workers.py). Its version is Yade's own ``yade.config.version``, the one ``yade
--version`` prints; a script's exception is printed as a process prints it (the screen) and is the run's error.

Like launch.py this file is run by Yade, not imported by demcheck; it loads engines/serve.py (standard library
only) by path, as Yade's Python has no demcheck.
"""

_YADE_NAMESPACE = dict(globals())  # before this script adds a name: what every deck starts from

import importlib.util  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402


def _serve_module():
    path = Path(sys.argv[0]).resolve().parents[1] / "serve.py"
    spec = importlib.util.spec_from_file_location("demcheck_engines_serve", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


serve = _serve_module()


class Server(serve.Server):
    """The Yade this script runs in."""

    def start(self) -> str:
        import yade.config

        return str(yade.config.version)

    def run(self, deck: str) -> float:
        return serve.run_script(deck, dict(_YADE_NAMESPACE))

    def reset(self, failed: bool) -> None:
        O.reset()  # noqa: F821 - Yade's Omega, in the namespace Yade runs this script in


_code = serve.serve(Server())
if _code:
    sys.exit(_code)
