"""The 1-D (head-on) and 3-D collision solvers solve the same head-on impacts: before their integrator cores
become one (issue "Engines as plug-ins", item 4), they must agree on every head-on case of the default
suite. Measured today: 9e-11 in restitution (BSHP, 10 m/s), ≤ 6e-12 in contact time, maximum overlap and
peak force — both run DP5 at rtol 1e-13 with their own error norms (1-D: the overlap and its rate; 3-D: the
positions, velocities and spins of both bodies), so their answers differ at the level of the tolerance,
not of round-off. The bound says that: 2e-10."""

from __future__ import annotations

import pytest

from demcheck import case as C
from demcheck.reference import collision, collision3d
from demcheck.laws.model import resolve

from .conftest import CASES

HEAD_ON = [case for f in sorted((CASES / "suite").glob("normal-*.toml")) for case in C.expand(f)]


@pytest.mark.parametrize("case", HEAD_ON, ids=[c.name for c in HEAD_ON])
def test_the_1d_and_3d_solvers_agree_head_on(case):
    model = resolve(case)
    assert collision.is_one_dimensional(case, model)
    a = collision.collide(case, "adaptive").metrics()
    b = collision3d.collide(case, model, "adaptive").metrics()
    for k in ("restitution", "contact_time", "max_overlap", "peak_force"):
        assert b[k] == pytest.approx(a[k], rel=2e-10), k
