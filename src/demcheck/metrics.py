"""Metrics: pure functions of a Result's series (its arrays: ``Result.table``), named as in docs/verify.md.

Where the Result has exact events (adaptive method) they are used; otherwise the metrics are read off the
time series the same way for every time-stepped source (the reference's verlet method and the engines):
contact start and end by linear interpolation of δ between the steps that bracket its sign change, the
impact rate from the last step before contact, the rebound rate from the first step after it. That reading of a
series is compiled (``stepped``): one function for every time-stepped source and for the batched solve
(reference/batch.py), which computes a collision's metrics without handing its series back to Python.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import KERNEL_CACHE

NORMAL_METRICS = ("restitution", "contact_time", "force_contact_time", "max_overlap", "peak_force",
                  "energy_dissipated")
TANGENTIAL_METRICS = ("tangential_restitution", "rebound_angle", "rebound_angular_velocity")


def _event(events, name):
    """The first event called ``name`` as {column: value}, or None."""
    if not events or not len(events["event"]):
        return None
    rows = np.flatnonzero(np.asarray(events["event"]) == name)
    return None if not rows.size else {k: v[rows[0]] for k, v in events.items()}


@njit(cache=KERNEL_CACHE)
def _crossing(t, y, k):
    """Time where y crosses 0 between samples k−1 and k (linear)."""
    y0, y1 = y[k - 1], y[k]
    if y1 == y0:
        return t[k]
    return t[k - 1] + (t[k] - t[k - 1]) * (y0 / (y0 - y1))


@njit(cache=KERNEL_CACHE)
def _window_max(y, lo, hi):
    """max(y[lo:hi]) as numpy's: NaN when any is NaN."""
    m = y[lo]
    for k in range(lo + 1, hi):
        if m != m:
            break
        if y[k] > m or y[k] != y[k]:
            m = y[k]
    return m


@njit(cache=KERNEL_CACHE)
def stepped(t, d, r, f):
    """The contact of a time series without events (t, δ, δ̇, Fn; float64): (k_s, t_s, v_in, k_e, t_e, v_out,
    k_f, t_f, δ_max, F_max). The contact starts at the first row k_s with δ > 0 (k_s = −1: never; t_s by linear
    interpolation from the row before, v_in its rate) and ends at the first row k_e ≥ k_s with δ ≤ 0 (k_e = the
    length and t_e = v_out = NaN when it does not); the force ends at the first row k_f with Fn ≤ 0 after the
    first with Fn > 0 inside the contact (k_f = −1: not before the contact ends); δ_max and F_max over the rows
    from k_s to k_e."""
    n = t.shape[0]
    nan = math.nan
    k_s = -1
    for k in range(n):
        if d[k] > 0:
            k_s = k
            break
    if k_s < 0:
        return -1, nan, nan, n, nan, nan, -1, nan, nan, nan
    t_s, v_in = t[0], r[0]
    if k_s > 0:
        t_s, v_in = _crossing(t, d, k_s), r[k_s - 1]
    k_e, t_e, v_out = n, nan, nan
    for k in range(k_s, n):
        if d[k] <= 0:
            k_e, t_e, v_out = k, _crossing(t, d, k), r[k]
            break
    hi = min(k_e, n)
    k_f, t_f = -1, nan
    for k in range(k_s, hi):
        if f[k] > 0:
            for j in range(k, hi):
                if f[j] <= 0:
                    k_f, t_f = j, _crossing(t, f, j)
                    break
            break
    top = min(k_e + 1, n)
    return k_s, t_s, v_in, k_e, t_e, v_out, k_f, t_f, _window_max(d, k_s, top), _window_max(f, k_s, top)


def from_stepped(reading: tuple) -> dict:
    """The normal metrics of a contact ``stepped`` found (k_s ≥ 0), but the energy dissipated (``rate_energy``):
    for a Result's series (``compute``) and a batched point's (reference/batch.py) alike."""
    k_s, t_s, v_in, k_e, t_e, v_out, k_f, t_f, d_max, f_max = reading
    contact_time = t_e - t_s
    return {"restitution": -v_out / v_in if v_in else math.nan, "contact_time": contact_time,
            "force_contact_time": t_f - t_s if k_f >= 0 else contact_time, "max_overlap": d_max, "peak_force": f_max}


