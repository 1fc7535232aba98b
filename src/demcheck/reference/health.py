"""Whether a result can be trusted: one set of rules for every source.

A time-stepped run (the reference's verlet method, LAMMPS, LIGGGHTS) goes through :func:`health`; the
adaptive method's converged answer through :func:`overlap_rule` alone (the same rule: the model's range
does not depend on the method). The statuses, first rule that fails wins:

* ``failed``: the state holds NaN or infinite values;
* ``unresolved``: fewer than ``min_steps`` steps inside the contact (or none, with a time step longer than
  ``1/min_steps`` of the elastic contact time): the time step is the cause, and the message names it;
* ``no-contact``: the bodies never touched;
* ``unstable``: the collision created energy, with a law that only stores or dissipates it
  (``TangentialLaw.passive``): the scheme is unstable at this step. A law that can create energy itself (a
  spring capped with its history left alone) is not judged by this rule: its energy balance is the law's;
  the comparison with the converged adaptive answer judges its time step;
* ``out-of-range``: the overlap passed half the smaller radius: the contact law has left its range (small
  overlaps), whatever the method — the impact is too fast or the material too soft for the model;
* ``no-separation``: the contact had not ended by the end of the run.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..case import Case
from ..metrics import f64

MAX_OVERLAP_FRACTION = 0.5  # of the smaller radius: beyond it a contact law of small overlaps means nothing
ENERGY_GAIN_TOLERANCE = 0.01  # of the impact kinetic energy, for laws that cannot create energy
MIN_STEPS = 5  # inside the contact, for a time-stepped answer to count as resolved
STATE_COLUMNS = ("delta", "delta_dot", "fn")


def overlap_rule(d_max: float, radius: float | None) -> tuple[str, str] | None:
    """("out-of-range", why) when the largest overlap passed half the smaller radius, else None."""
    if radius and d_max > MAX_OVERLAP_FRACTION * radius:
        return "out-of-range", (f"the overlap reached {d_max / radius:.3g} of the smaller radius (beyond "
                                f"{MAX_OVERLAP_FRACTION:g}): the contact law is outside its range of small overlaps; "
                                "the impact is too fast or the material too soft for this model")
    return None


def _steps(dt: float, t_c: float) -> str:
    return f"dt = {dt:.3g} s, {t_c / dt:.3g} steps per elastic contact time of {t_c:.3g} s"


@njit(cache=KERNEL_CACHE)
def reading(t, d, r, f):
    """What the rules read off a time series (t, δ, δ̇, Fn; float64), compiled: (k_bad, inside, δ_max, δ_last,
    t_last) — the first row whose state (δ, δ̇, Fn) is NaN or infinite (−1: none), the rows with δ > 0, the
    largest δ, and the last row's δ and t."""
    n = t.shape[0]
    k_bad, inside, d_max = -1, 0, -math.inf
    if n == 0:
        return k_bad, inside, d_max, math.nan, math.nan
    for k in range(n):
        if not (math.isfinite(d[k]) and math.isfinite(r[k]) and math.isfinite(f[k])):
            k_bad = k
            break
        if d[k] > 0:
            inside += 1
        d_max = max(d_max, d[k])
    return k_bad, inside, d_max, d[n - 1], t[n - 1]


def rules(read: tuple, dt: float, t_c: float, radius: float | None, min_steps: int, impact_energy,
          passive: bool, gained, floor: float = 0.0) -> tuple[str, str]:
    """(status, why) from a series' ``reading`` and ``t`` of its bad row (module docstring; the first rule
    that fails wins); ``gained()`` is the energy the collision created (−energy_dissipated), read only when the
    energy rule is reached, and ``impact_energy()`` the energy it is measured in, at least ``floor``: read only
    when the collision created more than the rule allows of the floor."""
    k_bad, inside, d_max, d_last, t_last, t_bad = read
    if k_bad >= 0:
        return "failed", f"the state became NaN or infinite at t = {t_bad:.3g} s ({_steps(dt, t_c)})"
    if inside < min_steps and (inside > 0 or t_c / dt < min_steps):
        return "unresolved", (f"only {inside} steps inside the contact ({_steps(dt, t_c)}): the time step does not "
                              f"resolve the collision (at least {min_steps} are needed)")
    if inside == 0:
        return "no-contact", "the bodies never touched"
    if passive:
        energy = gained()
        # (it holds for none created, and below the floor's share: e_in ≥ floor ≥ 0 — a floor that is not a positive
        # number proves nothing)
        if math.isfinite(energy) and energy > 0.0 and (not floor > 0.0 or energy > ENERGY_GAIN_TOLERANCE * floor):
            e_in = impact_energy()
            if e_in > 0 and energy > ENERGY_GAIN_TOLERANCE * e_in:
                return "unstable", (f"the collision created {energy / e_in:.3g} of the impact energy "
                                    f"({_steps(dt, t_c)}): the scheme is unstable at this time step")
    out = overlap_rule(float(d_max), radius)
    if out is not None:
        return out
    if d_last > 0:
        return "no-separation", f"the contact had not ended by the end of the run (t = {float(t_last):.3g} s)"
    return "ok", ""


