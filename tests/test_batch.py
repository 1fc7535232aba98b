"""Many reference collisions at once (reference/batch.py, issue 16 item 1): a batched point's row is what
``collide(case)`` and its ``metrics()`` give — the same compiled readers on the same series — and a sweep run in
this process is the batched one."""

import math

import numpy as np
import pandas as pd
import pytest

import demcheck
from demcheck import api
from demcheck.errors import ConfigError
from demcheck.comparisons import sweep
from demcheck.metrics import stepped
from demcheck.reference.batch import collide_many
from demcheck.reference.collision import collide
from demcheck.reference.health import reading

# the 1-D verlet solver's points (every status its rules give here), and points it does not take
POINTS = [
    ("cases/hertz-wall.toml", {}),
    ("cases/hertz-wall.toml", {"impact.speed": 0.3}),
    ("cases/hertz-wall.toml", {"run.dt": 4e-6}),  # unresolved: two steps inside the contact
    ("cases/hertz-wall.toml", {"impact.angle": 30.0}),  # a tangential velocity kept: tangential metrics
    ("cases/hertz-wall.toml", {"run.gravity": [0.0, 0.0, -9.81], "impact.speed": 1e-3, "impact.gap": 1e-4}),
    ("cases/hertz-wall.toml", {"materials.glass.youngs_modulus": 1e4}),  # out-of-range
    ("cases/glass-pair.toml", {}),
    ("cases/glass-pair.toml", {"impact.speed": 1.7}),
    ("cases/oblique-lsd-wall.toml", {}),  # 3-D: solved by collide
]


def _cases():
    return [demcheck.load(path, dict(keys)) for path, keys in POINTS]


def _same(a, b) -> bool:
    return a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))


@pytest.mark.parametrize("method", ["verlet", "adaptive"])
def test_a_batched_row_is_the_collide_result_bit_for_bit(method):
    cases = _cases()
    rows = collide_many(cases, method)
    statuses = set()
    for case, row in zip(cases, rows):
        result = collide(case, method)
        expect = {**result.metrics(), "status": result.status, "message": result.message}
        assert list(row) == list(expect), case.name
        # the normal metrics and the status: the same compiled solve and readers, bit for bit; the tangential
        # ones are computed in the kernel from the same velocities, where numpy's dot products are BLAS's (which
        # may sum or fuse in another order): to round-off
        for key, value in expect.items():
            if key in ("tangential_restitution", "rebound_angle", "rebound_angular_velocity"):
                assert row[key] == pytest.approx(value, rel=1e-12, abs=1e-12, nan_ok=True), key
            else:
                assert _same(row[key], value), (case.name, key, row[key], value)
        statuses.add(row["status"])
    if method == "verlet":
        assert {"ok", "unresolved", "out-of-range"} <= statuses
    assert rows[3]["rebound_angle"] == pytest.approx(30.0, rel=1e-4)  # the wall keeps the tangential velocity


def test_a_point_that_cannot_be_solved_keeps_its_row_with_the_error():
    case = demcheck.load("cases/hertz-wall.toml")
    rows = collide_many([case, case], "verlet", dt=1e-13)  # more steps than a verlet record may hold
    assert all(r["status"].startswith("error: --dt = 1e-13: ") and set(r) == {"status", "message"} for r in rows)


def test_the_api_returns_a_frame_and_checks_its_arguments():
    table = demcheck.collide_many(["cases/hertz-wall.toml", "cases/glass-pair.toml"], method="verlet")
    assert list(table["status"]) == ["ok", "ok"] and table["restitution"].between(0.99, 1.01).all()
    with pytest.raises(ConfigError, match="method = 'euler': must be adaptive or verlet"):
        demcheck.collide_many(["cases/hertz-wall.toml"], method="euler")
    with pytest.raises(ConfigError, match="dt = -1"):
        demcheck.collide_many(["cases/hertz-wall.toml"], dt=-1)


def test_a_sweep_in_this_process_is_the_per_point_one():
    vary = dict(sweep.parse_vary(v) for v in ["impact.speed=0.5:2:5", "run.dt=1e-7,4e-6"])
    points = api._sweep_points("cases/hertz-wall.toml", vary, [])  # api.sweep's grid
    batched = sweep.run_sweep(points, "verlet")
    each = [sweep.point_task(values, case, "reference", "verlet", None) for values, case in points]
    assert batched.equals(pd.DataFrame(each))
    assert set(batched["status"]) == {"ok", "unresolved"}


def test_stepped_reads_a_series_as_its_definition_says():
    """A hand-made series: δ crosses 0 upwards between t = 0 and 1 (at 0.5 by linear interpolation) and downwards
    between 2 and 3 (at 2.5); Fn drops to ≤ 0 between 1 and 2 (at 1.75)."""
    t = np.array([0.0, 1.0, 2.0, 3.0])
    d = np.array([-1.0, 1.0, 2.0, -2.0])
    r = np.array([2.0, 1.5, -1.0, -3.0])
    f = np.array([0.0, 3.0, -1.0, 0.0])
    k_s, t_s, v_in, k_e, t_e, v_out, k_f, t_f, d_max, f_max = stepped(t, d, r, f)
    assert (k_s, t_s, v_in, k_e, t_e, v_out, k_f, t_f, d_max, f_max) == (1, 0.5, 2.0, 3, 2.5, -3.0, 2, 1.75, 2.0, 3.0)
    # never overlapping; a contact that does not end; a NaN inside the window is the window's maximum (numpy's)
    assert stepped(t, -np.abs(d), r, f)[0] == -1
    k_s, _, _, k_e, t_e, v_out, *_ = stepped(t, np.abs(d) + 1.0, r, f)
    assert (k_s, k_e) == (0, 4) and math.isnan(t_e) and math.isnan(v_out)
    assert math.isnan(stepped(t, np.array([-1.0, 1.0, np.nan, -2.0]), r, f)[8])


def test_reading_finds_the_first_bad_row_and_counts_the_overlap():
    t = np.arange(5.0)
    d = np.array([-1.0, 1.0, 3.0, 2.0, -1.0])
    assert reading(t, d, d, d) == (-1, 3, 3.0, -1.0, 4.0)
    d[3] = np.inf
    assert reading(t, d, d, d)[0] == 3
    empty = np.empty(0)
    k_bad, inside, _, d_last, _ = reading(empty, empty, empty, empty)
    assert (k_bad, inside) == (-1, 0) and math.isnan(d_last)
