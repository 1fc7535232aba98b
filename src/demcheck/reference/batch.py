"""Many reference collisions at once: a sweep's points, or any list of cases, with what :func:`collide` and
``Result.metrics()`` would give for each — its metrics, status and message — without a Result per point.

The points the 1-D verlet solver takes (the method is verlet, and nothing moves the contact off the line of
centres: collision.is_one_dimensional) are solved in one compiled call (kernels.verlet_normal_many): each point's
series is read where it is made — by the same compiled readers a Result's metrics and health use
(metrics.stepped, health.reading) — and dropped, so that a point costs its kernel and little more. The others go
through :func:`collide` one by one. Either way a point's row is the same (tested: bit for bit for the normal
metrics and the status; the tangential metrics to round-off, numpy's dot products being BLAS's).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConfigError, DemcheckError
from ..metrics import NORMAL_METRICS, from_stepped, rate_energy
from . import health, kernels as K
from .collision import Geometry1D, collide, is_one_dimensional
from ..laws.model import characteristic_time, resolve
from .outcome import MESSAGES, ROW_BYTES_1D, STATUS, auto_dt, time_to_contact, verlet_capacity


def _point(case, method, dt):
    """The 1-D verlet solver's arguments for ``case`` and what its row needs, as collide takes them; None when
    the point is not the 1-D verlet solver's."""
    method = method or case.run.method
    if method != "verlet":
        return None
    model = resolve(case)
    geo = Geometry1D(case)
    if not is_one_dimensional(case, model, geo):
        return None
    t_c = characteristic_time(model)
    t_contact = time_to_contact(case)
    t_max = t_contact + 200.0 * t_c
    dt_given = bool(dt)
    dt = dt or case.run.dt or auto_dt(case, model, t_c)
    if not (dt > 0) or not math.isfinite(dt):
        raise ConfigError("--dt", dt, "must be > 0 (s) and finite")
    capacity = verlet_capacity(case, dt, dt_given, t_contact, t_c, t_max, ROW_BYTES_1D)
    # the frame's columns (kernels.FR_*): wall, n, then a wall's tangential velocity and gravity's tangential part,
    # or a pair's centre-of-mass velocity and gravity, then the masses and body 0's spin
    n = geo.n.tolist()
    if geo.wall:
        g = np.asarray(case.run.gravity, dtype=float)
        frame = [1.0, *n, *geo.tangential_velocity.tolist(), *(g - (g @ geo.n) * geo.n).tolist(), 0.0, 0.0, 0.0]
    else:
        m0, m1 = case.mass(0), case.mass(1)
        v0, v1 = np.asarray(case.particles[0].velocity), np.asarray(case.particles[1].velocity)
        frame = [0.0, *n, *((m0 * v0 + m1 * v1) / (m0 + m1)).tolist(), *map(float, case.run.gravity), m0, m1,
                 m0 + m1]
    frame += map(float, case.particles[0].angular_velocity)
    args = (model.normal_law.array(), model.pair.m_eff, geo.an, geo.delta0, geo.rate0, dt, t_max, capacity)
    judge = (dt, t_c, health.smallest_radius(case), lambda: health.impact_energy(case, model),
             health.impact_energy_floor(model), model.tangential_law.passive, model.params.get("m_eff"))
    return args, frame, judge


_NO_METRICS = dict.fromkeys(NORMAL_METRICS, math.nan)


def _row(o, judge) -> dict:
    """A batched point's metrics, status and message from its output row ``o`` (kernels.O_*), as
    metrics.compute and outcome.judge give them for its Result."""
    dt, t_c, radius, impact_energy, floor, passive, m_eff = judge
    out = dict(_NO_METRICS)
    if o[K.O_KS] >= 0:
        out.update(from_stepped(o[K.O_KS:K.O_FMAX + 1]))  # (the O_* columns from O_KS hold stepped's reading)
        if m_eff is not None:
            out["energy_dissipated"] = rate_energy(m_eff, o[K.O_VIN], o[K.O_VOUT])
        out.update({"tangential_restitution": o[K.O_TR], "rebound_angle": o[K.O_ANGLE],
                    "rebound_angular_velocity": o[K.O_SPIN]})
    status = STATUS[int(o[K.O_STATUS])]
    message = MESSAGES.get(status, "")
    if status != "too-many-steps":
        read = (int(o[K.O_BAD]), int(o[K.O_INSIDE]), o[K.O_DALL], o[K.O_DLAST], o[K.O_TLAST], o[K.O_TBAD])
        rule, why = health.rules(read, dt, t_c, radius, health.MIN_STEPS, impact_energy, passive,
                                 lambda: -out["energy_dissipated"], floor)
        if rule != "ok":
            status, message = rule, why
    return {**out, "status": status, "message": message}


def _scenario(case, method):
    """A scenario beyond sliding: the adaptive reference's solve (reference/scenarios.py), as Source.run gives it."""
    if method == "verlet":
        raise ConfigError("method", "verlet", f"run.scenario = \"{case.run.scenario}\" is solved by the "
                                              "adaptive reference only")
    from .scenarios import solve

    return solve(case)


def collide_many(cases, method: str | None = None, dt: float | None = None) -> list[dict]:
    """For each case: {metric: value, ..., "status", "message"}, what ``collide(case, method, dt)`` and its
    ``metrics()`` give; a point whose solve fails (a DemcheckError) has its error as its status ("error: …")
    and no metrics. The 1-D verlet points are solved in one compiled call (module docstring)."""
    if method not in (None, "adaptive", "verlet"):
        raise ConfigError("--method", method, "must be adaptive or verlet")
    rows: list[dict | None] = [None] * len(cases)
    batch = []
    for i, case in enumerate(cases):
        try:
            point = None if case.run.scenario != "collision" else _point(case, method, dt)
            if case.run.scenario != "collision":
                result = _scenario(case, method)
                rows[i] = {**result.metrics(), "status": result.status, "message": result.message}
            elif point is None:
                result = collide(case, method, dt)
                rows[i] = {**result.metrics(), "status": result.status, "message": result.message}
            else:
                batch.append((i, point))
        except DemcheckError as exc:
            rows[i] = {"status": f"error: {exc}", "message": str(exc)}
    if batch:
        cols = list(zip(*(p[0] for _, p in batch)))
        # the kernel's one specialisation: float64 laws and scalars (a dt given as an int too), int64 capacities
        args = [np.ascontiguousarray(np.stack(cols[0]), dtype=np.float64),
                *(np.asarray(c, dtype=np.float64) for c in cols[1:7]), np.asarray(cols[7], dtype=np.int64)]
        out = K.verlet_normal_many(*args, np.array([p[1] for _, p in batch], dtype=np.float64))
        for (i, point), o in zip(batch, out.tolist()):
            rows[i] = _row(o, point[2])
    return rows
