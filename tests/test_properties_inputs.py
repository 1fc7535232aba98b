"""Hostile numbers in every numeric key of a case file, through ``demcheck collide`` (in process, demcheck.cli.main):
0, subnormals, 1e±308, NaN, inf, negatives and whatever hypothesis draws. The command answers with exit 0, 1 or 2
only — bad input one line (exit 2), a run its health rules refuse a failure (exit 1) — never a traceback, and
never an "ok" verdict on a run whose numbers are not finite or whose contact never formed.

The CI profile (tests/conftest.py: derandomize, a fixed number of examples) makes the draw the same on every run."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re

import pytest
from hypothesis import given, note
from hypothesis import strategies as st

from demcheck import cli

from .conftest import CASES

HOSTILE = [0.0, -0.0, 5e-324, 2.2250738585072014e-308, 1e-308, 1e-300, 1e-200, 1e-100, 1e-30, 1e-9, -1.0,
           -1e308, 0.5, 1e4, 1e30, 1e100, 1e155, 1e200, 1e300, 1e308, 1.7976931348623157e308,
           math.nan, math.inf, -math.inf]
NUMBERS = st.one_of(st.sampled_from(HOSTILE), st.floats(allow_nan=True, allow_infinity=True),
                    st.integers(-(2**63), 2**63 - 1))

MATERIAL = ["density", "youngs_modulus", "poisson_ratio", "restitution", "friction", "friction_kinetic",
            "dissipative_constant", "tangential_restitution"]
IMPACT = ["speed", "angle", "gap", "spin"]
RUN = ["dt", "steps_per_contact", "rtol", "verlet_rtol"]

# (case file, the numeric keys it takes besides the materials', impact's and run's)
CASE_KEYS = {
    "hertz-wall.toml": ["particles.0.radius"],
    "glass-pair.toml": ["particles.0.radius", "particles.1.radius", "particles.1.position.0",
                        "particles.0.velocity.0", "particles.1.velocity.0"],
    "tti-pair.toml": ["particles.1.radius", "contact.eta_n", "contact.restitution"],
    "lsd-duration-wall.toml": ["contact.kn", "contact.eta_n", "contact.reference_velocity", "contact.restitution"],
    "hls-variable-wall.toml": ["contact.kl", "contact.S", "contact.restitution"],
    "oblique-lsd-wall.toml": ["contact.kt", "contact.eta_t", "contact.friction", "contact.tangential_restitution"],
    "oblique-walton-spin-wall.toml": ["contact.kt", "contact.friction_kinetic"],
    "kk-wall.toml": ["contact.eta_n", "run.gravity.2"],
}


def _keys(case: str) -> list[str]:
    impact = [] if case == "glass-pair.toml" else [f"impact.{k}" for k in IMPACT]
    return ([f"materials.glass.{k}" for k in MATERIAL] + impact + [f"run.{k}" for k in RUN] + CASE_KEYS[case])


def _toml(x) -> str:
    """A number as TOML writes it (nan, inf, -inf included)."""
    if isinstance(x, int):
        return str(x)
    return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf") if math.isinf(x) else repr(x)


def _vector_key(case: str, key: str, x) -> str:
    """``--set`` of one component of a vector key (particles.1.position.0 → the whole vector, that component x)."""
    import tomllib

    path, _, index = key.rpartition(".")
    raw = tomllib.loads((CASES / case).read_text())
    node = raw
    for part in path.split("."):
        node = node[int(part)] if isinstance(node, list) else node.get(part, {})
    vec = [_toml(v) for v in (node if isinstance(node, list) and len(node) == 3 else [0.0, 0.0, 0.0])]
    vec[int(index)] = _toml(x)
    return f"{path}=[{', '.join(vec)}]"


@st.composite
def hostile_cases(draw):
    case = draw(st.sampled_from(sorted(CASE_KEYS)))
    keys = draw(st.lists(st.sampled_from(_keys(case)), min_size=1, max_size=3, unique=True))
    sets = []
    for key in keys:
        x = draw(NUMBERS)
        sets.append(_vector_key(case, key, x) if key.rsplit(".", 1)[-1].isdigit() else f"{key}={_toml(x)}")
    method = draw(st.sampled_from(["adaptive", "verlet"]))
    return case, sets, method


def _run(argv: list[str]) -> tuple[int, str, str]:
    """demcheck's exit code, stdout and stderr, in this process (any exception but SystemExit propagates: a
    traceback fails the test)."""
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            cli.main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    return code, out.getvalue(), err.getvalue()


def _finite_ok(summary: dict) -> str | None:
    """What is wrong with an "ok" collision, or None: every metric it reports finite, a contact that formed."""
    m = summary["metrics"]
    if not (isinstance(m.get("max_overlap"), float) and m["max_overlap"] > 0):
        return f"max_overlap {m.get('max_overlap')!r}: the contact never formed"
    if not (isinstance(m.get("contact_time"), float) and m["contact_time"] > 0):
        return f"contact_time {m.get('contact_time')!r}"
    for k in ("restitution", "peak_force", "max_overlap", "contact_time", "energy_dissipated"):
        if not (isinstance(m.get(k), (int, float)) and math.isfinite(m[k])):
            return f"{k} = {m.get(k)!r}"
    return None


@given(hostile_cases())  # the profile's budget: tests/conftest.py (CI: derandomized, 40 examples)
def test_hostile_numbers_in_a_case_are_an_answer_never_a_traceback(args):
    case, sets, method = args
    argv = ["collide", str(CASES / case), "--method", method, "--json"]
    for s in sets:
        argv += ["--set", s]
    note(" ".join(argv))
    code, out, err = _run(argv)  # any exception but SystemExit fails the test here: a traceback
    assert code in (0, 1, 2), (code, err)
    assert "Traceback" not in err, err
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("demcheck: error: "), err
        return
    summary = json.loads(out)  # --json: one JSON object (strict: no NaN)
    if code == 0:
        assert summary["status"] == "ok"
        problem = _finite_ok(summary)
        assert problem is None, f"ok with {problem}"
    else:
        assert summary["status"] != "ok" and f"demcheck: reference: {summary['status']}:" in err, err


@pytest.mark.parametrize("sets", [
    ["impact.speed=1e155"],  # the issue's probe: v·v overflowed, the step bound let NaN through
    ["impact.speed=1e300"],
    ["impact.speed=5e-324"],
    ["impact.gap=1e300", "impact.speed=1e-300"],
    ["materials.glass.youngs_modulus=1e308", "impact.speed=1e308"],
    ["particles.0.radius=1e-300"],
    ["run.steps_per_contact=9223372036854775807"],
])
def test_the_issues_arithmetic_limits_are_one_line(sets):
    argv = ["collide", str(CASES / "hertz-wall.toml")]
    for s in sets:
        argv += ["--set", s]
    code, out, err = _run(argv)
    assert code == 2 and len(err.strip().splitlines()) == 1 and err.startswith("demcheck: error: "), (code, err)


NON_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.I)


@given(hostile_cases(), st.sampled_from(["lammps", "liggghts", "yade", "kratos"]))
def test_hostile_numbers_never_reach_an_engine_deck(args, engine):
    """The same numbers through ``demcheck deck``: a deck (exit 0) with only finite numbers in it, or one line
    (exit 2: bad input, or a model the engine cannot express) — never a traceback."""
    case, sets, _ = args
    argv = ["deck", str(CASES / case), "--engine", engine]
    for s in sets:
        argv += ["--set", s]
    note(" ".join(argv))
    code, out, err = _run(argv)
    assert code in (0, 2), (code, err)
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("demcheck: error: "), err
    else:
        assert not NON_FINITE.search(out), NON_FINITE.search(out).group(0)


@pytest.mark.parametrize("command", [["deck", "--engine", "lammps"], ["deck", "--engine", "liggghts"],
                                     ["collide", "--engine", "lammps"]])
def test_a_derived_coefficient_that_overflows_never_reaches_a_deck(command, monkeypatch):
    """Found by the property above: a 1e4 m sphere of E = 1e308 made LAMMPS's like-pair coefficient 4/3·Ē·√R̄
    inf, and the deck said `pair_coeff 2 2 hertz inf …`: refused, naming the case's most extreme number, before
    the deck is written or run."""
    from demcheck.engines import run as runner

    monkeypatch.setattr(runner, "run", lambda *a, **k: pytest.fail("an engine started"))
    argv = [command[0], str(CASES / "glass-pair.toml"), *command[1:], "--set", "particles.1.radius=1e4",
            "--set", "materials.glass.youngs_modulus=1e308"]
    code, out, err = _run(argv)
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert "materials.glass.youngs_modulus = 1e+308: makes the" in err and "not finite" in err and not out


def test_a_name_that_reads_nan_is_text_not_a_number():
    code, out, err = _run(["deck", str(CASES / "glass-pair.toml"), "--engine", "lammps", "--set", 'name="nan inf"'])
    assert code == 0 and "# case: nan inf" in out, err
