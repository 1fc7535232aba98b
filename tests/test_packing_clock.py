"""The packing loop's own clock (reference/packing.py, a timed run's ``clock``; benchmarks/bench_packing_phases.py):
timing a run changes none of its bits, and each phase's time lands in its own row and column. What the phases
cost is measured only in the benchmark, never here."""

from pathlib import Path

import numba
import numpy as np
import pytest

from demcheck import case as C
from demcheck.reference import packing as P

CASES = Path(__file__).resolve().parents[1] / "cases"
SHARE_ONLY = [P.F_LAUNCH, P.F_WAIT, P.K_LAUNCH, P.K_GATHER, P.K_WAIT]  # phases a one-thread run has not


def _same(a, b):
    for name in ("x", "v", "w", "hist", "dmax", "start"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.ke == b.ke and a.n_contacts == b.n_contacts


@pytest.mark.parametrize("threads", [1, pytest.param(2, marks=pytest.mark.skipif(
    numba.config.NUMBA_NUM_THREADS < 2, reason="numba has one thread here"))])
def test_a_timed_run_is_the_untimed_run_bit_for_bit_and_fills_its_phases(threads):
    """A polydisperse pour through its first collisions (rebuilds, recuts, contacts across the shares' cut): the
    same bits timed and untimed; the clock holds the counter's ticks and the CPU ns of each phase that ran, for
    each share and the serial row, and nothing where a phase does not exist."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    untimed = P.simulate(case, duration=0.03, threads=threads)
    clock = np.zeros((threads + 1, 2 * P.PHASES))
    timed = P.simulate(case, duration=0.03, threads=threads, clock=clock)
    _same(untimed, timed)
    assert untimed.n_contacts > 10
    wall, cpu = clock[:, :P.PHASES], clock[:, P.PHASES:]
    assert np.all(clock >= 0.0)
    serial = threads
    assert wall[serial, P.S_REBUILDS] >= 1 and cpu[serial, P.S_REBUILDS] == 0.0  # a count, no CPU column
    for c in range(threads):
        assert wall[c, P.F_WORK] > 0 and wall[c, P.K_WORK] > 0 and cpu[c, P.F_WORK] > 0 and cpu[c, P.K_WORK] > 0
        assert wall[c, P.S_REBUILD:].sum() == 0 and cpu[c, P.S_REBUILD:].sum() == 0  # the serial row's phases
    assert wall[serial, P.S_REBUILD] > 0 and wall[serial, P.S_OTHER] > 0 and wall[serial, :P.S_REBUILD].sum() == 0
    if threads == 1:
        assert wall[0, SHARE_ONLY].sum() == 0 and wall[serial, P.S_BALANCE] == 0  # no regions, no recut
    else:
        assert np.all(wall[:threads, [P.F_LAUNCH, P.F_WAIT, P.K_LAUNCH, P.K_WAIT]] > 0)
        assert wall[serial, P.S_BALANCE] > 0
        assert np.all(cpu[:threads, [P.F_LAUNCH, P.F_WAIT, P.K_LAUNCH, P.K_WAIT]] == 0)  # span two threads


@pytest.mark.parametrize("shape, dtype", [((3, 24), float), ((2, 12), float), ((2, 24), np.int64)])
def test_a_clock_of_another_shape_or_type_is_refused_before_any_step(shape, dtype):
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    st = P.PackState(case)
    x = st.x.copy()
    with pytest.raises(ValueError, match=r"clock: a C-contiguous float64 array of shape \(2, 24\)"):
        P.simulate(case, duration=0.001, state=st, clock=np.zeros(shape, dtype))
    np.testing.assert_array_equal(st.x, x)


def _one_mover(cross: bool, travel: float, axis: int):
    """poured-small without gravity, every sphere at rest but one, lifted clear of the others (a diameter and the
    skin above the highest), moving along ``axis`` so as to travel ``travel`` × the list's skin in the run, from
    0.2 skin inside the periodic boundary (``cross``: it crosses it) or from the box's middle: the in-loop
    rebuilds (the loop's clock) and the mover's end position (× the box's side)."""
    case = C.load(CASES / "optin" / "poured-small.toml", ["run.gravity=[0.0, 0.0, 0.0]"])
    st = P.PackState(case)
    assert not st.v.any() and not st.w.any()
    k = int(np.argmax(st.x[:, 2]))
    r = float(st.rad.max())
    skin = 0.3 * r  # the loop's (packing._setup)
    side = case.packing.box[axis]
    st.x[k, 2] += 2 * r + skin
    st.x[k, axis] = side - 0.2 * skin if cross else 0.5 * side
    dt = P.packing_dt(case)
    steps = 400
    st.v[k, axis] = travel * skin / (steps * dt)
    clock = np.zeros((2, 2 * P.PHASES))
    P.simulate(case, duration=steps * dt, state=st, clock=clock)
    assert st.steps == steps
    return int(clock[-1, P.S_REBUILDS]), float(st.x[k, axis]) / side


@pytest.mark.parametrize("axis", [0, 1])
def test_a_crossing_of_the_periodic_boundary_is_no_move_for_the_list(axis):
    """The list is rebuilt once a sphere has moved half the skin, its displacement since the last rebuild taken
    by minimum image: a sphere crossing the periodic boundary (0.4 skin from just inside it: wrapped to the box's
    other side) makes no rebuild — the old rule, the wrapped position's difference, made one at each crossing, a
    count growing with the box's perimeter at scale — while the same travel away from the boundary makes none
    either, and 0.6 skin makes one, across the boundary or not."""
    rebuilds, end = _one_mover(True, 0.4, axis)  # (crosses halfway)
    assert end < 0.5 and rebuilds == 0  # it wrapped, and no rebuild
    assert _one_mover(False, 0.4, axis)[0] == 0
    assert _one_mover(False, 0.6, axis)[0] == 1
    rebuilds, end = _one_mover(True, 0.6, axis)
    assert end < 0.5 and rebuilds == 1  # the true displacement, across the boundary
