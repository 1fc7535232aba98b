"""The 3-D two-body solver: oblique impacts, spin, and every tangential law (kernels3d)."""

from __future__ import annotations

import math
import time

import numpy as np

from ..case import Case
from ..errors import ConfigError
from ..result import Result
from . import adaptive3d, kernels, kernels3d as k3, verlet3d
from ..laws.model import ResolvedModel

# The seed's own rules: lever arms to the contact point (R − δ/2) for slip velocity and torque; in the
# verlet method the history is rotated into the new tangent plane keeping its length. A wall's slip arm is the
# slip arm unless a scheme sets "wall_slip_arm" ("surface": R − δ, the point on the wall's plane, is Yade's).
SEED_RULES = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact", "rotation": "rescale"}
_ARMS = {"contact": k3.ARM_CONTACT, "radius": k3.ARM_RADIUS, "surface": k3.ARM_SURFACE, "ratchet": k3.ARM_RATCHET}
_ROT = {"none": k3.ROT_NONE, "project": k3.ROT_PROJECT, "rescale": k3.ROT_RESCALE, "rescale_significant": k3.ROT_RESCALE_SIGNIFICANT,
        "scgeom": k3.ROT_SCGEOM}


def rules_array(rules: dict | None = None) -> np.ndarray:
    r = {**SEED_RULES, **(rules or {})}
    for key in ("slip_arm", "torque_arm"):
        if r[key] == "surface":
            raise ValueError(f"the arm R − δ is a wall's rule ({key} = 'surface' is not a pair's)")
    if "ratchet" in (r["torque_arm"], r["wall_torque_arm"]):
        raise ValueError("'ratchet' is a slip-velocity rule (Yade's ScGeom), not a torque's")
    return np.array([_ARMS[r["slip_arm"]], _ARMS[r["torque_arm"]], _ARMS[r["wall_torque_arm"]], _ROT[r["rotation"]],
                     _ARMS[r.get("wall_slip_arm") or r["slip_arm"]]], dtype=float)


def geometry(case: Case, t_scale: float) -> np.ndarray:
    geo = np.zeros(k3.G_SIZE)
    p0 = case.particles[0]
    geo[k3.G_R0] = p0.radius
    geo[k3.G_M0] = case.mass(0)
    geo[k3.G_I0] = 0.4 * case.mass(0) * p0.radius**2
    if len(case.particles) == 1:
        w = case.walls[0]
        geo[k3.G_WALL] = 1.0
        geo[k3.G_PX:k3.G_PX + 3] = w.point
        geo[k3.G_NX:k3.G_NX + 3] = w.normal
    else:
        p1 = case.particles[1]
        geo[k3.G_R1] = p1.radius
        geo[k3.G_M1] = case.mass(1)
        geo[k3.G_I1] = 0.4 * case.mass(1) * p1.radius**2
    geo[k3.G_GX:k3.G_GX + 3] = case.run.gravity
    geo[k3.G_TS] = t_scale
    return geo


def initial_state(case: Case) -> np.ndarray:
    y = np.zeros(21)
    p0 = case.particles[0]
    y[0:3], y[3:6], y[6:9] = p0.position, p0.velocity, p0.angular_velocity
    if len(case.particles) == 2:
        p1 = case.particles[1]
        y[9:12], y[12:15], y[15:18] = p1.position, p1.velocity, p1.angular_velocity
    return y


