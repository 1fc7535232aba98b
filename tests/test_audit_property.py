"""Issue 32: any coefficient string given to `demcheck models --engine E "…"` or written into a deck's pair_coeff for
`demcheck audit` ends with exit 0, 1, 2 or 3 — a refusal as one line on stderr — never a traceback. Strings are drawn
from the settings' own words, numbers that are no numbers to LAMMPS, substitutions and quotes, and arbitrary text."""

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from demcheck import cli

WORDS = ["hertz/material", "hooke", "hertz", "dmt", "jkr", "mdr", "damping", "tsuji", "coeff_restitution",
         "viscoelastic", "velocity", "mass_velocity", "none", "tangential", "linear_nohistory", "linear_history",
         "mindlin", "mindlin/force", "mindlin_rescale", "NULL", "rolling", "sds", "twisting", "marshall",
         "limit_damping", "heat", "area", "synchronized_verlet", "cutoff", "gran/hooke", "gran/hooke/history",
         "gran/hertz/history", "model", "hertz", "tangential", "history", "no_history", "coefficientRestitution=0.6",
         "1e5", "0.5", "0.3", "63e9", "-1", "0", "1", "2", "1e400", "1e-400", "nan", "inf", "0x10", "1_000", "１",
         "${x}", "$(1/0)", "$x", '"', "'", '"""', "#", "&", "*", "* *", "1 1", "\t", "\x1b[2J"]
STRINGS = st.one_of(st.lists(st.sampled_from(WORDS), max_size=14).map(" ".join), st.text(max_size=80))


def _run(argv, capsys):
    try:
        cli.main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    out = capsys.readouterr()
    return code, out.out, out.err


def _check(code, err):
    assert code in (0, 1, 2, 3), (code, err)
    assert "Traceback" not in err
    if code == 2:
        assert len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("engine", ["lammps", "liggghts"])
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(setting=STRINGS)
def test_models_any_setting_string(engine, setting, capsys):
    code, out, err = _run(["models", "--engine", engine, "--", setting], capsys)  # "--": a setting may start with "-"
    _check(code, err)


@pytest.mark.engine("lammps")
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(setting=STRINGS)
def test_audit_any_pair_coeff_string(setting, tmp_path_factory, capsys):
    deck = tmp_path_factory.mktemp("p") / "in.deck"
    line = setting.replace("\r", " ").replace("\n", " ").replace("\x00", " ")
    deck.write_text("units si\natom_style sphere\ncomm_modify vel yes\nregion box block -0.01 0.01 -0.01 0.01 -0.01 "
                    "0.01 units box\ncreate_box 1 box\ncreate_atoms 1 single 0 0 0.002 units box\nset type 1 diameter "
                    "0.002 density 2500\nvelocity all set 0 0 -1\ntimestep 1e-7\npair_style granular\n"
                    f"pair_coeff * * {line}\n", encoding="utf-8")
    code, out, err = _run(["audit", str(deck)], capsys)
    _check(code, err)


# 0, subnormals, the float limits, NaN and inf as LAMMPS would read them, and ordinary values (issue 32's property)
HOSTILE_NUMBERS = ["0", "-0", "5e-324", "2.2250738585072014e-308", "1e-308", "1e-200", "1e-30", "1e-9", "-1", "0.5",
                   "1e4", "63e9", "1e30", "1e100", "1e155", "1e300", "1e308", "1.7976931348623157e308", "1e400",
                   "nan", "inf", "-inf"]
METRICS = ("restitution", "contact_time")


def _coefficient(ordinary: str):
    """Half the draws the coefficient's ordinary value (so that most settings get as far as the probes), half a
    hostile number."""
    return st.one_of(st.just(ordinary), st.sampled_from(HOSTILE_NUMBERS))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(young=_coefficient("63e9"), nu=_coefficient("0.24"), e=_coefficient("0.6"), mu=_coefficient("0.5"))
def test_models_never_calls_a_contact_that_was_not_computed_exact(young, nu, e, mu, capsys):
    """Hostile numbers in every coefficient of a LAMMPS Hertz setting: exit 0, 1 or 2 only, never a traceback, and
    a fidelity of "exact" or "approximate" only where every probe's twin and seed produced finite metrics (a contact
    that never formed, passed through or overflowed is a failure, never a gap of 0)."""
    import json

    setting = f"hertz/material {young} {e} {nu} damping tsuji tangential mindlin NULL 1.0 {mu}"
    code, out, err = _run(["models", "--engine", "lammps", "--json", "--", setting], capsys)
    assert code in (0, 1, 2), (setting, code, err)
    assert "Traceback" not in err
    if code == 2:
        assert len(err.strip().splitlines()) == 1, err
        return
    r = json.loads(out)
    if r["fidelity"] in ("exact", "approximate"):
        for p in r["probes"]:
            for side in ("twin", "seed"):
                for k in METRICS:
                    v = p[side][k]
                    assert v is not None and v == v and abs(v) != float("inf"), (setting, p["angle"], side, k, v)
