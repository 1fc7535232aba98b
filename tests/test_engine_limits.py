"""What an engine itself refuses is checked before any work (engines.base.Engine.native_limits): LIGGGHTS stops on a
coefficientRestitution outside 0.05 < e <= 1 — in a case's [engine.liggghts] table, and as the input calibrate
would confirm. A confirming run that fails keeps what the twin found in the report."""

from __future__ import annotations

import pytest

from demcheck.engines import run as runner

from .helpers import cli_main
from .test_native import _case, to_toml


LIGGGHTS = {"pair_style": "gran model hertz tangential history"}


@pytest.fixture
def no_engine(monkeypatch):
    monkeypatch.setattr(runner, "run", lambda *a, **k: pytest.fail("an engine started"))


@pytest.mark.parametrize("e", ["0.01", "0.05"])  # (0, 1] is the deck reader's own rule
def test_a_native_restitution_liggghts_refuses_is_one_line_before_any_run(tmp_path, capsys, no_engine, e):
    path = tmp_path / "c.toml"
    path.write_text(to_toml(_case({"liggghts": {**LIGGGHTS, "coefficientRestitution": e}})))
    for argv in (["collide", path, "--engine", "liggghts"], ["deck", path, "--engine", "liggghts"],
                 ["verify", path, "--engines", "liggghts", "--report", tmp_path / "r"]):
        code, _, err = cli_main(argv, capsys)
        assert code == 2 and err.strip().count("\n") == 0, err
        assert f"engine.liggghts.coefficientRestitution = {float(e)}: must be in (0.05, 1]" in err, err
    assert not (tmp_path / "r").exists()


def test_calibrate_to_a_restitution_liggghts_cannot_take_is_refused_before_any_engine_run(tmp_path, capsys,
                                                                                        no_engine):
    path = tmp_path / "c.toml"
    path.write_text(to_toml(_case({"liggghts": LIGGGHTS})))
    code, _, err = cli_main(["calibrate", path, "--engine", "liggghts", "--target", "restitution=0.01"], capsys)
    assert code == 2 and err.strip().count("\n") == 0 and "out of reach" in err and "[0.05, 1]" in err, err


def test_a_failed_confirming_run_keeps_what_the_twin_found(tmp_path, capsys, monkeypatch):
    from demcheck.comparisons import calibrate
    from demcheck.result import Result

    def failing(case, engine, dt, native, cache=None):
        return Result(source=engine, method="engine", case_name=case.name, case_hash=case.hash, model={}, contact=None,
                      params={}, status="failed", message="lammps wrote NaN")

    monkeypatch.setattr(calibrate, "confirm_task", failing)
    path = tmp_path / "c.toml"
    path.write_text(to_toml(_case({"lammps": {"pair_coeff": "hertz/material 63e9 0.6 0.24 damping tsuji "
                                                            "tangential mindlin NULL 1.0 0.5"}})))
    code, out, err = cli_main(["calibrate", path, "--engine", "lammps", "--target", "restitution=0.5"], capsys)
    assert code == 1, err
    assert "damping tsuji e" in out and "paste:" in out and "NOT CONFIRMED: the confirming lammps run is failed" in out


def test_a_target_given_twice_is_refused_not_overwritten(tmp_path, capsys, no_engine):
    path = tmp_path / "c.toml"
    path.write_text(to_toml(_case({"liggghts": LIGGGHTS})))
    code, _, err = cli_main(["calibrate", path, "--engine", "liggghts", "--target", "restitution=0.5",
                          "--target", "restitution=0.6"], capsys)
    assert code == 2 and "--target = 'restitution=0.6': restitution is given twice" in err, err


@pytest.mark.engine("lammps")
def test_the_calibrated_line_pasted_back_realises_the_target_in_collide_as_it_runs(tmp_path):
    """calibrate works at the step collide runs the case's native setting at (its own step), so the line pasted
    back into the case realises the target in `demcheck collide` with no --dt (it was calibrated at the seed
    model's step, and only `collide --dt <calibrate's dt>` realised it)."""
    import demcheck
    from demcheck.comparisons.calibrate import ROOT_TOL

    from .test_native import TSUJI

    r = demcheck.calibrate(_case({"lammps": {"pair_coeff": TSUJI}}), "lammps", {"restitution": 0.6})
    assert r["confirmed"] is True
    line = r["lines"][0].removeprefix("pair_coeff * * ")
    again = demcheck.collide(_case({"lammps": {"pair_coeff": line}}), source="lammps")
    assert again.dt == r["dt"] and abs(again.metrics()["restitution"] - 0.6) <= ROOT_TOL