def health(result, t_c: float, radius: float | None = None, min_steps: int = MIN_STEPS,
           impact_energy: float | None = None, passive: bool = True) -> tuple[str, str]:
    """(status, why) of a time-stepped result (module docstring); ("ok", "") when every rule holds.
    ``radius``: the smaller radius (default: ``result.meta["radius0"]``); ``impact_energy``: the energy
    the energy rule is measured in (default ½ m̄ v² of the normal impact); ``passive``: whether the law can
    only store or dissipate energy (the energy rule applies only then)."""
    c = result.table("contact")  # the arrays: no DataFrame is built for the check
    t, d, r, f = (f64(c[k]) for k in ("t", *STATE_COLUMNS))
    read = reading(t, d, r, f)
    e_in = impact_energy
    if e_in is None:
        e_in = 0.5 * result.params.get("m_eff", 0.0) * result.params.get("impact_speed", 0.0) ** 2
    t_bad = float(t[read[0]]) if read[0] >= 0 else math.nan
    return rules((*read, t_bad), result.dt, t_c, radius or result.meta.get("radius0"), min_steps, lambda: e_in,
                 passive, lambda: -result.metrics()["energy_dissipated"], max(e_in, 0.0))


def check(result, case, model=None, min_steps: int = MIN_STEPS) -> tuple[str, str]:
    """:func:`health` of a time-stepped result of ``case``: the elastic contact time of its seed model, its
    smaller radius, and its impact energy (translation, tangential motion and spin: the units of the
    suite's energy metric, :func:`impact_scales`)."""
    from ..laws.model import characteristic_time, resolve

    model = model or resolve(case)
    return health(result, characteristic_time(model), smallest_radius(case), min_steps,
                  impact_scales(case, model)["impact_energy"], model.tangential_law.passive)


def apply(result, case, model=None, min_steps: int = MIN_STEPS):
    """Set ``result``'s status and message from :func:`check` when a rule fails; returns the result."""
    status, why = check(result, case, model, min_steps)
    if status != "ok":
        result.status, result.message = status, why
    return result


def smallest_radius(case) -> float:
    return min(p.radius for p in case.particles)


def impact_scales(case: Case, model) -> dict:
    """The units the oblique metrics are measured in (verdicts.scale): the impact energy, and v_in/R for a
    spin. Shared with bench and dt, so that their errors and the suite's verdicts speak the same units."""
    return {"impact_energy": impact_energy(case, model), "spin": model.pair.impact_speed / case.particles[0].radius}


def impact_energy(case: Case, model) -> float:
    """Kinetic energy of the relative motion, m̄|v_rel|²/2, plus the bodies' spin energy."""
    v = np.asarray(case.particles[0].velocity, float)
    if not case.walls:
        v = v - np.asarray(case.particles[1].velocity, float)
    e = 0.5 * model.pair.m_eff * float(v @ v)
    for i, p in enumerate(case.particles):
        w = np.asarray(p.angular_velocity, float)
        e += 0.5 * 0.4 * case.mass(i) * p.radius**2 * float(w @ w)
    return max(e, impact_energy_floor(model))


def impact_energy_floor(model) -> float:
    """½ m̄ v² of the normal impact: the least :func:`impact_energy` is."""
    return 0.5 * model.pair.m_eff * model.pair.impact_speed**2
