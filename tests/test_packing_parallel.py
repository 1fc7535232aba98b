"""The packing loop on several threads (issue 16, item 4): numba threads over shares of the particles and of the
Verlet list's rows, race-free — a contact's state is updated only by the thread that owns its row, a thread writes
the forces of its own particles and puts what it adds for another share's particle into its own buffer, summed
after the loop (reference/packing.py, run_threaded). What the threads compute is tested here; how fast they are,
only in benchmarks/bench_packing.py."""

import copy
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference import packing as P

CASES = Path(__file__).resolve().parents[1] / "cases"
two_threads = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="numba has one thread here")


def _states_equal(a, b):
    for name in ("x", "v", "w", "hist", "dmax", "start"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    np.testing.assert_array_equal(a.nbj[:a.start[-1]], b.nbj[:b.start[-1]])  # the list's entries (then spare room)
    assert a.n_contacts == b.n_contacts
    np.testing.assert_array_equal(a.contacts[:a.n_contacts], b.contacts[:b.n_contacts])
    assert a.ke == b.ke


def test_one_thread_of_the_threaded_loop_is_the_serial_loop_bit_for_bit(monkeypatch):
    """The threaded kernel on one thread (one share: no far buffer, the threaded rebuild, the second half kick
    fused with the next step's first) computes what the serial kernel does, in the same order: the same bits, on
    a polydisperse pour (three species: six pair laws and three wall laws) through its first collisions, with
    the contact records of the last step."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    serial = P.simulate(case, duration=0.04)
    P._prefer_openmp()  # as advance() does before a threaded run
    monkeypatch.setattr(P, "run", lambda *args: P.run_threaded(*args, 1))
    threaded = P.simulate(case, duration=0.04)
    assert serial.n_contacts > 20
    _states_equal(serial, threaded)


@two_threads
def test_two_threads_meet_one_to_round_off_over_a_short_horizon_of_a_pour():
    """Two threads against one on the same pour. A particle's force is summed in another order (its own share's
    contacts, then what the share before it added), which changes the last bits, and a pour is chaotic:
    collisions amplify a difference by orders of magnitude every few milliseconds (measured on this packing:
    1e-16 of the speeds at 0.02 s, 1e-12 at 0.025 s, 1e-7 m in position at 0.05 s). So the comparison is over a
    short horizon, the first 0.025 s (31 contacts, the first collisions with the floor and between spheres),
    where the difference measured 3e-12 of the forces and 4e-12 of the spins; the bound, 1e-8 of each
    quantity's largest value, leaves room for another machine's round-off and is far below anything physical.
    (On a settled bed, where chaos has nothing to amplify, two threads stayed within 5e-11 of one in the forces
    over 0.1 s: docs/packing.md.)"""
    case = C.load(CASES / "optin" / "poured-small.toml")
    before = numba.get_num_threads()
    one = P.simulate(case, duration=0.025, threads=1)
    two = P.simulate(case, duration=0.025, threads=2)
    assert numba.get_num_threads() == before  # the thread count is set for the run only
    nc = one.n_contacts
    assert nc > 20 and two.n_contacts == nc
    # contacts among the first and the last particles: both shares hold contacts
    assert one.contacts[:nc, 0].min() < 75 <= one.contacts[:nc, 0].max()
    np.testing.assert_array_equal(one.contacts[:nc, :2], two.contacts[:nc, :2])  # the same pairs touch
    tol = 1e-8
    for col, name in ((2, "overlap"), (3, "Fn"), (4, "|Ft|")):
        a, b = one.contacts[:nc, col], two.contacts[:nc, col]
        np.testing.assert_allclose(b, a, rtol=0, atol=tol * np.abs(a).max(), err_msg=name)
    for name in ("x", "v", "w"):
        a, b = getattr(one, name), getattr(two, name)
        np.testing.assert_allclose(b, a, rtol=0, atol=tol * np.abs(a).max(), err_msg=name)


@two_threads
def test_a_run_on_two_threads_continues_a_state_like_one():
    """advance() on threads carries the state as on one: the Verlet list, its contact states (walls first, then
    each pair beside its entry) and the contact records. Two threads then one on the same state against one
    then one, on the first collisions of a polydisperse pour."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    start = P.simulate(case, duration=0.03)
    a, b = copy.deepcopy(start), copy.deepcopy(start)
    P.simulate(case, duration=0.005, state=a, threads=2)
    P.simulate(case, duration=0.005, state=a, threads=1)
    P.simulate(case, duration=0.005, state=b, threads=1)
    P.simulate(case, duration=0.005, state=b, threads=1)
    assert a.n_contacts == b.n_contacts > 10
    np.testing.assert_array_equal(a.start, b.start)
    np.testing.assert_array_equal(a.nbj[:a.start[-1]], b.nbj[:b.start[-1]])
    for name in ("x", "v", "w", "hist", "dmax"):
        u, w = getattr(a, name), getattr(b, name)
        np.testing.assert_allclose(u, w, rtol=0, atol=1e-8 * np.abs(w).max(), err_msg=name)


