"""The N-body reference solver for packings: spheres, plane walls, periodic x and y, gravity.

The engines' scheme (velocity Verlet of fix nve/sphere, I = 0.4 m R²), Verlet neighbour lists in
compressed rows built from linked cells with a skin (rebuilt once a particle has moved half of it; O(N),
memory linear in N), each listed pair's contact state (history, largest overlap) stored beside it in the
list and carried over at a rebuild (as LAMMPS's fix neigh/history), and one state per particle–wall
contact. One thread (:func:`run`) or several (:func:`run_threaded`: numba threads over shares of the list's
rows, the same arithmetic per contact; docs/packing.md). The contact laws are the reference's compiled laws
(kernels.py's normal force, kernels3d.py's tangential laws), one law per pair of particle species, so any
normal × tangential model — engine twins included — runs here as in the two-body solvers. Tangential laws with a
displacement history (spring families, LTH, ZZYt), Walton's incrementally slipping friction (with its
reversal state per contact) and the history-free ones run; the LAMMPS twins' force-history variants
(mindlin/force, mindlin_rescale) do not (no deck uses them in a packing): ``resolve_laws`` says so.

Conventions as the two-body solver (kernels3d.py): n from i to j, δ = R_i + R_j − |x_j − x_i| > 0 in
contact, slip velocity at the contact point with the arms R − δ/2, torques r × F_t, history rotated into
the tangent plane by projection and rescale (the seed's rule), truncated by the law's Coulomb rule.
"""

from __future__ import annotations

import math

import numpy as np
from llvmlite import ir
from numba import njit, prange, types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.unsafe.ndarray import to_fixed_tuple

from .. import KERNEL_CACHE
from ..laws.normal_force import branched_force, L_LIMIT, loads_and_unloads, normal_force, spring_force
from ..laws.tangential_force import (discrete_slip, eta_of, F_DISCRETE_SLIP, F_HISTORY, F_NO_FORCE, F_OWN_RATE,
                                     F_REVERSAL, has, history_rate, kt_of, return_map, reverses, slip_surface,
                                     tangential_force)
from ..laws.tangential_laws.spring import SPRING, spring_slip  # the one fast path's law (_spring_law: its scalars)
from .packing_rolling import rolling_laws, rolling_torque
from .kernels3d import ARM_RADIUS, R_ROTATION, R_SLIP_ARM, R_TORQUE_ARM, R_WALL_SLIP_ARM, R_WALL_TORQUE_ARM, wall_arm
from .verlet3d import project_history, turn_history
from ..laws.tangential import T_FORCE, T_FAMILY, T_MU_K, T_MU_S, T_RESCALE, T_SIZE, T_TRUNC, TangentialLaw

# per contact (a row beside its neighbour-list entry): the tangential record's history (history_size: the
# displacement's 3; Walton's 9 with the load at the last reversal and the last nonzero slip velocity), at least 3;
# a spring law with μk < μs also its slip state (1). Rows are only as wide as the packing's laws need (memory
# and bandwidth)
HIST_WIDTH, SLIP_HIST_WIDTH = 3, 4


def history_width(records) -> int:
    """The columns of a contact's state row for the packing's tangential records (laws/tangential.py): the widest
    history, and for a law that slips by its own discrete rule (F_DISCRETE_SLIP: the spring family) with μk < μs
    its slip state too, in the column after its 3-vector history."""
    width = max([HIST_WIDTH, *(r.history_size for r in records)])
    if any(r.flags() & F_DISCRETE_SLIP and getattr(r, "mu_k", None) != getattr(r, "mu_s", None) for r in records):
        width = max(width, SLIP_HIST_WIDTH)
    return width


@njit(cache=KERNEL_CACHE)
def _cells(x, box_lo, box_hi, cell, periodic):
    """Linked cells at least ``cell`` (the largest contact distance) wide — a periodic axis with fewer than three
    cells is one cell, so that no neighbour cell is visited twice — as the particles sorted by cell: (dims, the
    cell of each particle, order, first), cell c holding order[first[c]:first[c + 1]] in descending index. Cells
    are numbered z fastest, so a column of neighbour cells is one range of ``order``."""
    n = x.shape[0]
    dims = np.empty(3, np.int64)
    for k in range(3):
        dims[k] = max(1, int((box_hi[k] - box_lo[k]) / cell))
        if k < 2 and periodic[k] and dims[k] < 3:
            dims[k] = 1
    which = np.empty(n, np.int64)
    first = np.zeros(dims[0] * dims[1] * dims[2] + 1, np.int64)
    for i in range(n):
        c0 = _cell_of(x[i, 0], box_lo[0], box_hi[0], dims[0], periodic[0])
        c1 = _cell_of(x[i, 1], box_lo[1], box_hi[1], dims[1], periodic[1])
        c2 = _cell_of(x[i, 2], box_lo[2], box_hi[2], dims[2], False)
        which[i] = (c0 * dims[1] + c1) * dims[2] + c2
        first[which[i] + 1] += 1
    for c in range(first.shape[0] - 1):
        first[c + 1] += first[c]
    fill = first[1:].copy()
    order = np.empty(n, np.int64)
    for i in range(n):
        fill[which[i]] -= 1
        order[fill[which[i]]] = i
    return dims, which, order, first


@njit(cache=KERNEL_CACHE, inline="always")
def _cell_of(xk, lo, hi, dim, per):
    s = (xk - lo) / (hi - lo)
    if per:
        s -= math.floor(s)
    return min(dim - 1, max(0, int(s * dim)))


@njit(cache=KERNEL_CACHE, inline="always")
def _separation(x, i, j, period):
    """x_j − x_i, by minimum image along the periodic axes: ``period`` = (lx, ly), 0 along an axis that is not
    periodic (a tuple, so that the force loop passes no array per pair: :func:`_law`)."""
    return (_image(x[j, 0] - x[i, 0], period[0]), _image(x[j, 1] - x[i, 1], period[1]), x[j, 2] - x[i, 2])


@njit(cache=KERNEL_CACHE, inline="always")
def _image(d, length):
    """The minimum image d − L·floor(d/L + ½) of a separation d along an axis of period L (none if L = 0).
    Where |d| ≤ 0.49 L the floor is 0 whatever the rounding, and d is returned without the division: most
    pairs, and the same bits."""
    if length != 0.0 and abs(d) > 0.49 * length:
        return d - length * math.floor(d / length + 0.5)
    return d


@njit(cache=KERNEL_CACHE)
def _period(box_lo, box_hi, periodic):
    """(lx, ly) of the periodic box for :func:`_separation`, 0 along an axis that is not periodic."""
    return (box_hi[0] - box_lo[0] if periodic[0] else 0.0, box_hi[1] - box_lo[1] if periodic[1] else 0.0)


NB_PER_PARTICLE = 8  # the neighbour list's first capacity per particle (pairs j > i); grown when short


@njit(cache=KERNEL_CACHE)
def _neighbour_rows(lo, hi, x, rad, skin, periodic, period, cells, start, nbj):
    """Rows lo…hi−1 of the Verlet list in compressed rows — for each i, the j > i within r_i + r_j + skin —
    from nbj[0] on (start[i]: where row i begins), as far as nbj has room; returns the entries needed (more
    than len(nbj): the rows are incomplete, and the caller builds them again in a longer array). The neighbour
    cells column by column, each cell's particles in descending index: the order of the linked cells this
    replaced, which is the order in which the force loop adds up a particle's contacts."""
    dims, which, order, first = cells
    rx = 1 if dims[0] >= 3 or not periodic[0] else 0
    ry = 1 if dims[1] >= 3 or not periodic[1] else 0
    count = 0
    for i in range(lo, hi):
        start[i] = count
        c0 = which[i] // (dims[1] * dims[2])
        c1 = which[i] // dims[2] % dims[1]
        c2 = which[i] % dims[2]
        for dx in range(-rx, rx + 1):
            for dy in range(-ry, ry + 1):
                cx, cy = c0 + dx, c1 + dy
                if cx < 0 or cx >= dims[0]:
                    if not periodic[0]:
                        continue
                    cx %= dims[0]
                if cy < 0 or cy >= dims[1]:
                    if not periodic[1]:
                        continue
                    cy %= dims[1]
                column = (cx * dims[1] + cy) * dims[2]  # cells c2 − 1 … c2 + 1 of this column
                for c in range(column + max(c2 - 1, 0), column + min(c2 + 1, dims[2] - 1) + 1):
                    # a cell's particles in descending index: those j > i come first, and the rest of the cell
                    # is skipped (half the distances a rebuild would compute; the same entries in the same order)
                    for k in range(first[c], first[c + 1]):
                        j = order[k]
                        if j <= i:
                            break
                        d0, d1, d2 = _separation(x, i, j, period)
                        reach = rad[i] + rad[j] + skin
                        if d0 * d0 + d1 * d1 + d2 * d2 < reach * reach:
                            if count < nbj.shape[0]:
                                nbj[count] = j
                            count += 1
    return count


@njit(cache=KERNEL_CACHE)
def _carry_states(lo, hi, new_start, new_j, start, nbj, hist, dmax, new_hist, new_dmax, base):
    """Rows lo…hi−1 of a new Verlet list take each pair's contact state (history, largest overlap) from the old
    list where the pair was listed (as LAMMPS's fix neigh/history); the walls' states (the first ``base``
    rows) are the caller's to copy."""
    for i in range(lo, hi):
        for q in range(new_start[i], new_start[i + 1]):
            j = new_j[q]
            for p in range(start[i], start[i + 1]):
                if nbj[p] == j:
                    if dmax[base + p] != 0.0:
                        new_hist[base + q, :] = hist[base + p, :]
                        new_dmax[base + q] = dmax[base + p]
                    break


@njit(cache=KERNEL_CACHE)
def _new_states(hist, dmax, base, entries):
    """Contact-state arrays for a new list of ``entries`` entries, the walls' rows (the first ``base``) kept."""
    new_hist = np.zeros((base + entries, hist.shape[1]))
    new_dmax = np.zeros(base + entries)
    new_hist[:base] = hist[:base]
    new_dmax[:base] = dmax[:base]
    return new_hist, new_dmax


