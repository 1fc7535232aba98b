"""Metrics: pure functions of a Result, named as in DESIGN.md.

Where the Result has exact events (adaptive method) they are used; otherwise the metrics are read off the
time series the same way for every time-stepped source (the reference's verlet method and the engines):
contact start and end by linear interpolation of δ between the steps that bracket its sign change, the
impact rate from the last step before contact, the rebound rate from the first step after it.
"""

from __future__ import annotations

import math

import numpy as np

NORMAL_METRICS = ("restitution", "contact_time", "force_contact_time", "max_overlap", "peak_force",
                  "energy_dissipated")
TANGENTIAL_METRICS = ("tangential_restitution", "rebound_angle", "rebound_angular_velocity")


def _event(events, name):
    if events is None or events.empty:
        return None
    rows = events[events["event"] == name]
    return None if rows.empty else rows.iloc[0]


def _crossing(t, y, k):
    """Time where y crosses 0 between samples k−1 and k (linear)."""
    y0, y1 = y[k - 1], y[k]
    if y1 == y0:
        return t[k]
    return t[k - 1] + (t[k] - t[k - 1]) * (y0 / (y0 - y1))


def compute(result) -> dict:
    c = result.contact
    nan = math.nan
    out = {name: nan for name in NORMAL_METRICS}
    if c is None or c.empty:
        return out
    t = c["t"].to_numpy()
    d = c["delta"].to_numpy()
    r = c["delta_dot"].to_numpy()
    f = c["fn"].to_numpy()
    ev = result.events
    start, end = _event(ev, "contact_start"), _event(ev, "contact_end")

    inside = np.flatnonzero(d > 0)
    if start is not None:
        t_s, v_in = float(start["t"]), float(start["delta_dot"])
        k_s = int(np.searchsorted(t, t_s))
    elif inside.size:
        k_s = int(inside[0])
        t_s = _crossing(t, d, k_s) if k_s > 0 else t[0]
        v_in = float(r[k_s - 1]) if k_s > 0 else float(r[0])
    else:
        return out
    if end is not None:
        t_e, v_out = float(end["t"]), float(end["delta_dot"])
        k_e = int(np.searchsorted(t, t_e))
    else:
        after = np.flatnonzero(d[k_s:] <= 0)
        if not after.size:
            k_e, t_e, v_out = len(t), nan, nan
        else:
            k_e = k_s + int(after[0])
            t_e = _crossing(t, d, k_e)
            v_out = float(r[k_e])
    window = slice(k_s, min(k_e + 1, len(t)))

    out["contact_time"] = t_e - t_s
    out["restitution"] = -v_out / v_in if v_in else nan
    fe = _event(ev, "force_end")
    if fe is not None:
        out["force_contact_time"] = float(fe["t"]) - t_s
    elif ev is not None and not ev.empty:
        out["force_contact_time"] = out["contact_time"]
    else:
        # the force ends where it first drops to ≤ 0 while the bodies still overlap; else with the overlap
        out["force_contact_time"] = out["contact_time"]
        k_in = np.arange(k_s, min(k_e, len(t)))
        pos = np.flatnonzero(f[k_in] > 0)
        if pos.size:
            stop = np.flatnonzero(f[k_in[pos[0]:]] <= 0)
            if stop.size:
                k = int(k_in[pos[0] + stop[0]])
                out["force_contact_time"] = _crossing(t, f, k) - t_s
    mo = _event(ev, "max_overlap")
    out["max_overlap"] = float(mo["delta"]) if mo is not None else float(np.max(d[window]))
    out["peak_force"] = float(np.max(f[window]))
    k_in = _row_at(t, t_s, k_s, start is not None, before=True)
    k_out = _row_at(t, t_e, k_e, end is not None, before=False)
    if "energy" in c.columns and k_out is not None:
        e = c["energy"].to_numpy()
        out["energy_dissipated"] = float(e[k_in] - e[k_out])
    else:
        m_eff = result.params.get("m_eff")
        if m_eff is not None:
            out["energy_dissipated"] = 0.5 * m_eff * (v_in * v_in - v_out * v_out)
    if "vrx" in c.columns:
        out.update(tangential(c, k_in, k_out))
    return out


def _row_at(t, t_x, k, exact: bool, before: bool):
    """Row of the state at contact start (exact event row, or the last step before) / end (event row, or the
    first step after)."""
    if k is None or k >= len(t):
        return None
    if exact:
        return int(np.argmin(np.abs(t - t_x)))
    return max(k - 1, 0) if before else k


def tangential(c, k_in: int, k_out: int | None) -> dict:
    """Tangential metrics from the relative velocity of the centres (v0 − v1, or v0 at a wall) and the spin
    of body 0, decomposed on the contact normal n at impact:

    * tangential_restitution = (v_out·t̂)/(v_in·t̂), t̂ the direction of v_in's tangential part (1 when the
      tangential velocity is kept, as without friction);
    * rebound_angle: angle of v_out from the outward normal, in degrees;
    * rebound_angular_velocity: ω0·(t̂ × n), positive in the rolling sense (t̂ from the contact-point slip at
      impact when the centres move head-on)."""
    nan = math.nan
    out = {k: nan for k in TANGENTIAL_METRICS}
    if k_out is None:
        return out
    n = c[["nx", "ny", "nz"]].to_numpy()[k_in]
    vr = c[["vrx", "vry", "vrz"]].to_numpy()
    v_in, v_out = vr[k_in], vr[k_out]
    vt_in = v_in - (v_in @ n) * n
    vt_out = v_out - (v_out @ n) * n
    out["rebound_angle"] = math.degrees(math.atan2(float(np.linalg.norm(vt_out)), float(-(v_out @ n))))
    speed_t = float(np.linalg.norm(vt_in))
    scale = float(np.linalg.norm(v_in))
    if speed_t > 1e-12 * scale:
        t_hat = vt_in / speed_t
        out["tangential_restitution"] = float(vt_out @ t_hat) / speed_t
    elif {"vtx", "vty", "vtz"} <= set(c.columns):
        slip = c[["vtx", "vty", "vtz"]].to_numpy()[k_in]
        s = float(np.linalg.norm(slip))
        t_hat = slip / s if s > 1e-12 * max(scale, 1e-300) else None
    else:
        t_hat = None
    if t_hat is not None and {"w0x", "w0y", "w0z"} <= set(c.columns):
        w_out = c[["w0x", "w0y", "w0z"]].to_numpy()[k_out]
        out["rebound_angular_velocity"] = float(w_out @ np.cross(t_hat, n))
    return out
