"""Results that must never pass (issue 12): every source's health, the engine-run cache's damage, runaway
records, and diagnostics that name their cause.

* one health function (reference/health.py) for the reference's verlet method and every engine: finite
  state, enough steps inside the contact, no energy created, overlap below half the smaller radius (the
  same overlap rule as the adaptive method's), the bodies separate;
* a non-finite engine value is never "agree" or "differs as expected";
* NaN/inf engine output is a failed run and never cached; a damaged cache entry is a logged miss, replaced;
* a verlet run that would record without bound is refused before it allocates (exit 2, the key named);
* an adaptive step never jumps over a contact; a run that never touched says so; a coarse step is named.
"""

from __future__ import annotations

import json
import logging
import math
import os
import re
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pandas as pd
import pytest

from demcheck import case as C
from demcheck.comparisons import verdicts as V
from demcheck.engines import discovery
from demcheck.engines.cache import Cache
from demcheck.engines.collide import META_KEYS as COLLIDE_META
from demcheck.reference import health as H
from demcheck.reference.collision import characteristic_time, collide
from demcheck.laws.model import resolve
from demcheck.result import Result

from .conftest import CASES
from .helpers import glass_case, oblique_case

R = 1.59e-3  # the glass spheres' radius (tests/helpers.py)


# ----------------------------------------------------------------------------- the health function


def _result(t, delta, rate, fn=None, dt=1e-6, m_eff=1.0, v=1.0):
    t = np.asarray(t, float)
    c = pd.DataFrame({"t": t, "delta": delta, "delta_dot": rate,
                      "fn": np.zeros_like(t) if fn is None else fn})
    return Result(source="x", method="engine", case_name="t", case_hash="h", model={}, params={"m_eff": m_eff,
                  "impact_speed": v}, contact=c, dt=dt)


def _bounce(n_inside=20, v_out=0.9, d_max=1e-5, n_after=2):
    """A sampled contact: approach at 1 m/s, a half sine of overlap d_max over n_inside steps, rebound at
    v_out; the energy balance is ½ m̄ (1 − v_out²) by construction."""
    k = np.arange(n_inside)
    delta = np.concatenate([[-1e-6], d_max * np.sin(np.pi * (k + 0.5) / n_inside), -1e-6 * np.arange(1, n_after + 1)])
    rate = np.concatenate([[1.0], np.linspace(1.0, -v_out, n_inside), np.full(n_after, -v_out)])
    return _result(np.arange(len(delta)) * 1e-6, delta, rate)


def test_a_healthy_sampled_contact_is_ok():
    assert H.health(_bounce(), t_c=20e-6, radius=R) == ("ok", "")


def test_too_few_steps_inside_the_contact_is_unresolved_and_names_the_step():
    status, why = H.health(_bounce(n_inside=3), t_c=3e-6, radius=R)
    assert status == "unresolved" and "dt = 1e-06 s" in why and "3 steps per elastic contact time" in why


def test_energy_created_is_unstable():
    # rebound at 1.2 m/s from 1 m/s: 44 % of the impact energy created
    status, why = H.health(_bounce(v_out=1.2), t_c=20e-6, radius=R)
    assert status == "unstable" and "created 0.44 of the impact energy" in why


def test_a_law_that_creates_energy_itself_is_not_called_unstable():
    # the same 44 % gain from a law that can create energy (a spring capped with its history left alone)
    assert H.health(_bounce(v_out=1.2), t_c=20e-6, radius=R, passive=False) == ("ok", "")


def test_a_capped_spring_with_its_history_left_alone_creates_energy_in_every_method():
    """Chung & Ooi Test 5 (steel, e 1, v_t/(μ v_n) 2.5) with the seed's TTIt (min() cap, history untruncated):
    the contact point's slip reverses while the history is far past the cap, so the capped force points along
    the new slip. The converged adaptive answer (rtol 1e-13) creates 6 % of the impact energy — the law's, not a
    scheme's —, the verlet method at 200 steps per contact the same to 0.3 % of it, and the time-stepped run is
    not called unstable for it; with Maw's truncation (the history kept on the cap) the same impact creates none."""
    from demcheck.reference.collision3d import collide as collide3d
    from demcheck.reference.health import impact_scales

    cases = C.expand(CASES / "benchmarks" / "chung-ooi-5-steel-tti.toml")
    case = next(c for c in cases if list(c.particles[0].velocity) == [3.75, 0.0, -5.0])
    model = resolve(case)
    assert not model.tangential_law.passive
    e_in = impact_scales(case, model)["impact_energy"]
    adaptive = collide3d(case, model, "adaptive")
    verlet = collide3d(case, model, "verlet")
    gain_a = -adaptive.metrics()["energy_dissipated"] / e_in
    gain_v = -verlet.metrics()["energy_dissipated"] / e_in
    assert 0.06 < gain_a < 0.07 and abs(gain_v - gain_a) < 0.003
    assert H.check(verlet, case, model) == ("ok", "")
    overlap = next(c for c in C.expand(CASES / "benchmarks" / "chung-ooi-5-steel-tti-overlap.toml")
                   if list(c.particles[0].velocity) == [3.75, 0.0, -5.0])
    m2 = resolve(overlap)
    assert m2.tangential_law.passive
    assert -collide3d(overlap, m2, "adaptive").metrics()["energy_dissipated"] <= 1e-9 * e_in


