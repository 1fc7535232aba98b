"""The present reader's path (LIGGGHTS decks; LAMMPS decks where the engine's module is missing): a loop whose body
sets nothing the audit reads is read once (LIGGGHTS's ParScale tutorials run their loops of `run`/`set
property/atom`/`next` that way), any other loop is refused; LIGGGHTS's `radius gaussian number μ σ` templates; bodies
that meet by growing (fix adapt … atom diameter) get the closing rate of their growth as the characteristic speed.
Each test fails on main 03c7b92 (label refused; `number` not a number; no speed)."""

import math

import pytest

from demcheck.comparisons import audit as A
from demcheck.engines.lammps import read as R
from demcheck.inputs.script import ScriptError

from .test_audit_corpus import LIGGGHTS, _deck


@pytest.fixture(autouse=True)
def _reader_path(monkeypatch):
    """These are the reader's rules: LIGGGHTS's own read (engines/liggghts/read.py, which follows loops in the
    engine, tests/test_audit_liggghts_read.py) is set aside, as where libliggghts is not installed."""
    from demcheck.engines.liggghts import read as LR

    monkeypatch.setattr(LR, "available", lambda: False)

NO_FRICTION = LIGGGHTS.replace("tangential history", "tangential no_history").replace(
    "coefficientFriction peratomtypepair 1 0.5", "coefficientFriction peratomtypepair 1 0.0").replace(
    "fix pts2 all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant 0.008\n", "").replace(
    "2 pts1 0.3 pts2 0.7", "1 pts1 1.0")
LOOP = """variable a loop 50
label loopStart
    set group all property/atom heatFluid 400
    run 10 post no
    next a
jump SELF loopStart
"""


@pytest.mark.engine("liggghts")
def test_a_loop_that_sets_nothing_read_once_and_probed_in_the_engine(tmp_path):
    r = A.audit(_deck(tmp_path, NO_FRICTION + LOOP))
    assert r["coverage"]["walls"]["probed"] == 1 and r["status"] != "not audited"
    wall = next(p for p in r["pairs"] if p["wall"])
    assert wall["probes"][0]["engine"]["status"] == "ok" and wall["probes"][0]["engine_vs_twin"] <= 1e-9
    loops = [n for n in r["not_audited"] if "read once" in n["why"]]
    assert len(loops) == 1 and "lines 25–29" in loops[0]["why"]


@pytest.mark.parametrize("body,why", [
    ("set type 1 diameter 0.004\n", "diameter changes the bodies"),
    ("pair_coeff * *\n", "a contact line"),
    ("timestep 0.00002\n", "the step"),
])
def test_a_loop_that_sets_what_the_audit_reads_is_refused(tmp_path, body, why):
    deck = _deck(tmp_path, LIGGGHTS + LOOP.replace("    next a\n", "    " + body + "    next a\n"))
    with pytest.raises(ScriptError, match="control flow"):
        A.read(deck)


def test_a_loop_no_variable_ends_is_refused(tmp_path):
    deck = _deck(tmp_path, LIGGGHTS + "label again\nrun 10\njump SELF again\n")
    with pytest.raises(ScriptError, match="control flow"):
        A.read(deck)


def test_lammps_loop_on_the_reader_path_when_the_engine_module_is_missing(tmp_path, monkeypatch):
    """Without the engine's module the reader reads the loop once and says which path read the deck."""
    monkeypatch.setattr(R, "available", lambda: False)
    deck = _deck(tmp_path, """units si
atom_style sphere
comm_modify vel yes
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
create_atoms 1 single 0 0 0.002 units box
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
pair_style granular
pair_coeff * * hooke 1e5 0.5 tangential linear_nohistory 0 0
fix w all wall/gran granular hooke 1e5 0.5 tangential linear_nohistory 0 0 zplane -0.01 NULL
timestep 1e-7
variable i loop 3
label go
run 100
next i
jump SELF go
""")
    setup = A.read(deck)
    assert setup.read_by.startswith("demcheck's reader") and "not installed" in setup.read_by
    assert len(setup.pairs) == 2


def test_gaussian_number_template_and_growth_speed(tmp_path):
    """`radius gaussian number 0.004 0.001` (its mean probed) and the packing tutorial's growth: every 40 steps the
    diameter × g, so two touching spheres of radius R close at 2(g − 1)R/(40·dt)."""
    g = (0.67 / 0.25) ** (40 / (3 * 50000))
    text = LIGGGHTS.replace("radius constant 0.005", "radius gaussian number 0.004 0.001").replace(
        "vel constant 0. 0. -1.", "vel constant 0. 0. 0.").replace("fix gravi all gravity 9.81 vector 0.0 0.0 -1.0\n", "")
    text += f"""compute rad all property/atom radius
variable dgrown atom {g!r}*2.*c_rad
fix grow all adapt 40 atom diameter v_dgrown
run 50000
"""
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert r["bodies"][1]["sizes"] == [0.004, 0.008]
    assert r["speed"] == pytest.approx(2 * (g - 1) * 0.008 / (40 * 1e-5), rel=1e-12)
    assert "growing bodies" in r["speed_from"]
    assert r["coverage"]["walls"]["probed"] == 3 and math.isfinite(r["speed"])
