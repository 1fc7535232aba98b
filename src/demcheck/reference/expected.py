"""Closed-form metrics of a resolved model where the notes derive them (LSDn, elastic Hertz, HLS).

Used by the tests (closed form against converged integration) and by the verification suite
("the reference solver against its closed form")."""

from __future__ import annotations

from ..laws import analytic
from ..laws.model import ResolvedModel
from ..laws.normal import HysteresisNormal


def closed_form_metrics(model: ResolvedModel) -> dict:
    """Metric name → closed-form value, for the metrics this model has one for (may be empty). The closed forms
    are the gravity-free collision's: a case with any gravity has none (a wall contact also carries the weight,
    and the bodies' kinetic energy changes with their fall)."""
    law, pair = model.normal_law, model.pair
    m, v = pair.m_eff, pair.impact_speed
    nid = model.normal.id
    if model.tangential.id != "none" or not (v > 0) or any(model.gravity):
        return {}
    if nid == "lsd":
        k, eta = law.k, law.eta
        t_f = analytic.lsd_force_end_time(m, k, eta)
        e = analytic.lsd_restitution_limited(m, k, eta) if law.limit else analytic.lsd_restitution(m, k, eta)
        out = {
            "restitution": e,
            "max_overlap": analytic.lsd_max_overlap(m, k, eta, v),
            "peak_force": analytic.lsd_peak_force(m, k, eta, v),
            "force_contact_time": t_f,
            "energy_dissipated": 0.5 * m * v * v * (1 - e * e),
        }
        if law.limit:
            # free flight from the force end until δ = 0
            d_f, _ = analytic._lsd_state(m, k, eta, v, t_f)
            out["contact_time"] = t_f + d_f / (e * v)
        else:
            out["contact_time"] = analytic.lsd_duration(m, k, eta)
        return out
    if nid == "hertz":
        t_c = analytic.hertz_duration(m, pair.r_eff, pair.e_eff, v)
        return {
            "restitution": 1.0,
            "contact_time": t_c,
            "force_contact_time": t_c,
            "max_overlap": analytic.hertz_max_overlap(m, pair.r_eff, pair.e_eff, v),
            "peak_force": analytic.hertz_peak_force(m, pair.r_eff, pair.e_eff, v),
            "energy_dissipated": 0.0,
        }
    if nid == "hls" and isinstance(law.slots()[0], HysteresisNormal):
        kw = {"s": law.s} if law.ku == 0.0 else {"e": (law.kl / law.ku) ** 0.5}
        e = analytic.hls_restitution(m, law.kl, v, **kw)
        return {
            "restitution": e,
            "force_contact_time": analytic.hls_duration(m, law.kl, v, **kw),
            "contact_time": analytic.hls_overlap_duration(m, law.kl, v, **kw),
            "max_overlap": analytic.hls_max_overlap(m, law.kl, v),
            "peak_force": analytic.hls_peak_force(m, law.kl, v),
            "energy_dissipated": 0.5 * m * v * v * (1 - e * e),
        }
    return {}


def scenario_closed_forms(case) -> dict:
    """Metric name → closed-form value of a case's scenario beyond sliding (reference/scenarios.py: rolling,
    incline, twist, pull_off, adhesive_impact, conduction); empty for a collision."""
    if case.run.scenario == "collision":
        return {}
    from .scenarios import scenario_metrics

    return scenario_metrics(case, closed=True)