@njit(cache=KERNEL_CACHE)
def _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax, base):
    """A new Verlet list for positions x, each pair's contact state carried over (:func:`_carry_states`); the
    walls' contact states (the first ``base`` rows) stay as they are. Returns the new arrays."""
    n = x.shape[0]
    cells = _cells(x, box_lo, box_hi, 2.0 * rad.max() + skin, periodic)
    period = _period(box_lo, box_hi, periodic)
    new_start = np.empty(n + 1, np.int64)
    new_j = np.empty(max(nbj.shape[0], NB_PER_PARTICLE * n), np.int64)
    # (np.int64: a literal argument would make numba compile a specialisation of the callee for it)
    zero = np.int64(0)
    need = _neighbour_rows(zero, n, x, rad, skin, periodic, period, cells, new_start, new_j)
    if need > new_j.shape[0]:
        new_j = np.empty(need + need // 4, np.int64)
        _neighbour_rows(zero, n, x, rad, skin, periodic, period, cells, new_start, new_j)
    new_start[n] = need
    new_hist, new_dmax = _new_states(hist, dmax, base, new_j.shape[0])
    _carry_states(zero, n, new_start, new_j, start, nbj, hist, dmax, new_hist, new_dmax, base)
    return new_start, new_j, new_hist, new_dmax


@njit(cache=KERNEL_CACHE, parallel=True)
def _rebuild_threaded(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax, base, chunks):
    """:func:`_rebuild` on threads, a share of the rows each (``chunks``): the same list and states. Each share
    builds its rows into its own array (room: its rows' last entries and a quarter more), then they are laid end
    to end; a share that ran out of room makes the whole rebuild the serial one."""
    n = x.shape[0]
    m = chunks.shape[0] - 1
    cells = _cells(x, box_lo, box_hi, 2.0 * rad.max() + skin, periodic)
    period = _period(box_lo, box_hi, periodic)
    room = NB_PER_PARTICLE
    for c in range(m):  # as the serial rebuild's first try: NB_PER_PARTICLE a row, or the old entries and a quarter
        room = max(room, NB_PER_PARTICLE * (chunks[c + 1] - chunks[c]),
                   (start[chunks[c + 1]] - start[chunks[c]]) * 5 // 4 + NB_PER_PARTICLE)
    rows = np.empty((m, room), np.int64)
    ends = np.empty(m, np.int64)
    new_start = np.empty(n + 1, np.int64)
    for c in prange(m):
        ends[c] = _neighbour_rows(chunks[c], chunks[c + 1], x, rad, skin, periodic, period, cells, new_start, rows[c])
    if ends.max() > room:
        return _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax, base)
    at = np.zeros(m + 1, np.int64)
    for c in range(m):
        at[c + 1] = at[c] + ends[c]
    size = max(nbj.shape[0], NB_PER_PARTICLE * n)  # the serial rebuild's lengths, so that the states' arrays match
    if at[m] > size:
        size = at[m] + at[m] // 4
    new_j = np.empty(size, np.int64)
    for c in prange(m):
        for i in range(chunks[c], chunks[c + 1]):
            new_start[i] += at[c]
        new_j[at[c]:at[c + 1]] = rows[c, :ends[c]]
    new_start[n] = at[m]
    new_hist, new_dmax = _new_states(hist, dmax, base, new_j.shape[0])
    for c in prange(m):
        _carry_states(chunks[c], chunks[c + 1], new_start, new_j, start, nbj, hist, dmax, new_hist, new_dmax, base)
    return new_start, new_j, new_hist, new_dmax


# the rolling slot's arguments of the compiled loop where the case names no rolling law (laws_r, roll_kind, roll_col,
# roll_kn)
NO_ROLLING = (np.zeros((1, 1)), np.int64(-1), np.int64(-1), np.int64(-1))

NL_SIZE = L_LIMIT + 1  # the length of a normal law's array (kernels.py)


@njit(cache=KERNEL_CACHE)
def _law(laws_n, laws_t, p):
    """Law ``p``'s normal and tangential arrays as tuples. The force loop hands its laws and vectors to the
    compiled laws by value: every array it passed (a law's row, a buffer) cost a reference count per contact
    — atomic operations that took 80 % of the loop (docs/packing.md)."""
    return to_fixed_tuple(laws_n[p], NL_SIZE), to_fixed_tuple(laws_t[p], T_SIZE)


@njit(cache=KERNEL_CACHE)
def _other_tangential(nl, tl, delta, n, vt, hist, fabs, dt, update, ft, rot, zero3):
    """The tangential force of a contact by its law's traits (``has``; every law but the spring's fast path,
    :func:`_spring_law`), into ``ft`` (history ``hist``, one contact's row, updated in place; ``zero3``: zeros,
    the slip direction these laws do not read — the caller's buffer: a global array is a read-only type of its
    own, and numba would compile tangential_force for it). In verlet_3d's order: a law with a history has it
    turned, incremented (by v_t, or its own rate), projected, then slipped by its own discrete rule or by its
    slip surface and return map; a law that stores the history at a reversal of the slip keeps it in hist[3:6]
    and the last nonzero slip velocity in hist[6:9] (Walton's layout)."""
    if has(tl, F_HISTORY) and update:
        hist[0], hist[1], hist[2] = turn_history(hist[0], hist[1], hist[2], n, rot, kt_of(tl, delta), tl[T_MU_K],
                                                 fabs)
        if has(tl, F_REVERSAL):
            if reverses(vt, hist[6:9]):  # L* = L
                hist[3], hist[4], hist[5] = hist[0], hist[1], hist[2]
            if vt[0] != 0.0 or vt[1] != 0.0 or vt[2] != 0.0:
                hist[6], hist[7], hist[8] = vt[0], vt[1], vt[2]
        if has(tl, F_OWN_RATE):
            rate = history_rate(tl, nl, hist[0:3], vt, fabs, delta, hist[3:6])
            for k in range(3):
                hist[k] += rate[k] * dt
        else:
            for k in range(3):
                hist[k] += vt[k] * dt
        hist[0], hist[1], hist[2] = project_history(hist[0], hist[1], hist[2], n, rot)
        if has(tl, F_DISCRETE_SLIP):
            _discrete(nl, tl, delta, vt, hist, fabs, ft)
            return
        sliding = slip_surface(tl, nl, hist, vt, fabs, delta, tl[T_MU_S])[0] > 0.0
        if sliding:
            mapped = return_map(tl, nl, hist, vt, fabs, delta, tl[T_MU_K])
            hist[0], hist[1], hist[2] = mapped[0], mapped[1], mapped[2]
        out = tangential_force(tl, nl, hist, vt, fabs, delta, sliding, zero3)
        ft[0], ft[1], ft[2] = out[0], out[1], out[2]
        return
    out = tangential_force(tl, nl, hist, vt, fabs, delta, np.bool_(False), zero3)
    if has(tl, F_DISCRETE_SLIP):  # setup: the trial force within the static limit, history untouched
        tn = math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2)
        cap = tl[T_MU_S] * fabs
        if tn > cap and tn > 0.0:
            out = out * (cap / tn)
    ft[0], ft[1], ft[2] = out[0], out[1], out[2]


@njit(cache=KERNEL_CACHE, inline="always")
def _discrete(nl, tl, delta, vt, hist, fabs, ft):
    """A law's own discrete slip after the increment (discrete_slip), with its slip state in hist[3] where μk < μs
    (a slip goes on while the force exceeds μk|Fn|), as the spring's fast path keeps it."""
    two_mu = tl[T_MU_K] != tl[T_MU_S]
    mu = tl[T_MU_K] if two_mu and hist[3] != 0.0 else tl[T_MU_S]
    xi, out, sliding = discrete_slip(tl, nl, hist[0:3], vt, fabs, delta, mu)
    hist[0], hist[1], hist[2] = xi[0], xi[1], xi[2]
    if two_mu:
        hist[3] = 1.0 if sliding else 0.0
    ft[0], ft[1], ft[2] = out[0], out[1], out[2]


@njit(cache=KERNEL_CACHE, inline="always")
def _spring_law(nl, tl, delta, n, vt, xi0, xi1, xi2, slipping, fabs, dt, rot):
    """The spring family with scalars only (laws and vectors as tuples), for the packing solver's inner loop,
    by the verlet rules of kernels3d (turn_history, the increment, project_history, spring_slip — as
    verlet_3d), from the history (xi0, xi1, xi2). A slip goes on while the force exceeds μk|Fn| (``slipping``:
    the contact slipped at the last step; kept where μk < μs). Returns (history, force, sliding)."""
    kt = kt_of(tl, delta)
    xi0, xi1, xi2 = turn_history(xi0, xi1, xi2, n, rot, kt, tl[T_MU_K], fabs)
    xi0, xi1, xi2 = project_history(xi0 + vt[0] * dt, xi1 + vt[1] * dt, xi2 + vt[2] * dt, n, rot)
    mu = tl[T_MU_K] if slipping else tl[T_MU_S]
    return spring_slip(xi0, xi1, xi2, vt, kt, eta_of(tl, nl, delta), tl[T_TRUNC], mu, tl[T_MU_K], fabs)


@njit(cache=KERNEL_CACHE, inline="always")
def _react(f, tq, j, f0, f1, f2, b, t0, t1, t2):
    """The reaction on particle j of a pair's force (f0, f1, f2) on i, and its torque b (t0, t1, t2)."""
    f[j, 0] -= f0
    f[j, 1] -= f1
    f[j, 2] -= f2
    tq[j, 0] += b * t0
    tq[j, 1] += b * t1
    tq[j, 2] += b * t2