def collide(case: Case, model: ResolvedModel, method: str, dt: float | None = None, rtol: float | None = None,
            rules: dict | None = None) -> Result:
    from ..laws.model import characteristic_time
    from .outcome import MESSAGES, ROW_BYTES_3D, STATUS, auto_dt, judge, time_to_contact, verlet_capacity

    t_c = characteristic_time(model)
    v = model.pair.impact_speed
    geo = geometry(case, t_c)
    rul = rules_array(rules)
    y0 = initial_state(case)
    nl, tl = model.normal_law.array(), model.tangential_law.array()
    v_rel = np.linalg.norm(y0[3:6] - y0[12:15]) if len(case.particles) == 2 else np.linalg.norm(y0[3:6])
    v_scale = max(v_rel, v)
    r0 = case.particles[0].radius
    t_contact = time_to_contact(case)
    t_max = t_contact + 200.0 * t_c
    started = time.perf_counter()
    if method == "adaptive":
        if model.tangential_law.force_history or model.tangential_law.rescale_history:
            raise ConfigError("--method", method, "a force history or a contact-radius rescale of the "
                              "tangential history (engine twins) is defined for the engines' scheme only: use the "
                              "verlet method")
        rtol = rtol or case.run.rtol
        l_scale = 0.3 * v * t_c
        f_scale = model.pair.m_eff * v / t_c
        scales = np.concatenate([np.full(3, l_scale), np.full(3, v_scale), np.full(3, v_scale / r0)] * 2
                                + [np.full(3, f_scale if model.tangential_law.history_is_load else l_scale)])
        status, n, rec, ne, ev_t, ev_c = adaptive3d.adaptive_3d(y0, nl, tl, geo, rul, rtol, scales, t_max, POINTS)
        asked = rtol
        floor = _round_off_floor(rec[:n], l_scale)
        while _out_of_points(status, n, ne) and rtol < floor <= RTOL_RELAX_CEILING:
            # a tolerance float64 cannot hold on these positions is the solver's to relax: to the first decade
            # above the round-off floor (then a decade more while the points still run out). A floor above the
            # ceiling (a tiny impact speed) is the user's to decide: the message says to raise run.rtol
            rtol = min(max(10.0 * rtol, 10.0 ** math.ceil(math.log10(floor))), RTOL_RELAX_CEILING)
            status, n, rec, ne, ev_t, ev_c = adaptive3d.adaptive_3d(y0, nl, tl, geo, rul, rtol, scales, t_max, POINTS)
            floor = max(floor, _round_off_floor(rec[:n], l_scale))
        names = {**kernels.EVENT_NAMES, **k3.EVENT_NAMES_3D}
        idx = np.searchsorted(rec[:, k3.C_T], ev_t)
        events = {"t": ev_t, "event": np.array([names.get(int(c), "force_end_again") if c > 0
                                                else "force_end_again" for c in ev_c], dtype=object),
                  "delta": rec[idx, k3.C_D], "delta_dot": rec[idx, k3.C_R], "fn": rec[idx, k3.C_FN]}
        used_dt = None
    elif method == "verlet":
        dt_given = bool(dt)
        dt = dt or case.run.dt or auto_dt(case, model)
        if not (dt > 0) or not math.isfinite(dt):
            raise ConfigError("--dt", dt, "must be > 0 (s) and finite")
        capacity = verlet_capacity(case, dt, dt_given, t_contact, t_c, t_max, ROW_BYTES_3D)
        status, n, rec = verlet3d.verlet_3d(y0, nl, tl, geo, rul, dt, t_max, capacity)
        events, used_dt, rtol = None, dt, None
    else:
        raise ConfigError("--method", method, "must be adaptive or verlet")
    wall_time = time.perf_counter() - started
    contact, particles = tables(rec, wall=len(case.particles) == 1)
    status_name = STATUS[status]
    result = Result(
        source="reference", method=method, case_name=case.name, case_hash=case.hash, model=model.describe(),
        params=dict(model.params), contact=contact, particles=particles, events=events, dt=used_dt, rtol=rtol,
        wall_time=wall_time, status=status_name, message=MESSAGES.get(status_name, ""),
        meta={"solver": "3d", "steps": int(n), "rules": {**SEED_RULES, **(rules or {})},
              "radius0": r0},
    )
    if status_name == "too-many-steps" and method == "adaptive" and not _out_of_points(status, n, ne):
        result.message = (f"the adaptive method located more than {adaptive3d.MAX_EVENTS} events (stick/slip "
                          f"switches, the last at t = {ev_t[-1]:.6g} s): the contact chattered between two states "
                          "(a defect of the solver: please report the case)")
    elif status_name == "too-many-steps" and method == "adaptive":
        result.message = _points_message(result, rtol, l_scale)
    elif method == "adaptive" and rtol != asked:
        result.meta["rtol_asked"] = asked
        result.message = (f"rtol relaxed from {asked:g} to {rtol:g}: at {asked:g} the steps shrank on the float64 "
                          f"round-off of the bodies' positions (the overlap scale {l_scale:.3g} m against positions "
                          f"~{_largest_position(result):.3g} m)")
    tlaw = model.tangential_law
    if tlaw.pushes_at_onset and not result.message:
        result.message = ("truncation=overlap with a Kt that vanishes at contact onset: where the dashpot exceeds "
                          "the cap the Maw overlap grows like δ^(-1/4) and the friction can push along the slip "
                          "(docs/models.md, finding 9); truncation=force is the seed's formulation")
    return judge(result, case, model)


