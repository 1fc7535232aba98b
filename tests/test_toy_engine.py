"""A third engine from outside demcheck's source (tests/toy_engine, registered through
DEMCHECK_ENGINE_PLUGINS) runs in `collide --engine`, `verify` and `models` with no edit anywhere else."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from .conftest import CASES, ROOT


def _demcheck(*args, tmp_path):
    # this source tree's demcheck (src) and its tests' toy engine (the root), not an installed demcheck
    env = dict(os.environ, DEMCHECK_ENGINE_PLUGINS="tests.toy_engine", PYTHONPATH=f"{ROOT}:{ROOT / 'src'}",
               DEMCHECK_CACHE=str(tmp_path / "cache"))
    return subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=600)


def test_models_lists_the_plugged_in_engine(tmp_path):
    p = _demcheck("models", "--json", tmp_path=tmp_path)
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)["models"]
    seed = [r for r in rows if r["slot"] in ("normal", "tangential")]  # the seed models: the toy runs every one
    assert seed and all(r["engines"]["toy"]["fidelity"] == "exact" for r in seed)
    # the laws beyond sliding are listed for every engine, the plug-in included: it writes no scenario deck
    beyond = [r for r in rows if r["slot"] not in ("normal", "tangential")]
    assert beyond and all(r["engines"]["toy"]["fidelity"] == "none" for r in beyond)
    assert all("deck is written" in r["engines"]["toy"]["reason"] or "no scenario runs it" in
               r["engines"]["toy"]["reason"] for r in beyond)


@pytest.mark.parametrize("case", ["glass-pair.toml", "oblique-lsd-wall.toml"])
def test_collide_runs_the_plugged_in_engine(case, tmp_path):
    p = _demcheck("collide", str(CASES / case), "--engine", "toy", "--json", tmp_path=tmp_path)
    assert p.returncode == 0, p.stderr
    toy = json.loads(p.stdout)
    assert toy["source"] == "toy" and toy["status"] == "ok" and toy["engine_version"] == "1.0"
    ref = json.loads(_demcheck("collide", str(CASES / case), "--method", "verlet", "--dt", repr(toy["dt"]),
                               "--json", tmp_path=tmp_path).stdout)
    # the toy engine is the reference verlet method: the same numbers, read back through a dump (%.17g)
    for k in ("restitution", "contact_time", "max_overlap", "peak_force"):
        assert toy["metrics"][k] == pytest.approx(ref["metrics"][k], rel=1e-9), k


def test_verify_judges_the_plugged_in_engine(tmp_path):
    p = _demcheck("verify", str(CASES / "glass-pair.toml"), "--engines", "toy", "--report", str(tmp_path / "r"),
                  "--json", tmp_path=tmp_path)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    case = out["cases"][0]
    assert case["sources"]["toy"]["status"] == "ok"
    toy = [c for c in case["comparisons"] if c["source"] == "toy"]
    assert toy and all(c["verdict"] == "agree" for c in toy)
    assert "toy" in (tmp_path / "r" / "latest" / "report.md").read_text()


def test_a_plug_in_that_cannot_be_imported_is_one_line(tmp_path):
    env = dict(os.environ, DEMCHECK_ENGINE_PLUGINS="tests.no_such_engine", PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-m", "demcheck", "models"], capture_output=True, text=True, env=env,
                       cwd=tmp_path, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "DEMCHECK_ENGINE_PLUGINS" in p.stderr