@njit(cache=KERNEL_CACHE)
def _contact_forces(lo, hi, x, v, w, rad, species, n_species, laws_n, laws_t, walls, period, start, nbj,
                    hist, dmax, f, tq, f_far, tq_far, records, dt, update, rules, laws_r, roll_kind, roll_col,
                    roll_kn):
    """Forces and torques of the contacts of particles lo…hi−1 (their pairs in the Verlet list, j > i, and
    their walls), added into ``f`` and ``tq`` — for a particle j ≥ hi into ``f_far`` and ``tq_far`` instead (the
    same arrays when lo…hi−1 are all the rows). A contact's state (history, largest overlap) is row r of
    ``hist``, ``dmax``: particle i's with wall k at i·n_walls + k, a listed pair's beside it, at n·n_walls + its
    list entry; a contact that has ended is forgotten (its state zeroed) when next seen apart. Laws: row
    si·n_species + sj of ``laws_n``/``laws_t`` for a pair of species si, sj, row n_species² + si for the walls.
    ``records`` (one row per list entry, or none): each touching pair's (δ, Fn, |Ft|).

    The rolling slot (``roll_kind`` ≥ 0: the law's place in packing_rolling's switch; -1 none, and nothing of it is
    computed): row p of ``laws_r`` is the law's record for the contact's law row p; its torque M(w = ω_i − ω_j, n,
    |Fn|) goes to i and −M to j (a wall takes −M); a law with a history keeps it in columns roll_col… of the
    contact's state row (roll_col -1: none), updated only with ``update``: the set-up call gives the law its step's
    increment too but stores nothing (as LIGGGHTS's rolling models do), so that a spring held at its limit stays
    there across a chunk's set-up — with no increment it would sit exactly on the limit, below it by the law's
    test, and its dashpot would come back for that one call (type C's, 0.8 % more torque at a set-up every 500 steps).
    A law that reads the contact's normal stiffness (its record's ``kn_column``: ``roll_kn`` ≥ 0, packing_rolling.
    rolling_laws) gets its row copied with kn written at that place, per contact and step: the normal spring's secant
    stiffness F_spring/δ (:func:`_secant_stiffness`, the elastic part, not the damped total); with ``roll_kn`` -1
    the row is passed as it is and no kn is computed.

    A row's contacts are computed, and their states updated, by whoever computes the row: the rows lo…hi−1 may
    be one thread's share, writing f and tq only for its own particles, its far buffers for the others'
    (:func:`run_threaded`)."""
    n_w = walls.shape[0]
    base = x.shape[0] * n_w
    nbuf = np.empty(3)  # the laws that take arrays (all but the updated spring family)
    vtbuf = np.empty(3)
    ftbuf = np.empty(3)
    zero3 = np.zeros(3)
    rwbuf = np.empty(3)  # the rolling law's w, n and history
    rnbuf = np.empty(3)
    rhbuf = np.zeros(3)
    rcbuf = np.empty(laws_r.shape[1])  # a law's row with the contact's kn (roll_kn ≥ 0)
    t_width = roll_col if roll_col >= 0 else hist.shape[1]  # the tangential law's columns of a state row
    segments = walls.shape[1] > W_PLANE  # a wall table with segments' columns (wall_table); a plane's is 6 wide
    rot = rules[R_ROTATION]
    slip_radius = rules[R_SLIP_ARM] == ARM_RADIUS
    torque_radius = rules[R_TORQUE_ARM] == ARM_RADIUS
    record = records.shape[0] > 0
    # the pairs' law and the walls' law, each as tuples, fetched again only when it changes: a particle on a wall
    # would otherwise switch between the two twice a row — a wall contact cost three pair contacts (docs/packing.md)
    law = np.int64(0)  # (not a literal: its first value would compile _law for it while the types are inferred)
    pair_nl, pair_tl = _law(laws_n, laws_t, law)
    wall_law = np.int64(n_species * n_species)
    wall_nl, wall_tl = _law(laws_n, laws_t, wall_law)
    for i in range(lo, hi):
        end = start[i + 1]
        for e in range(start[i], end + n_w):
            if e < end:  # the listed pair (i, j)
                j = nbj[e]
                r = base + e
                d0, d1, d2 = _separation(x, i, j, period)  # scalars: no allocation on the hot path
                touch = rad[i] + rad[j]
                dist2 = d0 * d0 + d1 * d1 + d2 * d2
                if not dist2 < touch * touch:
                    if dmax[r] != 0.0:  # the contact has ended: forget it
                        dmax[r] = 0.0
                        hist[r, :] = 0.0
                    continue
                dist = math.sqrt(dist2)
                delta = touch - dist
                n0, n1, n2 = d0 / dist, d1 / dist, d2 / dist
                # lever arms by rule (kernels3d): the contact point R − δ/2, or the full radius
                ai = rad[i] if slip_radius else rad[i] - 0.5 * delta
                aj = rad[j] if slip_radius else rad[j] - 0.5 * delta
                bi = rad[i] if torque_radius else rad[i] - 0.5 * delta
                bj = rad[j] if torque_radius else rad[j] - 0.5 * delta
                vr0, vr1, vr2 = v[i, 0] - v[j, 0], v[i, 1] - v[j, 1], v[i, 2] - v[j, 2]
                rate = vr0 * n0 + vr1 * n1 + vr2 * n2
                # ω_i × (a_i n) + ω_j × (a_j n)
                o0 = ai * w[i, 0] + aj * w[j, 0]
                o1 = ai * w[i, 1] + aj * w[j, 1]
                o2 = ai * w[i, 2] + aj * w[j, 2]
                u0 = vr0 + o1 * n2 - o2 * n1
                u1 = vr1 + o2 * n0 - o0 * n2
                u2 = vr2 + o0 * n1 - o1 * n0
                p = species[i] * n_species + species[j]
                if p != law:  # another law: its tuples (once per change, not per contact)
                    pair_nl, pair_tl = _law(laws_n, laws_t, p)
                    law = p
                nl, tl = pair_nl, pair_tl
            else:  # wall k: a plane through p with normal nw into the domain (or a strip of it: a segment)
                k = e - end
                j, bj = -1, 0.0
                r = i * n_w + k
                delta = rad[i] - ((x[i, 0] - walls[k, 0]) * walls[k, 3] + (x[i, 1] - walls[k, 1]) * walls[k, 4]
                                  + (x[i, 2] - walls[k, 2]) * walls[k, 5])
                n0, n1, n2 = -walls[k, 3], -walls[k, 4], -walls[k, 5]  # from the particle into the wall
                if segments and walls[k, W_S0] > -math.inf:  # a strip: none unless |h| < R (its plane's distance
                    if delta > 0.0 and delta < 2.0 * rad[i]:  # bounds every point's of it: most walls stop here)
                        delta, n0, n1, n2 = _segment_contact(x, i, rad[i], walls, k, delta, n0, n1, n2)
                    else:
                        delta = -1.0
                if not delta > 0.0:
                    if dmax[r] != 0.0:
                        dmax[r] = 0.0
                        hist[r, :] = 0.0
                    continue
                ai = wall_arm(rules[R_WALL_SLIP_ARM], rad[i], delta)
                bi = wall_arm(rules[R_WALL_TORQUE_ARM], rad[i], delta)
                rate = v[i, 0] * n0 + v[i, 1] * n1 + v[i, 2] * n2
                # the contact point's velocity v + ω × (a n)
                u0 = v[i, 0] + ai * (w[i, 1] * n2 - w[i, 2] * n1)
                u1 = v[i, 1] + ai * (w[i, 2] * n0 - w[i, 0] * n2)
                u2 = v[i, 2] + ai * (w[i, 0] * n1 - w[i, 1] * n0)
                p = n_species * n_species + species[i]
                if p != wall_law:
                    wall_nl, wall_tl = _law(laws_n, laws_t, p)
                    wall_law = p
                nl, tl = wall_nl, wall_tl
            vn = u0 * n0 + u1 * n1 + u2 * n2
            vt0, vt1, vt2 = u0 - vn * n0, u1 - vn * n1, u2 - vn * n2
            dm = max(dmax[r], delta)
            dmax[r] = dm
            fn = normal_force(nl, delta, rate, dm)
            # the spring (every deck's law), updated: its scalar copy, the fast path — the same arithmetic as the
            # traits' path below gives it (tests/test_tangential_traits.py runs a copy of it under another family)
            if tl[T_FAMILY] == SPRING and update:
                two_mu = tl[T_MU_K] != tl[T_MU_S]
                xi0, xi1, xi2, ft0, ft1, ft2, sliding = _spring_law(nl, tl, delta, (n0, n1, n2), (vt0, vt1, vt2),
                                                                    hist[r, 0], hist[r, 1], hist[r, 2],
                                                                    two_mu and hist[r, 3] != 0.0, abs(fn), dt, rot)
                hist[r, 0], hist[r, 1], hist[r, 2] = xi0, xi1, xi2
                if two_mu:
                    hist[r, 3] = 1.0 if sliding else 0.0
            elif has(tl, F_NO_FORCE):
                ft0 = ft1 = ft2 = 0.0
            else:
                nbuf[0], nbuf[1], nbuf[2] = n0, n1, n2
                vtbuf[0], vtbuf[1], vtbuf[2] = vt0, vt1, vt2
                _other_tangential(laws_n[p], laws_t[p], delta, nbuf, vtbuf, hist[r, :t_width], abs(fn), dt, update,
                                  ftbuf, rot, zero3)
                ft0, ft1, ft2 = ftbuf[0], ftbuf[1], ftbuf[2]
            f0, f1, f2 = -fn * n0 + ft0, -fn * n1 + ft1, -fn * n2 + ft2
            # torques (b n) × F_t
            t0 = n1 * ft2 - n2 * ft1
            t1 = n2 * ft0 - n0 * ft2
            t2 = n0 * ft1 - n1 * ft0
            f[i, 0] += f0
            f[i, 1] += f1
            f[i, 2] += f2
            tq[i, 0] += bi * t0
            tq[i, 1] += bi * t1
            tq[i, 2] += bi * t2
            if j >= 0:
                if j < hi:
                    _react(f, tq, j, f0, f1, f2, bj, t0, t1, t2)
                else:  # another share's particle
                    _react(f_far, tq_far, j, f0, f1, f2, bj, t0, t1, t2)
                if record:
                    records[e, 0], records[e, 1] = delta, fn
                    records[e, 2] = math.sqrt(ft0 ** 2 + ft1 ** 2 + ft2 ** 2)
            if roll_kind >= 0:
                roll_row = laws_r[p]
                if roll_kn >= 0:  # the law reads kn: its row with this contact's, now
                    rcbuf[:] = roll_row
                    rcbuf[roll_kn] = _secant_stiffness(nl, delta, dm)
                    roll_row = rcbuf
                _rolling(i, j, hi, r, w, n0, n1, n2, abs(fn), dt, update, roll_row, roll_kind, roll_col, hist, tq,
                         tq_far, rwbuf, rnbuf, rhbuf)


# a wall's row (wall_table): its point and normal (W_PLANE columns: a plane's whole row), then, in a table with a
# segment, its direction along the strip, the strip's extent [s0, s1] (−inf, inf: a plane), and for each of the strip's
# two edge lines (s0's, then s1's) whether it is this wall's (1) or another's (0: a corner shared with an earlier
# wall) and up to two other walls whose strips end on that line (−1: none)
W_PLANE, W_ALONG, W_S0, W_S1, W_EDGES = 6, 6, 9, 10, 11
W_EDGE = 3  # columns per edge line: its own?, sharer, sharer
W_WIDTH = W_EDGES + 2 * W_EDGE


