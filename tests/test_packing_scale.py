"""The packing loop at scale (issue 33): what its speed-ups keep — the fused integration pass is the unfused
velocity Verlet bit for bit; a share's far buffer is added in over the rows it can reach. How fast, only in
benchmarks/bench_packing_scale.py and docs/packing.md ("At scale")."""

import copy
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.reference import packing as P
from demcheck.reference.collision3d import rules_array

CASES = Path(__file__).resolve().parents[1] / "cases"


def _unfused(case, st, dt, steps):
    """Velocity Verlet written out as the engines' fix nve/sphere reads — a half kick and a drift, the forces, a
    half kick, each a pass of its own over the particles (numpy) — around the loop's own force and rebuild kernels,
    from the loop's own setup: the loop as it was before its passes were fused."""
    sp, laws_n, laws_t, wall_n, wall_t = P.resolve_laws(case)
    lawn, lawt = P.law_table(laws_n, laws_t, wall_n, wall_t)
    walls = np.array([[*w.point, *w.normal] for w in case.walls], float).reshape(-1, 6)
    g = np.asarray(case.run.gravity, float)
    lo, hi, periodic = P.box_of(case, st.x, st.rad)
    rules = rules_array(None)
    x, v, w, rad, mass, n = st.x, st.v, st.w, st.rad, st.mass, len(st.rad)
    inertia, period, skin, _, _, x_ref, f, tq, start, nbj, hist, dmax, _ = P._setup(
        x, v, w, rad, mass, sp, laws_n.shape[0], lawn, lawt, walls, lo, hi, periodic, dt, steps, 1, st.start, st.nbj,
        st.hist, st.dmax, rules, *P.NO_ROLLING)
    ke, rebuilds = [], 0
    for _ in range(steps):
        v += 0.5 * dt * (f / mass[:, None] + g)
        x += dt * v
        w += 0.5 * dt * tq / inertia[:, None]
        for k in range(2):
            below, above = x[:, k] < lo[k], x[:, k] >= hi[k]
            x[below, k] += hi[k] - lo[k]
            x[above & ~below, k] -= hi[k] - lo[k]
        d = x - x_ref
        if (d[:, 0] ** 2 + d[:, 1] ** 2 + d[:, 2] ** 2).max() > (0.5 * skin) ** 2:
            start, nbj, hist, dmax = P._rebuild(x, rad, lo, hi, periodic, skin, start, nbj, hist, dmax,
                                                n * walls.shape[0])
            x_ref = x.copy()
            rebuilds += 1
        f[:], tq[:] = 0.0, 0.0
        P._contact_forces(np.int64(0), n, x, v, w, rad, sp, laws_n.shape[0], lawn, lawt, walls, period, start, nbj,
                          hist, dmax, f, tq, f, tq, np.zeros((0, 3)), dt, np.bool_(True), rules, *P.NO_ROLLING)
        v += 0.5 * dt * (f / mass[:, None] + g)
        w += 0.5 * dt * tq / inertia[:, None]
        e = 0.0
        for i in range(n):  # in the loop's order
            e += 0.5 * mass[i] * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
        ke.append(e)
    return ke, rebuilds, hist, dmax


