"""Contact tables from the bodies' states, the same way for every time-stepped source.

An engine's dump gives, per step, the end-of-step positions, velocities, angular velocities and the forces
of that step; a two-body contact is read off them (per-contact output would be re-evaluated at output
time, docs/models.md, Reading the engines' output). A body's force in the dump is the whole force on it: the contact's plus its
weight m·g (``fix gravity``), so the contact's is the body's force less its weight (the case's run.gravity).
The reference's verlet twin writes its bodies' forces the same way (``body_forces``: contact + weight) and is
read off its states through the same function (``restate``), so engine and twin are compared quantity by
quantity with nothing but the engine in between.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..result import frame_of


def contact_table(t, x0, v0, w0, f0, r0, m0, *, x1=None, v1=None, w1=None, r1=None, m1=None,
                  wall_point=None, wall_normal=None) -> pd.DataFrame:
    """:func:`contact_columns` as a DataFrame."""
    return frame_of(contact_columns(t, x0, v0, w0, f0, r0, m0, x1=x1, v1=v1, w1=w1, r1=r1, m1=m1,
                                    wall_point=wall_point, wall_normal=wall_normal))


def contact_columns(t, x0, v0, w0, f0, r0, m0, *, x1=None, v1=None, w1=None, r1=None, m1=None,
                    wall_point=None, wall_normal=None) -> dict:
    """Columns as the reference's 3-D tables (arrays): δ, δ̇ (end-of-step velocities), Fn (= −F0·n, repulsive > 0),
    Ft (F0's tangential part), slip velocity (arms R − δ/2), n, relative velocity, ω0, kinetic energy."""
    t = np.asarray(t, float)
    x0, v0, w0, f0 = (np.asarray(a, float) for a in (x0, v0, w0, f0))
    if wall_normal is not None:
        nw = np.asarray(wall_normal, float)
        n = np.broadcast_to(-nw, x0.shape).copy()
        dist = (x0 - np.asarray(wall_point, float)) @ nw
        delta = r0 - dist
        vr = v0.copy()
        a0 = r0 - 0.5 * delta
        vc = v0 + np.cross(w0, a0[:, None] * n)
        energy = 0.5 * m0 * np.einsum("ij,ij->i", v0, v0) + 0.5 * (0.4 * m0 * r0 * r0) * np.einsum("ij,ij->i", w0, w0)
    else:
        x1, v1, w1 = (np.asarray(a, float) for a in (x1, v1, w1))
        d = x1 - x0
        dist = np.linalg.norm(d, axis=1)
        n = d / dist[:, None]
        delta = r0 + r1 - dist
        vr = v0 - v1
        a0, a1 = r0 - 0.5 * delta, r1 - 0.5 * delta
        vc = v0 + np.cross(w0, a0[:, None] * n) - (v1 + np.cross(w1, -a1[:, None] * n))
        energy = (0.5 * m0 * np.einsum("ij,ij->i", v0, v0) + 0.5 * (0.4 * m0 * r0 * r0) * np.einsum("ij,ij->i", w0, w0)
                  + 0.5 * m1 * np.einsum("ij,ij->i", v1, v1) + 0.5 * (0.4 * m1 * r1 * r1) * np.einsum("ij,ij->i", w1, w1))
    rate = np.einsum("ij,ij->i", vr, n)
    fn = -np.einsum("ij,ij->i", f0, n)
    ft = f0 + fn[:, None] * n
    vt = vc - np.einsum("ij,ij->i", vc, n)[:, None] * n
    return {
        "t": t, "delta": delta, "delta_dot": rate, "fn": fn,
        "ftx": ft[:, 0], "fty": ft[:, 1], "ftz": ft[:, 2], "vtx": vt[:, 0], "vty": vt[:, 1], "vtz": vt[:, 2],
        "nx": n[:, 0], "ny": n[:, 1], "nz": n[:, 2], "vrx": vr[:, 0], "vry": vr[:, 1], "vrz": vr[:, 2],
        "w0x": w0[:, 0], "w0y": w0[:, 1], "w0z": w0[:, 2], "energy": energy,
    }


def _rows(table, keep: slice):
    """Rows ``keep`` of a DataFrame or of a table of arrays."""
    if isinstance(table, dict):
        return {k: v[keep] for k, v in table.items()}
    return table.iloc[keep].reset_index(drop=True)


def trim(table):
    """Up to the first step after the contact ended (as the reference's verlet method stops)."""
    d = np.asarray(table["delta"], dtype=float)
    inside = np.flatnonzero(d > 0)
    if not inside.size:
        return table
    after = np.flatnonzero(d[inside[0]:] <= 0)
    if not after.size:
        return table
    return _rows(table, slice(None, inside[0] + int(after[0]) + 1))


def weight(case, i: int = 0) -> np.ndarray:
    """Body i's weight m·g (N), from the case's run.gravity."""
    return case.mass(i) * np.asarray(case.run.gravity, float)


def _body(particles, i: int):
    """Body i's rows of a particles table (DataFrame or arrays), in time order, as {column: array}."""
    if isinstance(particles, dict):
        rows = np.flatnonzero(np.asarray(particles["id"]) == i)
        rows = rows[np.argsort(particles["t"][rows], kind="stable")]
        return {k: v[rows] for k, v in particles.items()}
    p = particles[particles["id"] == i].sort_values("t")
    return {k: p[k].to_numpy() for k in p.columns}


def from_particles(particles, case):
    """The contact table of a case's two bodies from a particles table with forces (t, id, x.., v.., w..,
    fx..) — ids 0 and 1 in the case's order. The forces are the bodies' whole forces, as an engine dumps them:
    the contact's is body 0's force less its weight. A DataFrame gives a DataFrame, arrays give arrays."""
    columns = _contact_from_bodies(particles, case)
    return columns if isinstance(particles, dict) else frame_of(columns)


def _contact_from_bodies(particles, case) -> dict:
    p0 = _body(particles, 0)
    t = p0["t"]
    r0, m0 = case.particles[0].radius, case.mass(0)
    cols = (["x", "y", "z"], ["vx", "vy", "vz"], ["wx", "wy", "wz"], ["fx", "fy", "fz"])
    a0 = [np.column_stack([p0[k] for k in c]) for c in cols]
    a0[3] = a0[3] - weight(case, 0)
    if case.walls:
        w = case.walls[0]
        return contact_columns(t, *a0, r0, m0, wall_point=w.point, wall_normal=w.normal)
    p1 = _body(particles, 1)
    a1 = [np.column_stack([p1[k] for k in c]) for c in cols[:3]]
    return contact_columns(t, *a0, r0, m0, x1=a1[0], v1=a1[1], w1=a1[2], r1=case.particles[1].radius,
                           m1=case.mass(1))


def body_forces(contact, particles, case):
    """A copy of ``particles`` (a reference run's states: t, id, x.., v.., w..) with body 0's forces as an
    engine dumps them: the contact's force on it (−Fn n + Ft, from ``contact``, row for row) plus its weight
    m₀·g. Body 1's forces are not read (NaN). DataFrames give a DataFrame, arrays give arrays."""
    vec = lambda p: np.column_stack([np.asarray(contact[p + a], dtype=float) for a in "xyz"])  # noqa: E731
    f0 = -np.asarray(contact["fn"], dtype=float)[:, None] * vec("n") + vec("ft") + weight(case, 0)
    if isinstance(particles, dict):
        parts = dict(particles)
        p0 = np.flatnonzero(np.asarray(parts["id"]) == 0)
        for k, col in enumerate(("fx", "fy", "fz")):
            parts[col] = np.full(len(parts["id"]), np.nan)
            parts[col][p0] = f0[:, k]
        return parts
    parts = particles.copy()
    p0 = (parts["id"] == 0).to_numpy()
    for k, col in enumerate(("fx", "fy", "fz")):
        parts[col] = np.nan
        parts.loc[p0, col] = f0[:, k]
    return parts


def restate(result, case):
    """A reference run (the verlet method: its contact table row for row with body 0's states) read off its
    states exactly as an engine's is: the bodies' forces written as an engine's (``body_forces``), the contact
    table read back (``from_particles``) and trimmed. Returns ``result`` with both tables replaced (arrays)."""
    parts = body_forces(result.table("contact"), result.table("particles"), case)
    result.contact = trim(from_particles(parts, case))
    result.particles = parts
    return result