@njit(cache=KERNEL_CACHE, inline="always")
def _segment_contact(x, i, radius, walls, k, delta, n0, n1, n2):
    """The contact of sphere i with the strip of wall k (a segment: its plane's points p + s·a + t·(n × a) with
    s0 ≤ s ≤ s1, a thin plate, touched from either side): (δ, the normal from the sphere into the wall). Where the
    centre projects inside [s0, s1] it is the plane's — on the normal's side (height h ≥ 0) the plane wall's own (δ,
    n given), behind it its mirror (δ = R + h, along +n: the plate pushes the sphere back where it is); outside, the
    nearer edge line's — δ = R − ρ, ρ the centre's distance to the line, along the line's normal through the centre
    — unless that line is another wall's too (a corner: one contact, its first wall's) or the centre projects inside
    the strip of a wall sharing it (that face holds the sphere); then none."""
    d0, d1, d2 = x[i, 0] - walls[k, 0], x[i, 1] - walls[k, 1], x[i, 2] - walls[k, 2]
    s = d0 * walls[k, W_ALONG] + d1 * walls[k, W_ALONG + 1] + d2 * walls[k, W_ALONG + 2]
    h = d0 * walls[k, 3] + d1 * walls[k, 4] + d2 * walls[k, 5]  # the centre's height over the plane
    if s >= walls[k, W_S0] and s <= walls[k, W_S1]:
        if h >= 0.0:
            return delta, n0, n1, n2
        return radius + h, -n0, -n1, -n2
    col = W_EDGES if s < walls[k, W_S0] else W_EDGES + W_EDGE
    if walls[k, col] == 0.0:  # the corner's contact is its first wall's
        return -1.0, n0, n1, n2
    for c in range(col + 1, col + W_EDGE):
        o = int(walls[k, c])
        if o >= 0:
            so = ((x[i, 0] - walls[o, 0]) * walls[o, W_ALONG] + (x[i, 1] - walls[o, 1]) * walls[o, W_ALONG + 1]
                  + (x[i, 2] - walls[o, 2]) * walls[o, W_ALONG + 2])
            if so >= walls[o, W_S0] and so <= walls[o, W_S1]:
                return -1.0, n0, n1, n2
    se = walls[k, W_S0] if s < walls[k, W_S0] else walls[k, W_S1]
    q0 = (s - se) * walls[k, W_ALONG] + h * walls[k, 3]  # from the edge line to the centre
    q1 = (s - se) * walls[k, W_ALONG + 1] + h * walls[k, 4]
    q2 = (s - se) * walls[k, W_ALONG + 2] + h * walls[k, 5]
    rho = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
    if rho == 0.0:  # the centre on the line: the plane's normal
        return radius, n0, n1, n2
    return radius - rho, -q0 / rho, -q1 / rho, -q2 / rho


@njit(cache=KERNEL_CACHE, inline="always")
def _secant_stiffness(nl, delta, dmax):
    """The normal spring's secant stiffness F_spring/δ at overlap δ > 0 (law ``nl``, largest overlap ``dmax``): a
    one-branch law's spring without its dashpot (Hooke's k, Hertz's (4/3)E*√(R̄δ)), a loading/unloading law's
    force of its branch (it has no dashpot)."""
    if loads_and_unloads(nl):
        return branched_force(nl, delta, dmax) / delta
    return spring_force(nl, delta) / delta


@njit(cache=KERNEL_CACHE, inline="always")
def _rolling(i, j, hi, r, w, n0, n1, n2, fabs, dt, update, c, roll_kind, roll_col, hist, tq, tq_far, wbuf, nbuf,
             hbuf):
    """The rolling torque of contact state row r (particle i with j, or a wall: j = -1), the law's row ``c``: M on
    i, −M on j (into ``tq_far`` for a particle j ≥ hi, another share's), its history (columns roll_col…) updated
    with ``update``."""
    if j >= 0:
        wbuf[0], wbuf[1], wbuf[2] = w[i, 0] - w[j, 0], w[i, 1] - w[j, 1], w[i, 2] - w[j, 2]
    else:
        wbuf[0], wbuf[1], wbuf[2] = w[i, 0], w[i, 1], w[i, 2]
    nbuf[0], nbuf[1], nbuf[2] = n0, n1, n2
    if roll_col >= 0:
        hbuf[0], hbuf[1], hbuf[2] = hist[r, roll_col], hist[r, roll_col + 1], hist[r, roll_col + 2]
    m, h = rolling_torque(roll_kind, c, wbuf, nbuf, fabs, dt, hbuf)
    if update and roll_col >= 0:
        hist[r, roll_col], hist[r, roll_col + 1], hist[r, roll_col + 2] = h[0], h[1], h[2]
    tq[i, 0] += m[0]
    tq[i, 1] += m[1]
    tq[i, 2] += m[2]
    if j >= 0:
        if j < hi:
            tq[j, 0] -= m[0]
            tq[j, 1] -= m[1]
            tq[j, 2] -= m[2]
        else:
            tq_far[j, 0] -= m[0]
            tq_far[j, 1] -= m[1]
            tq_far[j, 2] -= m[2]


@njit(cache=KERNEL_CACHE)
def _new_records(start):
    """One record row per list entry, δ = −1 until the entry is seen touching."""
    return np.full((start[start.shape[0] - 1], 3), -1.0)


@njit(cache=KERNEL_CACHE)
def _contact_table(start, nbj, records, contacts):
    """The touching pairs' records as rows (i, j, δ, Fn, |Ft|) of ``contacts``, in list order (as many as fit);
    returns their number."""
    nc = 0
    for i in range(start.shape[0] - 1):
        for e in range(start[i], start[i + 1]):
            if records[e, 0] >= 0.0:
                if nc < contacts.shape[0]:
                    contacts[nc, 0], contacts[nc, 1] = i, nbj[e]
                    contacts[nc, 2], contacts[nc, 3], contacts[nc, 4] = records[e, 0], records[e, 1], records[e, 2]
                nc += 1
    return nc


@njit(cache=KERNEL_CACHE, inline="always")
def _kick_drift(lo, hi, x, v, w, f, tq, mass, inertia, gravity, dt, box_lo, box_hi, periodic, x_ref):
    """The first half kick and the drift of particles lo…hi−1, wrapped into the periodic box, their force and
    torque then zeroed for the next force loop; returns the largest squared displacement since the last rebuild."""
    moved = 0.0
    half = 0.5 * dt
    period = _period(box_lo, box_hi, periodic)
    for i in range(lo, hi):
        m, j = mass[i], inertia[i]
        v0 = v[i, 0] + half * (f[i, 0] / m + gravity[0])
        v1 = v[i, 1] + half * (f[i, 1] / m + gravity[1])
        v2 = v[i, 2] + half * (f[i, 2] / m + gravity[2])
        v[i, 0], v[i, 1], v[i, 2] = v0, v1, v2
        w[i, 0] += half * tq[i, 0] / j
        w[i, 1] += half * tq[i, 1] / j
        w[i, 2] += half * tq[i, 2] / j
        f[i, 0] = f[i, 1] = f[i, 2] = 0.0
        tq[i, 0] = tq[i, 1] = tq[i, 2] = 0.0
        dd = _drift(i, x, v0, v1, v2, dt, box_lo, box_hi, periodic, x_ref, period)
        if dd > moved:
            moved = dd
    return moved


@njit(cache=KERNEL_CACHE, inline="always")
def _kick_and_next(lo, hi, x, v, w, f, tq, mass, inertia, gravity, dt, box_lo, box_hi, periodic, x_ref, drift):
    """The second half kick of particles lo…hi−1 and, with ``drift``, the next step's first half kick and drift,
    in one pass over each particle (its force and torque then zeroed for the next force loop): the arithmetic of
    a kick, a kick and a drift (:func:`_kick_drift`) one after the other, the same bits, at a third of the memory
    traffic — these passes took as long as the force loop in a pour's onset (docs/packing.md, "At scale").
    Returns (translational and rotational kinetic energy after the first kick, the largest squared displacement
    since the last rebuild)."""
    e = 0.0
    e_rot = 0.0
    moved = 0.0
    half = 0.5 * dt
    period = _period(box_lo, box_hi, periodic)
    for i in range(lo, hi):
        m, j = mass[i], inertia[i]
        a0, a1, a2 = f[i, 0] / m + gravity[0], f[i, 1] / m + gravity[1], f[i, 2] / m + gravity[2]
        s0, s1, s2 = half * tq[i, 0] / j, half * tq[i, 1] / j, half * tq[i, 2] / j
        v0, v1, v2 = v[i, 0] + half * a0, v[i, 1] + half * a1, v[i, 2] + half * a2
        w0, w1, w2 = w[i, 0] + s0, w[i, 1] + s1, w[i, 2] + s2
        e += 0.5 * m * (v0 ** 2 + v1 ** 2 + v2 ** 2)
        e_rot += 0.5 * j * (w0 ** 2 + w1 ** 2 + w2 ** 2)
        if drift:
            v0, v1, v2 = v0 + half * a0, v1 + half * a1, v2 + half * a2
            w0, w1, w2 = w0 + s0, w1 + s1, w2 + s2
            f[i, 0] = f[i, 1] = f[i, 2] = 0.0
            tq[i, 0] = tq[i, 1] = tq[i, 2] = 0.0
            dd = _drift(i, x, v0, v1, v2, dt, box_lo, box_hi, periodic, x_ref, period)
            if dd > moved:  # (not max(): the same choice as before where dd is NaN)
                moved = dd
        v[i, 0], v[i, 1], v[i, 2] = v0, v1, v2
        w[i, 0], w[i, 1], w[i, 2] = w0, w1, w2
    return e, e_rot, moved


@njit(cache=KERNEL_CACHE, inline="always")
def _drift(i, x, v0, v1, v2, dt, box_lo, box_hi, periodic, x_ref, period):
    """Particle i's drift by dt at the velocity (v0, v1, v2), wrapped into the periodic box; returns its squared
    displacement since the last rebuild (x_ref: the positions then), by minimum image along the periodic axes
    (``period``: :func:`_period`'s): the true displacement, not ~L for a particle that has crossed the box's
    boundary since.

    A crossing alone needs no rebuild (LAMMPS and LIGGGHTS do not rebuild on one either; they re-wrap at their
    reneighbouring). The list's entries are pairs of indices and every distance in the list's build and the force
    loop is a minimum image (:func:`_separation`): the distance on the torus, which a wrap leaves unchanged and
    which moves by at most |u_i| + |u_j| when particles i and j are displaced by u_i, u_j. A pair not listed at
    the rebuild was then at least r_i + r_j + skin apart, so it cannot touch before one of them has moved skin/2,
    which this displacement detects whatever the wraps in between (|u| ≤ skin/2 ≪ L/2, so its minimum image is
    u) — whatever the box's size, the torus distance being a metric (a box narrower than two interaction ranges,
    the neighbour search's one cell along such an axis, sees one image of a pair, the nearest, before as after).
    The linked cells are only built at a rebuild, from the positions of the moment. The old rule (the wrapped
    position's difference) rebuilt the list at every crossing: a count growing with the box's perimeter
    (docs/packing.md, "At scale")."""
    x[i, 0] += dt * v0
    x[i, 1] += dt * v1
    x[i, 2] += dt * v2
    for k in range(2):
        if periodic[k]:
            L = box_hi[k] - box_lo[k]
            if x[i, k] < box_lo[k]:
                x[i, k] += L
            elif x[i, k] >= box_hi[k]:
                x[i, k] -= L
    # (_image: the difference itself below 0.49 L — every sphere that has not crossed — so the same bits as before;
    # ``period`` is the caller's, taken once a pass: read from the box here, per sphere, the kick pass took 6x as long)
    d0, d1 = _image(x[i, 0] - x_ref[i, 0], period[0]), _image(x[i, 1] - x_ref[i, 1], period[1])
    return d0 ** 2 + d1 ** 2 + (x[i, 2] - x_ref[i, 2]) ** 2


