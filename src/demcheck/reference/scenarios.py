"""The scenarios beyond sliding of a case (``[run] scenario``): the case read into reference/beyond.py's solvers,
and the same inputs into their closed forms.

Each scenario's metrics (DESIGN names):

* ``rolling`` (a sphere rolling on a level wall, constant_torque): rolling_stop_time, rolling_distance; viscous
  (type B, which never stops): rolling_time_constant T (v = v0 e^{−t/T}), rolling_distance (to rest, v0·T);
* ``incline`` (constant_torque, epsd): incline_critical_angle (rad), the tilt at which the sphere starts to roll;
* ``twist`` (sds, marshall; marshall at the Hertz contact radius under the sphere's weight): twist_stop_time, from
  the twisting spring at its limit (the closed form's assumption);
* ``pull_off`` (jkr, dmt; sjkr added to an elastic Hertz law between like spheres): pull_off_force (N, the
  largest tension), separation_at_pull_off (m, the overlap at which the contact breaks: negative, a neck; 0 for
  dmt and sjkr);
* ``adhesive_impact`` (jkr): restitution at the case's approach speed v and capture_velocity √(v² − v_out²) (the
  energy of the loop; nan when the bodies are captured: the solve then bounds it from below only);
* ``conduction`` (radius, area, lens): heat_time_constant (s) at the case's fixed overlap.

The case's checks (case.py, ``_check_scenario``) guarantee the inputs each scenario reads.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..laws.heat import conductance
from ..laws.model import resolve
from ..result import Result
from . import beyond as _b

SCENARIO_METRICS = {
    "rolling": ("rolling_stop_time", "rolling_distance"),
    "incline": ("incline_critical_angle",),
    "twist": ("twist_stop_time",),
    "pull_off": ("pull_off_force", "separation_at_pull_off"),
    "adhesive_impact": ("restitution", "capture_velocity"),
    "conduction": ("heat_time_constant",),
}
# the rolling scenario of a law that never stops (its record's trait ``decays``: type B, v = v0 e^{−t/T}): its time
# constant and the distance to rest v0·T
DECAY_METRICS = ("rolling_time_constant", "rolling_distance")


def _decays(case) -> bool:
    """Whether the case rolls under a law that never stops (the rolling record's trait ``decays``)."""
    return case.run.scenario == "rolling" and resolve(case).slot("rolling").decays


def metric_names(case) -> tuple:
    """The metrics of a case's scenario: SCENARIO_METRICS, or DECAY_METRICS for a rolling law that never stops."""
    return DECAY_METRICS if _decays(case) else SCENARIO_METRICS[case.run.scenario]


def _on_wall(case):
    """(mass, radius, g, θ, n) of the sphere on the wall: θ the wall's tilt against gravity."""
    p, n = case.particles[0], np.asarray(case.walls[0].normal, dtype=float)
    g_vec = np.asarray(case.run.gravity, dtype=float)
    g = float(np.linalg.norm(g_vec))
    theta = math.acos(min(1.0, float(-(g_vec @ n)) / g))
    return case.mass(0), p.radius, g, theta, n


def _twisting_law(case, law):
    """The law the twist runs at the Hertz contact radius under the weight (Marshall's: the sds law there)."""
    if not law.from_contact_radius:
        return law
    mass, radius, g, theta, _ = _on_wall(case)
    a = (3.0 * mass * g * math.cos(theta) * radius / (4.0 * resolve(case).pair.e_eff)) ** (1.0 / 3.0)
    return law.at(a)


def _rolling(case, model, closed):
    law = model.slot("rolling")
    mass, radius, g, theta, n = _on_wall(case)
    v = np.asarray(case.particles[0].velocity, dtype=float)
    v0 = float(np.linalg.norm(v - (v @ n) * n))
    if law.decays:
        return _rolling_viscous(law, mass, radius, v0, g, closed)
    t_stop, s_stop = _b.rolling_stop_closed(law.mu_r, law.r_roll, radius, v0, g)
    if closed:
        return {"rolling_stop_time": t_stop, "rolling_distance": s_stop}
    out = _b.rolling_on_plane(law, mass, radius, v0, g, t_end=4.0 * t_stop)  # the horizon only
    return {k: out.get(k, math.nan) for k in SCENARIO_METRICS["rolling"]}


def _rolling_viscous(law, mass, radius, v0, g, closed):
    """Type B: the time constant T = 1.4 m R²/Cr and the distance to rest v0·T (closed), or from the integration:
    the e-fold time of the speed and the distance at 40 T (e^{−40} of it left)."""
    tau, dist = _b.rolling_viscous_closed(law.c_r, mass, radius, v0)
    if closed:
        return {"rolling_time_constant": tau, "rolling_distance": dist}
    out = _b.rolling_on_plane(law, mass, radius, v0, g, t_end=40.0 * tau)  # the horizon only
    return {"rolling_time_constant": _b.efold_time(out["t"], out["v"]), "rolling_distance": float(out["x"][-1])}


def _incline(case, model, closed):
    law = model.slot("rolling")
    mass, radius, g, _, _ = _on_wall(case)
    if closed:
        return {"incline_critical_angle": _b.incline_closed(law.mu_r, law.r_roll, radius, 0.0, g)[0]}
    return {"incline_critical_angle": _b.incline_critical_angle(law, mass, radius, g)}


def _twist(case, model, closed):
    law = _twisting_law(case, model.slot("twisting"))
    mass, radius, g, theta, n = _on_wall(case)
    fn = mass * g * math.cos(theta)
    omega0 = abs(float(np.asarray(case.particles[0].angular_velocity) @ n))
    t_stop = _b.twist_stop_closed(mass, radius, omega0, law.mu_tw, fn)
    if closed:
        return {"twist_stop_time": t_stop}
    return {"twist_stop_time": _b.twist_decay(law, mass, radius, omega0, fn, 10.0 * t_stop)["twist_stop_time"]}


def _pull_off(case, model, closed):
    law = model.slot("adhesion")
    if not law.replaces_normal:  # a cohesion added to the elastic Hertz law (case.py: like spheres, elastic hertz)
        nl, radius = model.normal_law, case.particles[0].radius
        if closed:
            return {"pull_off_force": _b.sjkr_pull_off_closed(nl.k, law.k_c, law.area, radius, model.pair.r_eff),
                    "separation_at_pull_off": 0.0}
        return _b.cohesive_pull_off(law, lambda d: nl.k * d ** nl.a, 0.5 * radius)
    if closed:
        return {"pull_off_force": law.pull_off_force("load"), "separation_at_pull_off": law.separation_at_pull_off()}
    return _b.pull_off(law)


def _adhesive_impact(case, model, closed):
    law, pair = model.slot("adhesion"), model.pair
    v = pair.impact_speed
    if closed:
        vs = _b.capture_velocity_closed(law.r_eff, law.e_eff, law.w, pair.m_eff, law.control)
        return {"restitution": _b.adhesive_restitution_closed(v, vs), "capture_velocity": vs}
    out = _b.adhesive_impact(law, pair.m_eff, v)
    e = out["restitution"]
    vs = math.nan if out["captured"] else v * math.sqrt(max(0.0, 1.0 - e * e))
    return {"restitution": e, "capture_velocity": vs}


def _conduction(case, model, closed):
    law = model.slot("heat")
    c0, c1 = (case.mass(i) * case.materials[p.material].specific_heat for i, p in enumerate(case.particles))
    tau = _b.heat_time_constant_closed(conductance(law, case.run.overlap), c0, c1)
    if closed:
        return {"heat_time_constant": tau}
    t0, t1 = case.run.temperatures
    return {"heat_time_constant": _b.conduction(law, case.run.overlap, c0, c1, t0, t1, 20.0 * tau)[
        "heat_time_constant"]}


def stepped_metrics(case, run: dict) -> dict:
    """The case's scenario metrics from a stepped run (an engine's output or a twin's: one computation for both).
    ``run``: the wall scenarios' samples t, x, v, omega (rows × 3) of the sphere; pull_off's ``delta`` and ``fn``
    along the imposed path; adhesive_impact's ``v_rel`` (the separation speed at the end, along the line of
    centres) and ``touching`` (the contact still closed at the end); conduction's t and ``dT`` (T1 − T0)."""
    scenario = case.run.scenario
    if scenario in ("rolling", "incline", "twist"):
        _, _, g, theta, n = _on_wall(case)
        t, x, v, w = (np.asarray(run[k], dtype=float) for k in ("t", "x", "v", "omega"))
        if scenario == "twist":
            sign = math.copysign(1.0, float(np.asarray(case.particles[0].angular_velocity) @ n))
            return {"twist_stop_time": _b.first_stop(t, sign * (w @ n))[0]}
        if scenario == "rolling":
            v0 = np.asarray(case.particles[0].velocity, dtype=float)
            u = v0 - (v0 @ n) * n
            u /= np.linalg.norm(u)
            if _decays(case):  # the e-fold time; the distance at the end plus v·T still to go
                tau = _b.efold_time(t, v @ u)
                return {"rolling_time_constant": tau,
                        "rolling_distance": float((x[-1] - x[0]) @ u + (v[-1] @ u) * tau)}
            t_stop, s = _b.first_stop(t, v @ u, (x - x[0]) @ u)
            return {"rolling_stop_time": t_stop, "rolling_distance": s}
        gv = np.asarray(case.run.gravity, dtype=float)
        down = gv - (gv @ n) * n
        down /= np.linalg.norm(down)
        acc = _b.fitted_acceleration(t, v @ down)
        return {"incline_critical_angle": _b.critical_angle_from_acceleration(acc, theta, g)}
    if scenario == "pull_off":
        return _b.pull_off_of_path(run["delta"], run["fn"])
    if scenario == "adhesive_impact":
        v = resolve(case).pair.impact_speed
        if run["touching"]:
            return {"restitution": 0.0, "capture_velocity": math.nan}
        e = float(run["v_rel"]) / v
        return {"restitution": e, "capture_velocity": v * math.sqrt(max(0.0, 1.0 - e * e))}
    return {"heat_time_constant": _b.efold_time(run["t"], run["dT"])}


SOLVERS = {"rolling": _rolling, "incline": _incline, "twist": _twist, "pull_off": _pull_off,
           "adhesive_impact": _adhesive_impact, "conduction": _conduction}


def scenario_metrics(case, closed: bool = False) -> dict:
    """The case's scenario metrics from the reference's integration (or, ``closed``, its closed forms)."""
    out = SOLVERS[case.run.scenario](case, resolve(case), closed)
    return {k: float(out[k]) for k in metric_names(case)}


def solve(case) -> Result:
    """The reference's Result of a scenario case: no series, its metrics (Result.metrics reads them)."""
    model = resolve(case)
    start = time.perf_counter()
    metrics = scenario_metrics(case)
    bad = [k for k, v in metrics.items() if not math.isfinite(v)]
    status, message = "ok", ""
    if bad and case.run.scenario != "adhesive_impact":
        status, message = "failed", f"the {case.run.scenario} solve gave no {', '.join(bad)} (not finite)"
    return Result(source="reference", method="adaptive", case_name=case.name, case_hash=case.hash,
                  model=model.describe(), params=dict(model.params), contact=None, rtol=_b.RTOL,
                  wall_time=time.perf_counter() - start, status=status, message=message,
                  meta={"scenario": case.run.scenario, "scenario_metrics": metrics})
