"""Child of bench_adaptive.py (section 5): the suite's oblique cases, every variant, solved by the adaptive 3-D method
at the case's default tolerance with the demcheck found first on sys.path (PYTHONPATH: a tree before a change, or
this one). Prints one JSON object: per variant the median CPU time (time.process_time: the machine is shared, and a
solve's CPU time depends far less on the others' load than its wall time) of the compiled kernel alone and of
collide(), the output points, and the metrics. Arguments: repeats, then the suite files' names to run (all)."""

import glob
import itertools
import json
import statistics
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from demcheck import case as C
from demcheck.laws.model import resolve
from demcheck.reference import adaptive3d, collision3d
from demcheck.resources import case_path


def variants(only=()):
    for path in sorted(glob.glob(str(Path(case_path("suite/oblique-lth")).parent / "oblique-*.toml"))):
        name = Path(path).stem
        if only and name not in only:
            continue
        raw0 = tomllib.loads(Path(path).read_text())
        var = raw0.pop("variants", {})
        for vals in itertools.product(*var.values()):
            raw = json.loads(json.dumps(raw0))
            for key, v in zip(var, vals):
                table, field = key.split(".")
                raw[table][field] = v
            yield f"{name}[{','.join(f'{v:g}' for v in vals)}]", raw


def main(repeat: int, only=()) -> None:
    orig = adaptive3d.adaptive_3d
    out = {}
    for label, raw in variants(only):
        case = C.from_dict(raw)
        model = resolve(case)
        kernel = []

        def timed(*a):
            t0 = time.process_time()
            r = orig(*a)
            kernel.append(time.process_time() - t0)
            return r

        collision3d.adaptive3d.adaptive_3d = timed
        full = []
        r = collision3d.collide(case, model, "adaptive")  # warm
        once = kernel[-1]
        kernel.clear()
        for _ in range(1 if once > 0.3 else repeat):
            t0 = time.process_time()
            r = collision3d.collide(case, model, "adaptive")
            full.append(time.process_time() - t0)
        collision3d.adaptive3d.adaptive_3d = orig
        m = {k: (None if not np.isfinite(v) else float(v)) for k, v in r.metrics().items()}
        out[label] = {"kernel": statistics.median(kernel), "collide": statistics.median(full),
                      "points": int(r.meta["steps"]), "status": r.status, "metrics": m}
    print(json.dumps(out))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5, tuple(sys.argv[2:]))