@njit(cache=KERNEL_CACHE)
def _setup(x, v, w, rad, mass, species, n_species, laws_n, laws_t, walls, box_lo, box_hi, periodic, dt, steps,
           ke_every, start, nbj, hist, dmax, rules, laws_r, roll_kind, roll_col, roll_kn):
    """What a run starts from: a new Verlet list (its pair states carried over) and the forces of the initial
    state, computed without touching histories (as the engines do). Returns (inertia, period, skin, the kinetic
    energy series and the flags to fill, the positions at the rebuild, f, tq, the list and its states, the
    contact records)."""
    n_p = x.shape[0]
    skin = 0.3 * rad.max()
    start, nbj, hist, dmax = _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax,
                                      n_p * walls.shape[0])
    f = np.zeros((n_p, 3))
    tq = np.zeros((n_p, 3))
    period = _period(box_lo, box_hi, periodic)
    records = _new_records(start) if steps == 0 else np.zeros((0, 3))  # records at the last step only
    # (np.int64, np.bool_: a literal argument would make numba compile a specialisation of the callee for it)
    _contact_forces(np.int64(0), n_p, x, v, w, rad, species, n_species, laws_n, laws_t, walls, period, start, nbj,
                    hist, dmax, f, tq, f, tq, records, dt, np.bool_(False), rules, laws_r, roll_kind, roll_col,
                    roll_kn)
    return (0.4 * mass * rad * rad, period, skin, np.zeros(steps // ke_every + 1), np.zeros(2, np.int64), x.copy(),
            f, tq, start, nbj, hist, dmax, records)


# ----------------------------------------------------------------------------- the loop's own clock
# A timed run (benchmarks/bench_packing_phases.py) passes ``clock``, an array of (shares + 1) rows of 2 × PHASES
# columns, into which the loop adds what each phase took: columns 0…PHASES−1 by the time-stamp counter (ticks, wall
# time), columns PHASES… by the clock of the thread that ran the phase (CPU ns: its work's and the serial phases';
# a region's launch and wait span two threads and have only the counter's). Row c (c < shares) holds share c's
# phases, the last row the calling thread's serial ones. An untimed run passes an empty array (0 rows): a test of
# its length per phase, and no clock is read. Timing changes no arithmetic.
F_LAUNCH, F_WORK, F_WAIT = 0, 1, 2  # the force region: its start to a share's, the share's work, its end to the region's
K_LAUNCH, K_GATHER, K_WORK, K_WAIT = 3, 4, 5, 6  # the kick region likewise, the far buffers' gather apart
S_REBUILD, S_AFTER, S_BALANCE, S_OTHER, S_REBUILDS = 7, 8, 9, 10, 11  # serial: rebuilds (and their count) …
PHASES = 12
CLOCK_THREAD_CPUTIME_ID = 3  # Linux's <time.h>


@intrinsic
def _ticks(typingctx):
    """The processor's time-stamp counter (llvm.readcyclecounter; ~7 ns here): a timed run's wall clock."""
    def codegen(context, builder, signature, args):
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(64), []),
                                            "llvm.readcyclecounter")
        return builder.call(fn, [])
    return types.int64(), codegen


@intrinsic
def _thread_ns(typingctx):
    """The calling thread's CPU time in ns (libc's clock_gettime(CLOCK_THREAD_CPUTIME_ID), called by name, so
    that the kernel stays cacheable; ~0.6 µs here): a timed run's CPU clock."""
    def codegen(context, builder, signature, args):
        i64 = ir.IntType(64)
        ts = cgutils.alloca_once(builder, ir.LiteralStructType([i64, i64]))
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), ts.type])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
        builder.call(fn, [ir.Constant(ir.IntType(32), CLOCK_THREAD_CPUTIME_ID), ts])
        sec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 0))
        ns = builder.load(cgutils.gep_inbounds(builder, ts, 0, 1))
        return builder.add(builder.mul(sec, ir.Constant(i64, 1_000_000_000)), ns)
    return types.int64(), codegen


@njit(cache=KERNEL_CACHE)
def clock_ticks():
    """The time-stamp counter now (a timed run's calibration)."""
    return _ticks()


@njit(cache=KERNEL_CACHE, inline="always")
def _now(clock):
    """(time-stamp counter, this thread's CPU ns) in a timed run (``clock`` not empty), else (0, 0)."""
    if clock.shape[0] == 0:
        return np.int64(0), np.int64(0)
    return _ticks(), _thread_ns()


@njit(cache=KERNEL_CACHE, inline="always")
def _add(clock, row, phase, since):
    """clock[row, phase] += the counter's ticks since ``since`` (a pair from :func:`_now`), and the CPU ns into its
    column PHASES + phase, in a timed run; returns the clocks now ((0, 0) untimed)."""
    if clock.shape[0] == 0:
        return np.int64(0), np.int64(0)
    now = _ticks(), _thread_ns()
    clock[row, phase] += now[0] - since[0]
    clock[row, PHASES + phase] += now[1] - since[1]
    return now


@njit(cache=KERNEL_CACHE, inline="always")
def _begin(clock, row, phase, since):
    """A share's start in a region: the counter's ticks since the region's start (``since``, the calling thread's
    clocks) into clock[row, phase] in a timed run; returns this thread's clocks now ((0, 0) untimed)."""
    if clock.shape[0] == 0:
        return np.int64(0), np.int64(0)
    now = _ticks(), _thread_ns()
    clock[row, phase] += now[0] - since[0]
    return now


@njit(cache=KERNEL_CACHE, inline="always")
def _count(clock, row, column):
    """clock[row, column] += 1 in a timed run (a count beside the times)."""
    if clock.shape[0] > 0:
        clock[row, column] += 1.0


@njit(cache=KERNEL_CACHE, inline="always")
def _waits(clock, ends, phase, since):
    """Each share's wait at a region's end (the counter from its work's end, ``ends``, to now) into
    clock[share, phase]; returns the calling thread's clocks now (its CPU in the region is its share's row's, or
    spinning)."""
    if clock.shape[0] == 0:
        return np.int64(0), np.int64(0)
    now = _ticks()
    for c in range(ends.shape[0]):
        clock[c, phase] += now - ends[c]
    return now, _thread_ns()


@njit(cache=KERNEL_CACHE, inline="always")
def _energy(ke, flags, step, ke_every, e, e_rot):
    """Keeps the translational kinetic energy e every ke_every steps; False, flagged, once e + e_rot is not
    finite (the run stops)."""
    if step % ke_every == 0:
        ke[step // ke_every] = e
    if math.isfinite(e + e_rot):
        return True
    flags[1] = 1
    return False


@njit(cache=KERNEL_CACHE, nogil=True)
def run(x, v, w, rad, mass, species, n_species, laws_n, laws_t, walls, box_lo, box_hi, periodic, gravity, dt, steps,
        ke_every, start, nbj, hist, dmax, contacts, rules, clock, laws_r, roll_kind, roll_col, roll_kn):
    """Velocity Verlet for ``steps`` steps from the given state (x, v, w modified in place; the contact states
    travel with the Verlet list, rebuilt here, the walls' first). Returns (translational kinetic energy every
    ke_every steps, number of pair contacts at the end (their records in ``contacts``), flags [unused,
    non-finite], and the Verlet list with its contact states: start, nbj, hist, dmax). The kinetic energy is
    translational, as the engines' thermo `ke` (the rotational energy only tells whether the run stays finite):
    without a rolling law (the case's rolling slot: ``laws_r``, ``roll_kind``, ``roll_col``, :func:`_rolling`) a
    sphere rolling or spinning about its contact normal keeps its rotational energy in every source; with one its
    rolling is resisted, a spin about the normal still is not (no twisting slot here). One
    thread; :func:`run_threaded` is the same on several. ``clock``: a timed run's (2 rows of 2 × PHASES), or empty."""
    n_p = x.shape[0]
    inertia, period, skin, ke, flags, x_ref, f, tq, start, nbj, hist, dmax, records = _setup(
        x, v, w, rad, mass, species, n_species, laws_n, laws_t, walls, box_lo, box_hi, periodic, dt, steps, ke_every,
        start, nbj, hist, dmax, rules, laws_r, roll_kind, roll_col, roll_kn)
    # one pass over the particles a step besides the force loop: the second half kick fused with the next step's
    # first half kick and drift (_kick_and_next), as the threaded loop does
    moved = _kick_drift(0, n_p, x, v, w, f, tq, mass, inertia, gravity, dt, box_lo, box_hi, periodic, x_ref)
    serial = clock.shape[0] - 1
    t = _now(clock)
    for step in range(1, steps + 1):
        # rebuild the Verlet list once any particle has moved half the skin (by minimum image: a crossing of the
        # periodic boundary is no move, _drift)
        if moved > (0.5 * skin) ** 2:
            t = _add(clock, serial, S_OTHER, t)
            start, nbj, hist, dmax = _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax,
                                              n_p * walls.shape[0])
            t = _add(clock, serial, S_REBUILD, t)
            x_ref[:, :] = x
            t = _add(clock, serial, S_AFTER, t)
            _count(clock, serial, S_REBUILDS)
        if step == steps:
            records = _new_records(start)
        t = _add(clock, serial, S_OTHER, t)
        _contact_forces(np.int64(0), n_p, x, v, w, rad, species, n_species, laws_n, laws_t, walls, period, start,
                        nbj, hist, dmax, f, tq, f, tq, records, dt, np.bool_(True), rules, laws_r, roll_kind, roll_col,
                        roll_kn)
        t = _add(clock, 0, F_WORK, t)
        e, e_rot, moved = _kick_and_next(0, n_p, x, v, w, f, tq, mass, inertia, gravity, dt, box_lo, box_hi,
                                         periodic, x_ref, step < steps)
        t = _add(clock, 0, K_WORK, t)
        if not _energy(ke, flags, step, ke_every, e, e_rot):
            break
    _add(clock, serial, S_OTHER, t)
    return ke, _contact_table(start, nbj, records, contacts), flags, start, nbj, hist, dmax


