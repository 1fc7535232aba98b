"""demcheck pack --duration far below one step (issue 32: exit 2 with one line, or a run): it is a run — the
packing's one step (case.packing_run rounds the steps up), the same in the reference and an engine."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from .conftest import ROOT

POURED = ROOT / "src" / "demcheck" / "cases" / "packing" / "poured.toml"


def _pack(*args):
    p = subprocess.run([sys.executable, "-m", "demcheck", "pack", str(POURED), "--duration", "1e-300", "--json",
                        *args], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


@pytest.mark.engine("lammps")
def test_a_duration_below_one_step_is_one_step_in_the_reference_and_an_engine():
    ref, lmp = _pack(), _pack("--engine", "lammps")
    assert ref["particles"] == lmp["particles"] == 2000 and ref["contacts"] == lmp["contacts"] == 0
    assert ref["metrics"]["bed_height"] == pytest.approx(lmp["metrics"]["bed_height"], rel=1e-12)
