"""The normal laws one module each (hooke, hertz, hls; a family id each, a switch generated from them) compute the
bits the hand-written switch over one viscoelastic module and hls computed: every seed normal model and every
engine twin of them through the normal force facade and the solvers' force functions on a grid of states, and
the case files through every solver that calls the normal force (1-D and 3-D, adaptive and verlet, the packing
loop), against tests/golden/normal_bits.json — written by tests/normal_bits.py run on main at 7b9469c, before the
change (the command is in that module). The golden file holds every case file (``--all``); the test runs
tests/damping_bits.py's share of them (the top-level cases, the suite's normal impacts, the packings), and
``python -m tests.normal_bits --check tests/golden/normal_bits.json --all`` the rest."""

import json
from pathlib import Path

import pytest

from .damping_bits import CASES, case_files, one_case
from .normal_bits import grid

GOLDEN = json.loads((Path(__file__).parent / "golden" / "normal_bits.json").read_text())
FILES = [str(p.relative_to(CASES)) for p in case_files()]


def test_the_golden_file_covers_every_seed_normal_model_and_every_case_file():
    from demcheck.laws import normal

    seeds = {name.removesuffix("-limited") for name in GOLDEN["grid"] if "-pair-" not in name and "-wall-" not in name}
    assert seeds == set(normal.REGISTRY)
    assert {name.rsplit("-", 1)[1] for name in GOLDEN["grid"] if "-pair-" in name or "-wall-" in name} == \
        {"lammps", "liggghts", "yade", "kratos"}
    shipped = {str(p.relative_to(CASES)) for p in case_files(every=True)}
    # every case file of the golden's commit (7b9469c) is still shipped; files added since (the sandpile's heaps) are
    # not in it, and its bits are the split's check, not a list of today's files
    assert set(GOLDEN["cases"]) <= shipped and len(GOLDEN["cases"]) == 122
    assert set(FILES) < set(GOLDEN["cases"])
    cases = [c for f in FILES for c in GOLDEN["cases"][f].values()]
    assert len(cases) >= 25 and sum(isinstance(c, dict) and "3d-adaptive" in c for c in cases) >= 10


def test_the_normal_force_gives_the_same_bits_as_before():
    now = grid()
    assert sorted(now) == sorted(GOLDEN["grid"])
    for name, values in GOLDEN["grid"].items():
        diff = [i for i, (a, b) in enumerate(zip(values, now[name], strict=True)) if a != b]
        assert not diff, f"{name}: {len(diff)} values differ, first at {diff[0]}: {values[diff[0]]} → {now[name][diff[0]]}"


@pytest.mark.parametrize("path", FILES)
def test_every_case_gives_the_same_bits_as_before(path):
    assert one_case(CASES / path) == GOLDEN["cases"][path]
