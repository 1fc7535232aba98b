"""The input-language reader of `demcheck audit` (inputs/script.py): comments, continuations, quotes, variables
and substitution, include, control flow refused; nothing it reads is executed."""

import math

import pytest

from demcheck.inputs import script as S


def _read(tmp_path, text, name="in.deck"):
    p = tmp_path / name
    p.write_text(text)
    return S.read(p)


def test_comments_continuations_and_quotes(tmp_path):
    sc = _read(tmp_path, "# a comment\nunits si   # trailing\npair_style granular &\n  # not a comment here? &\n"
                         "timestep 1e-7\nprint 'a # b' \"c d\"\nprint \"\"\"x\n# y\n\"\"\"\n")
    words = [c.words for c in sc.commands]
    assert words[0] == ["units", "si"]
    # the '&' joins the next line; a '#' there starts a comment that runs to the end of the joined line — and a
    # comment that ends in '&' continues too, so LAMMPS never runs the timestep line (checked with lmp: a
    # `# comment &` line followed by `print "HIDDEN"` prints nothing)
    assert words[1] == ["pair_style", "granular"]
    assert words[2] == ["print", "a # b", "c d"]
    assert words[3] == ["print", "x\n# y\n"]
    assert [c.line for c in sc.commands] == [2, 3, 6, 7]


def test_variables_and_substitution(tmp_path):
    sc = _read(tmp_path, "variable E equal 63e9\nvariable nu equal 0.24\nvariable r index 1e-3 2e-3\n"
                         "variable r index 5\nvariable s string hertz/material\n"
                         "variable k equal 4/3*v_E/(2*(1-v_nu^2))\n"
                         "pair_coeff * * ${s} $E 0.6 ${nu} $(2*v_r) ${k} $(sqrt(4):%.3f)\n"
                         "print '${E}'\n")
    w = sc.commands[-2].words
    assert w[:4] == ["pair_coeff", "*", "*", "hertz/material"]
    assert float(w[4]) == 63e9 and float(w[6]) == 0.24
    assert float(w[7]) == 2e-3  # an index variable keeps its first definition
    # closed form: (4/3)·63e9/(2(1 − 0.24²)), to the 15 digits substitution writes
    assert float(w[8]) == pytest.approx(4 / 3 * 63e9 / (2 * (1 - 0.24**2)), rel=1e-14)
    assert w[9] == "2.000"
    # LAMMPS 22Jul2025 substitutes inside quotes too (checked with its library: `print '${E}'` prints 63000000000)
    assert sc.commands[-1].words == ["print", "63000000000"]


def test_unknown_variables_are_a_problem_not_a_guess(tmp_path):
    sc = _read(tmp_path, "variable t equal step*dt\nvariable a atom x\nfix 1 all print ${t}\nfix 2 all print $a\n")
    assert "not a number" in sc.commands[2].problem and "?" in sc.commands[2].words
    assert "not defined" in sc.commands[3].problem
    assert sc.unread and "atom" in sc.unread[0][1]


# 2^3^2 and -2^2 as LAMMPS 22Jul2025 evaluates them (its library's lammps_expand: 64 and 4 — left to right, a sign
# binding tighter than ^; tests/test_audit_engine_read.py compares the reader with the engine on more)
@pytest.mark.parametrize("expr,value", [("2^3^2", 64.0), ("-2^2", 4.0), ("(1+2)*3-4/8", 8.5),
                                        ("PI", math.pi), ("atan2(1,1)*4", math.pi), ("min(3,max(1,2))", 2.0),
                                        ("1e-3*2", 2e-3), (".5", 0.5)])
def test_evaluator(expr, value):
    assert S.evaluate(expr, {}) == pytest.approx(value, rel=1e-15)


@pytest.mark.parametrize("expr", ["__import__('os')", "1/0", "x", "step", "2 > 1", "(1", "1 2", "(-8)^(1/3)",
                                  "10^400"])
def test_evaluator_refuses(expr):
    with pytest.raises(S._Unevaluable):
        S.evaluate(expr, {})