def rate_energy(m_eff: float, v_in: float, v_out: float) -> float:
    """The energy dissipated from the approach rates at contact start and end: ½ m̄ (v_in² − v_out²)."""
    return 0.5 * m_eff * (v_in * v_in - v_out * v_out)


def f64(x) -> np.ndarray:
    """A column as the compiled readers take it: float64, contiguous and writeable (one specialisation)."""
    return np.require(np.asarray(x, dtype=np.float64), requirements=("C", "W"))


def compute(result) -> dict:
    if "scenario_metrics" in result.meta:  # a scenario beyond sliding: its solve's metrics (reference/scenarios.py)
        return dict(result.meta["scenario_metrics"])
    c = result.table("contact")
    nan = math.nan
    out = {name: nan for name in NORMAL_METRICS}
    if not c or not len(c["t"]):
        return out
    t, d, r, f = (f64(c[k]) for k in ("t", "delta", "delta_dot", "fn"))
    ev = result.table("events")
    if not ev or not len(ev["event"]):
        read = stepped(t, d, r, f)
        k_s, t_s, v_in, k_e, t_e, v_out = read[:6]
        if k_s < 0:
            return out
        out.update(from_stepped(read))
        return _rest(result, c, out, t, t_s, k_s, False, t_e, k_e, False, v_in, v_out)
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
    fe = _event(ev, "force_end")  # (a series without events: where Fn first drops to ≤ 0 inside; ``stepped``)
    out["force_contact_time"] = float(fe["t"]) - t_s if fe is not None else out["contact_time"]
    mo = _event(ev, "max_overlap")
    out["max_overlap"] = float(mo["delta"]) if mo is not None else float(np.max(d[window]))
    out["peak_force"] = float(np.max(f[window]))
    return _rest(result, c, out, t, t_s, k_s, start is not None, t_e, k_e, end is not None, v_in, v_out)


def _rest(result, c, out: dict, t, t_s, k_s, exact_start: bool, t_e, k_e, exact_end: bool, v_in, v_out) -> dict:
    """The energy dissipated and the tangential metrics, from the rows at contact start and end."""
    k_in = _row_at(t, t_s, k_s, exact_start, before=True)
    k_out = _row_at(t, t_e, k_e, exact_end, before=False)
    if "energy" in c and k_out is not None:
        e = c["energy"]
        out["energy_dissipated"] = float(e[k_in] - e[k_out])
    else:
        m_eff = result.params.get("m_eff")
        if m_eff is not None:
            out["energy_dissipated"] = rate_energy(m_eff, v_in, v_out)
    if "vrx" in c:
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


def _vectors(c, prefix: str, k: int) -> np.ndarray:
    return np.array([c[prefix + "x"][k], c[prefix + "y"][k], c[prefix + "z"][k]], dtype=float)


def tangential(c, k_in: int, k_out: int | None) -> dict:
    """Tangential metrics (``c``: the contact table's arrays, or a DataFrame) from the relative velocity of the centres (v0 − v1, or v0 at a wall) and the spin
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
    if not isinstance(c, dict):
        c = {k: c[k].to_numpy() for k in c.columns}
    n = _vectors(c, "n", k_in)
    v_in, v_out = _vectors(c, "vr", k_in), _vectors(c, "vr", k_out)
    vt_in = v_in - (v_in @ n) * n
    vt_out = v_out - (v_out @ n) * n
    out["rebound_angle"] = math.degrees(math.atan2(float(np.linalg.norm(vt_out)), float(-(v_out @ n))))
    speed_t = float(np.linalg.norm(vt_in))
    scale = float(np.linalg.norm(v_in))
    if speed_t > 1e-12 * scale:
        t_hat = vt_in / speed_t
        out["tangential_restitution"] = float(vt_out @ t_hat) / speed_t
    elif {"vtx", "vty", "vtz"} <= c.keys():
        slip = _vectors(c, "vt", k_in)
        s = float(np.linalg.norm(slip))
        t_hat = slip / s if s > 1e-12 * max(scale, 1e-300) else None
    else:
        t_hat = None
    if t_hat is not None and {"w0x", "w0y", "w0z"} <= c.keys():
        w_out = _vectors(c, "w0", k_out)
        out["rebound_angular_velocity"] = float(w_out @ np.cross(t_hat, n))
    return out
