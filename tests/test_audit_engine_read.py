"""demcheck audit reads a LAMMPS deck as LAMMPS reads it (engines/lammps/read.py): the set-up evaluated by the engine
in a worker process under an allow-list and a budget, control flow followed with the engine's values, nothing that
writes files or runs code executed, a crashed or exhausted worker reported, never fatal. Decks written here, each
read and probed by the real engine; each test fails on main 03c7b92 (no engine read: control flow refused, no
``read_by``)."""

import json
import subprocess
import sys

import pytest

from demcheck.comparisons import audit as A
from demcheck.engines.lammps import read as R
from demcheck.inputs.script import ScriptError

from .conftest import ROOT
from .helpers import write_deck as _deck

HEAD = """units si
atom_style sphere
comm_modify vel yes
boundary f f f
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
"""
LAW = """pair_style granular
pair_coeff * * hertz/material 63e9 0.9 0.3 damping coeff_restitution tangential linear_nohistory 0 0
timestep 2e-8
"""


@pytest.mark.engine("lammps")
def test_loop_and_if_evaluated_by_the_engine(tmp_path):
    """A loop places the two bodies ($(…) of the loop variable), an if sizes them: the engine follows both; the
    probe runs at their relative approach speed (2 m/s), the radius the taken branch sets (1 mm, not 0.5 mm)."""
    deck = _deck(tmp_path, HEAD + """variable k loop 2
label place
create_atoms 1 single 0 0 $(0.0025*v_k-0.00375) units box
next k
jump SELF place
variable big equal 1
if "${big} > 0" then "set type 1 diameter 0.002 density 2500" else "set type 1 diameter 0.001 density 1000"
group one id 1
group two id 2
velocity one set 0 0 1
velocity two set 0 0 -1
""" + LAW + "run 1000\n")
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LAMMPS")
    assert r["bodies"][1]["radius"] == 0.001 and r["bodies"][1]["density"] == pytest.approx(2500.0, rel=1e-12)
    assert r["speed"] == pytest.approx(2.0, rel=1e-12) and "approach speed of atoms 1 and 2" in r["speed_from"]
    assert r["status"] == "clean" and r["coverage"]["pairs"]["probed"] == 1
    probe = r["pairs"][0]["probes"][0]
    assert probe["engine"]["restitution"] == pytest.approx(0.9, abs=2e-3)  # coeff_restitution's e, in the engine


@pytest.mark.engine("lammps")
def test_lattice_bodies_and_random_velocities_read_from_the_engine(tmp_path):
    """create_atoms on a lattice region, set by a region group, velocity ramp: the present reader cannot place or
    speed them; the engine's 27 atoms give the bodies (radius, density) and the largest relative approach speed
    (the ramp's ends, 8 mm apart along z, meet at 1 − (−1) = 2 m/s)."""
    deck = _deck(tmp_path, HEAD + """lattice sc 0.004
region inner block -0.004 0.004 -0.004 0.004 -0.004 0.004 units box
create_atoms 1 region inner
group middle region inner
set group middle diameter 0.003 density 1200
velocity all ramp vz 1 -1 z -0.004 0.004 units box
""" + LAW + "run 100000000\n")
    answer = R.engine_read(deck)
    atoms = answer.state["atoms"]
    assert len(atoms) == 27 and all(a["radius"] == 0.0015 for a in atoms)
    assert sorted({a["v"][2] for a in atoms}) == [-1.0, 0.0, 1.0]
    r = A.audit(deck)
    assert r["bodies"][1]["radius"] == 0.0015 and r["bodies"][1]["density"] == pytest.approx(1200.0, rel=1e-12)
    assert r["speed"] == pytest.approx(2.0, rel=1e-12) and "approach speed" in r["speed_from"]
    assert r["coverage"]["pairs"]["probed"] == 1 and r["pairs"][0]["probes"][0]["engine"]["restitution"] == \
        pytest.approx(0.9, abs=2e-3)