def test_an_overlap_beyond_half_the_radius_is_out_of_range():
    deep = _bounce(d_max=0.6 * R)
    status, why = H.health(deep, t_c=20e-6, radius=R)
    assert status == "out-of-range"
    assert _reported_ratio(why) == pytest.approx(deep.contact["delta"].max() / R, rel=1e-3)  # 0.598: sampled
    assert H.health(_bounce(d_max=0.4 * R), t_c=20e-6, radius=R)[0] == "ok"


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_state_is_a_failed_run(bad):
    r = _bounce()
    r.contact.loc[7, "delta_dot"] = bad
    status, why = H.health(r, t_c=20e-6, radius=R)
    assert status == "failed" and "NaN or infinite at t = 7e-06 s" in why


def test_a_contact_that_does_not_end_is_no_separation():
    status, why = H.health(_bounce(n_after=0), t_c=20e-6, radius=R)
    assert status == "no-separation"


def test_never_touching_is_no_contact_unless_the_step_is_the_cause():
    miss = _result([0.0, 1e-6, 2e-6], [-3e-6, -2e-6, -1e-6], [1.0, 1.0, 1.0])
    assert H.health(miss, t_c=20e-6, radius=R)[0] == "no-contact"
    status, why = H.health(miss, t_c=1e-9, radius=R)  # dt = 1000 contact times
    assert status == "unresolved" and "0.001 steps per elastic contact time" in why


# ----------------------------------------------------------------------------- the adaptive method's range


def _hertz_max_overlap(case) -> float:
    """Elastic Hertz: δ_max = (15 m̄ v² / (16 Ē √R̄))^(2/5) (closed form, independent of the solvers)."""
    p = resolve(case).pair
    return (15 * p.m_eff * p.impact_speed**2 / (16 * p.e_eff * math.sqrt(p.r_eff))) ** 0.4


def _reported_ratio(message: str) -> float:
    return float(re.search(r"overlap reached ([0-9.e+-]+) of the smaller radius", message).group(1))


@pytest.mark.parametrize("overrides,radii", [
    (["impact.speed=1e4"], 3.2),  # 10 km/s
    (["materials.glass.youngs_modulus=1.0"], 44.5),  # 1 Pa
])
def test_the_adaptive_method_refuses_overlaps_beyond_the_model(glass_pair, overrides, radii):
    """The ratio reported is the elastic closed form's to within the glass's weak damping (e = 0.97)."""
    case = C.load(glass_pair, overrides)
    assert _hertz_max_overlap(case) / R == pytest.approx(radii, rel=0.01)  # the case is what it claims
    for method in ("adaptive", "verlet"):
        r = collide(case, method)
        assert r.status == "out-of-range", (method, r.status, r.message)
        assert _reported_ratio(r.message) == pytest.approx(radii, rel=0.05) and "range" in r.message
    assert collide(C.load(glass_pair)).status == "ok"


def test_the_overlap_rule_takes_the_smaller_radius():
    """A 0.2 mm sphere on a 3 mm one at 2.4 km/s: the overlap is ~1.2 of the small radius but 0.08 of the
    large one; the rule reads it against the small radius, for both methods."""
    text = textwrap.dedent("""
        name = "ratio"
        [materials.glass]
        density = 2500.0
        youngs_modulus = 71e9
        poisson_ratio = 0.22
        restitution = 0.97
        [[particles]]
        material = "glass"
        radius = 2e-4
        [[particles]]
        material = "glass"
        radius = 3e-3
        [impact]
        speed = 2400.0
        [contact]
        normal = "hertz"
        """)
    case = C.loads(text)
    assert 0.5 * 2e-4 < _hertz_max_overlap(case) < 0.5 * 3e-3
    for method in ("adaptive", "verlet"):
        r = collide(case, method)
        assert r.status == "out-of-range"
        assert _reported_ratio(r.message) == pytest.approx(_hertz_max_overlap(case) / 2e-4, rel=0.05)


# ----------------------------------------------------------------------------- verdicts never pass a broken value