@pytest.mark.parametrize("threads", [0, -1, 1.5, "2", True, None, numba.config.NUMBA_NUM_THREADS + 1])
def test_a_bad_number_of_threads_is_one_clear_line_before_anything_runs(threads):
    case = C.load(CASES / "packing" / "column-lsd.toml")
    st = P.PackState(case)
    x = st.x.copy()
    with pytest.raises(ConfigError) as info:
        P.simulate(case, state=st, threads=threads)
    message = str(info.value)
    assert info.value.exit_code == 2 and "\n" not in message
    assert message.startswith("--threads = ")
    assert f"must be a whole number from 1 to {numba.config.NUMBA_NUM_THREADS}" in message
    np.testing.assert_array_equal(st.x, x)  # refused before any step
    with pytest.raises(ConfigError):
        P.advance(case, st, 1e-6, 10, threads=threads)


def test_numba_num_threads_bounds_the_threads():
    """NUMBA_NUM_THREADS is the most threads a run may ask for (numba cannot start more)."""
    script = ("from demcheck import case as C\nfrom demcheck.reference import packing as P\n"
              f"P.simulate(C.load({str(CASES / 'packing' / 'column-lsd.toml')!r}), threads=2)\n")
    p = subprocess.run([sys.executable, "-c", script], env={**os.environ, "NUMBA_NUM_THREADS": "1"},
                       capture_output=True, text=True)
    assert p.returncode != 0
    assert "demcheck.errors.ConfigError: --threads = 2: must be a whole number from 1 to 1" in p.stderr


@two_threads
def test_the_warm_up_compiles_the_threaded_kernel():
    """`demcheck warmup` compiles the threaded kernel too (cached on disk like the others), so that a first run on
    several threads does not compile it; one specialisation each."""
    from demcheck.comparisons.warmup import _packing

    _packing()
    assert len(P.run.signatures) == 1 and len(P.run_threaded.signatures) == 1


def _pack(*args):
    return subprocess.run([sys.executable, "-m", "demcheck", "pack", *args], capture_output=True, text=True,
                          timeout=600)


@pytest.mark.parametrize("args, rule", [
    (["--threads", "0"], "--threads = 0: must be >= 1"),
    (["--threads", "1.5"], "--threads = '1.5': must be an integer >= 1"),
    (["--threads", "4096"], "--threads = 4096: must be a whole number from 1 to "),
    (["--threads", "2", "--engine", "lammps"], "--threads = 2: applies to the reference"),
    (["--mpi", "2"], "--mpi = 2: applies to an engine"),
])
def test_pack_threads_and_ranks_are_checked_in_one_line(args, rule):
    p = _pack(str(CASES / "packing" / "column-lsd.toml"), *args)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and rule in lines[0], p.stderr


