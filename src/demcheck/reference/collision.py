"""Two-body collision solver: a particle–particle or particle–wall impact.

Methods (docs/models.md):

* ``adaptive`` integrates to a relative tolerance with embedded Dormand–Prince 5(4), locating contact
  start, contact end, the force end, the maximum overlap, the peak force and every loading/unloading
  switch as events (kernels.adaptive_normal);
* ``verlet`` is the engines' velocity-Verlet scheme at a given dt (kernels.verlet_normal).

What a scene does not need is skipped: when nothing can move the contact off the line of centres
(no tangential force, and a wall, or a head-on pair) the problem is solved in 1-D along the normal.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..case import Case
from ..errors import ConfigError
from ..result import Result
from . import health, kernels
from ..laws.model import ResolvedModel, characteristic_time, resolve
from .outcome import (MESSAGES, ROW_BYTES_1D, STATUS, auto_dt, judge, time_to_contact,  # noqa: F401 - the solvers'
                      verlet_capacity)  # shared names, re-exported for callers of this module

class Geometry1D:
    """The line of centres of a two-body scene and the 1-D initial state along it."""

    def __init__(self, case: Case):
        p0 = case.particles[0]
        x0, v0 = np.asarray(p0.position), np.asarray(p0.velocity)
        g = np.asarray(case.run.gravity)
        self.wall = len(case.particles) == 1
        if self.wall:
            w = case.walls[0]
            self.n = -np.asarray(w.normal)  # from the particle into the wall
            self.delta0 = p0.radius - float((x0 - np.asarray(w.point)) @ np.asarray(w.normal))
            self.rate0 = float(v0 @ self.n)
            self.an = float(g @ self.n)
            self.tangential_velocity = v0 - self.rate0 * self.n
        else:
            p1 = case.particles[1]
            x1, v1 = np.asarray(p1.position), np.asarray(p1.velocity)
            sep = x1 - x0
            dist = float(np.linalg.norm(sep))
            self.n = sep / dist
            self.delta0 = p0.radius + p1.radius - dist
            v_rel = v0 - v1
            self.rate0 = float(v_rel @ self.n)
            self.an = 0.0
            self.tangential_velocity = v_rel - self.rate0 * self.n


def is_one_dimensional(case: Case, model: ResolvedModel, geo: Geometry1D | None = None) -> bool:
    """True when the normal solve alone is exact: no tangential force, and the contact normal cannot turn
    (a plane wall, or a pair whose relative velocity lies on the line of centres). ``geo``: the case's, when
    the caller has it."""
    if model.tangential.id != "none":
        return False
    if len(case.particles) == 1:
        return True
    geo = geo or Geometry1D(case)
    return float(np.linalg.norm(geo.tangential_velocity)) <= 1e-12 * max(abs(geo.rate0), 1e-300)


def collide(case: Case, method: str | None = None, dt: float | None = None,
            rtol: float | None = None) -> Result:
    method = method or case.run.method
    if method not in ("adaptive", "verlet"):
        raise ConfigError("--method", method, "must be adaptive or verlet")
    model = resolve(case)
    if not is_one_dimensional(case, model):
        from . import collision3d

        return collision3d.collide(case, model, method, dt=dt, rtol=rtol)
    geo = Geometry1D(case)
    law = model.normal_law.array()
    m = model.pair.m_eff
    t_c = characteristic_time(model)
    v = model.pair.impact_speed
    t_contact = time_to_contact(case)
    t_max = t_contact + 200.0 * t_c
    radius = health.smallest_radius(case)
    started = time.perf_counter()
    if method == "adaptive":
        rtol = rtol or case.run.rtol
        out = kernels.adaptive_normal(law, m, geo.an, geo.delta0, geo.rate0, rtol, t_c, v * t_c, v, t_max,
                                      1_000_000)
        status, n, T, D, R, F, ne, ET, EC, ED, ER, EF = out
        events = {
            "t": ET, "event": np.array([kernels.EVENT_NAMES.get(abs(int(c)), "?") if c > 0 else "force_end_again"
                                        for c in EC], dtype=object),
            "delta": ED, "delta_dot": ER, "fn": EF}
        used_dt = None
    else:
        dt_given = bool(dt)
        dt = dt or case.run.dt or auto_dt(case, model)
        if not (dt > 0) or not math.isfinite(dt):
            raise ConfigError("--dt", dt, "must be > 0 (s) and finite")
        capacity = verlet_capacity(case, dt, dt_given, t_contact, t_c, t_max, ROW_BYTES_1D)
        status, n, T, D, R, F = kernels.verlet_normal(law, m, geo.an, geo.delta0, geo.rate0, dt, t_max, capacity)
        events = None
        used_dt, rtol = dt, None
    wall_time = time.perf_counter() - started
    contact = {"t": T, "delta": D, "delta_dot": R, "fn": F}
    particles = _particles_1d(case, geo, contact)
    _add_frame_columns(contact, particles, case, geo)
    status_name = STATUS[status]
    result = Result(
        source="reference", method=method, case_name=case.name, case_hash=case.hash,
        model=model.describe(), params=dict(model.params), contact=contact, particles=particles, events=events,
        dt=used_dt, rtol=rtol, wall_time=wall_time, status=status_name,
        message=MESSAGES.get(status_name, ""),
        meta={"solver": "1d-normal", "steps": int(n), "radius0": radius},
    )
    return judge(result, case, model)


def _particles_1d(case: Case, geo: Geometry1D, contact: dict) -> dict:
    """Rebuild both bodies' centres and velocities from the 1-D solution (the centre of mass of a pair
    moves uniformly; a particle keeps its velocity along a wall): the particles table's arrays, body 0's
    rows first."""
    t = contact["t"]
    d = contact["delta"]
    r = contact["delta_dot"]
    bodies = []
    p0 = case.particles[0]
    x0, v0 = np.asarray(p0.position), np.asarray(p0.velocity)
    g = np.asarray(case.run.gravity)
    if geo.wall:
        vt = geo.tangential_velocity
        gt = g - (g @ geo.n) * geo.n
        pos = x0 + np.outer(t, vt) + 0.5 * np.outer(t * t, gt) + np.outer(d - geo.delta0, geo.n)
        vel = vt + np.outer(t, gt) + np.outer(r, geo.n)
        bodies.append((pos, vel, p0.angular_velocity))
    else:
        p1 = case.particles[1]
        m0, m1 = case.mass(0), case.mass(1)
        mt = m0 + m1
        x1, v1 = np.asarray(p1.position), np.asarray(p1.velocity)
        xc = (m0 * x0 + m1 * x1) / mt
        vc = (m0 * v0 + m1 * v1) / mt
        com = xc + np.outer(t, vc) + 0.5 * np.outer(t * t, g)
        vcom = vc + np.outer(t, g)
        sep = p0.radius + p1.radius - d  # distance between centres
        bodies.append((com - np.outer(sep * m1 / mt, geo.n), vcom + np.outer(r * m1 / mt, geo.n),
                       p0.angular_velocity))
        bodies.append((com + np.outer(sep * m0 / mt, geo.n), vcom - np.outer(r * m0 / mt, geo.n),
                       p1.angular_velocity))
    n, k = len(t), len(bodies)
    pos = np.concatenate([b[0] for b in bodies]) if k > 1 else bodies[0][0]
    vel = np.concatenate([b[1] for b in bodies]) if k > 1 else bodies[0][1]
    omega = np.repeat(np.array([b[2] for b in bodies], dtype=float), n, axis=0)
    return {"t": np.tile(t, k), "id": np.repeat(np.arange(k, dtype=np.int64), n),
            "x": pos[:, 0], "y": pos[:, 1], "z": pos[:, 2], "vx": vel[:, 0], "vy": vel[:, 1], "vz": vel[:, 2],
            "wx": omega[:, 0], "wy": omega[:, 1], "wz": omega[:, 2]}


def _add_frame_columns(contact: dict, particles: dict, case: Case, geo: Geometry1D) -> None:
    """The relative centre velocity, the (fixed) normal and body 0's spin, for the tangential metrics (added
    to the contact table's arrays)."""
    n = len(contact["t"])
    vr = np.column_stack([particles[c][:n] for c in ("vx", "vy", "vz")])
    if not geo.wall:
        vr = vr - np.column_stack([particles[c][n:] for c in ("vx", "vy", "vz")])
    for i, axis in enumerate("xyz"):
        contact[f"vr{axis}"] = vr[:, i]
        contact[f"n{axis}"] = np.full(n, geo.n[i], dtype=float)
        contact[f"w0{axis}"] = np.full(n, float(case.particles[0].angular_velocity[i]))