REBALANCE = 50  # steps between two cuts of the threaded loop's shares (besides one at each rebuild)
# a force share's work, in list entries (a distance test apart): a row (its loop, its particle's walls tested) 9 with
# the pour's one wall, a touching pair 32 more, a wall contact 20 more. Least-squares fits of the force loop's CPU
# time over blocks of 1000 rows of the 32 000-sphere pour at 0.02 s (bench_packing_phases.py --fit) give 37–38 ns a
# touching pair and 23 a wall contact, 12–14 a row and 1.5–2.4 an entry (rows and entries trade off in the fit);
# the weights were then set by the balance they give over the pour (its contacts form between two cuts): the bed's
# share of two at 1.008 x the mean (24 and 15 for the contacts: 1.035 x; the weights before, a row 1 + walls and
# a contact 6: 1.08 x; benchmarks/results/bench_packing_phases.txt)
ROW_COST, WALL_TEST_COST, PAIR_COST, WALL_COST = 7.0, 2.0, 32.0, 20.0


@njit(cache=KERNEL_CACHE)
def _balance(start, n_walls, dmax, chunks):
    """Row bounds ``chunks`` (len = shares + 1) that give each share about the same work: each row costs
    ROW_COST and WALL_TEST_COST a wall, each of its list entries one more, each touching pair (a nonzero largest
    overlap) PAIR_COST more and each wall contact WALL_COST more — the contacts of a pour gather in the bed while
    the rows above are falling apart."""
    n = start.shape[0] - 1
    m = chunks.shape[0] - 1
    base = n * n_walls
    cost = np.empty(n + 1)
    cost[0] = 0.0
    for i in range(n):
        c = ROW_COST + WALL_TEST_COST * n_walls + (start[i + 1] - start[i])
        for k in range(n_walls):
            if dmax[i * n_walls + k] != 0.0:
                c += WALL_COST
        for e in range(start[i], start[i + 1]):
            if dmax[base + e] != 0.0:
                c += PAIR_COST
        cost[i + 1] = cost[i] + c
    chunks[0] = 0
    i = 0
    for c in range(1, m):
        while i < n and cost[i] * m < cost[n] * c:
            i += 1
        chunks[c] = i
    chunks[m] = n


@njit(cache=KERNEL_CACHE)
def _far_ends(start, nbj, chunks, far):
    """For each share, one past the largest particle its rows list (``far``): what it adds into its far buffer
    lies below, so that the shares after it add in only their rows below that (:func:`_gather`) — the particles a
    share's contacts reach across its cut, a layer of the packing, not all of the next share's."""
    for c in range(chunks.shape[0] - 1):
        top = 0
        for e in range(start[chunks[c]], start[chunks[c + 1]]):
            if nbj[e] >= top:
                top = nbj[e] + 1
        far[c] = top


GATHER_COST = 0.5  # a far-buffer row's gather against a particle's kick (the kick region's cut: :func:`_kick_cut`)


@njit(cache=KERNEL_CACHE)
def _kick_cut(chunks, far, kicks):
    """The kick region's own cut ``kicks`` (len = shares + 1): particles in about equal work, each costing one
    and GATHER_COST more for each far buffer that holds a row of it (share c's, below far[c] and past its own
    particles). The force region's cut (``chunks``) balances contacts — a pour's bed gathers them in the lowest
    shares — and would leave the kick, whose work is per particle, to the shares above (measured at 32 000
    spheres: the two kick shares' CPU 1 : 1.4, benchmarks/results/bench_packing_phases.txt)."""
    m = chunks.shape[0] - 1
    n = chunks[m]
    total = float(n)
    for c in range(m):
        total += GATHER_COST * max(0, far[c] - chunks[c + 1])
    kicks[0] = 0
    i = 0
    done = 0.0
    for b in range(1, m):
        while i < n and done * m < total * b:
            done += 1.0
            for c in range(m):
                if chunks[c + 1] <= i < far[c]:
                    done += GATHER_COST
            i += 1
        kicks[b] = i
    kicks[m] = n


@njit(cache=KERNEL_CACHE)
def _cut(start, n_walls, dmax, nbj, chunks, far, kicks):
    """The threaded loop's cuts: the force region's shares (:func:`_balance`), their far ends (:func:`_far_ends`)
    and the kick region's shares (:func:`_kick_cut`)."""
    _balance(start, n_walls, dmax, chunks)
    _far_ends(start, nbj, chunks, far)
    _kick_cut(chunks, far, kicks)


@njit(cache=KERNEL_CACHE, inline="always")
def _gather(lo, hi, chunks, far, f_far, tq_far, f, tq):
    """Into f and tq of particles lo…hi−1 (a share of the kick region's cut), what the force region's shares
    added for them into their far buffers — share c's rows past its own particles and below far[c] (nothing lies
    beyond) — in the order of the shares, as a particle's own share's thread would; each row read is zeroed for
    the next step."""
    for c in range(chunks.shape[0] - 1):
        for i in range(max(lo, chunks[c + 1]), min(hi, far[c])):
            for k in range(3):
                f[i, k] += f_far[c, i, k]
                tq[i, k] += tq_far[c, i, k]
                f_far[c, i, k] = tq_far[c, i, k] = 0.0


@njit(cache=KERNEL_CACHE, nogil=True, parallel=True)
def run_threaded(x, v, w, rad, mass, species, n_species, laws_n, laws_t, walls, box_lo, box_hi, periodic, gravity, dt,
                 steps, ke_every, start, nbj, hist, dmax, contacts, rules, clock, laws_r, roll_kind, roll_col, roll_kn,
                 threads):
    """:func:`run` on ``threads`` threads (numba's, prange). The particles, and with them the rows of the
    Verlet list, are cut into as many shares of about equal work (:func:`_balance`, again at each rebuild, which
    is threaded too). A share's contacts are computed by one thread, which alone updates their states (a pair's
    sits beside its entry, a wall contact's in its particle's row) and writes the forces and torques of its own
    particles; what it adds for another share's particle (a pair across the cut, j > i) goes into its far
    buffer. The kick region has a cut of its own (:func:`_kick_cut`: its work is per particle, the force region's
    per contact): each of its shares adds in what the far buffers hold for its particles (:func:`_gather`, in
    the order of the force region's shares), then kicks and drifts them. Race-free, and no locks: two parallel
    regions a step (three more at a rebuild). The same arithmetic per contact as :func:`run`: with one thread the
    same bits; with more, a particle's force is summed in another order (round-off), the same whatever the kick
    region's cut (only the kinetic energy's partial sums follow it). ``clock``: a timed run's (shares + 1 rows of 2 × PHASES), or empty."""
    n_p = x.shape[0]
    n_w = walls.shape[0]
    inertia, period, skin, ke, flags, x_ref, f, tq, start, nbj, hist, dmax, records = _setup(
        x, v, w, rad, mass, species, n_species, laws_n, laws_t, walls, box_lo, box_hi, periodic, dt, steps, ke_every,
        start, nbj, hist, dmax, rules, laws_r, roll_kind, roll_col, roll_kn)
    chunks = np.empty(threads + 1, np.int64)  # each share's rows of the list, and its particles
    far = np.empty(threads, np.int64)  # each share's far buffer holds particles below far[share] only
    kicks = np.empty(threads + 1, np.int64)  # the kick region's shares of the particles
    _cut(start, n_w, dmax, nbj, chunks, far, kicks)
    f_far = np.zeros((threads, n_p, 3))  # per share: what it adds for particles of the shares after it
    tq_far = np.zeros((threads, n_p, 3))
    moved = np.zeros(threads)
    e_share = np.zeros(threads)
    e_rot_share = np.zeros(threads)
    # two parallel regions a step, the fewest velocity Verlet allows (a region's launch and its barrier are the
    # threads' overhead): the forces, then the second half kick fused with the next step's first and its drift
    if steps > 0:
        for b in prange(threads):
            moved[b] = _kick_drift(kicks[b], kicks[b + 1], x, v, w, f, tq, mass, inertia, gravity, dt, box_lo,
                                   box_hi, periodic, x_ref)
    serial = clock.shape[0] - 1
    ends = np.zeros(threads, np.int64)  # a timed run's: the end of each share's work in a region
    t = _now(clock)
    for step in range(1, steps + 1):
        most = 0.0
        for b in range(threads):
            most = max(most, moved[b])
        if most > (0.5 * skin) ** 2:
            t = _add(clock, serial, S_OTHER, t)
            # its rows cut as the kicks' particles: a row's cost there is its cells' search, not its contacts
            start, nbj, hist, dmax = _rebuild_threaded(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist,
                                                       dmax, n_p * n_w, kicks)
            t = _add(clock, serial, S_REBUILD, t)
            x_ref[:, :] = x
            _cut(start, n_w, dmax, nbj, chunks, far, kicks)
            t = _add(clock, serial, S_AFTER, t)
            _count(clock, serial, S_REBUILDS)
        elif step % REBALANCE == 0:  # the contacts formed since (a pour's bed grows between rebuilds)
            t = _add(clock, serial, S_OTHER, t)
            _cut(start, n_w, dmax, nbj, chunks, far, kicks)
            t = _add(clock, serial, S_BALANCE, t)
        if step == steps:
            records = _new_records(start)
        t = _add(clock, serial, S_OTHER, t)
        for c in prange(threads):
            began = _begin(clock, c, F_LAUNCH, t)
            _contact_forces(chunks[c], chunks[c + 1], x, v, w, rad, species, n_species, laws_n, laws_t, walls, period,
                            start, nbj, hist, dmax, f, tq, f_far[c], tq_far[c], records, dt, np.bool_(True), rules,
                            laws_r, roll_kind, roll_col, roll_kn)
            ends[c] = _add(clock, c, F_WORK, began)[0]
        t = _waits(clock, ends, F_WAIT, t)
        for b in prange(threads):
            began = _begin(clock, b, K_LAUNCH, t)
            _gather(kicks[b], kicks[b + 1], chunks, far, f_far, tq_far, f, tq)
            began = _add(clock, b, K_GATHER, began)
            # the kick, and the next step's first half kick and drift in the same pass unless the run is over
            e_share[b], e_rot_share[b], moved[b] = _kick_and_next(kicks[b], kicks[b + 1], x, v, w, f, tq, mass,
                                                                  inertia, gravity, dt, box_lo, box_hi, periodic,
                                                                  x_ref, step < steps)
            ends[b] = _add(clock, b, K_WORK, began)[0]
        t = _waits(clock, ends, K_WAIT, t)
        e = 0.0
        e_rot = 0.0
        for b in range(threads):
            e += e_share[b]
            e_rot += e_rot_share[b]
        if not _energy(ke, flags, step, ke_every, e, e_rot):
            break
    _add(clock, serial, S_OTHER, t)
    return ke, _contact_table(start, nbj, records, contacts), flags, start, nbj, hist, dmax


