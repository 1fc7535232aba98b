"""demcheck calibrate: the native input that realises a target in an engine at its dt (Brent's method on the
twin, confirmed by one engine run)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import demcheck
from demcheck.comparisons.calibrate import ROOT_TOL
from demcheck.errors import ConfigError

from .test_native import TSUJI, _case, to_toml, tsuji_restitution

ROOT = Path(__file__).resolve().parents[1]


def test_tsuji_twin_calibration_inverts_the_law():
    # the twin's root: an input e below 0.6 (tsuji realises more than it is given), realising 0.6 to the root
    # tolerance; independently, the input's converged realised e lies near 0.6 too (the time step's error apart)
    r = demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), "lammps", {"restitution": 0.6}, confirm=False)
    e = r["inputs"]["restitution"]
    assert e["from"] == 0.6 and e["to"] < 0.6 and abs(e["twin"] - 0.6) <= ROOT_TOL
    # (at the step collide runs the native law at, its own t_c / 200: the step's error is 6.2e-4 there)
    assert abs(tsuji_restitution(e["to"]) - 0.6) < 1e-3
    assert "damping tsuji" in r["lines"][0] and r["lines"][0].startswith("pair_coeff * * hertz/material")
    assert r["confirmed"] is None


@pytest.mark.engine("lammps")
def test_lammps_tsuji_calibration_is_confirmed_by_the_engine(tmp_path):
    f = tmp_path / "tsuji.toml"
    f.write_text(to_toml(_case({"lammps": {"pair_coeff": TSUJI}})))
    p = subprocess.run([sys.executable, "-m", "demcheck", "calibrate", str(f), "--engine", "lammps", "--target",
                        "restitution=0.6", "--json"], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    import json

    r = json.loads(p.stdout)
    e = r["inputs"]["restitution"]
    assert e["to"] < 0.6 and abs(e["engine"] - 0.6) <= ROOT_TOL and r["confirmed"] is True
    # the pasted line, read back as a case's native setting, realises the target in the engine
    line = r["lines"][0].removeprefix("pair_coeff * * ")
    again = demcheck.collide(_case({"lammps": {"pair_coeff": line}}), source="lammps", dt=r["dt"])
    assert abs(again.metrics()["restitution"] - 0.6) <= ROOT_TOL


def test_liggghts_limitforce_calibration_lowers_the_input():
    case = _case({"liggghts": {"pair_style": "gran model hertz tangential history limitForce on"}})
    r = demcheck.calibrate(case, "liggghts", {"restitution": 0.6}, confirm=False)
    e = r["inputs"]["restitution"]
    assert e["to"] < 0.6 and abs(e["twin"] - 0.6) <= ROOT_TOL
    assert any(x.startswith("fix m_restitution all property/global coefficientRestitution") for x in r["lines"])


@pytest.mark.parametrize("engine, targets, key", [
    ("lammps", {"restitution": 1.5}, "targets.restitution"),
    ("lammps", {"restitution": "0.6"}, "targets.restitution"),
    ("lammps", {"restitutio": 0.6}, "targets"),
    ("lammps", {}, "targets"),
    ("lammpz", {"restitution": 0.6}, "engine"),
    ("lammps", {"tangential_restitution": 0.3}, "targets.tangential_restitution"),
])
def test_bad_calibration_input_is_one_config_error_naming_the_apis_argument(engine, targets, key):
    """An API caller sees the API's argument names (``targets``, ``engine``), never the command line's options."""
    with pytest.raises(ConfigError) as err:
        demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), engine, targets, confirm=False)
    assert err.value.key == key, str(err.value)
    assert "--" not in str(err.value).split(" = ")[0]


def test_an_unreachable_target_names_the_apis_argument_and_the_commands_option(tmp_path):
    """The same refusal from the API (``targets.restitution``) and the command line (``--target restitution``)."""
    with pytest.raises(ConfigError) as err:
        demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), "lammps", {"restitution": 0.05}, confirm=False)
    assert err.value.key == "targets.restitution" and "out of reach" in err.value.rule
    with pytest.raises(ConfigError, match=r"^dt = -1\.0"):
        demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), "lammps", {"restitution": 0.6}, dt=-1.0)
    f = tmp_path / "c.toml"
    f.write_text(to_toml(_case({"lammps": {"pair_coeff": TSUJI}})))
    p = subprocess.run([sys.executable, "-m", "demcheck", "calibrate", str(f), "--engine", "lammps", "--target",
                        "restitution=0.05", "--no-confirm"], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 2 and p.stderr.strip().count("\n") == 0, p.stderr
    assert "--target restitution = 0.05: out of reach" in p.stderr, p.stderr


def test_an_unreachable_target_says_so():
    # an input e in [0.001, 1] of tsuji realises at least about 0.4 at a wall: 0.05 is out of reach
    with pytest.raises(ConfigError) as err:
        demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), "lammps", {"restitution": 0.05}, confirm=False)
    assert "out of reach" in err.value.rule


def test_cli_bad_target_exits_2_before_any_work(tmp_path):
    p = subprocess.run([sys.executable, "-m", "demcheck", "calibrate", "cases/glass-pair.toml", "--engine", "lammps",
                        "--target", "restitution"], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 2 and "--target" in p.stderr and p.stderr.strip().count("\n") == 0


def test_a_scenario_case_is_refused_before_any_run():
    """The twin and the confirming run are Source.run's (comparisons/sources.py), which solves a scenario beyond
    sliding as that scenario: a restitution target is an impact's, so a scenario case is one ConfigError."""
    from demcheck.case import expand

    from .conftest import CASES

    case = expand(CASES / "suite" / "beyond-rolling.toml")[0]
    with pytest.raises(ConfigError) as err:
        demcheck.calibrate(case, "lammps", {"restitution": 0.6}, confirm=False)
    assert (err.value.key, err.value.value) == ("run.scenario", "rolling") and "collision" in err.value.rule