def _points_message(result: Result, rtol: float, l_scale: float) -> str:
    """Why the adaptive 3-D method ran out of output points. It integrates the bodies' positions: at a tiny
    impact speed the contact's overlap scale is far below their float64 spacing times 1/rtol, and the steps
    shrink on round-off (measured, oblique LSD at a wall: 1e-9 m/s needs 92 000 points at rtol = 1e-12,
    7 000 at 1e-11, 700 at 1e-10)."""
    from .outcome import MESSAGES

    x = _largest_position(result)
    if l_scale > 0 and np.spacing(x) / l_scale > rtol:
        return (f"the adaptive method needed more than {result.meta['steps']} points: the contact's overlap scale "
                f"({l_scale:.3g} m) is {l_scale / x:.2g} of the bodies' positions (~{x:.3g} m), and the tolerance "
                f"rtol = {rtol:g} fights their float64 round-off: raise run.rtol (each decade takes about ten "
                "times fewer points) or the impact speed")
    return MESSAGES["too-many-steps"]


POINTS = 200_000  # the adaptive method's output points


def _out_of_points(status: int, n: int, ne: int) -> bool:
    """Whether an adaptive run stopped on its output points (round-off shrinking the steps), not its events."""
    from .outcome import STATUS

    return STATUS[status] == "too-many-steps" and ne < adaptive3d.MAX_EVENTS and n >= POINTS - 2


# the loosest tolerance the adaptive method relaxes to by itself (the metrics' verdicts need ~1e-6 at most)
RTOL_RELAX_CEILING = 1e-10


def _round_off_floor(rec: np.ndarray, l_scale: float) -> float:
    """The relative tolerance below which the bodies' float64 positions cannot resolve the overlap scale."""
    x = float(max(np.max(np.abs(rec[:, k3.C_X0:k3.C_X0 + 3])), np.max(np.abs(rec[:, k3.C_X1:k3.C_X1 + 3])))) \
        if len(rec) else 0.0
    return np.spacing(x) / l_scale if l_scale > 0 else 0.0


def _largest_position(result: Result) -> float:
    p = result.table("particles")
    return float(max(np.max(np.abs(p[c])) for c in ("x", "y", "z"))) if len(p["t"]) else 0.0


def tables(rec: np.ndarray, wall: bool) -> tuple[dict, dict]:
    """The contact and particles tables of a 3-D run's record, as arrays (Result.table): views of ``rec`` where
    a column is one of its own."""
    t = rec[:, k3.C_T]
    v0, v1 = rec[:, k3.C_V0:k3.C_V0 + 3], rec[:, k3.C_V1:k3.C_V1 + 3]
    vr = v0 - v1 if not wall else v0
    contact = {
        "t": t, "delta": rec[:, k3.C_D], "delta_dot": rec[:, k3.C_R], "fn": rec[:, k3.C_FN],
        "ftx": rec[:, k3.C_FT], "fty": rec[:, k3.C_FT + 1], "ftz": rec[:, k3.C_FT + 2],
        "vtx": rec[:, k3.C_VT], "vty": rec[:, k3.C_VT + 1], "vtz": rec[:, k3.C_VT + 2],
        "nx": rec[:, k3.C_N], "ny": rec[:, k3.C_N + 1], "nz": rec[:, k3.C_N + 2],
        "vrx": vr[:, 0], "vry": vr[:, 1], "vrz": vr[:, 2],
        "w0x": rec[:, k3.C_W0], "w0y": rec[:, k3.C_W0 + 1], "w0z": rec[:, k3.C_W0 + 2],
        "energy": rec[:, k3.C_E], "slipping": rec[:, k3.C_SLIP].astype(bool),
    }
    bodies = [(k3.C_X0, k3.C_V0, k3.C_W0)] + ([] if wall else [(k3.C_X1, k3.C_V1, k3.C_W1)])

    def column(which: int, j: int) -> np.ndarray:  # body 0's rows, then body 1's
        parts = [rec[:, b[which] + j] for b in bodies]
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    particles = {"t": np.tile(t, len(bodies)), "id": np.repeat(np.arange(len(bodies), dtype=np.int64), len(t))}
    for which, names in enumerate((("x", "y", "z"), ("vx", "vy", "vz"), ("wx", "wy", "wz"))):
        for j, name in enumerate(names):
            particles[name] = column(which, j)
    return contact, particles