# ----------------------------------------------------------------------------- Python side


def solver_fingerprint() -> str:
    """A hash of the reference solver's source (every module of demcheck.reference) and of numba's and
    numpy's versions: part of the key under which verify caches a reference packing, so that a change to the
    solver never serves a stale result."""
    import hashlib

    import numba

    from .. import reference_fingerprint

    return hashlib.sha256(f"{reference_fingerprint()} numba {numba.__version__} numpy {np.__version__}".encode()
                          ).hexdigest()[:16]


def species_of(case) -> tuple[np.ndarray, list[int]]:
    """Species (material, radius) of each particle, and one representative particle per species."""
    keys, rep, sp = {}, [], np.empty(len(case.particles), np.int64)
    for i, p in enumerate(case.particles):
        k = (p.material, p.radius)
        if k not in keys:
            keys[k] = len(rep)
            rep.append(i)
        sp[i] = keys[k]
    return sp, rep


def resolve_laws(case):
    """Per species pair (and per species against the walls) the normal and tangential law arrays."""
    from ..errors import ConfigError
    from ..laws.contact import pair_of
    from ..laws.model import models_of
    from ..laws.normal import NormalLaw

    normal, tangential = models_of(case)
    sp, rep = species_of(case)
    ns = len(rep)
    params = case.contact.params
    laws_n = np.zeros((ns, ns, len(NormalLaw(0).array())))
    laws_t = np.zeros((ns, ns, T_SIZE))
    wall_n = np.zeros((ns, len(NormalLaw(0).array())))
    wall_t = np.zeros((ns, T_SIZE))

    def law(pair):
        nl, _ = normal.resolve(pair, params, case.contact.limit_force)
        tl, _ = tangential.resolve(pair, params, nl)
        arr = tl.array()
        if arr[T_FORCE] != 0.0 or arr[T_RESCALE] != 0.0:  # every tangential family runs, these two variants not
            raise ConfigError("contact.tangential", tangential.id,
                              "is not supported by the packing solver (a force history or a contact-radius "
                              "rescale of the history: engine twins of the two-body solver)")
        return nl.array(), arr

    for a in range(ns):
        for b in range(a, ns):
            laws_n[a, b], laws_t[a, b] = law(pair_of(case, rep[a], rep[b]))
            laws_n[b, a], laws_t[b, a] = laws_n[a, b], laws_t[a, b]
        if case.walls:
            wall_n[a], wall_t[a] = law(pair_of(case, rep[a], None))
    return sp, laws_n, laws_t, wall_n, wall_t


def packing_dt(case) -> float:
    """dt: the case's, or the elastic contact time of the smallest species' pair law at the speed of a
    one-diameter drop, over steps_per_contact (case.packing_step: the rule every source shares)."""
    from ..case import packing_step

    return packing_step(case)


def with_batches(case):
    """The case with every particle it will hold: an inserted packing's batches all in (case.insertion_batches, in
    order: batch 0 is the case's own particles), for its laws and species; any other case as it is."""
    from dataclasses import replace

    from ..case import Particle, insertion_batches

    if case.packing is None or case.packing.insertion is None:
        return case
    return replace(case, particles=tuple(Particle(**p) for batch in insertion_batches(case.packing) for p in batch))


class PackState:
    """The state of a packing run (arrays the compiled kernel updates in place). An inserted packing's state holds
    the particles inserted so far (the first ``len(x)`` of ``full``'s; :meth:`insert_batches`)."""

    def __init__(self, case):
        self.case = case
        self.full = full = with_batches(case)
        n = len(full.particles)
        self.x = np.array([p.position for p in full.particles], float)
        self.v = np.array([p.velocity for p in full.particles], float)
        self.w = np.array([p.angular_velocity for p in full.particles], float)
        self.rad = np.array([p.radius for p in full.particles], float)
        self.mass = np.array([full.mass(i) for i in range(n)], float)
        self.species_all = species_of(full)[0]
        self._all = (self.x, self.v, self.w, self.rad, self.mass)
        _, _, laws_t, _, wall_t = resolve_laws(full)
        rows = [*laws_t.reshape(-1, T_SIZE), *(wall_t if case.walls else ())]
        width = history_width([TangentialLaw.from_array(t).slot() for t in rows])
        # the rolling law's: (kind, its history's columns, its table, its kn column) — its history after the
        # tangential one's
        self.rolling = rolling_laws(full, species_of(full)[1])
        self.roll_col = width if self.rolling[1] else -1
        width += self.rolling[1]
        # the contact states (history, largest overlap): particle i's with wall k in row i·n_walls + k, then
        # each pair of the Verlet list (compressed rows; built by run()) beside its entry
        ins = case.packing.insertion if case.packing is not None else None
        if ins is not None:
            self._take(ins.batch)  # the first batch: the others join the run
        now = len(self.x)
        self.start = np.zeros(now + 1, np.int64)
        self.nbj = np.zeros(0, np.int64)
        self.hist = np.zeros((now * len(case.walls), width))
        self.dmax = np.zeros(now * len(case.walls))
        self.contacts = np.zeros((8 * n + 16, 5))
        self.n_contacts = 0
        self.time = 0.0
        self.ke = []  # (t, kinetic energy)
        self.walls = tuple(case.walls)  # the walls present (a timed wall is removed: remove_walls)
        self.steps = 0  # steps run from the start (a timed wall's removal counts them)
        # an inserted packing's batches after the first: (time, particles in once it is in)
        self.batches = [] if ins is None else [(b * ins.every, (b + 1) * ins.batch) for b in range(1, ins.batches)]

    @property
    def species(self) -> np.ndarray:
        """The species of the particles present."""
        return self.species_all[:len(self.x)]

    def _take(self, n: int) -> None:
        """The first n particles of ``full`` present, those present before kept as they are."""
        have = len(self.x)
        arrays = [np.concatenate([mine, every[have:n]]) if n > have else every[:n].copy()
                  for mine, every in zip((self.x, self.v, self.w, self.rad, self.mass), self._all)]
        self.x, self.v, self.w, self.rad, self.mass = arrays

    def next_insertion(self, dt: float) -> int:
        """The step (from the start) after which the next batch is inserted; a huge number where none is left."""
        return step_at(self.batches[0][0], dt) if self.batches else 2 ** 62

    def insert_batches(self, dt: float) -> bool:
        """Inserts the batches whose time has come (after ``steps`` steps): the new particles join at rest with no
        contact state (the walls' rows of the state grow, the pairs' follow; the next run's list finds their
        pairs). A new particle overlapping one already there is a ConfigError naming the insertion region.
        Returns whether any was inserted."""
        from ..errors import ConfigError

        done = False
        while self.batches and step_at(self.batches[0][0], dt) <= self.steps:
            t, n = self.batches.pop(0)
            have, n_w = len(self.x), len(self.walls)
            self._take(n)
            clash = _first_clash(self.x, self.rad, have)
            if clash is not None:
                i, j = clash
                raise ConfigError("packing.insertion.region", [list(c) for c in self.case.packing.insertion.region],
                                  f"the batch inserted at {t:g} s puts particle {j} into particle {i}, which is "
                                  "still there: the region must be clear when a batch comes in")
            self.start = np.concatenate([self.start, np.full(n - have, self.start[-1], np.int64)])
            rows, pairs = self.hist[:have * n_w], self.hist[have * n_w:]
            self.hist = np.concatenate([rows, np.zeros(((n - have) * n_w, self.hist.shape[1])), pairs])
            self.dmax = np.concatenate([self.dmax[:have * n_w], np.zeros((n - have) * n_w), self.dmax[have * n_w:]])
            done = True
        return done

    def next_removal(self, dt: float) -> int:
        """The step (from the start) after which the next timed wall is removed (:func:`removal_step`); a huge
        number where none is left."""
        steps = [removal_step(w.until, dt) for w in self.walls if getattr(w, "until", None) is not None]
        return min(steps, default=2 ** 62)

    def remove_walls(self, dt: float) -> bool:
        """Removes the timed walls whose time has come (after ``steps`` steps), with their contact states; every
        other contact's state is kept (the pairs' after the walls' rows move up). Returns whether any was removed."""
        keep = [getattr(w, "until", None) is None or removal_step(w.until, dt) > self.steps for w in self.walls]
        if all(keep):
            return False
        n, n_w = len(self.x), len(self.walls)
        rows = np.arange(n * n_w).reshape(n, n_w)[:, keep].ravel()
        self.hist = np.concatenate([self.hist[rows], self.hist[n * n_w:]])
        self.dmax = np.concatenate([self.dmax[rows], self.dmax[n * n_w:]])
        self.walls = tuple(w for w, k in zip(self.walls, keep) if k)
        return True


def step_at(t: float, dt: float) -> int:
    """The first step whose end (k·dt) is at or past time t; a time one round-off past a step's end (0.1·3 s at
    0.1 s: 0.30000000000000004) is that step's."""
    return math.ceil(t / dt * (1.0 - 1e-12))


def removal_step(until: float, dt: float) -> int:
    """The step after which a wall with ``until`` (s) is removed (:func:`step_at`, at least the first)."""
    return max(1, step_at(until, dt))


def _first_clash(x: np.ndarray, rad: np.ndarray, have: int) -> tuple[int, int] | None:
    """A particle i < have overlapped by a new one j ≥ have (None: none): new ones are clear of each other."""
    from scipy.spatial import cKDTree

    if have == 0:
        return None
    old = cKDTree(x[:have])
    for j in range(have, len(x)):
        for i in old.query_ball_point(x[j], rad[j] + float(rad[:have].max())):
            if np.linalg.norm(x[j] - x[i]) < (rad[i] + rad[j]) * (1 - 1e-12):
                return int(i), int(j)
    return None


def box_of(case, x, rad):
    """(lo, hi, periodic): the packing's periodic box in x and y, and a z range that holds the particles."""
    spec = case.packing
    rmax = float(rad.max())
    zlo = min(0.0, float((x[:, 2] - rad).min())) - rmax
    zhi = float((x[:, 2] + rad).max()) + 4 * rmax
    if spec is not None and spec.box is not None:
        lx, ly = spec.box
        return np.array([0.0, 0.0, zlo]), np.array([lx, ly, zhi]), np.array([True, True])
    lo = (x - rad[:, None]).min(axis=0) - 4 * rmax
    hi = (x + rad[:, None]).max(axis=0) + 4 * rmax
    lo[2], hi[2] = zlo, zhi
    return lo, hi, np.array([False, False])


