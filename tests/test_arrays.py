"""Results as arrays (issue 16): a collision's series stay numpy arrays, its metrics are computed on them, and
the DataFrames are built on request. The array path must give the same numbers as the frame path it replaced:
``_frame_metrics`` below is the metric code as it ran on pandas tables (metrics.py before the change, frozen
here), and every case — pair and wall, head-on and oblique, adaptive and verlet, the reference and an
engine's twin read off its states — must give identical metrics (==, no tolerance) and identical tables."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pandas as pd
import pytest

from demcheck.case import load
from demcheck.engines import states
from demcheck.engines.collide import twin_states
from demcheck.metrics import compute
from demcheck.reference.collision import collide
from demcheck.result import Result, frame_of

CASES = ["cases/hertz-wall.toml", "cases/glass-pair.toml", "cases/oblique-lsd-wall.toml",
         "cases/oblique-viscous-sliding-pair.toml", "cases/tti-limited-wall.toml"]

# ----------------------------------------------------------------------------- the frame path, frozen


def _frame_metrics(c: pd.DataFrame, ev: pd.DataFrame | None, params: dict) -> dict:
    """metrics.compute as it was on pandas tables (the contact table ``c``, the events ``ev``)."""
    nan = math.nan
    out = {name: nan for name in ("restitution", "contact_time", "force_contact_time", "max_overlap",
                                  "peak_force", "energy_dissipated")}
    if c is None or c.empty:
        return out
    t = c["t"].to_numpy()
    d = c["delta"].to_numpy()
    r = c["delta_dot"].to_numpy()
    f = c["fn"].to_numpy()
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
    elif params.get("m_eff") is not None:
        out["energy_dissipated"] = 0.5 * params["m_eff"] * (v_in * v_in - v_out * v_out)
    if "vrx" in c.columns:
        out.update(_tangential(c, k_in, k_out))
    return out


def _event(events, name):
    if events is None or events.empty:
        return None
    rows = events[events["event"] == name]
    return None if rows.empty else rows.iloc[0]


def _crossing(t, y, k):
    y0, y1 = y[k - 1], y[k]
    if y1 == y0:
        return t[k]
    return t[k - 1] + (t[k] - t[k - 1]) * (y0 / (y0 - y1))


def _row_at(t, t_x, k, exact, before):
    if k is None or k >= len(t):
        return None
    if exact:
        return int(np.argmin(np.abs(t - t_x)))
    return max(k - 1, 0) if before else k


def _tangential(c, k_in, k_out):
    nan = math.nan
    out = {k: nan for k in ("tangential_restitution", "rebound_angle", "rebound_angular_velocity")}
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


# ----------------------------------------------------------------------------- the comparisons


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(a[k] == b[k] or (math.isnan(a[k]) and math.isnan(b[k])) for k in a)


def _sources(path):
    case = load(path)
    out = {m: collide(case, m) for m in ("adaptive", "verlet")}
    if path.startswith("cases/oblique") or "pair" in path:
        out["lammps-twin"] = twin_states(case, "lammps", out["verlet"].dt)
    return out


@pytest.fixture(scope="module")
def results():
    return {(p, k): r for p in CASES for k, r in _sources(p).items()}


def test_the_cases_cover_pair_wall_head_on_oblique_and_a_twin(results):
    keys = {k for _, k in results}
    assert keys == {"adaptive", "verlet", "lammps-twin"}
    assert {r.meta["solver"] for r in results.values()} == {"1d-normal", "3d"}
    assert all(r.status == "ok" for r in results.values()), {k: r.message for k, r in results.items() if not r.ok}


@pytest.mark.parametrize("path", CASES)
def test_array_metrics_equal_the_frame_path_exactly(results, path):
    for (p, source), r in results.items():
        if p != path:
            continue
        fresh = Result(**_fields(r))
        arrays = compute(fresh)  # on the arrays: no DataFrame built
        assert "_contact_frame" not in fresh.__dict__ and "_events_frame" not in fresh.__dict__
        framed = _frame_metrics(r.contact, r.events, r.params)
        assert _same(arrays, framed), (source, {k: (arrays[k], framed.get(k)) for k in arrays})
        assert np.isfinite(arrays["restitution"]) and np.isfinite(arrays["contact_time"])
        if r.meta["solver"] == "3d" or "vrx" in r.table("contact"):
            assert "rebound_angle" in arrays


def test_a_planted_difference_is_seen(results):
    """The comparison can fail: one overlap sample moved by one ulp inside the contact moves a metric."""
    r = results[("cases/glass-pair.toml", "verlet")]
    c = {k: v.copy() for k, v in r.table("contact").items()}
    k = int(np.argmax(c["fn"]))
    c["fn"][k] = np.nextafter(c["fn"][k], np.inf)
    moved = Result(**{**_fields(r), "contact": c})
    assert not _same(compute(moved), _frame_metrics(r.contact, r.events, r.params))


def _fields(r):
    return dict(source=r.source, method=r.method, case_name=r.case_name, case_hash=r.case_hash, model=r.model,
                params=r.params, contact=r.table("contact"), particles=r.table("particles"), events=r.table("events"),
                dt=r.dt, rtol=r.rtol, status=r.status, meta=r.meta)


def test_frames_are_built_on_request_and_equal_the_plain_constructor(results):
    for (p, source), r in results.items():
        for name in ("contact", "particles", "events"):
            cols = r.table(name)
            if cols is None:
                assert getattr(r, name) is None
                continue
            frame = getattr(r, name)
            assert getattr(r, name) is frame  # built once
            pd.testing.assert_frame_equal(frame, pd.DataFrame(dict(cols)), check_exact=True)
            copy = r.to_frame(name)
            assert copy is not frame and copy.equals(frame)


def test_a_dataframe_given_to_a_result_is_its_table_and_assignment_resets_the_metrics(results):
    r = results[("cases/oblique-lsd-wall.toml", "verlet")]
    framed = Result(**{**_fields(r), "contact": r.contact.copy(), "particles": r.particles.copy()})
    assert _same(framed.metrics(), r.metrics())
    assert framed.final_state() == r.final_state()
    shorter = r.contact.iloc[: len(r.contact) // 3].reset_index(drop=True)  # ends inside the contact
    framed.contact = shorter
    assert _same(framed.metrics(), _frame_metrics(shorter, None, r.params))
    assert math.isnan(framed.metrics()["restitution"])


def test_the_states_reader_gives_the_same_table_from_a_frame_and_from_arrays(results):
    """The engines read their dumps as DataFrames, the twins' states stay arrays: one function, both kinds."""
    case = load("cases/oblique-viscous-sliding-pair.toml")
    r = collide(case, "verlet")
    parts_a = states.body_forces(r.table("contact"), r.table("particles"), case)
    parts_f = states.body_forces(r.contact, r.particles, case)
    pd.testing.assert_frame_equal(parts_f, frame_of(parts_a), check_exact=True)
    from_a = states.trim(states.from_particles(parts_a, case))
    from_f = states.trim(states.from_particles(parts_f, case))
    assert isinstance(from_a, dict) and isinstance(from_f, pd.DataFrame)
    pd.testing.assert_frame_equal(from_f, frame_of(from_a), check_exact=True)


def test_a_result_pickles_without_its_frames(results):
    r = results[("cases/oblique-viscous-sliding-pair.toml", "adaptive")]
    r.contact  # noqa: B018 - build the frame
    back = pickle.loads(pickle.dumps(r))
    assert "_contact_frame" not in back.__dict__
    pd.testing.assert_frame_equal(back.contact, r.contact, check_exact=True)
    assert _same(back.metrics(), r.metrics())
