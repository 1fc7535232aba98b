"""comparisons/sources.py: a Source is the reference (a method), an engine build or a twin, with one run(case, dt)
and one plan(case, engines); its label is rendered and parsed in one place."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import pytest

from demcheck.case import expand, load
from demcheck.comparisons import sources as S
from demcheck.engines import registry
from demcheck.errors import ConfigError

from .conftest import CASES

SRC = Path(__file__).resolve().parents[1] / "src" / "demcheck"


def test_every_label_parses_back_to_its_source_and_pickles_as_it():
    labels = ["reference", "reference-adaptive", "reference-verlet"]
    labels += [n for n in registry.names()] + [f"{n}-twin" for n in registry.names()]
    for label in labels:
        src = S.Source.parse(label)
        assert src.label == label and str(src) == label
        assert pickle.loads(pickle.dumps(src)) == src
    assert S.Source.parse("lammps-twin").kind == S.TWIN and S.Source.parse("lammps-twin").name == "lammps"
    assert S.Source.parse("lammps").twin() == S.Source.parse("lammps-twin")
    assert S.Source.parse("lammps").engine is registry.get("lammps")  # the Engine object itself


@pytest.mark.parametrize("label", ["nosuch", "nosuch-twin", "twin", "", "reference-euler"])
def test_an_unknown_label_is_a_config_error_naming_the_key(label):
    with pytest.raises(ConfigError, match="^--engine = ") as exc:
        S.Source.parse(label, "--engine")
    assert "must be reference, an engine" in str(exc.value)


def test_a_method_label_is_refused_where_the_reference_takes_its_method_apart():
    with pytest.raises(ConfigError, match="reference-verlet"):
        S.Source.parse("reference-verlet", "--engine", methods=False)


def test_the_reference_source_runs_its_method():
    case = load(CASES / "hertz-wall.toml")
    r = S.VERLET.run(case)
    assert (r.source, r.method) == ("reference", "verlet") and r.ok
    a = S.ADAPTIVE.run(case, rtol=1e-6)
    assert a.method == "adaptive" and a.rtol == 1e-6


def test_the_twin_runs_the_engines_formula_at_the_case_step():
    case = load(CASES / "hertz-wall.toml")
    twin = S.Source.parse("lammps-twin").run(case)
    assert twin.source == "lammps-twin" and twin.ok
    from demcheck.case import run_length

    assert twin.dt == run_length(case)[0]  # no dt, no native setting: the case's own step


def test_plan_says_which_engines_can_run_a_case_and_why_not():
    case = expand(CASES / "suite" / "oblique-sliding.toml")[0]
    found = {e: {"found": e != "lammps", "why": "lammps is not usable here", "how_to_install": "pip"}
             for e in registry.names()}
    plan = {p.source.label: p for p in S.plan(case, ("lammps", "yade", "liggghts"), found)}
    assert list(plan) == ["lammps", "yade", "liggghts"]  # the order asked
    assert (plan["lammps"].status, plan["lammps"].why) == (S.MISSING, "lammps is not usable here")
    assert plan["yade"].status == S.NOT_EXPRESSIBLE and plan["yade"].why == "; ".join(plan["yade"].mapping.reasons)
    assert plan["liggghts"].runs and plan["liggghts"].mapping.native is not None
    # an engine object is taken as it is
    assert S.plan(case, [registry.get("yade")], found)[0].status == S.NOT_EXPRESSIBLE


def test_run_a_source_and_parse_a_label_exist_once():
    """No layer above the engines parses a source label by hand or looks an engine up by name to run it: the
    label's suffix lives in sources.py alone, and the five "run this source" sites go through Source.run."""
    pattern = re.compile(r"removesuffix\(\"-twin\"\)|endswith\(\"-twin\"\)|partition\(\"-twin\"\)|"
                         r"removesuffix\('-twin'\)")
    above = [f for f in SRC.rglob("*.py") if f.parts[-2] in ("comparisons", "demcheck") or f.name in ("api.py", "cli.py")]
    offenders = [str(f.relative_to(SRC)) for f in above if pattern.search(f.read_text())]
    assert offenders == []
    runners = re.compile(r"\btwin_states\(|\bcollide as run_engine\b")
    for name in ("api.py", "cli.py", "comparisons/sweep.py", "comparisons/bench.py", "comparisons/stress.py",
                 "comparisons/suite.py"):
        assert not runners.search((SRC / name).read_text()), name


def test_a_native_step_too_fine_names_what_set_it_not_dt():
    """Issue 32: an error named --dt when none was given (the step came from the case's native setting)."""
    import demcheck
    from demcheck.engines.collide import setting_deck

    from .test_native import TSUJI, _case

    raw = _case({"lammps": {"pair_coeff": TSUJI.replace("63e9", "63e18")}})  # a native law 10^9 times stiffer
    raw["impact"]["gap"] = 1e-12
    case = demcheck.load(raw)
    for run in (lambda: S.Source.parse("lammps").run(case), lambda: setting_deck(case, "lammps")):
        with pytest.raises(ConfigError) as exc:
            run()
        assert exc.value.key == "run.steps_per_contact" and "[engine.lammps]" in exc.value.rule, exc.value
        assert "--dt" not in str(exc.value).split(":")[0]
    with pytest.raises(ConfigError, match="^--dt = 9e-12"):  # a step given is named as given
        S.Source.parse("lammps").run(case, 9e-12)