@two_threads
def test_pack_on_two_threads_settles_the_column_as_on_one():
    """`demcheck pack --threads 2` runs the threaded loop and says so; a settled column's metrics are the one-thread
    run's to round-off (a settled stack has nothing chaotic to amplify the summation order)."""
    import json

    one = json.loads(_pack(str(CASES / "packing" / "column-lsd.toml"), "--json").stdout)
    p = _pack(str(CASES / "packing" / "column-lsd.toml"), "--threads", "2", "--json")
    assert p.returncode == 0, p.stderr
    two = json.loads(p.stdout)
    assert (one["threads"], two["threads"]) == (1, 2)
    assert two["contacts"] == one["contacts"]
    for k, v in one["metrics"].items():
        if isinstance(v, float):
            assert two["metrics"][k] == pytest.approx(v, rel=1e-9, abs=1e-12 * max(1.0, abs(v))), k


def test_a_run_that_goes_non_finite_stops_in_the_serial_loop_s_state(monkeypatch):
    """A state that is not finite (one sphere's speed NaN: what a blown-up step leaves) stops the run at its first
    step (the kinetic energy not finite after the kick, the next step's half kick and drift done in the same pass:
    both loops fuse them). The threaded loop on one thread stops where the serial one does and leaves the same
    state, bit for bit."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    dt = P.packing_dt(case)

    def state():
        st = P.PackState(case)
        st.v[7, 2] = np.nan
        return st

    serial = state()
    ke_s, _, flags_s = P.advance(case, serial, dt, 10, ke_every=1)
    assert flags_s[1] == 1  # the serial loop stopped: non-finite
    P._prefer_openmp()
    monkeypatch.setattr(P, "run", lambda *args: P.run_threaded(*args, 1))
    threaded = state()
    ke_t, _, flags_t = P.advance(case, threaded, dt, 10, ke_every=1)
    assert flags_t[1] == 1
    np.testing.assert_array_equal(ke_s, ke_t)
    for name in ("x", "v", "w"):
        np.testing.assert_array_equal(getattr(serial, name), getattr(threaded, name), err_msg=name)


@pytest.mark.parametrize("old_skin", [1.2e-3, 0.0])
@pytest.mark.parametrize("cut", [[0, 40, 41, 120], [0, 0, 60, 120], [0, 120, 120, 120]])
def test_the_threaded_rebuild_is_the_serial_one(cut, old_skin):
    """The Verlet list built by shares (here three, uneven: one of a single row, and empty ones) and laid end to
    end is the serial rebuild's: the same rows, entries, carried contact states and array lengths, on a dense
    cloud whose list is longer than the first guess (NB_PER_PARTICLE a row). From an old list of the same reach
    each share's rows fit the room it is given (the threaded path: asserted); from a shorter one the rows outgrow
    it and the serial rebuild takes over."""
    rng = np.random.default_rng(7)
    n, r = 120, 1e-3
    x = rng.uniform(0.0, 8e-3, (n, 3))
    rad = np.full(n, r)
    lo, hi, periodic = np.zeros(3), np.array([8e-3, 8e-3, 8e-3]), np.array([True, True])
    skin = 1.2e-3
    empty = (np.zeros(n + 1, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0))
    old = P._rebuild(x, rad, lo, hi, periodic, old_skin, *empty, 0)
    dmax = rng.uniform(0.0, 1.0, old[3].shape[0]) * (rng.uniform(size=old[3].shape[0]) < 0.5)  # states to carry
    old = (old[0], old[1], rng.uniform(size=(old[1].shape[0], 3)), dmax)
    x2 = x + rng.normal(0.0, 2e-5, x.shape)
    serial = P._rebuild(x2, rad, lo, hi, periodic, skin, *old, 0)
    threaded = P._rebuild_threaded(x2, rad, lo, hi, periodic, skin, *old, 0, np.array(cut, np.int64))
    new_start = serial[0]
    assert new_start[-1] > P.NB_PER_PARTICLE * n  # the list outgrew the first guess
    shares = [(cut[c], cut[c + 1]) for c in range(len(cut) - 1)]
    room = max([P.NB_PER_PARTICLE] + [max(P.NB_PER_PARTICLE * (b - a), (old[0][b] - old[0][a]) * 5 // 4
                                          + P.NB_PER_PARTICLE) for a, b in shares])
    fits = max(new_start[b] - new_start[a] for a, b in shares) <= room
    assert fits == (old_skin == skin)
    for name, a, b in zip(("start", "nbj", "hist", "dmax"), serial, threaded):
        assert a.shape == b.shape, name
        if name == "nbj":
            a, b = a[:new_start[-1]], b[:new_start[-1]]  # the entries (then spare room)
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert (serial[3] != 0.0).sum() > 10  # states were carried over


def test_the_kick_regions_own_cut_gathers_every_far_row_once_in_the_force_shares_order():
    """The kick region cuts the particles by its own work (a particle, and GATHER_COST for each far buffer holding
    a row of it), not by the force region's contacts: its shares hold about equal cost, and together they add every
    far-buffer row once, into the particle it belongs to, in the order of the force region's shares — what each
    particle's force-region share added before (the same sums, bit for bit), each row then zeroed."""
    rng = np.random.default_rng(7)
    n = 1000
    chunks = np.array([0, 300, 700, n], np.int64)
    far = np.array([650, 1000, n], np.int64)
    f_far = np.zeros((3, n, 3))
    tq_far = np.zeros((3, n, 3))
    for c in range(3):
        f_far[c, chunks[c + 1]:far[c]] = rng.normal(size=(far[c] - chunks[c + 1], 3))
        tq_far[c, chunks[c + 1]:far[c]] = rng.normal(size=(far[c] - chunks[c + 1], 3))
    f, tq = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    want_f, want_tq = f.copy(), tq.copy()
    for c in range(3):  # the force shares' order: share c's buffer after those before it
        want_f += f_far[c]
        want_tq += tq_far[c]
    kicks = np.empty(4, np.int64)
    P._kick_cut(chunks, far, kicks)
    assert kicks[0] == 0 and kicks[-1] == n and np.all(np.diff(kicks) > 0)
    assert not np.array_equal(kicks, chunks)
    cost = 1.0 + P.GATHER_COST * sum((np.arange(n) >= chunks[c + 1]) & (np.arange(n) < far[c]) for c in range(3))
    shares = [cost[kicks[b]:kicks[b + 1]].sum() for b in range(3)]
    assert max(shares) - min(shares) <= 2 * cost.max()
    for b in range(3):
        P._gather(kicks[b], kicks[b + 1], chunks, far, f_far, tq_far, f, tq)
    np.testing.assert_array_equal(f, want_f)
    np.testing.assert_array_equal(tq, want_tq)
    assert not f_far.any() and not tq_far.any()


def test_the_force_cut_weighs_contacts_as_measured():
    """The force region's cut weighs a touching pair PAIR_COST list entries and a wall contact WALL_COST besides
    the row's ROW_COST (and WALL_TEST_COST a wall): rows alike but for their contacts are cut where the weighted
    costs are even (the bed's rows, full of contacts, in a smaller share)."""
    n, n_w = 400, 1
    start = np.arange(n + 1, dtype=np.int64) * 2  # two entries a row
    dmax = np.zeros(n * n_w + 2 * n)
    dmax[n * n_w:n * n_w + 2 * 100] = 1e-6  # rows 0…99: both pairs touching
    dmax[:100] = 1e-6  # and their walls
    chunks = np.empty(3, np.int64)
    P._balance(start, n_w, dmax, chunks)
    row = P.ROW_COST + P.WALL_TEST_COST + 2
    cost = np.full(n, row)
    cost[:100] += 2 * P.PAIR_COST + P.WALL_COST
    half = np.searchsorted(np.cumsum(cost), cost.sum() / 2)
    assert abs(chunks[1] - half) <= 1 and chunks[1] < n // 2