SCALES = {"impact_energy": 1e-5, "spin": 600.0}
RULE = V.ExpectedDifference(engine="lammps", versions=("*",), reason="documented")


def _judge(value, twin, expected=(RULE,), **kw):
    return V.judge_engine("lammps", "22 Jul 2025", {"normal": "hertz"}, "restitution", value, 0.8, twin, 0.8,
                          "exact", [], SCALES, V.Tolerances(), list(expected), **kw)


@pytest.mark.parametrize("value", [math.nan, math.inf])
@pytest.mark.parametrize("expected", [(RULE,), ()], ids=["with-rule", "no-rule"])
def test_a_non_finite_engine_value_is_failed_never_expected(value, expected):
    c = _judge(value, 0.8, expected)
    assert c.verdict == V.FAILED and "not finite" in c.reason


def test_a_non_finite_twin_cannot_confirm_an_engine_value():
    assert _judge(0.8, math.nan).verdict == V.FAILED


def test_a_broken_engine_run_is_failed_whatever_its_values():
    c = _judge(314.5, 314.5, status="unresolved", message="only 1 steps inside the contact")
    assert c.verdict == V.FAILED and c.reason == "unresolved: only 1 steps inside the contact"
    assert _judge(0.8, 0.8).verdict == V.AGREE  # the same values from a healthy run agree


# ----------------------------------------------------------------------------- engines: health and NaN output


def _engine_marks(engine):
    return pytest.param(engine, marks=pytest.mark.engine(engine))


@pytest.mark.parametrize("engine", [_engine_marks("lammps"), _engine_marks("liggghts")])
def test_an_engine_run_at_a_coarse_step_is_unresolved(engine, glass_pair):
    """dt = 3e-5 s is 0.32 of the glass pair's elastic contact time (9.5 µs): one step inside the contact,
    a 'restitution' of 314."""
    from demcheck.engines.collide import collide as run_engine

    case = C.load(glass_pair)
    assert characteristic_time(resolve(case)) / 3e-5 < 1
    r = run_engine(case, engine, dt=3e-5)
    assert r.status == "unresolved" and not r.ok
    assert "dt = 3e-05 s" in r.message and "steps inside the contact" in r.message


@pytest.mark.engine("lammps")
def test_cli_collide_reports_an_unhealthy_engine_run_and_exits_1(glass_pair, tmp_path):
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(glass_pair), "--engine", "lammps",
                        "--dt", "3e-5"], capture_output=True, text=True, env=env)
    assert p.returncode == 1
    assert "demcheck: lammps: unresolved: only 1 steps inside the contact" in p.stderr


FAKE = """#!{python}
# LAMMPS, with {bad!r} written over the vx column of the dump's later blocks (an engine whose output
# turned NaN)
import pathlib, subprocess, sys
rc = subprocess.call([{real!r}] + sys.argv[1:])
p = pathlib.Path("dump.txt")
if p.exists():
    lines = p.read_text().splitlines(True)
    col = None
    for i, line in enumerate(lines):
        if line.startswith("ITEM: ATOMS"):
            col = line.split()[2:].index("vx")
        elif col is not None and i > len(lines) // 2 and not line.startswith("ITEM") and len(line.split()) > col + 1:
            parts = line.split()
            parts[col] = {bad!r}
            lines[i] = " ".join(parts) + "\\n"
    p.write_text("".join(lines))
sys.exit(rc)
"""


@pytest.fixture(params=["nan", "-inf"])
def nan_lammps(request, tmp_path, monkeypatch):
    real = discovery.find("lammps")
    if real is None:
        pytest.skip("lammps not installed")
    exe = tmp_path / "fake-lmp"
    exe.write_text(FAKE.format(python=sys.executable, real=real.executable, bad=request.param))
    exe.chmod(0o755)
    monkeypatch.setenv("DEMCHECK_LAMMPS", str(exe))
    discovery.find.cache_clear()
    yield exe
    discovery.find.cache_clear()


@pytest.mark.engine("lammps")
def test_non_finite_engine_output_is_a_failed_run_never_cached(nan_lammps, tmp_path, monkeypatch):
    from demcheck.engines.collide import collide as run_engine

    case = glass_case("hertz", {})
    cache = Cache(tmp_path / "cache")
    r = run_engine(case, "lammps", cache=cache)
    assert r.status == "failed" and "NaN or infinite" in r.message
    assert not list((tmp_path / "cache").rglob("*.npz"))  # never cached
    # the real engine afterwards: a miss, then a healthy run that is cached
    monkeypatch.delenv("DEMCHECK_LAMMPS")
    discovery.find.cache_clear()
    ok = run_engine(case, "lammps", cache=cache)
    assert ok.status == "ok" and not ok.meta["cached"] and math.isfinite(ok.metrics()["restitution"])
    assert run_engine(case, "lammps", cache=cache).meta["cached"]