def test_include_relative_and_confined(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "mat.in").write_text("variable E equal 7e10\n")
    sc = _read(tmp_path, "include sub/mat.in\ntimestep $E\n")
    assert sc.commands[-1].words[0] == "timestep" and float(sc.commands[-1].words[1]) == 7e10
    assert sc.commands[-1].file == "in.deck"
    (tmp_path / "outside.in").write_text("units si\n")
    inner = tmp_path / "sub" / "in.deck"
    inner.write_text("include ../outside.in\n")
    with pytest.raises(S.ScriptError, match="outside the deck's directory"):
        S.read(inner)


@pytest.mark.parametrize("line", ["jump SELF loop", "next a", "if \"${a} > 1\" then quit"])
def test_control_flow_is_refused(tmp_path, line):
    with pytest.raises(S.ScriptError, match="not audited: control flow") as exc:
        _read(tmp_path, f"units si\n{line}\n")
    assert "in.deck:2" in str(exc.value) and exc.value.exit_code == 2


def test_a_label_alone_does_nothing_and_next_after_it_is_still_refused(tmp_path):
    """A label no jump reaches has no effect in LAMMPS; a `next` that no loop closes changes a variable for the lines
    after it: refused."""
    sc = _read(tmp_path, "units si\nlabel here\ntimestep 1e-7\n")
    assert [c.name for c in sc.commands] == ["units", "timestep"]
    with pytest.raises(S.ScriptError, match="in.deck:4: 'next' outside a loop"):
        _read(tmp_path, "units si\nvariable a index 1 2\nlabel here\nnext a\ntimestep ${a}\n")


def test_unclosed_quote_names_the_line(tmp_path):
    with pytest.raises(S.ScriptError, match=r"in.deck:2: a quote"):
        _read(tmp_path, "units si\nprint 'abc\n")


def test_shell_and_python_lines_are_read_not_run(tmp_path):
    marker = tmp_path / "touched"
    sc = _read(tmp_path, f"shell touch {marker}\npython f input 0 format f here \"\"\"\nopen('{marker}','w')\n\"\"\"\n")
    assert [c.name for c in sc.commands] == ["shell", "python"]
    assert not marker.exists()


def test_a_metric_one_side_lacks_is_never_dropped_from_a_comparison():
    """The audit's worst difference over a probe's metrics: one side's NaN is an infinite difference (Python's max()
    would drop it where it is not first), a metric neither side produces is skipped."""
    import math

    from demcheck.comparisons.audit import _worst

    scales = {"impact_energy": 1.0, "spin": 1.0}
    ok = {"restitution": 0.5, "tangential_restitution": math.nan}
    assert _worst(ok, dict(ok), ["restitution", "tangential_restitution"], scales) == 0.0
    bad = {"restitution": math.nan, "tangential_restitution": math.nan}
    assert _worst({"restitution": 0.5, "tangential_restitution": 0.7}, bad,
                  ["tangential_restitution", "restitution"], scales) == math.inf


def test_quit_in_an_included_file_ends_the_whole_input(tmp_path):
    """LAMMPS stops at `quit` wherever it stands: the lines after the include are never run, so never read."""
    (tmp_path / "part.in").write_text("timestep 1e-7\nquit\n")
    (tmp_path / "deck.in").write_text("units si\ninclude part.in\ntimestep 5e-7\n")
    sc = S.read(tmp_path / "deck.in")
    assert [c.words for c in sc.commands][-1] == ["quit"]
    assert ["timestep", "5e-7"] not in [c.words for c in sc.commands]


def test_a_huge_type_count_is_bad_input_not_a_memory_bomb(tmp_path):
    import subprocess
    import sys

    deck = tmp_path / "big.in"
    deck.write_text("units si\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 300000000 box\n")
    p = subprocess.run([sys.executable, "-m", "demcheck", "audit", str(deck)], capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 2 and "atom types" in p.stderr and p.stderr.strip().count("\n") == 0, p.stderr
