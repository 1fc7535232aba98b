"""The tangential laws, one module each, compute the bits the seed's single switch computed: every registered
tangential seed model (and the spring's truncations) through the 3-D adaptive and verlet solvers and the packing
loop, on an oblique spinning impact on a wall and of a pair, against tests/data/tangential_bits.json — written
by tests/tangential_bits.py run on the code before the move (commit 8f27648; the command is in that module)."""

import json
from pathlib import Path

import pytest

from .tangential_bits import VARIANTS, one

GOLDEN = json.loads((Path(__file__).parent / "data" / "tangential_bits.json").read_text())


def test_the_golden_file_covers_every_registered_tangential_model():
    from demcheck.laws import tangential

    assert {law for law, _ in VARIANTS} == set(tangential.REGISTRY)
    assert len(GOLDEN) == 2 * len(VARIANTS)


@pytest.mark.parametrize("law,params", VARIANTS, ids=[f"{law}-{'-'.join(map(str, p.values()))}" for law, p in VARIANTS])
@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
def test_every_tangential_law_gives_the_same_bits_as_before(law, params, wall):
    key = f"{law}{json.dumps(params, sort_keys=True)}{'-wall' if wall else '-pair'}"
    assert one(law, params, wall) == GOLDEN[key]
