"""Several builds of one engine in one run (engines/builds.py): parsing, discovery, cache keys, and a second
build of the toy engine side by side with the first in collide, verify and diff."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys

import pytest

from demcheck.engines import builds, cache, discovery, registry
from demcheck.errors import ConfigError

from .conftest import CASES, ROOT


def script(path, banner, then=""):
    path.write_text(f"#!/bin/sh\nif [ \"$1\" = -h ]; then echo '{banner}'; exit 0; fi\n{then}\n")
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


@pytest.mark.parametrize("spec,message", [
    ("lammps@", "must be ENGINE, ENGINE=PATH or ENGINE@LABEL=PATH"),
    ("lammps@old", "a labelled build needs its executable: lammps@old=PATH"),
    ("ansys@x=/bin/sh", "must be lammps, liggghts"),
    ("lammps@x=/no/such/lmp", "/no/such/lmp is not an executable file"),
    ("lammps@x=/bin/sh,lammps@x=/bin/sh", "names the source lammps@x twice"),
])
def test_bad_build_specs_name_the_rule(spec, message):
    with pytest.raises(ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")):
        builds.parse_list(spec)


def test_a_build_is_a_source_with_its_own_version_and_cache_key(tmp_path):
    exe = script(tmp_path / "lmp", "Large-scale Atomic/Molecular Massively Parallel Simulator - 2 Aug 2023")
    try:
        assert discovery.resolve(f"lammps,lammps@2023={exe}") == ["lammps", "lammps@2023"]
        info = discovery.find("lammps@2023")
        assert (info.name, info.executable, info.version) == ("lammps@2023", str(exe), "2 Aug 2023")
        assert builds.engine_of("lammps@2023") == "lammps" and registry.get("lammps@2023").rules == \
            registry.get("lammps").rules  # the engine's own vocabulary and scheme
        k = cache.key("lammps@2023", info.version, "deck", {})
        assert k != cache.key("lammps", info.version, "deck", {})  # the label is in the key
        assert k != cache.key("lammps@2023", "22 Jul 2025", "deck", {})  # so is the version
        os.utime(exe, ns=(1, 1))  # a rebuilt binary that prints the same version
        assert cache.key("lammps@2023", info.version, "deck", {}) != k
        # expected differences follow the build's own version
        from demcheck.comparisons import verdicts as V

        exp = builds.expected_for(V.load_expected(), ["lammps", "lammps@2023"])
        lam = [e for e in exp if e.engine == "lammps"]
        assert [e.versions for e in exp if e.engine == "lammps@2023"] == [e.versions for e in lam] and lam
    finally:
        discovery.drop("lammps@2023")
    assert "lammps@2023" not in registry.names()
    with pytest.raises(ValueError, match="unknown engine 'lammps@2023'"):
        discovery.find("lammps@2023")


def test_an_executable_that_is_not_the_engine_is_refused(tmp_path):
    exe = script(tmp_path / "lmp", "not a LAMMPS banner")
    with pytest.raises(ConfigError, match="is not a usable lammps build"):
        discovery.resolve(f"lammps@x={exe}")
    assert "lammps@x" not in registry.names()


def _demcheck(*args, tmp_path):
    # this source tree's demcheck (src) and its tests' toy engine (the root), not an installed demcheck
    env = dict(os.environ, DEMCHECK_ENGINE_PLUGINS="tests.toy_engine", PYTHONPATH=f"{ROOT}:{ROOT / 'src'}",
               DEMCHECK_CACHE=str(tmp_path / "cache"))
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=600)


def test_two_builds_of_the_toy_engine_side_by_side(tmp_path):
    """A second toy build (version 2.0, the same runner) beside the first: its own column with its version in
    collide and verify, its own cache entries, and diff finds nothing moved between the two builds."""
    toy2 = script(tmp_path / "toy2", "toy engine 2.0",
                  f"PYTHONPATH={ROOT}:{ROOT / 'src'} exec {sys.executable} -m tests.toy_engine.runner \"$@\"")
    p = _demcheck("collide", CASES / "hertz-wall.toml", "--engine", f"toy,toy@v2={toy2}", "--json", tmp_path=tmp_path)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert (out["toy"]["engine_version"], out["toy@v2"]["engine_version"]) == ("1.0", "2.0")
    assert out["toy@v2"]["source"] == "toy@v2" and out["toy@v2"]["metrics"] == out["toy"]["metrics"]
    p = _demcheck("verify", CASES / "hertz-wall.toml", "--engines", f"toy,toy@v2={toy2}", "--report", "r",
                  tmp_path=tmp_path)
    assert p.returncode == 0, p.stderr
    from .helpers import md_plain

    md = md_plain((tmp_path / "r" / "latest" / "report.md").read_text())  # the text as rendered (names escaped)
    assert "Engines: toy 1.0; toy@v2 2.0" in md and "| toy@v2: e · t · δ · F · E · et · ω |" in md
    res = json.loads((tmp_path / "r" / "latest" / "results.json").read_text())
    (case,) = res["cases"]
    assert {k["source"] for k in case["comparisons"]} >= {"toy", "toy@v2"}
    assert all(k["verdict"] == "agree" for k in case["comparisons"] if k["source"] == "toy@v2")
    assert res["cache"]["misses"] >= 2  # one run per build: the label and version are in the key
    p = _demcheck("diff", "r/latest", "r/latest", "--source", "toy=toy@v2", "--json", tmp_path=tmp_path)
    d = json.loads(p.stdout)
    assert p.returncode == 0 and d["regressions"] == 0 and not [r for r in d["rows"] if r["source"] == "toy@v2"]
    assert d["engines"]["toy@v2"] == {"old": "1.0", "new": "2.0"}



@pytest.mark.engine("lammps")
def test_bench_and_stress_run_a_second_build_too(tmp_path):
    """bench and stress read --engines as verify does: a build is a source of its own, with its version (here a
    second label for the same LAMMPS binary)."""
    exe = discovery.find("lammps").executable
    p = _demcheck("bench", CASES / "hertz-wall.toml", "--engines", f"lammps@again={exe}", "--steps", "50",
                  "--report", "r", "--json", tmp_path=tmp_path)
    assert p.returncode in (0, 1), p.stderr
    out = json.loads(p.stdout)
    assert "lammps@again 22 Jul 2025" in out["engines"]
    assert "lammps@again" in json.dumps(out["cases"])
    bad = _demcheck("stress", CASES / "hertz-wall.toml", "--engines", "lammps@x=/bin/true", "--report", "r",
                    tmp_path=tmp_path)
    assert bad.returncode == 2 and "is not a usable lammps build" in bad.stderr