@pytest.mark.engine("lammps")
def test_files_and_code_never_executed_and_listed(tmp_path):
    """shell, write_data, dump, log, print/fix print to a file, partition's command, run … every's command: not one
    runs (no file appears), each is listed as never executed; `run 100000000` runs as run 0 (the read ends at
    once)."""
    deck = _deck(tmp_path, HEAD + """create_atoms 1 single 0 0 0.002 units box
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
shell touch shell-ran
write_data written.data
dump d all atom 1 dumped.txt
log logged.txt
print "hello" file printed.txt
fix fp all print 1 "x" file fix-printed.txt
partition yes 1 shell touch partition-ran
""" + LAW + """fix w all wall/gran granular hertz/material 63e9 0.9 0.3 damping coeff_restitution tangential linear_nohistory 0 0 zplane -0.01 NULL
run 100000000 every 5 "shell touch every-ran"
""")
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LAMMPS")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.deck"]
    listed = {n["text"].split()[0] + (" print" if "fix" in n["text"] else ""): n["why"] for n in r["not_audited"]}
    for head in ("shell", "write_data", "dump", "log", "print", "fix print", "partition", "run"):
        assert "never executed" in listed[head], (head, listed)
    assert r["coverage"]["walls"]["probed"] == 1 and r["coverage"]["pairs"]["probed"] == 1
    assert {f["code"] for p in r["pairs"] for f in p["findings"] if f["kind"] == "trap"} == {"wall-moduli"}


@pytest.mark.engine("lammps")
def test_unbounded_loop_refused_with_the_budget(tmp_path):
    """A jump that never ends: refused (exit 2) after the budget of commands, the reason in the one line and in
    --json's object; demcheck itself returns."""
    deck = _deck(tmp_path, HEAD + "label again\nvariable x equal 1\njump SELF again\n" + LAW)
    with pytest.raises(ScriptError, match=f"more than {R.MAX_COMMANDS} commands"):
        A.read(deck)
    p = subprocess.run([sys.executable, "-m", "demcheck", "audit", "--json", str(deck)], capture_output=True,
                       text=True, cwd=ROOT)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert f"more than {R.MAX_COMMANDS} commands" in json.loads(p.stdout)["error"]


@pytest.mark.engine("lammps")
def test_a_dead_or_slow_worker_falls_back_to_the_reader_and_says_why(tmp_path, monkeypatch):
    """The worker killed (here: a module that does not exist, exit 1) or out of its time budget (a box of 2.7e10
    lattice points): demcheck goes on with its own reader, and read_by says why."""
    deck = _deck(tmp_path, HEAD + """create_atoms 1 single 0 0 0.002 units box
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
""" + LAW + "fix w all wall/gran granular hooke 1e5 0.5 tangential linear_nohistory 0 0 zplane -0.01 NULL\n")
    monkeypatch.setattr(R, "MODULE", "demcheck.engines.lammps.no_such_worker")
    setup = A.read(deck)
    assert setup.read_by.startswith("demcheck's reader") and "worker died (exit status 1" in setup.read_by
    monkeypatch.undo()
    bomb = _deck(tmp_path, "units lj\natom_style sphere\ncomm_modify vel yes\nlattice sc 1\nregion b block 0 3000 0 3000 "
                 "0 3000\ncreate_box 1 b\ncreate_atoms 1 box\nset type 1 diameter 1 density 1\n"
                 "velocity all set 0 0 -1\npair_style granular\npair_coeff * * hooke 1000 0.5 tangential "
                 "linear_nohistory 0 0\n", "in.bomb")
    monkeypatch.setattr(R, "MAX_SECONDS", 3.0)
    setup = A.read(bomb)
    assert "more than its 3 s budget" in setup.read_by