@pytest.mark.engine("lammps")
def test_cli_collide_with_non_finite_engine_output_exits_1(nan_lammps, glass_pair, tmp_path):
    env = dict(os.environ, DEMCHECK_LAMMPS=str(nan_lammps), DEMCHECK_CACHE=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(glass_pair), "--engine", "lammps"],
                       capture_output=True, text=True, env=env)
    assert p.returncode == 1 and "demcheck: lammps: failed:" in p.stderr and "NaN or infinite" in p.stderr


# ----------------------------------------------------------------------------- the engine-run cache

META = {"version": "v", "workdir": "/w", "wall_time": 1.0, "warnings": []}
COLUMNS = ("step", "id", "x")
# what an engine collision asks of an entry (engines/collide.py): its columns, its metadata's keys and types, rows
GET = dict(columns=COLUMNS, meta_keys=COLLIDE_META, min_rows=1)


def _table():
    return pd.DataFrame({"step": [0, 0, 1, 1], "id": [1, 2, 1, 2], "x": [0.0, 1.0, 0.5, 1.5]})


def _entry(cache, k="ab" * 32):
    cache.put(k, _table(), META)
    return k, cache._path(k)


def _rewrite_meta(path, meta):
    with np.load(path) as z:
        cols, data = z["columns"], z["data"]
    with open(path, "wb") as fh:
        np.savez(fh, columns=cols, data=data, meta=np.array(json.dumps(meta)))


DAMAGE = {
    "truncated": lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]),
    "changed-bytes": lambda p: p.write_bytes(_flip(p.read_bytes())),
    "zero-bytes": lambda p: p.write_bytes(b""),
    "not-a-zip": lambda p: p.write_text("hello"),
    "meta-without-keys": lambda p: _rewrite_meta(p, {"version": "v"}),
    "meta-not-an-object": lambda p: _rewrite_meta(p, [1, 2]),
    "non-finite": lambda p: _put_raw(p, pd.DataFrame({"step": [0], "id": [1], "x": [math.nan]})),
    "missing-column": lambda p: _put_raw(p, pd.DataFrame({"step": [0], "id": [1]})),
    # metadata of the wrong type (once a TypeError in collide: Path(None))
    "meta-workdir-null": lambda p: _rewrite_meta(p, {**META, "workdir": None}),
    "meta-version-a-number": lambda p: _rewrite_meta(p, {**META, "version": 5}),
    "meta-wall-time-a-string": lambda p: _rewrite_meta(p, {**META, "wall_time": "1.0"}),
    "meta-wall-time-nan": lambda p: _rewrite_meta(p, {**META, "wall_time": math.nan}),
    "meta-wall-time-true": lambda p: _rewrite_meta(p, {**META, "wall_time": True}),
    "meta-warnings-a-string": lambda p: _rewrite_meta(p, {**META, "warnings": "w"}),
    "meta-warnings-not-strings": lambda p: _rewrite_meta(p, {**META, "warnings": [1]}),
    # a table without rows (once a silent hit)
    "zero-rows": lambda p: _put_raw(p, _table().iloc[:0]),
}


def _flip(b: bytes) -> bytes:
    """Change 8 bytes of the stored data array (past the member's name and its 128-byte .npy header): a
    Bad CRC-32 on reading."""
    start = b.index(b"\x93NUMPY", b.index(b"data.npy")) + 128 + 8
    return b[:start] + bytes(x ^ 0xFF for x in b[start:start + 8]) + b[start + 8:]


def _put_raw(path, table):
    with open(path, "wb") as fh:
        np.savez(fh, columns=np.array(list(table.columns)), data=table.to_numpy(dtype=float),
                 meta=np.array(json.dumps(META)))


def test_the_damage_is_what_it_claims(tmp_path):
    """The damaged files raise what the issue reports when read directly (so the cache test could fail)."""
    k, path = _entry(Cache(tmp_path))
    DAMAGE["changed-bytes"](path)
    with pytest.raises(zipfile.BadZipFile, match="Bad CRC-32"):
        with np.load(path) as z:
            z["data"]
    DAMAGE["zero-bytes"](path)
    with pytest.raises(EOFError):
        np.load(path)


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_a_damaged_entry_is_a_logged_miss_and_is_replaced(tmp_path, caplog, damage):
    cache = Cache(tmp_path)
    k, path = _entry(cache)
    DAMAGE[damage](path)
    with caplog.at_level(logging.WARNING, logger="demcheck.cache"):
        assert cache.get(k, **GET) is None
        assert cache.get(k, **GET) is None
    logged = [r for r in caplog.records if r.name == "demcheck.cache"]
    assert len(logged) == 1 and str(path) in logged[0].getMessage() and "\n" not in logged[0].getMessage()
    assert cache.misses == 2 and cache.hits == 0
    cache.put(k, _table(), META)
    table, meta = cache.get(k, **GET)
    assert table.equals(_table()) and meta == META


