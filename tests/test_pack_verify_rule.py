"""`pack` and `verify` measure a packing by one rule (issue: `pack` stopped early where the kinetic energy dipped —
at a turning point of a layer bouncing in phase — and counted the solid fraction two diameters from the floor and
the surface, `verify` one): both run the case's whole duration and use packing_metrics.BULK_MARGIN."""

import json
import math
import subprocess
import sys

import pytest

from demcheck.case import load
from demcheck.comparisons import packing_metrics as PM
from demcheck.comparisons.packing_suite import reference_packing

from .conftest import CASES


@pytest.mark.parametrize("name", ["layer-kk", "column-lsd"])
def test_pack_and_verify_measure_the_same_packing(name):
    path = CASES / "packing" / f"{name}.toml"
    p = subprocess.run([sys.executable, "-m", "demcheck", "pack", str(path), "--json"], capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    case = load(path)
    x, rad, contacts, ke, time, _ = reference_packing(case)
    assert out["time"] == pytest.approx(time, rel=1e-12)  # the whole duration, no early stop
    box = case.packing.box if case.packing else None
    m = PM.compute(x, rad, box=box, forces=contacts[:, 3], overlaps=contacts[:, 2], ke=[e for _, e in ke])
    compared = 0
    for k in ("solid_fraction", "coordination_number", "bed_height", "max_overlap_ratio"):
        if k not in m:
            continue
        if math.isnan(m[k]):  # a layer too thin for a bulk slab: JSON has null
            assert out["metrics"][k] is None, k
        else:
            assert out["metrics"][k] == pytest.approx(m[k], rel=1e-12, abs=1e-15), k
            compared += 1
    assert compared >= 2
