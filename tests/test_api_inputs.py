"""Every public function of the Python API checks every argument's type and range before any work: a wrong one
is a ConfigError naming the argument (docs/api.md), never a bare TypeError or ValueError from inside, and no
engine starts."""

from __future__ import annotations

import itertools
import math

import pytest

import demcheck
from demcheck.engines import run as runner
from demcheck.errors import ConfigError

CASE = "cases/hertz-wall.toml"
TARGETS = {"restitution": 0.5}

CALLS = [
    # sweep
    ("sweep vary value a number (the issue)", lambda: demcheck.sweep(CASE, vary={"impact.speed": 5}), "vary.impact.speed"),
    ("sweep vary value None", lambda: demcheck.sweep(CASE, vary={"impact.speed": None}), "vary.impact.speed"),
    ("sweep vary key a number", lambda: demcheck.sweep(CASE, vary={5: [1.0]}), "vary"),
    ("sweep vary an endless iterator", lambda: demcheck.sweep(CASE, vary={"impact.speed": itertools.count(1)}),
     "vary.impact.speed"),
    ("sweep dt True", lambda: demcheck.sweep(CASE, vary={"impact.speed": [1.0]}, dt=True), "dt"),
    # verify
    ("verify(42) (the issue)", lambda: demcheck.verify(42), "paths"),
    ("verify(None)", lambda: demcheck.verify(None), "paths"),
    ("verify([42])", lambda: demcheck.verify([42]), "paths"),
    ("verify engines a number", lambda: demcheck.verify(CASE, engines=5), "engines"),
    ("verify jobs text", lambda: demcheck.verify(CASE, engines="none", jobs="x"), "jobs"),
    ("verify jobs 0", lambda: demcheck.verify(CASE, engines="none", jobs=0), "jobs"),
    ("verify jobs 1.5", lambda: demcheck.verify(CASE, engines="none", jobs=1.5), "jobs"),
    ("verify timeout text", lambda: demcheck.verify(CASE, engines="none", timeout="x"), "timeout"),
    ("verify timeout NaN", lambda: demcheck.verify(CASE, engines="none", timeout=math.nan), "timeout"),
    ("verify report a number", lambda: demcheck.verify(CASE, engines="none", report=5), "report"),
    ("verify cache text", lambda: demcheck.verify(CASE, engines="none", cache="no"), "cache"),
    # collide, collide_many, load
    ("collide overrides a number (the issue)", lambda: demcheck.collide(CASE, overrides=5), "overrides"),
    ("collide overrides with a number key", lambda: demcheck.collide(CASE, overrides={5: 1}), "overrides"),
    ("collide method a number", lambda: demcheck.collide(CASE, method=5), "method"),
    ("collide dt True", lambda: demcheck.collide(CASE, dt=True), "dt"),
    ("collide timeout text", lambda: demcheck.collide(CASE, source="lammps", timeout="x"), "timeout"),
    ("collide timeout -1", lambda: demcheck.collide(CASE, source="lammps", timeout=-1), "timeout"),
    ("collide source a list", lambda: demcheck.collide(CASE, source=["lammps"]), "source"),
    ("collide_many a number", lambda: demcheck.collide_many(5), "cases"),
    ("load overrides a number", lambda: demcheck.load(CASE, overrides=5), "overrides"),
    ("load overrides bytes", lambda: demcheck.load(CASE, overrides=b"impact.speed=1"), "overrides"),
    ("load an empty key", lambda: demcheck.load(CASE, overrides={"": 1.0}), "(empty key)"),
    ("load a key with an empty part", lambda: demcheck.load(CASE, overrides={"impact..speed": 1.0}), "impact..speed"),
    # calibrate
    ("calibrate targets as text (the issue)", lambda: demcheck.calibrate(CASE, "lammps", "restitution=0.5"), "targets"),
    ("calibrate targets None", lambda: demcheck.calibrate(CASE, "lammps", None), "targets"),
    ("calibrate engine a number", lambda: demcheck.calibrate(CASE, 5, TARGETS), "engine"),
    ("calibrate confirm text", lambda: demcheck.calibrate(CASE, "lammps", TARGETS, confirm="no"), "confirm"),
    ("calibrate dt text", lambda: demcheck.calibrate(CASE, "lammps", TARGETS, dt="1e-7"), "dt"),
    # audit, packing_universe
    ("audit a number", lambda: demcheck.audit(5), "path"),
    ("audit engine a number", lambda: demcheck.audit("x.in", engine=5), "engine"),
    ("audit run_engine text", lambda: demcheck.audit("x.in", run_engine="no"), "run_engine"),
    ("audit speed True", lambda: demcheck.audit("x.in", speed=True), "speed"),
    ("packing_universe a number", lambda: demcheck.packing_universe(5), "path"),
    ("packing_universe no such path", lambda: demcheck.packing_universe("/nonexistent/run"), "path"),
]


@pytest.mark.parametrize("what, call, key", CALLS, ids=[c[0] for c in CALLS])
def test_a_wrong_argument_is_one_config_error_before_any_work(what, call, key, monkeypatch):
    monkeypatch.chdir(demcheck.__file__.rsplit("/src/", 1)[0] if "/src/" in demcheck.__file__ else ".")
    started = []
    monkeypatch.setattr(runner, "run", lambda *a, **k: started.append(a) or pytest.fail("an engine started"))
    with pytest.raises(ConfigError) as err:
        call()
    assert err.value.key == key, str(err.value)
    assert "\n" not in str(err.value) and not started


@pytest.mark.parametrize("make", ["file", "latest-dir"])
def test_a_report_directory_demcheck_cannot_use_is_refused_before_the_runs(tmp_path, make):
    """verify(report=…) where the report cannot be written was found only after every case ran."""
    report = tmp_path / "rep"
    if make == "file":
        report.write_text("x")
    else:
        (report / "latest").mkdir(parents=True)
    with pytest.raises(ConfigError) as err:
        demcheck.verify(CASE, engines="none", report=report)
    assert err.value.key == "report"