def test_a_healthy_entry_round_trips(tmp_path):
    cache = Cache(tmp_path)
    k, _ = _entry(cache)
    table, meta = cache.get(k, **GET)
    assert table.equals(_table()) and table["id"].dtype == np.int64 and meta == META and cache.hits == 1


def test_an_entry_failing_the_callers_own_check_is_a_logged_miss(tmp_path, caplog):
    """The caller's check of what it reads (an engine collision: a row for every body) makes a miss of an entry
    that loads but cannot be its run."""
    cache = Cache(tmp_path)
    k, path = _entry(cache)
    one_body = lambda table, meta: None if set(table["id"]) == {1, 2} else "not every body"  # noqa: E731
    _put_raw(path, _table()[_table()["id"] == 1])
    with caplog.at_level(logging.WARNING, logger="demcheck.cache"):
        assert cache.get(k, **GET, check=one_body) is None
    assert "not every body" in caplog.records[-1].getMessage() and cache.misses == 1
    cache.put(k, _table(), META)
    assert cache.get(k, **GET, check=one_body)[0].equals(_table())


def _shard_a_file(cache, k):
    path = cache._path(k)
    if path.parent.exists():
        path.unlink(missing_ok=True)
        path.parent.rmdir()
    path.parent.parent.mkdir(parents=True, exist_ok=True)
    path.parent.write_text("a file where the shard directory goes")


def _entry_a_directory(cache, k):
    path = cache._path(k)
    path.unlink(missing_ok=True)
    (path / "inside").mkdir(parents=True)


def _cache_a_file(cache, k):
    import shutil

    shutil.rmtree(cache.dir, ignore_errors=True)
    cache.dir.write_text("a file where the cache directory goes")


PUT_DAMAGE = {"shard-a-file": _shard_a_file, "entry-a-directory": _entry_a_directory, "cache-a-file": _cache_a_file}


@pytest.mark.parametrize("damage", list(PUT_DAMAGE))
def test_a_put_that_cannot_write_logs_once_and_goes_on(tmp_path, caplog, damage):
    """A file where a directory goes, a directory where the entry goes: once FileExistsError / IsADirectoryError
    out of Cache.put. The result is not cached, one line says so, and nothing is raised."""
    cache = Cache(tmp_path / "cache")
    k = "ab" * 32
    PUT_DAMAGE[damage](cache, k)
    with caplog.at_level(logging.WARNING, logger="demcheck.cache"):
        assert cache.put(k, _table(), META) is False
        assert cache.put(k, _table(), META) is False
        assert cache.get(k, **GET) is None
    logged = [r.getMessage() for r in caplog.records if r.name == "demcheck.cache"]
    not_cached = [m for m in logged if "not cached" in m]
    assert len(not_cached) == 1 and str(cache._path(k)) in not_cached[0] and "\n" not in not_cached[0], logged
    assert len(logged) == 1, logged
    assert not list(tmp_path.rglob("*.tmp")), "no temporary file left behind"


def test_the_cache_never_stores_non_finite_tables(tmp_path):
    cache = Cache(tmp_path)
    bad = pd.DataFrame({"step": [0], "id": [1], "x": [math.inf]})
    assert cache.put("cd" * 32, bad, META) is False
    assert not list(tmp_path.rglob("*.npz"))


def test_refresh_never_reads_and_writes_over(tmp_path):
    k, path = _entry(Cache(tmp_path))
    fresh = Cache(tmp_path, refresh=True)
    assert fresh.get(k) is None and fresh.misses == 1
    newer = _table().assign(x=[9.0, 9.0, 9.0, 9.0])
    fresh.put(k, newer, META)
    assert Cache(tmp_path).get(k)[0].equals(newer)


def _rows_of(path, query):
    """Rewrite a real entry keeping its columns and metadata and only the rows of ``query``."""
    with np.load(path) as z:
        cols, data, meta = [str(c) for c in z["columns"]], z["data"], z["meta"]
    kept = pd.DataFrame(data, columns=cols).query(query)
    with open(path, "wb") as fh:
        np.savez(fh, columns=np.array(cols), data=kept.to_numpy(dtype=float), meta=meta)


ENGINE_DAMAGE = {"zero-rows": lambda p: _rows_of(p, "id < 0"), "one-body-only": lambda p: _rows_of(p, "id == 1")}


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("damage", ["truncated", "zero-bytes", "meta-without-keys", "meta-workdir-null",
                                    "meta-wall-time-a-string", "zero-rows", "one-body-only"])
