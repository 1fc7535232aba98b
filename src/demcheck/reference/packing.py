"""The N-body reference solver for packings: spheres, plane walls, periodic x and y, gravity.

The engines' scheme (velocity Verlet of fix nve/sphere, I = 0.4 m R²), Verlet neighbour lists in
compressed rows built from linked cells with a skin (rebuilt once a particle has moved half of it; O(N),
memory linear in N), each listed pair's contact state (history, largest overlap) stored beside it in the
list and carried over at a rebuild (as LAMMPS's fix neigh/history), and one state per particle–wall
contact. The contact laws are the reference's compiled laws (kernels.py's normal force, kernels3d.py's
tangential laws), one law per pair of particle species, so any normal × tangential model — engine twins
included — runs here as in the two-body solvers. Tangential laws with a
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
from numba import njit

from .kernels import normal_force
from .kernels3d import (ARM_RADIUS, R_ROTATION, R_SLIP_ARM, R_TORQUE_ARM, R_WALL_SLIP_ARM, R_WALL_TORQUE_ARM, eta_of,
                        kt_of, project_history, return_map, slip_surface, spring_slip, tangential_force,
                        turn_history, wall_arm, walton_reverses, walton_stiffness)
from .tangential import LTH, NONE, SPRING, T_FORCE, T_FAMILY, T_MU_K, T_MU_S, T_RESCALE, T_SIZE, T_TRUNC, WALTON, ZZY

# per contact (a row beside its neighbour-list entry): the tangential history (3); a spring law with μk < μs
# also its slip state (1); Walton's the load at the last reversal (3) and the last nonzero slip velocity (3).
# Rows are only as wide as the packing's laws need (memory and bandwidth)
HIST_WIDTH, SLIP_HIST_WIDTH, WALTON_HIST_WIDTH = 3, 4, 9


@njit(cache=True)
def _cells(x, box_lo, box_hi, cell, periodic):
    """Linked cells: (head, nxt, dims), cells at least the largest contact distance wide. A periodic axis
    with fewer than three cells is one cell, so that no neighbour cell is visited twice."""
    dims = np.empty(3, np.int64)
    for k in range(3):
        dims[k] = max(1, int((box_hi[k] - box_lo[k]) / cell))
        if k < 2 and periodic[k] and dims[k] < 3:
            dims[k] = 1
    ncell = dims[0] * dims[1] * dims[2]
    head = -np.ones(ncell, np.int64)
    nxt = -np.ones(x.shape[0], np.int64)
    for i in range(x.shape[0]):
        idx = _cell_index(x[i], box_lo, box_hi, dims, periodic)
        nxt[i] = head[idx]
        head[idx] = i
    return head, nxt, dims


@njit(cache=True, inline="always")
def _cell_of(xk, lo, hi, dim, per):
    s = (xk - lo) / (hi - lo)
    if per:
        s -= math.floor(s)
    return min(dim - 1, max(0, int(s * dim)))


@njit(cache=True)
def _cell_index(xi, box_lo, box_hi, dims, periodic):
    c0 = _cell_of(xi[0], box_lo[0], box_hi[0], dims[0], periodic[0])
    c1 = _cell_of(xi[1], box_lo[1], box_hi[1], dims[1], periodic[1])
    c2 = _cell_of(xi[2], box_lo[2], box_hi[2], dims[2], False)
    return (c0 * dims[1] + c1) * dims[2] + c2


@njit(cache=True, inline="always")
def _separation(x, i, j, box, periodic):
    """x_j − x_i, by minimum image along the periodic axes."""
    d0 = x[j, 0] - x[i, 0]
    d1 = x[j, 1] - x[i, 1]
    d2 = x[j, 2] - x[i, 2]
    if periodic[0]:
        d0 -= box[0] * math.floor(d0 / box[0] + 0.5)
    if periodic[1]:
        d1 -= box[1] * math.floor(d1 / box[1] + 0.5)
    return d0, d1, d2


NB_PER_PARTICLE = 8  # the neighbour list's first capacity per particle (pairs j > i); grown when short


@njit(cache=True)
def _build_neighbours(x, rad, box_lo, box_hi, periodic, skin, start, nbj):
    """Verlet list in compressed rows: for each i, the j > i within r_i + r_j + skin (linked cells of that
    width) in nbj[start[i]:start[i+1]]. Returns the number of entries needed; when it exceeds len(nbj) the
    list is incomplete and the caller grows nbj and builds again."""
    cell = 2.0 * rad.max() + skin
    head, nxt, dims = _cells(x, box_lo, box_hi, cell, periodic)
    box = box_hi - box_lo
    rx = 1 if dims[0] >= 3 or not periodic[0] else 0
    ry = 1 if dims[1] >= 3 or not periodic[1] else 0
    count = 0
    for i in range(x.shape[0]):
        start[i] = count
        c0 = _cell_of(x[i, 0], box_lo[0], box_hi[0], dims[0], periodic[0])
        c1 = _cell_of(x[i, 1], box_lo[1], box_hi[1], dims[1], periodic[1])
        c2 = _cell_of(x[i, 2], box_lo[2], box_hi[2], dims[2], False)
        for dx in range(-rx, rx + 1):
            for dy in range(-ry, ry + 1):
                for dz in range(-1, 2):
                    cx, cy, cz = c0 + dx, c1 + dy, c2 + dz
                    if cx < 0 or cx >= dims[0]:
                        if not periodic[0]:
                            continue
                        cx %= dims[0]
                    if cy < 0 or cy >= dims[1]:
                        if not periodic[1]:
                            continue
                        cy %= dims[1]
                    if cz < 0 or cz >= dims[2]:
                        continue
                    j = head[(cx * dims[1] + cy) * dims[2] + cz]
                    while j >= 0:
                        if j > i:
                            d0, d1, d2 = _separation(x, i, j, box, periodic)
                            reach = rad[i] + rad[j] + skin
                            if d0 * d0 + d1 * d1 + d2 * d2 < reach * reach:
                                if count < nbj.shape[0]:
                                    nbj[count] = j
                                count += 1
                        j = nxt[j]
    start[x.shape[0]] = count
    return count


@njit(cache=True)
def _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax):
    """A new Verlet list, each pair's contact state (history, largest overlap) carried over from the old
    list where the pair was already listed (as LAMMPS's fix neigh/history). Returns the new arrays."""
    n = x.shape[0]
    new_start = np.empty(n + 1, np.int64)
    new_j = np.empty(max(nbj.shape[0], NB_PER_PARTICLE * n), np.int64)
    need = _build_neighbours(x, rad, box_lo, box_hi, periodic, skin, new_start, new_j)
    if need > new_j.shape[0]:
        new_j = np.empty(need + need // 4, np.int64)
        _build_neighbours(x, rad, box_lo, box_hi, periodic, skin, new_start, new_j)
    new_hist = np.zeros((new_j.shape[0], hist.shape[1]))
    new_dmax = np.zeros(new_j.shape[0])
    for i in range(n):
        for q in range(new_start[i], new_start[i + 1]):
            j = new_j[q]
            for p in range(start[i], start[i + 1]):
                if nbj[p] == j:
                    if dmax[p] != 0.0:
                        new_hist[q, :] = hist[p, :]
                        new_dmax[q] = dmax[p]
                    break
    return new_start, new_j, new_hist, new_dmax


@njit(cache=True, inline="always")
def _contact_force(nl, tl, delta, rate, n, vt, hist2, row, dmax_in, dt, update, ft, rot):
    """Normal force (+ repulsive) of one contact, and its tangential force into ``ft``, updating its history
    (row ``row`` of ``hist2``) in place by the verlet rules of kernels3d.verlet_3d: rotate-rescale, increment,
    truncate; ``update`` False at setup, where the engines compute forces without touching histories.
    Returns (Fn, δ_max). Inlined into the force loop with the spring family's scalar law (every deck's law):
    a call per contact, with its dozen array arguments, cost the loop 40 % (0.80 against 0.48 ms per step on
    the 2000-sphere packing; docs/packing.md). The laws that build arrays (kernels3d's functions) stay in
    :func:`_other_tangential`, called."""
    dmax = max(dmax_in, delta)
    fn = normal_force(nl, delta, rate, dmax)
    family = tl[T_FAMILY]
    ft[0] = ft[1] = ft[2] = 0.0
    if family == NONE:
        return fn, dmax
    if family == SPRING and update:
        return _spring(nl, tl, delta, n, vt, hist2, row, abs(fn), dt, ft, fn, dmax, rot)
    _other_tangential(nl, tl, delta, n, vt, hist2[row], abs(fn), dt, update, ft, rot)
    return fn, dmax


@njit(cache=True)
def _other_tangential(nl, tl, delta, n, vt, hist, fabs, dt, update, ft, rot):
    """The tangential force of every law but the updated spring family, into ``ft`` (history ``hist``, one
    contact's row, updated in place)."""
    family = tl[T_FAMILY]
    if (family == LTH or family == ZZY or family == WALTON) and update:
        # Langston's and Zheng's laws on their overlap history, Walton's on its load history (with the load at
        # the last reversal L* in hist[3:6] and the last nonzero slip velocity in hist[6:9]), by kernels3d's functions
        # in verlet_3d's order
        hist[0], hist[1], hist[2] = turn_history(hist[0], hist[1], hist[2], n, rot, kt_of(tl, delta), tl[T_MU_K],
                                                 fabs)
        if family == WALTON:
            if walton_reverses(vt, hist[6:9]):  # L* = L
                hist[3], hist[4], hist[5] = hist[0], hist[1], hist[2]
            if vt[0] != 0.0 or vt[1] != 0.0 or vt[2] != 0.0:
                hist[6], hist[7], hist[8] = vt[0], vt[1], vt[2]
            kw = walton_stiffness(tl, hist[0:3], vt, fabs, hist[3:6])
            for k in range(3):
                hist[k] += kw * vt[k] * dt
        else:
            for k in range(3):
                hist[k] += vt[k] * dt
        hist[0], hist[1], hist[2] = project_history(hist[0], hist[1], hist[2], n, rot)
        sliding = slip_surface(tl, nl, hist, vt, fabs, delta, tl[T_MU_S])[0] > 0.0
        if sliding:
            mapped = return_map(tl, nl, hist, vt, fabs, delta, tl[T_MU_K])
            hist[0], hist[1], hist[2] = mapped[0], mapped[1], mapped[2]
        out = tangential_force(tl, nl, hist, vt, fabs, delta, sliding, ZERO3)
        ft[0], ft[1], ft[2] = out[0], out[1], out[2]
        return
    out = tangential_force(tl, nl, hist, vt, fabs, delta, False, ZERO3)
    if family == SPRING:  # setup: the trial force within the static limit, history untouched
        tn = math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2)
        cap = tl[T_MU_S] * fabs
        if tn > cap and tn > 0.0:
            out = out * (cap / tn)
    ft[0], ft[1], ft[2] = out[0], out[1], out[2]


ZERO3 = np.zeros(3)


@njit(cache=True, inline="always")
def _spring(nl, tl, delta, n, vt, hist, row, fabs, dt, ft, fn, dmax, rot):
    """The spring family with scalars only, for the packing solver's inner loop, by the verlet rules of
    kernels3d (turn_history, the increment, project_history, spring_slip — as verlet_3d). A slip goes on while
    the force exceeds μk|Fn|: where μk < μs the contact's slip state is kept in hist[row, 3]."""
    kt = kt_of(tl, delta)
    xi0, xi1, xi2 = turn_history(hist[row, 0], hist[row, 1], hist[row, 2], n, rot, kt, tl[T_MU_K], fabs)
    xi0, xi1, xi2 = project_history(xi0 + vt[0] * dt, xi1 + vt[1] * dt, xi2 + vt[2] * dt, n, rot)
    two_mu = tl[T_MU_K] != tl[T_MU_S]
    mu = tl[T_MU_K] if two_mu and hist[row, 3] != 0.0 else tl[T_MU_S]
    xi0, xi1, xi2, ft[0], ft[1], ft[2], sliding = spring_slip(xi0, xi1, xi2, vt, kt, eta_of(tl, nl, delta), tl[T_TRUNC],
                                                           mu, tl[T_MU_K], fabs)
    hist[row, 0], hist[row, 1], hist[row, 2] = xi0, xi1, xi2
    if two_mu:
        hist[row, 3] = 1.0 if sliding else 0.0
    return fn, dmax


@njit(cache=True)
def _forces(x, v, w, rad, species, laws_n, laws_t, wall_n, wall_t, walls, box_lo, box_hi, periodic, start, nbj,
            hist, dmax, w_hist, w_dmax, f, tq, contacts, nc_out, dt, update, rules):
    """Forces and torques of every contact; contact records (i, j, δ, Fn, |Ft|) into ``contacts``. A pair's
    contact state (history, largest overlap) lives beside it in the Verlet list (``hist``, ``dmax``), a
    particle–wall contact's in row i·n_walls + k of ``w_hist``, ``w_dmax``; a contact that has ended is
    forgotten (its state zeroed) when next seen apart."""
    n_p = x.shape[0]
    n_w = walls.shape[0]
    f[:, :] = 0.0
    tq[:, :] = 0.0
    nbuf = np.empty(3)
    vtbuf = np.empty(3)
    ft = np.empty(3)
    rot = rules[R_ROTATION]
    box = box_hi - box_lo
    nc = 0
    nl, tl, law_i, law_j = laws_n[0, 0], laws_t[0, 0], 0, 0
    wnl, wtl, wall_i = wall_n[0], wall_t[0], 0
    for i in range(n_p):
        for q in range(start[i], start[i + 1]):
            j = nbj[q]
            d0, d1, d2 = _separation(x, i, j, box, periodic)  # scalars: no allocation on the hot path
            touch = rad[i] + rad[j]
            dist2 = d0 * d0 + d1 * d1 + d2 * d2
            if dist2 < touch * touch:
                dist = math.sqrt(dist2)
                delta = touch - dist
                n0, n1, n2 = d0 / dist, d1 / dist, d2 / dist
                # lever arms by rule (kernels3d): the contact point R − δ/2, or the full radius
                ai = rad[i] if rules[R_SLIP_ARM] == ARM_RADIUS else rad[i] - 0.5 * delta
                aj = rad[j] if rules[R_SLIP_ARM] == ARM_RADIUS else rad[j] - 0.5 * delta
                bi = rad[i] if rules[R_TORQUE_ARM] == ARM_RADIUS else rad[i] - 0.5 * delta
                bj = rad[j] if rules[R_TORQUE_ARM] == ARM_RADIUS else rad[j] - 0.5 * delta
                vr0, vr1, vr2 = v[i, 0] - v[j, 0], v[i, 1] - v[j, 1], v[i, 2] - v[j, 2]
                rate = vr0 * n0 + vr1 * n1 + vr2 * n2
                # ω_i × (a_i n) + ω_j × (a_j n)
                o0 = ai * w[i, 0] + aj * w[j, 0]
                o1 = ai * w[i, 1] + aj * w[j, 1]
                o2 = ai * w[i, 2] + aj * w[j, 2]
                u0 = vr0 + o1 * n2 - o2 * n1
                u1 = vr1 + o2 * n0 - o0 * n2
                u2 = vr2 + o0 * n1 - o1 * n0
                vn = u0 * n0 + u1 * n1 + u2 * n2
                nbuf[0], nbuf[1], nbuf[2] = n0, n1, n2
                vtbuf[0], vtbuf[1], vtbuf[2] = u0 - vn * n0, u1 - vn * n1, u2 - vn * n2
                si, sj = species[i], species[j]
                if si != law_i or sj != law_j:  # a new species pair: its law views (once, not per contact)
                    nl, tl = laws_n[si, sj], laws_t[si, sj]
                    law_i, law_j = si, sj
                fn, dm = _contact_force(nl, tl, delta, rate, nbuf, vtbuf, hist, q, dmax[q], dt, update, ft, rot)
                dmax[q] = dm
                f0, f1, f2 = -fn * n0 + ft[0], -fn * n1 + ft[1], -fn * n2 + ft[2]
                f[i, 0] += f0
                f[i, 1] += f1
                f[i, 2] += f2
                f[j, 0] -= f0
                f[j, 1] -= f1
                f[j, 2] -= f2
                # torques (a n) × F_t
                t0 = n1 * ft[2] - n2 * ft[1]
                t1 = n2 * ft[0] - n0 * ft[2]
                t2 = n0 * ft[1] - n1 * ft[0]
                tq[i, 0] += bi * t0
                tq[i, 1] += bi * t1
                tq[i, 2] += bi * t2
                tq[j, 0] += bj * t0
                tq[j, 1] += bj * t1
                tq[j, 2] += bj * t2
                if nc < contacts.shape[0]:
                    contacts[nc, 0], contacts[nc, 1] = i, j
                    contacts[nc, 2], contacts[nc, 3] = delta, fn
                    contacts[nc, 4] = math.sqrt(ft[0] ** 2 + ft[1] ** 2 + ft[2] ** 2)
                nc += 1
            elif dmax[q] != 0.0:  # the contact has ended: forget it
                dmax[q] = 0.0
                hist[q, :] = 0.0
        # walls: plane through p with normal nw into the domain
        for k in range(walls.shape[0]):
            dist = (x[i, 0] - walls[k, 0]) * walls[k, 3] + (x[i, 1] - walls[k, 1]) * walls[k, 4] \
                + (x[i, 2] - walls[k, 2]) * walls[k, 5]
            delta = rad[i] - dist
            if delta > 0.0:
                n0, n1, n2 = -walls[k, 3], -walls[k, 4], -walls[k, 5]  # from the particle into the wall
                ai = wall_arm(rules[R_WALL_SLIP_ARM], rad[i], delta)
                bi = wall_arm(rules[R_WALL_TORQUE_ARM], rad[i], delta)
                rate = v[i, 0] * n0 + v[i, 1] * n1 + v[i, 2] * n2
                # the contact point's velocity v + ω × (a n), scalars: no allocation on the hot path
                u0 = v[i, 0] + ai * (w[i, 1] * n2 - w[i, 2] * n1)
                u1 = v[i, 1] + ai * (w[i, 2] * n0 - w[i, 0] * n2)
                u2 = v[i, 2] + ai * (w[i, 0] * n1 - w[i, 1] * n0)
                vn = u0 * n0 + u1 * n1 + u2 * n2
                nbuf[0], nbuf[1], nbuf[2] = n0, n1, n2
                vtbuf[0], vtbuf[1], vtbuf[2] = u0 - vn * n0, u1 - vn * n1, u2 - vn * n2
                row = i * n_w + k
                if species[i] != wall_i:
                    wnl, wtl = wall_n[species[i]], wall_t[species[i]]
                    wall_i = species[i]
                fn, dm = _contact_force(wnl, wtl, delta, rate, nbuf, vtbuf, w_hist, row, w_dmax[row], dt, update, ft,
                                        rot)
                w_dmax[row] = dm
                f[i, 0] += -fn * n0 + ft[0]
                f[i, 1] += -fn * n1 + ft[1]
                f[i, 2] += -fn * n2 + ft[2]
                # torque (b n) × F_t
                tq[i, 0] += bi * (n1 * ft[2] - n2 * ft[1])
                tq[i, 1] += bi * (n2 * ft[0] - n0 * ft[2])
                tq[i, 2] += bi * (n0 * ft[1] - n1 * ft[0])
            elif w_dmax[i * n_w + k] != 0.0:
                w_dmax[i * n_w + k] = 0.0
                w_hist[i * n_w + k, :] = 0.0
    nc_out[0] = nc


@njit(cache=True, nogil=True)
def run(x, v, w, rad, mass, species, laws_n, laws_t, wall_n, wall_t, walls, box_lo, box_hi, periodic, gravity,
        dt, steps, ke_every, start, nbj, hist, dmax, w_hist, w_dmax, contacts, rules):
    """Velocity Verlet for ``steps`` steps from the given state (x, v, w, the wall contact states modified in
    place; the pair contact states travel with the Verlet list, rebuilt here). Returns (translational kinetic
    energy every ke_every steps, number of pair contacts at the end, flags [unused, non-finite], and the
    Verlet list with its pair states: start, nbj, hist, dmax). The kinetic energy is translational, as the
    engines' thermo `ke`: these laws have no rolling or twisting resistance, so a sphere rolling or spinning
    about its contact normal keeps its rotational energy in every source."""
    n_p = x.shape[0]
    inertia = 0.4 * mass * rad * rad
    f = np.zeros((n_p, 3))
    tq = np.zeros((n_p, 3))
    nc_out = np.zeros(2, np.int64)
    skin = 0.3 * rad.max()
    x_ref = x.copy()
    ke = np.zeros(steps // ke_every + 1)
    flags = np.zeros(2, np.int64)
    start, nbj, hist, dmax = _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax)
    # setup: forces of the initial state without touching histories (as the engines do)
    _forces(x, v, w, rad, species, laws_n, laws_t, wall_n, wall_t, walls, box_lo, box_hi, periodic, start, nbj,
            hist, dmax, w_hist, w_dmax, f, tq, contacts, nc_out, dt, False, rules)
    for step in range(1, steps + 1):
        for i in range(n_p):
            for k in range(3):
                v[i, k] += 0.5 * dt * (f[i, k] / mass[i] + gravity[k])
                x[i, k] += dt * v[i, k]
                w[i, k] += 0.5 * dt * tq[i, k] / inertia[i]
        for i in range(n_p):  # periodic wrap of positions
            for k in range(2):
                if periodic[k]:
                    L = box_hi[k] - box_lo[k]
                    if x[i, k] < box_lo[k]:
                        x[i, k] += L
                    elif x[i, k] >= box_hi[k]:
                        x[i, k] -= L
        # rebuild the Verlet list once any particle has moved half the skin (or wrapped around the box)
        moved = 0.0
        for i in range(n_p):
            dd = (x[i, 0] - x_ref[i, 0]) ** 2 + (x[i, 1] - x_ref[i, 1]) ** 2 + (x[i, 2] - x_ref[i, 2]) ** 2
            if dd > moved:
                moved = dd
        if moved > (0.5 * skin) ** 2:
            start, nbj, hist, dmax = _rebuild(x, rad, box_lo, box_hi, periodic, skin, start, nbj, hist, dmax)
            x_ref[:, :] = x
        _forces(x, v, w, rad, species, laws_n, laws_t, wall_n, wall_t, walls, box_lo, box_hi, periodic, start, nbj,
                hist, dmax, w_hist, w_dmax, f, tq, contacts, nc_out, dt, True, rules)
        e = 0.0  # translational, as the engines' thermo `ke`
        e_rot = 0.0
        for i in range(n_p):
            for k in range(3):
                v[i, k] += 0.5 * dt * (f[i, k] / mass[i] + gravity[k])
                w[i, k] += 0.5 * dt * tq[i, k] / inertia[i]
            e += 0.5 * mass[i] * (v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
            e_rot += 0.5 * inertia[i] * (w[i, 0] ** 2 + w[i, 1] ** 2 + w[i, 2] ** 2)
        if step % ke_every == 0:
            ke[step // ke_every] = e
        if not math.isfinite(e + e_rot):
            flags[1] = 1
            break
    return ke, nc_out[0], flags, start, nbj, hist, dmax


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
    from .contact import pair_of
    from .model import models_of
    from .normal import NormalLaw

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


class PackState:
    """The state of a packing run (arrays the compiled kernel updates in place)."""

    def __init__(self, case):
        n = len(case.particles)
        self.case = case
        self.x = np.array([p.position for p in case.particles], float)
        self.v = np.array([p.velocity for p in case.particles], float)
        self.w = np.array([p.angular_velocity for p in case.particles], float)
        self.rad = np.array([p.radius for p in case.particles], float)
        self.mass = np.array([case.mass(i) for i in range(n)], float)
        _, _, laws_t, _, wall_t = resolve_laws(case)
        def any_law(test):
            return bool(np.any(test(laws_t)) or (case.walls and np.any(test(wall_t))))

        walton = any_law(lambda t: t[..., T_FAMILY] == WALTON)
        two_mu = any_law(lambda t: (t[..., T_FAMILY] == SPRING) & (t[..., T_MU_K] != t[..., T_MU_S]))
        width = WALTON_HIST_WIDTH if walton else SLIP_HIST_WIDTH if two_mu else HIST_WIDTH
        # the Verlet list (compressed rows) and, beside each listed pair, its contact state; built by run()
        self.start = np.zeros(n + 1, np.int64)
        self.nbj = np.zeros(0, np.int64)
        self.hist = np.zeros((0, width))
        self.dmax = np.zeros(0)
        # particle–wall contact states: row i·n_walls + k
        self.w_hist = np.zeros((n * len(case.walls), width))
        self.w_dmax = np.zeros(n * len(case.walls))
        self.contacts = np.zeros((8 * n + 16, 5))
        self.n_contacts = 0
        self.time = 0.0
        self.ke = []  # (t, kinetic energy)


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


def advance(case, st: PackState, dt: float, steps: int, rules: dict | None = None, laws=None, walls=None,
            gravity=None, ke_every: int | None = None):
    """``steps`` velocity-Verlet steps of the packing state ``st`` (updated): (kinetic energy every ke_every
    steps, number of pair contacts, flags [unused, non-finite])."""
    from .collision3d import rules_array

    sp, laws_n, laws_t, wall_n, wall_t = laws or resolve_laws(case)
    if walls is None:
        walls = np.array([[*w.point, *w.normal] for w in case.walls], float).reshape(-1, 6)
    g = np.asarray(case.run.gravity if gravity is None else gravity, float)
    lo, hi, periodic = box_of(case, st.x, st.rad)
    ke, nc, flags, st.start, st.nbj, st.hist, st.dmax = run(
        st.x, st.v, st.w, st.rad, st.mass, sp, laws_n, laws_t, wall_n, wall_t, walls, lo, hi, periodic, g, dt, steps,
        ke_every or max(1, steps // 20), st.start, st.nbj, st.hist, st.dmax, st.w_hist, st.w_dmax, st.contacts,
        rules_array(rules))
    return ke, nc, flags


def simulate(case, duration: float | None = None, dt: float | None = None, rest: float = 0.0,
             chunk: int = 2000, state: PackState | None = None, rules: dict | None = None) -> PackState:
    """Run the packing for ``duration`` (s; default the case's packing.duration) — `pack` and `verify` alike, as
    the engines do: an early stop where the kinetic energy dips (``rest`` × N m g R, off by default) can fall on a
    turning point of a layer bouncing in phase, not on a settled state; dt and the number of steps are case.packing_run's (a run
    past its bound is a ConfigError before any step). ``rules``: the kinematic rules (collision3d's names;
    default the seed's), e.g. an engine's rules (engines.base.Engine.rules) for its twin."""
    from ..case import packing_run
    from ..errors import ConfigError

    dt, duration, total = packing_run(case, duration, dt)  # dt and steps, bounded, as every engine's deck
    sp, laws_n, laws_t, wall_n, wall_t = resolve_laws(case)
    st = state or PackState(case)
    walls = np.array([[*w.point, *w.normal] for w in case.walls], float).reshape(-1, 6)
    g = np.asarray(case.run.gravity, float)
    scale = len(case.particles) * float(st.mass.mean()) * max(float(np.linalg.norm(g)), 1e-300) * float(st.rad.mean())
    done = 0
    while done < total:
        n_steps = min(chunk, total - done)
        ke, nc, flags = advance(case, st, dt, n_steps, rules, laws=(sp, laws_n, laws_t, wall_n, wall_t),
                                walls=walls, gravity=g)
        if flags[1]:
            raise ConfigError("run.dt", dt, "the packing became non-finite: the time step is too large")
        for k, e in enumerate(ke[1:], start=1):
            st.ke.append((st.time + k * max(1, n_steps // 20) * dt, float(e)))
        done += n_steps
        st.time += n_steps * dt
        st.n_contacts = int(nc)
        if st.ke and st.ke[-1][1] < rest * scale:
            break
    return st