def wall_table(walls) -> np.ndarray:
    """The walls (case.Wall) as the loop reads them: a plane's point and normal (W_PLANE columns), all a table
    holds where every wall is a plane (the loop then tests no segment); with a segment among them W_WIDTH columns:
    each segment's direction along its strip, its extent and its two edge lines (whose they are, and which other
    segments end on them: a corner is one contact, :func:`_segment_contact`), a plane's extent (−inf, inf)."""
    from ..errors import ConfigError

    table = np.array([[*w.point, *w.normal] for w in walls], float).reshape(-1, W_PLANE)
    if not any(getattr(w, "extent", None) for w in walls):
        return table
    wide = np.full((len(walls), W_WIDTH), -1.0)
    wide[:, :W_PLANE] = table
    ends = {}  # (wall, 0 | 1) → (a point of the edge line, its direction)
    for k, w in enumerate(walls):
        wide[k, W_ALONG:W_ALONG + 3] = w.along if w.extent else 0.0
        wide[k, W_S0], wide[k, W_S1] = w.extent if w.extent else (-math.inf, math.inf)
        if w.extent:
            line = np.cross(w.normal, w.along)
            for side in (0, 1):
                ends[(k, side)] = (np.asarray(w.point) + w.extent[side] * np.asarray(w.along), line)
    for (k, side), (q, b) in ends.items():
        scale = 1e-9 * (1.0 + float(np.abs(q).max()))
        shared = [o for (o, other), (q2, b2) in ends.items() if o != k and np.linalg.norm(np.cross(b, b2)) < 1e-9
                  and np.linalg.norm((q - q2) - ((q - q2) @ b) * b) < scale]
        if len(shared) > W_EDGE - 1:
            raise ConfigError(f"walls.{k}.extent", list(walls[k].extent), f"ends on an edge line that {len(shared)} "
                              f"other walls' strips end on too: a corner is shared by at most {W_EDGE} walls")
        col = W_EDGES + side * W_EDGE
        wide[k, col] = 0.0 if shared and min(shared) < k else 1.0
        wide[k, col + 1:col + 1 + len(shared)] = shared
    return wide


def law_table(laws_n, laws_t, wall_n, wall_t):
    """resolve_laws's laws as the kernels take them: one row per species pair (si·n_species + sj), then one
    per species against the walls (n_species² + si), normal and tangential."""
    ns = laws_n.shape[0]
    return (np.concatenate([laws_n.reshape(ns * ns, -1), wall_n]),
            np.concatenate([laws_t.reshape(ns * ns, -1), wall_t]))


def fall_time(case) -> float:
    """The time the lowest body of a packing's starting state needs to touch a floor (a wall that gravity points
    into) falling freely from rest: √(2h/|g|), h its smallest gap to such a floor. No contact with a floor can form
    sooner, so a shorter run cannot give a packing; 0 where nothing falls (no gravity, no floor, a body touching)."""
    g = np.asarray(case.run.gravity, float)
    gn = float(np.linalg.norm(g))
    x = np.array([p.position for p in case.particles], float).reshape(-1, 3)
    r = np.array([p.radius for p in case.particles], float)
    gaps = [(x - np.asarray(w.point, float)) @ np.asarray(w.normal, float) - r for w in case.walls
            if gn > 0.0 and float(np.dot(w.normal, g)) < 0.0]
    if not gaps or len(r) == 0:
        return 0.0
    h = max(0.0, float(min(gap.min() for gap in gaps)))
    # the component of g along the floor's normal sets the fall; the floors are taken as normal to g
    return math.sqrt(2.0 * h / gn)


def check_threads(threads) -> int:
    """``threads`` as a number of threads for the packing loop: a whole number from 1 to numba's threads
    (NUMBA_NUM_THREADS, by default the machine's cores); anything else is a ConfigError."""
    import numba

    from ..errors import ConfigError

    most = numba.config.NUMBA_NUM_THREADS
    if isinstance(threads, (bool, np.bool_)) or not isinstance(threads, (int, np.integer)) or not 1 <= threads <= most:
        raise ConfigError("--threads", threads, f"must be a whole number from 1 to {most}, the threads numba may "
                          "use here (NUMBA_NUM_THREADS)")
    return int(threads)


def _prefer_openmp():
    """numba's threading layer for the threaded loop: OpenMP first, then its own work queue, TBB last, unless the
    user chose (NUMBA_THREADING_LAYER or NUMBA_THREADING_LAYER_PRIORITY). The loop launches two parallel regions
    per step; numba's TBB layer builds a task arena per launch: measured, 0.27 ms a launch, growing to 3.7 ms within
    a minute (its memory too), against tens of microseconds for OpenMP under the same load (docs/packing.md). The
    layer is chosen once per process, at the first parallel launch or compilation: this runs before the kernel's."""
    import os

    import numba

    if "NUMBA_THREADING_LAYER" not in os.environ and "NUMBA_THREADING_LAYER_PRIORITY" not in os.environ:
        numba.config.THREADING_LAYER_PRIORITY = ["omp", "workqueue", "tbb"]


def advance(case, st: PackState, dt: float, steps: int, rules: dict | None = None, laws=None, walls=None,
            gravity=None, ke_every: int | None = None, threads: int = 1, clock: np.ndarray | None = None):
    """``steps`` velocity-Verlet steps of the packing state ``st`` (updated): (kinetic energy every ke_every
    steps, number of pair contacts, flags [unused, non-finite]). ``threads``: 1 runs :func:`run`, more
    :func:`run_threaded` on that many of numba's threads. ``clock``: None, or a timed run's array of
    (threads + 1, 2 × PHASES) float64 into which the loop adds each phase's time-stamp-counter ticks (the
    module's clock notes; benchmarks/bench_packing_phases.py)."""
    import numba

    from .collision3d import rules_array

    threads = check_threads(threads)
    if clock is None:
        clock = np.zeros((0, 2 * PHASES))  # untimed
    elif clock.shape != (threads + 1, 2 * PHASES) or clock.dtype != np.float64 or not clock.flags.c_contiguous:
        raise ValueError(f"clock: a C-contiguous float64 array of shape {(threads + 1, 2 * PHASES)}, not {clock.shape}")
    sp, laws_n, laws_t, wall_n, wall_t = laws or resolve_laws(case)
    if walls is None:
        walls = wall_table(st.walls)
    g = np.asarray(case.run.gravity if gravity is None else gravity, float)
    lo, hi, periodic = box_of(case, st.x, st.rad)
    roll_kind, _, laws_r, roll_kn = st.rolling
    args = (st.x, st.v, st.w, st.rad, st.mass, sp, laws_n.shape[0], *law_table(laws_n, laws_t, wall_n, wall_t), walls,
            lo, hi, periodic, g, dt, steps, ke_every or max(1, steps // 20), st.start, st.nbj, st.hist, st.dmax,
            st.contacts, rules_array(rules), clock, laws_r, np.int64(roll_kind), np.int64(st.roll_col),
            np.int64(roll_kn))
    if threads == 1:
        out = run(*args)
    else:
        _prefer_openmp()
        before = numba.get_num_threads()  # numba's thread count is the calling thread's own
        numba.set_num_threads(threads)
        try:
            out = run_threaded(*args, threads)
        finally:
            numba.set_num_threads(before)
    ke, nc, flags, st.start, st.nbj, st.hist, st.dmax = out
    return ke, nc, flags


def simulate(case, duration: float | None = None, dt: float | None = None, rest: float = 0.0,
             chunk: int = 2000, state: PackState | None = None, rules: dict | None = None,
             threads: int = 1, clock: np.ndarray | None = None, observe=None) -> PackState:
    """Run the packing for ``duration`` (s; default the case's packing.duration) — `pack` and `verify` alike, as
    the engines do: an early stop where the kinetic energy dips (``rest`` × N m g R, off by default) can fall on a
    turning point of a layer bouncing in phase, not on a settled state; dt and the number of steps are case.packing_run's (a run
    past its bound is a ConfigError before any step). ``rules``: the kinematic rules (collision3d's names;
    default the seed's), e.g. an engine's rules (engines.base.Engine.rules) for its twin. ``threads``: the force
    loop's threads (default 1: the same bits on every run; more: each step the same to round-off, which a pour's
    collisions amplify — the same packing in its statistics, docs/packing.md). ``clock``: a timed run's (advance).

    The run goes in chunks of at most ``chunk`` steps, each ending where something happens between steps: a timed
    wall removed (its ``until``: :func:`removal_step`), an inserted packing's batch coming in (every ``every`` s:
    :meth:`PackState.insert_batches`), an observation (``observe`` = (steps, fn): fn(state) after each of those
    steps, counted from the start; step 0 is the starting state). The Verlet list and every contact's state carry
    over from chunk to chunk (as they do in one run)."""
    from ..case import packing_run
    from ..errors import ConfigError

    threads = check_threads(threads)
    dt, duration, total = packing_run(case, duration, dt)  # dt and steps, bounded, as every engine's deck
    st = state or PackState(case)
    _, laws_n, laws_t, wall_n, wall_t = resolve_laws(st.full)
    walls = wall_table(st.walls)
    g = np.asarray(case.run.gravity, float)
    scale = len(case.particles) * float(st.mass.mean()) * max(float(np.linalg.norm(g)), 1e-300) * float(st.rad.mean())
    looks = sorted(set(observe[0])) if observe else []
    if looks and looks[0] <= st.steps:
        observe[1](st)  # the starting state
    looks = [k for k in looks if k > st.steps]
    done = 0
    while done < total:
        events = (st.next_removal(dt), st.next_insertion(dt), looks[0] if looks else 2 ** 62)
        n_steps = min(chunk, total - done, max(1, min(events) - st.steps))
        ke, nc, flags = advance(case, st, dt, n_steps, rules, laws=(st.species, laws_n, laws_t, wall_n, wall_t),
                                walls=walls, gravity=g, threads=threads, clock=clock)
        if flags[1]:
            raise ConfigError("run.dt", dt, "the packing became non-finite: the time step is too large")
        for k, e in enumerate(ke[1:], start=1):
            st.ke.append((st.time + k * max(1, n_steps // 20) * dt, float(e)))
        done += n_steps
        st.steps += n_steps
        st.time += n_steps * dt
        st.n_contacts = int(nc)
        if st.remove_walls(dt):
            walls = wall_table(st.walls)
        st.insert_batches(dt)
        while looks and looks[0] <= st.steps:
            looks.pop(0)
            observe[1](st)
        if st.ke and st.ke[-1][1] < rest * scale:
            break
    return st