def test_an_engine_run_over_a_damaged_entry_runs_again_and_replaces_it(tmp_path, damage, caplog):
    from demcheck.engines.collide import collide as run_engine

    case = glass_case("hertz", {})
    first = run_engine(case, "lammps", cache=Cache(tmp_path))
    (path,) = tmp_path.rglob("*.npz")
    ENGINE_DAMAGE.get(damage, DAMAGE.get(damage))(path)
    with caplog.at_level(logging.WARNING, logger="demcheck.cache"):
        again = run_engine(case, "lammps", cache=Cache(tmp_path))
    assert again.status == "ok" and not again.meta["cached"]
    assert again.metrics()["restitution"] == first.metrics()["restitution"]
    assert len([r for r in caplog.records if str(path) in r.getMessage()]) == 1
    assert run_engine(case, "lammps", cache=Cache(tmp_path)).meta["cached"]


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("damage", list(PUT_DAMAGE))
def test_an_engine_run_whose_entry_cannot_be_written_keeps_its_result(tmp_path, damage, caplog):
    from demcheck.engines.cache import key
    from demcheck.engines.collide import collide as run_engine, deck, run_identity

    case = glass_case("hertz", {})
    cache = Cache(tmp_path / "cache")
    dk = deck(case, "lammps")  # the deck collide runs: the seed model's mapping (no native setting)
    # its entry's key: the deck's commands (run_identity), as collide keys a run
    PUT_DAMAGE[damage](cache, key("lammps", discovery.find("lammps").version, *run_identity(dk)))
    first = run_engine(case, "lammps")
    with caplog.at_level(logging.WARNING, logger="demcheck.cache"):
        res = run_engine(case, "lammps", cache=cache)
    assert res.status == "ok" and not res.meta["cached"]
    assert res.metrics() == first.metrics()
    assert len([r for r in caplog.records if "not cached" in r.getMessage()]) == 1
    assert not run_engine(case, "lammps", cache=Cache(tmp_path / "cache")).meta["cached"]


# ----------------------------------------------------------------------------- runaway records


def _limited(args, gib=4, module=("-m", "demcheck")):
    """Run demcheck (or a script) with its address space bounded: a missing refusal then fails here (a
    MemoryError), not the machine."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (gib << 30, gib << 30))

    return subprocess.run([sys.executable, *module, *args], capture_output=True, text=True, timeout=300,
                          preexec_fn=limit)


FAR = """
import dataclasses, sys
from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference.collision import collide

case = C.load(sys.argv[1], ["impact.speed=1e-9"])
# the bodies put back on their straight paths by S = {shift} s of flight, whatever the case loader did with the
# free flight: the solver must refuse on its own
S = {shift}
parts = tuple(dataclasses.replace(p, position=tuple(x - S * v for x, v in zip(p.position, p.velocity)))
              for p in case.particles)
try:
    collide(dataclasses.replace(case, particles=parts), "verlet")
except ConfigError as exc:
    print(f"{{exc.key}}|{{exc}}")
"""


@pytest.mark.parametrize("path", [CASES / "glass-pair.toml", CASES / "oblique-lsd-wall.toml"], ids=["1d", "3d"])
def test_a_verlet_run_that_would_record_without_bound_is_refused(path):
    """1e-9 m/s over 800 s of free flight: ~3e8 steps of the auto dt (3e-6 s), refused before allocating."""
    p = _limited([str(path)], module=("-c", FAR.format(shift=800.0)))
    assert p.returncode == 0, p.stderr[-2000:]
    key, message = p.stdout.strip().split("|", 1)
    assert key == "impact.speed" and "free flight to contact takes" in message and "\n" not in message


@pytest.mark.parametrize("method", ["adaptive", "verlet"])
@pytest.mark.parametrize("path", [CASES / "glass-pair.toml", CASES / "oblique-lsd-wall.toml"], ids=["1d", "3d"])
def test_tiny_impact_speeds_run_or_say_why_in_one_line(path, method):
    """demcheck collide at 1e-9 m/s, both methods, in bounded memory: a run (status ok, exit 0), a status
    with its reason (exit 1) or a refusal (exit 2), each one line — never a MemoryError or a traceback."""
    p = _limited(["collide", str(path), "--method", method, "--set", "impact.speed=1e-9", "--json"])
    lines = p.stderr.strip().splitlines()
    if p.returncode == 0:
        assert json.loads(p.stdout)["status"] == "ok"
    elif p.returncode == 1:
        status = json.loads(p.stdout)["status"]
        assert lines == [f"demcheck: reference: {status}: {json.loads(p.stdout)['message']}"], p.stderr[-2000:]
    else:
        assert p.returncode == 2 and len(lines) == 1 and lines[0].startswith("demcheck: error: "), p.stderr[-2000:]


def test_the_adaptive_3d_method_at_a_tiny_speed_names_its_tolerance():
    """Oblique LSD at a wall at 1e-9 m/s: the overlap scale is ~1e-11 of the positions; at rtol = 1e-13 the
    points run out and the message says to raise run.rtol; at 1e-10 the answer is LSD's input restitution
    (0.9, speed-independent for the linear law), to the looser tolerance's accuracy."""
    case = C.load(CASES / "oblique-lsd-wall.toml", ["impact.speed=1e-9"])
    r = collide(case)
    assert r.status == "too-many-steps" and "raise run.rtol" in r.message and "round-off" in r.message
    loose = collide(C.load(CASES / "oblique-lsd-wall.toml", ["impact.speed=1e-9", "run.rtol=1e-10"]))
    assert loose.status == "ok" and loose.metrics()["restitution"] == pytest.approx(0.9, abs=1e-4)


