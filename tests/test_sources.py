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


def test_the_seed_model_at_an_engines_step_is_read_off_its_states_as_an_engines_run_is():
    """``restated``: the suite's seed verlet run at an engine's step — the two-body kernel, its contact table read
    off the bodies' states (engines.states.restate), not the reference's own (1-D) run of the case."""
    from pandas.testing import assert_frame_equal

    from demcheck.engines import states
    from demcheck.laws.model import characteristic_time, resolve
    from demcheck.reference import collision3d

    case = load(CASES / "hertz-wall.toml")
    dt = characteristic_time(resolve(case)) / 37
    got = S.VERLET.run(case, dt, restated=True)
    want = states.restate(collision3d.collide(case, resolve(case), "verlet", dt=dt), case)
    assert got.ok and got.dt == dt
    assert_frame_equal(got.contact, want.contact)
    assert got.metrics() == want.metrics()


def test_the_reference_solves_a_model_given_by_the_two_body_kernel():
    """``model``: the audit's seed run and its converged answer of a deck's law — the reference solving that model
    (the seed's, or an engine's twin model) by the two-body kernel with the seed's rules, not restated, not the
    case's own (1-D) solve and not the case's seed model."""
    from pandas.testing import assert_frame_equal

    from demcheck.engines.mapping import contact_mapping, twin_model
    from demcheck.laws.model import resolve
    from demcheck.reference import collision3d

    import demcheck

    from .test_native import TSUJI, _case

    case = demcheck.load(_case({"lammps": {"pair_coeff": TSUJI}}, angle=30.0))  # tsuji damping: not the seed's e
    native = S.Source.parse("lammps").native(case)
    twin = twin_model(resolve(case), contact_mapping(case, "lammps", native).require())
    got = S.ADAPTIVE.run(case, model=twin)
    want = collision3d.collide(case, twin, "adaptive")
    assert got.ok and got.method == "adaptive"
    assert_frame_equal(got.contact, want.contact)
    assert got.metrics() == want.metrics()
    seed = S.ADAPTIVE.run(case, model=resolve(case))
    assert seed.metrics() == collision3d.collide(case, resolve(case), "adaptive").metrics()
    assert seed.metrics()["restitution"] != got.metrics()["restitution"]  # another law: another answer
    with pytest.raises(TypeError, match="model= is the reference's"):  # never silently ignored
        S.Source.parse("lammps-twin").run(case, model=twin)
    head_on = load(CASES / "hertz-wall.toml")  # a 1-D case: the case's own solve is the 1-D kernel's
    assert S.ADAPTIVE.run(head_on, model=resolve(head_on)).metrics() == \
        collision3d.collide(head_on, resolve(head_on), "adaptive").metrics()


def test_a_twins_converged_answer_is_its_adaptive_solve_with_the_engines_rules():
    """``converged``: the twin solved by the adaptive method with the engine's kinematic rules (bench's and the
    native commands' "converged" answer); a twin with a force history has none and runs its scheme at ``dt``,
    saying why."""
    from demcheck.engines.collide import twin_states
    from demcheck.engines.mapping import contact_mapping

    from demcheck.laws.model import characteristic_time, resolve

    case = expand(CASES / "suite" / "oblique-viscous.toml")[0]
    nat = contact_mapping(case, "lammps").require()
    dt = characteristic_time(resolve(case)) / 20
    conv = S.Source.parse("lammps-twin").run(case, dt, native=nat, converged=True)
    assert conv.method == "adaptive" and conv.ok and "no_adaptive" not in conv.meta
    assert conv.source == "lammps-twin"
    verlet = twin_states(case, "lammps", dt, native=nat)  # the twin at that step: another answer
    assert verlet.metrics()["restitution"] != conv.metrics()["restitution"]


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


# a source run by hand: a twin (twin_states, a twin's kernel), the two-body kernel, an engine's or the reference's
# collide (imported, or under another name), a scenario's solve, run or twin
RUNNERS = re.compile(
    r"\btwin_states\b|\.twin_collide\(|\bcollision3d\.collide\(|\bcollide as \w+"
    r"|from \.+(?:engines\.collide|reference\.collision|reference\.collision3d) import (?:\([^)]*\)|[^\n]*)\bcollide\b"
    r"|from \.+reference\.scenarios import (?:\([^)]*\)|[^\n]*)\bsolve\b|\bscenario\.(?:run|twin)\("
    r"|\bimport scenario as \w+")