@pytest.mark.parametrize("threads", [0, 1])
def test_the_fused_integration_pass_is_the_unfused_velocity_verlet_bit_for_bit(threads, monkeypatch):
    """The loop makes one pass over the particles a step besides the force loop (the second half kick, the next
    step's first half kick and drift, the forces zeroed) where velocity Verlet reads as three: the same arithmetic
    per particle in the same order, so the same bits — positions, velocities, spins, contact states and the
    kinetic energy — on a polydisperse pour through its first collisions, list rebuilds included; the serial
    kernel and the threaded one on one thread alike."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    dt, steps = P.packing_dt(case), 6000
    landing = P.simulate(case, duration=0.03)  # the first spheres on the floor, the rest falling
    ref = copy.deepcopy(landing)
    ke, rebuilds, hist, dmax = _unfused(case, ref, dt, steps)
    if threads:
        P._prefer_openmp()
        monkeypatch.setattr(P, "run", lambda *args: P.run_threaded(*args, threads))
    st = copy.deepcopy(landing)
    ke_loop, _, flags = P.advance(case, st, dt, steps, ke_every=1)
    assert rebuilds >= 3 and (dmax != 0.0).sum() > 20 and flags[1] == 0  # rebuilds, contacts
    for name in ("x", "v", "w"):
        np.testing.assert_array_equal(getattr(st, name), getattr(ref, name), err_msg=name)
    np.testing.assert_array_equal(st.hist, hist)
    np.testing.assert_array_equal(st.dmax, dmax)
    # the energy summed here in Python (numpy scalars) and there compiled: the loop before the fusion read the
    # same, a few of the 6000 values one unit of the last place apart
    np.testing.assert_allclose(ke_loop[1:], ke, rtol=1e-15, atol=0.0)


def test_pairs_and_walls_each_keep_their_own_law_in_the_force_loop():
    """The force loop keeps the pairs' law and the walls' law side by side, each fetched again only when it
    changes (a sphere on the floor went from one to the other and back in each row). Three species, each sphere
    on the floor and touching the next, sliding and spinning, so that every row switches between a pair law and a
    wall law: the forces and torques of all the contacts in one call are those of the pair contacts alone plus
    the wall contacts alone (each call with one kind of law only), to round-off, and every contact carries load."""
    case = C.load(CASES / "optin" / "poured-small-poly.toml")
    sp_case, rep = P.species_of(case)
    sp, laws_n, laws_t, wall_n, wall_t = P.resolve_laws(case)
    lawn, lawt = P.law_table(laws_n, laws_t, wall_n, wall_t)
    species = np.array([2, 0, 1, 2, 0], np.int64) % len(rep)
    rad = np.array([case.particles[rep[s]].radius for s in species])
    n = len(rad)
    x = np.zeros((n, 3))
    x[:, 2] = rad - 2e-5
    for i in range(1, n):
        x[i, 0] = x[i - 1, 0] + np.sqrt((rad[i - 1] + rad[i] - 3e-5) ** 2 - (x[i, 2] - x[i - 1, 2]) ** 2)
    rng = np.random.default_rng(5)
    v, w = rng.normal(0.0, 0.05, (n, 3)), rng.normal(0.0, 50.0, (n, 3))
    floor = np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]])
    rules, dt = rules_array(None), 1e-7

    def forces(walls, start, nbj):
        states = n * walls.shape[0] + len(nbj)
        hist, dmax = np.zeros((states, 4)), np.zeros(states)
        f, tq = np.zeros((n, 3)), np.zeros((n, 3))
        P._contact_forces(np.int64(0), n, x, v, w, rad, species, len(rep), lawn, lawt, walls, (0.0, 0.0), start,
                          nbj, hist, dmax, f, tq, f, tq, np.zeros((0, 3)), dt, np.bool_(True), rules, *P.NO_ROLLING)
        assert (dmax > 0.0).all()  # every contact touching
        return f, tq

    chain = np.array([0, 1, 2, 3, 4, 4], np.int64), np.arange(1, n, dtype=np.int64)
    f_all, tq_all = forces(floor, *chain)
    f_pairs, tq_pairs = forces(np.zeros((0, 6)), *chain)
    f_walls, tq_walls = forces(floor, np.zeros(n + 1, np.int64), np.zeros(0, np.int64))
    scale = np.abs(f_all).max()
    np.testing.assert_allclose(f_all, f_pairs + f_walls, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(tq_all, tq_pairs + tq_walls, rtol=0, atol=1e-12 * np.abs(tq_all).max())
    assert np.abs(f_walls[:, :2]).min() > 0.0 and np.abs(f_pairs[:, 0]).min() > 0.0  # friction on the floor, loads


def test_a_share_s_far_buffer_is_added_in_over_every_row_its_list_reaches():
    """Two threads: what a share adds for a later share's particle goes into its far buffer, which the later
    share adds in only below far[share] (_far_ends) — so far[share] must lie above every particle the share's
    rows list, and it is one past the largest (a layer above the cut, not the whole next share), for shares that
    are uneven, empty or single rows."""
    rng = np.random.default_rng(11)
    n, r = 300, 1e-3
    x = rng.uniform(0.0, 1.2e-2, (n, 3))
    x = x[np.argsort(x[:, 2])]  # a layered order, as a pour's lattice
    lo, hi, periodic = np.zeros(3), np.full(3, 1.2e-2), np.array([True, True])
    empty = (np.zeros(n + 1, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)), np.zeros(0))
    start, nbj, _, _ = P._rebuild(x, np.full(n, r), lo, hi, periodic, 0.3 * r, *empty, 0)
    for cut in ([0, 150, 300], [0, 0, 299, 300], [0, 1, 2, 300]):
        chunks = np.array(cut, np.int64)
        far = np.zeros(len(cut) - 1, np.int64)
        P._far_ends(start, nbj, chunks, far)
        for c in range(len(cut) - 1):
            listed = nbj[start[cut[c]]:start[cut[c + 1]]]
            assert far[c] == (listed.max() + 1 if listed.size else 0)
    half = np.zeros(2, np.int64)
    P._far_ends(start, nbj, np.array([0, 150, 300], np.int64), half)
    assert 150 < half[0] < 300  # the first share's list reaches into the second, not to its end