def test_a_time_step_that_would_record_without_bound_is_refused(glass_pair):
    p = _limited(["collide", str(glass_pair), "--method", "verlet", "--dt", "1e-14"])
    assert p.returncode == 2, p.stderr[-2000:]
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("demcheck: error: --dt = 1e-14:")
    assert "steps per elastic contact time" in lines[0]


# ----------------------------------------------------------------------------- diagnostics that name their cause


def test_an_adaptive_step_never_jumps_over_a_graze():
    """Two glass spheres passing at 89.99°: the surfaces overlap while the line of relative motion is inside
    D = R0 + R1, for 2 D cos θ / v ≈ 1.1 µs (the force-free pass-by; the forces are weak: δ ~ 5e-11 m)."""
    case = C.load(CASES / "oblique-viscous-sliding-pair.toml", ["impact.angle=89.99"])
    r = collide(case)
    assert r.status == "ok", r.message
    assert {"contact_start", "contact_end"} <= set(r.events["event"])
    geometric = 2 * (2 * R) * math.cos(math.radians(89.99)) / 1.0
    assert r.metrics()["contact_time"] == pytest.approx(geometric, rel=0.1)


@pytest.mark.parametrize("eps", [1e-7, 1e-9])
@pytest.mark.parametrize("tangential", [None, "sliding"], ids=["1d", "3d"])
def test_a_touch_at_the_top_of_a_throw_is_found(tangential, eps):
    """A sphere thrown at 0.1 m/s towards a wall against gravity (g pointing away from it) from
    v²/2g − ε: the free flight reaches an overlap ε at its turning point, a touch of ~2√(2ε/g) (29 µs for
    1e-9 m) that a growing free-flight step jumped over. It starts where the free flight's quadratic says:
    t = 2 gap / (v + √(v² − 2 g gap))."""
    import dataclasses

    v, g = 0.1, 9.81
    gap = v * v / (2 * g) - eps
    over = [f"run.gravity=[0.0, 0.0, {g}]"]
    case = (glass_case("hertz", {}, wall=True, speed=v, overrides=over) if tangential is None else
            oblique_case(tangential, {}, normal="hertz", normal_params={}, wall=True, speed=v, angle=0.0,
                         overrides=over))
    # the gap set on the loaded case (the wall is z = 0 with normal +z): the solver's answer, whatever the
    # case loader's policy on long free flights
    p0 = case.particles[0]
    case = dataclasses.replace(case, particles=(dataclasses.replace(p0, position=(0.0, 0.0, p0.radius + gap)),))
    r = collide(case)
    assert r.status == "ok", r.message
    start = r.events[r.events["event"] == "contact_start"]["t"].to_numpy()
    assert start.size == 1 and start[0] == pytest.approx(2 * gap / (v + math.sqrt(v * v - 2 * g * gap)), rel=1e-9)
    assert r.metrics()["restitution"] > 0


@pytest.mark.parametrize("solver", ["1d", "3d"])
def test_an_adaptive_run_that_ends_before_any_touch_is_no_contact(solver):
    """The kernels' own status when the run ends in free flight (a t_max shorter than the free flight):
    'the bodies never touched', not 'the contact did not end'."""
    from demcheck.reference import adaptive3d, collision3d, kernels
    from demcheck.reference.collision import STATUS

    case = glass_case("hertz", {}, wall=True)  # 1.59 µs of free flight at 1 m/s
    model = resolve(case)
    t_c, t_max = characteristic_time(model), 1e-7
    if solver == "1d":
        out = kernels.adaptive_normal(model.normal_law.array(), model.pair.m_eff, 0.0, -1.59e-6, 1.0, 1e-10, t_c,
                                      t_c, 1.0, t_max, 1000)
    else:
        rules = collision3d.rules_array()
        out = adaptive3d.adaptive_3d(collision3d.initial_state(case), model.normal_law.array(),
                             model.tangential_law.array(), collision3d.geometry(case, t_c), rules, 1e-10,
                             np.full(21, 1e-3), t_max, 1000)
    assert STATUS[out[0]] == "no-contact"