# modules that still run a source by hand, and why (each one a known exception, not a place the check skips)
KNOWN = {
    "comparisons/warmup.py": "compiles the reference's kernels: it runs no source for a result",
}


def _runs_a_source_by_hand(root: Path) -> dict:
    """Each module of comparisons/ (but sources.py), api.py and cli.py under ``root`` that runs a source by hand:
    what it runs."""
    files = sorted((root / "comparisons").rglob("*.py")) + [root / "api.py", root / "cli.py"]
    out = {}
    for f in files:
        name = f.relative_to(root).as_posix()
        hits = [m.group(0) for m in RUNNERS.finditer(f.read_text())]
        if hits and name != "comparisons/sources.py":
            out[name] = hits
    return out


def test_run_a_source_and_parse_a_label_exist_once():
    """No layer above the engines parses a source label by hand or looks an engine up by name to run it: the
    label's suffix lives in sources.py alone, and every module of comparisons/, api.py and cli.py runs a source
    through Source.run (but the KNOWN ones, each with its reason)."""
    pattern = re.compile(r"removesuffix\(\"-twin\"\)|endswith\(\"-twin\"\)|partition\(\"-twin\"\)|"
                         r"removesuffix\('-twin'\)")
    above = [f for f in SRC.rglob("*.py") if f.parts[-2] in ("comparisons", "demcheck") or f.name in ("api.py", "cli.py")]
    offenders = [str(f.relative_to(SRC)) for f in above if pattern.search(f.read_text())]
    assert offenders == []
    by_hand = _runs_a_source_by_hand(SRC)
    assert set(by_hand) - set(KNOWN) == set(), by_hand
    assert set(KNOWN) <= set(by_hand), "a known exception that no longer runs a source by hand: drop it"


def test_the_static_check_sees_each_way_of_running_a_source_by_hand(tmp_path):
    """The check above fails on each way a module ran a source before issue 29's step (45ceacd): validate.py's
    engine run under another name and its reference's collide, calibrate.py's twin_states and engine collide,
    bench.py's twin kernel and two-body kernel, suite.py's seed verlet, scenario_rows.py's scenario run."""
    lines = {
        "validate": "    from ..engines.collide import collide as run_engine\n",
        "validate_ref": "    from ..reference.collision import collide\n",
        "calibrate": "from ..engines.collide import collide, setting, twin_states\n",
        "calibrate_twin": "    v = twin_states(case, engine, step, native=knob.set(x))\n",
        "bench": "    conv = states.restate(engine.twin_collide(case, model, native, dt), case)\n",
        "suite": "    states.restate(collision3d.collide(case, model, \"verlet\", dt=res.dt), case)\n",
        "stress": "from ..reference.collision import characteristic_time, collide\n",
        "scenario_rows": "    res = scenario.run(case, src.engine, timeout=opts.timeout, cache=opts.cache)\n",
        "solve": "    from ..reference.scenarios import solve\n",
        "alias": "    from ..engines import scenario as sc\n",
    }
    (tmp_path / "comparisons").mkdir()
    for name in ("api.py", "cli.py", "comparisons/sources.py"):
        (tmp_path / name).write_text("from ..engines.collide import collide, twin_states\n")  # sources.py may
    for name, line in lines.items():
        (tmp_path / "comparisons" / f"{name}.py").write_text(line)
    assert set(_runs_a_source_by_hand(tmp_path)) == {f"comparisons/{n}.py" for n in lines} | {"api.py", "cli.py"}
    (tmp_path / "comparisons" / "fine.py").write_text("from ..reference.collision import characteristic_time\n"
                                                      "from ..reference.batch import collide_many\n"
                                                      "res = VERLET.run(case, dt, restated=True)\n")
    assert "comparisons/fine.py" not in _runs_a_source_by_hand(tmp_path)


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


def test_a_model_given_for_a_scenario_case_is_refused_not_ignored():
    """Source.run(model=…) solves a collision of that model; a scenario case runs its own laws, so a model given for
    one is an error (it was silently ignored)."""
    from demcheck.case import expand, load
    from demcheck.comparisons.sources import ADAPTIVE
    from demcheck.laws.model import resolve
    from demcheck.resources import case_path

    glass = resolve(load(case_path("glass-pair")))
    (first,) = sorted((Path(case_path("glass-pair")).parent / "suite").glob("beyond-*.toml"))[:1]
    scenario = next(iter(expand(first)))
    assert scenario is not None and scenario.run.scenario != "collision"
    with pytest.raises(TypeError, match="model= solves a collision"):
        ADAPTIVE.run(scenario, model=glass)
