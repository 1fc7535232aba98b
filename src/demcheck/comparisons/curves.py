"""Distances between a source's force–time and force–overlap curves and the reference's.

Both curves start at their own contact onset (t = 0 at δ = 0, found by interpolation for time-stepped
sources, exactly for the adaptive method). The reference's adaptive output is interpolated monotonically
(PCHIP, no overshoot at the kinks of hysteretic or clipped laws) at the source's sample times. Forces are
in units of the reference's peak force, overlaps of its maximum overlap:

* force–time: normalised L2 (RMS over the samples in contact) and maximum of |ΔF|/F_peak;
* force–overlap: the same of the distance √((Δδ/δ_max)² + (ΔF/F_peak)²) between points at equal time
  since onset, which measures the loop (loading and unloading branches) rather than the time course alone.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import PchipInterpolator


def _onset(t, d):
    inside = np.flatnonzero(d > 0)
    if not inside.size:
        return None
    k = int(inside[0])
    if k == 0:
        return t[0]
    return t[k - 1] + (t[k] - t[k - 1]) * d[k - 1] / (d[k - 1] - d[k])


def distances(source_contact, reference_contact, reference_events=None) -> dict:
    nan = math.nan
    out = {"force_time_l2": nan, "force_time_max": nan, "force_overlap_l2": nan, "force_overlap_max": nan}
    if source_contact is None or reference_contact is None or source_contact.empty or reference_contact.empty:
        return out
    tr, dr, fr = (reference_contact[c].to_numpy() for c in ("t", "delta", "fn"))
    ts, ds, fs = (source_contact[c].to_numpy() for c in ("t", "delta", "fn"))
    t0r = None
    if reference_events is not None and not reference_events.empty:
        rows = reference_events[reference_events["event"] == "contact_start"]
        if not rows.empty:
            t0r = float(rows["t"].iloc[0])
    t0r = t0r if t0r is not None else _onset(tr, dr)
    t0s = _onset(ts, ds)
    if t0r is None or t0s is None:
        return out
    keep = np.concatenate([[True], np.diff(tr) > 0])  # events repeat a time; PCHIP needs it increasing
    tr, dr, fr = tr[keep], dr[keep], fr[keep]
    ref_in = dr > 0
    t_end = tr[ref_in].max() - t0r if ref_in.any() else 0.0
    x = ts - t0s
    sel = (ds > 0) & (x >= 0) & (x <= t_end)
    if sel.sum() < 2:
        return out
    f_i = PchipInterpolator(tr - t0r, fr)(x[sel])
    d_i = PchipInterpolator(tr - t0r, dr)(x[sel])
    f_peak = np.max(np.abs(fr[ref_in])) if ref_in.any() else 1.0
    d_max = np.max(dr[ref_in]) if ref_in.any() else 1.0
    df = (fs[sel] - f_i) / f_peak
    dd = (ds[sel] - d_i) / d_max
    loop = np.hypot(df, dd)
    out.update(force_time_l2=float(np.sqrt(np.mean(df * df))), force_time_max=float(np.max(np.abs(df))),
               force_overlap_l2=float(np.sqrt(np.mean(loop * loop))), force_overlap_max=float(np.max(loop)))
    return out