@pytest.mark.engine("lammps")
def test_a_line_the_engine_refuses_is_a_trap(tmp_path):
    """LAMMPS 22Jul2025 stops on `jkr … damping tsuji` (a cohesive normal model with tsuji): the deck as written
    does not run; the audit says so as a trap naming the line and the engine's message."""
    deck = _deck(tmp_path, HEAD + """create_atoms 1 single 0 0 0.002 units box
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
pair_style granular
pair_coeff * * jkr 1e5 0.1 0.3 50 tangential mindlin NULL 1.0 0.5 damping tsuji
fix w all wall/gran granular hooke 1e5 0.5 tangential linear_nohistory 0 0 zplane -0.01 NULL
timestep 2e-8
""")
    r = A.audit(deck)
    refused = [f for f in A.read(deck).findings if f.code == "engine-refuses"]
    assert refused and "in.deck:11" in refused[0].where and "Cannot use tsuji model" in refused[0].text
    assert r["read_by"].startswith("demcheck's reader") and "the engine stops here" in r["read_by"]
    assert r["traps"] >= 1 and r["status"] == "traps" and r["coverage"]["walls"]["probed"] == 1


@pytest.mark.engine("lammps")
def test_the_readers_formulas_agree_with_the_engines(tmp_path):
    """The reader's evaluator (LIGGGHTS decks, and LAMMPS decks without the engine) against LAMMPS's own $(…): ^ is
    left to right and a sign binds tighter (main evaluated 2^3^2 = 512 and -2^2 = -4; LAMMPS gives 64 and 4)."""
    from demcheck.inputs.script import evaluate

    exprs = ["2^3^2", "-2^2", "2^-1", "2*3^2", "-3^2*2", "1-2^2", "(1+2)^2^0.5", "4/2/2", "2-3-4", "-(2)^3",
             "sqrt(16)^2", "2^3^-1", "10^10^10"]
    deck = _deck(tmp_path, "".join(f"variable x{i} equal $({e})\n" for i, e in enumerate(exprs))
                 + "".join(f"print ${{x{i}}}\n" for i in range(len(exprs))))
    answer = R.engine_read(deck)
    engine = [float(rec["words"][3]) for rec in answer.lines if rec["words"] and rec["words"][0] == "variable"]
    assert len(engine) == len(exprs)
    for e, x in zip(exprs, engine):
        assert evaluate(e, {}) == pytest.approx(x, rel=1e-12), e


@pytest.mark.engine("lammps")
def test_a_jump_inside_an_if_leaves_the_branch_and_its_file(tmp_path):
    """`if "${k} < 3" then "jump SELF place"`: the loop runs while k < 3 (two atoms, at −3 mm and 0), and the lines
    after it run once, as in LAMMPS (a jump from a branch ends the file position the if was read at)."""
    deck = _deck(tmp_path, HEAD + """variable k loop 3
label place
create_atoms 1 single 0 0 $(0.003*v_k-0.006) units box
next k
if "${k} < 3" then "jump SELF place"
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
""")
    answer = R.engine_read(deck)
    assert sorted(a["x"][2] for a in answer.state["atoms"]) == pytest.approx([-0.003, 0.0], abs=1e-15)
    assert [rec["words"][0] for rec in answer.lines if rec["words"]].count("set") == 1


@pytest.mark.engine("lammps")
def test_a_parallel_layout_is_not_a_refusal(tmp_path):
    """``processors 2 1 *`` lays the deck out on two ranks; the read runs on one, where LAMMPS stops at create_box
    ("Could not create 3d grid of processors"). The layout changes no contact: it is not executed, and the deck is
    read by the engine with no engine-refuses trap (main 61ee0df reported one)."""
    deck = _deck(tmp_path, HEAD.replace("boundary f f f\n", "boundary f f f\nprocessors 2 1 *\n") + """
create_atoms 1 single 0 0 0 units box
create_atoms 1 single 0.0021 0 0 units box
set atom * diameter 0.002 density 2500
velocity all set 0 0 0
set atom 2 vx -0.5
""" + LAW + "run 1000\n")
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LAMMPS"), r["read_by"]
    assert not [f for f in A.read(deck).findings if f.code == "engine-refuses"]
    assert r["coverage"]["pairs"]["probed"] == 1
