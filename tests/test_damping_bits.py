"""The damping laws, one module each, compute the bits the viscoelastic law's single formula computed: every seed
normal model through the compiled normal force and the 1-D adaptive solver's force events on a grid of states,
and the top-level cases, the suite's normal impacts and the packings through every solver that calls the normal
force (1-D and 3-D, adaptive and verlet, the packing loop), against tests/data/damping_bits.json — written by
tests/damping_bits.py run on the code before the damping slot got its own compiled functions (main at 215e3c3;
the command is in that module)."""

import json
from pathlib import Path

import pytest

from .damping_bits import CASES, case_files, grid, one_case

GOLDEN = json.loads((Path(__file__).parent / "data" / "damping_bits.json").read_text())
FILES = [str(p.relative_to(CASES)) for p in case_files()]


def test_the_golden_file_covers_every_seed_normal_model_and_every_file():
    from demcheck.laws import normal

    assert {name.removesuffix("-limited") for name in GOLDEN["grid"]} == set(normal.REGISTRY)
    assert sorted(GOLDEN["cases"]) == sorted(FILES)
    cases = [c for f in FILES for c in GOLDEN["cases"][f].values()]
    assert len(cases) >= 25 and sum(isinstance(c, dict) and "3d-adaptive" in c for c in cases) >= 10


def test_the_normal_force_gives_the_same_bits_as_before():
    now = grid()
    for name, values in GOLDEN["grid"].items():
        diff = [i for i, (a, b) in enumerate(zip(values, now[name], strict=True)) if a != b]
        assert not diff, f"{name}: {len(diff)} values differ, first at {diff[0]}: {values[diff[0]]} → {now[name][diff[0]]}"


@pytest.mark.parametrize("path", FILES)
def test_every_case_gives_the_same_bits_as_before(path):
    assert one_case(CASES / path) == GOLDEN["cases"][path]