@pytest.mark.parametrize("path", [CASES / "glass-pair.toml", CASES / "hertz-wall.toml"])
def test_a_time_step_beyond_the_contact_is_named_as_the_cause(path):
    """E = 1e300 Pa: the elastic contact time is ~1e-66 s, dt = 1e-3 s; whatever the run saw, the step is
    the cause."""
    case = C.load(path, ["materials.glass.youngs_modulus=1e300"])
    r = collide(case, "verlet", dt=1e-3)
    assert r.status == "unresolved"
    assert "dt = 0.001 s" in r.message and "steps per elastic contact time" in r.message


@pytest.mark.engine("lammps")
def test_non_finite_packing_output_is_a_failed_run_never_cached(tmp_path, monkeypatch):
    """A packing whose final state holds NaN fails (it would otherwise drop out of every finite-only
    comparison and pass), and nothing of it is cached."""
    from demcheck import case as C
    from demcheck.errors import EngineFailed
    from demcheck.engines.packing import run_engine

    real = discovery.find("lammps")
    exe = tmp_path / "fake-lmp"
    exe.write_text(FAKE.format(python=sys.executable, real=real.executable, bad="nan")
                   .replace('pathlib.Path("dump.txt")', 'pathlib.Path("final.txt")'))
    exe.chmod(0o755)
    monkeypatch.setenv("DEMCHECK_LAMMPS", str(exe))
    discovery.find.cache_clear()
    try:
        case = C.load(CASES / "packing" / "column-lsd.toml")
        with pytest.raises(EngineFailed, match="NaN or infinite values .*column vx"):
            run_engine(case, "lammps", cache=Cache(tmp_path / "cache"))
        assert not list((tmp_path / "cache").rglob("*.npz"))
    finally:
        monkeypatch.delenv("DEMCHECK_LAMMPS")
        discovery.find.cache_clear()


@pytest.mark.engine("lammps")
def test_a_contact_that_outlasts_the_step_bound_is_no_separation_and_not_cached(tmp_path, monkeypatch):
    """The engine collide reruns a contact that has not ended four times longer; when the longer run would
    pass the step bound it stops there (never a bad-input error after an engine has run), and the unhealthy
    result is not cached."""
    import dataclasses

    from demcheck.engines import collide as EC
    from demcheck.errors import ConfigError

    real = EC.deck

    def short_then_bounded(case, engine, dt=None, length=1.0, native=None, **options):
        if length > 1.0:
            raise ConfigError("run.steps_per_contact", 20000, "the run would take too many steps")
        dk = real(case, engine, dt, length, native=native, **options)
        steps = int(re.search(r"^run (\d+)$", dk.text, re.M).group(1))
        return dataclasses.replace(dk, text=dk.text.replace(f"\nrun {steps}\n", f"\nrun {steps // 10}\n"))

    monkeypatch.setattr(EC, "deck", short_then_bounded)
    cache = Cache(tmp_path / "cache")
    res = EC.collide(glass_case("hertz", {}), "lammps", cache=cache)
    assert res.status == "no-separation", res.message
    assert not list((tmp_path / "cache").rglob("*.npz"))  # an unhealthy run is never cached


def test_the_energy_rule_reads_the_impact_energy_only_when_it_could_fail():
    """health.rules: the impact energy is at least its floor (½ m̄ v²), so a collision that created no more than
    ENERGY_GAIN_TOLERANCE of the floor passes without computing it; one that created more is judged on it."""
    from demcheck.reference import health

    read = (-1, 50, 1e-6, -1e-7, 1e-4, float("nan"))  # resolved, touched, in range, separated

    def never():
        raise AssertionError("the impact energy was read")

    args = (read, 1e-7, 1e-5, 1e-3, 5)
    assert health.rules(*args, never, True, lambda: 0.009, floor=1.0) == ("ok", "")
    assert health.rules(*args, never, True, lambda: -1.0, floor=0.0) == ("ok", "")
    assert health.rules(*args, never, False, lambda: 5.0, floor=1.0) == ("ok", "")  # not passive: no rule
    assert health.rules(*args, lambda: 2.0, True, lambda: 0.019, floor=1.0) == ("ok", "")  # 0.95 % of 2
    status, why = health.rules(*args, lambda: 1.5, True, lambda: 0.02, floor=1.0)
    assert status == "unstable" and why.startswith("the collision created 0.0133 of the impact energy")
