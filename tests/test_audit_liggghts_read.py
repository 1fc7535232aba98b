"""demcheck audit reads a LIGGGHTS deck as LIGGGHTS reads it (engines/liggghts/read.py through the LAMMPS family's
walk, engines/family_read.py): the set-up evaluated by libliggghts in a worker process under an allow-list and a
budget, loops followed with the engine's values, the bodies an insertion makes read from the engine, nothing that
writes files or runs code executed, the engine's own ERROR (it exits the worker) reported as a trap, and a
restart file the folder lacks read from the deck of the folder that writes it. Decks written here in the
patterns of LIGGGHTS's tutorials, each read by the real LIGGGHTS 3.8; each test fails on main 47e91d4 (no
LIGGGHTS read: control flow refused, the reader's read_by, a restart's deck with nothing probed)."""

import json
import math
import subprocess
import sys

import pytest

from demcheck.comparisons import audit as A
from demcheck.inputs.script import ScriptError

from .conftest import ROOT

HEAD = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region reg block -0.05 0.05 -0.05 0.05 -0.01 0.1 units box
create_box 2 reg
neighbor 0.002 bin
neigh_modify delay 0
"""
MATERIALS = """fix m1 all property/global youngsModulus peratomtype 5e6 5e6
fix m2 all property/global poissonsRatio peratomtype 0.45 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5
fix m4 all property/global coefficientFriction peratomtypepair 2 0.3 0.3 0.3 0.3
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
"""
STL = """solid floor
facet normal 0 0 1
outer loop
vertex -0.05 -0.05 0.0
vertex 0.05 -0.05 0.0
vertex 0.05 0.05 0.0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.05 -0.05 0.0
vertex 0.05 0.05 0.0
vertex -0.05 0.05 0.0
endloop
endfacet
endsolid floor
"""


def _deck(folder, text, name="in.deck"):
    p = folder / name
    p.write_text(text)
    return p


@pytest.mark.engine("liggghts")
def test_templates_loop_and_walls_read_by_liggghts(tmp_path):
    """A loop sets a template's radius (the engine's value after the loop: 3 mm; a reader reading the loop once
    would take 1 mm), a distribution of two templates is inserted by fix insert/pack, a mesh wall and a primitive
    wall on the particles' own type: LIGGGHTS reads it all, the bodies' sizes and speed are those of the atoms
    LIGGGHTS inserted, every pair and wall is probed; shell, write_restart and dump are never executed (no file
    appears) and are listed."""
    (tmp_path / "wall.stl").write_text(STL)
    deck = _deck(tmp_path, HEAD + """variable k loop 3
label grow
variable r equal 0.001*${k}
next k
jump SELF grow
""" + MATERIALS + """fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix cad all mesh/surface file wall.stl type 2
fix meshwall all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad
fix top all wall/gran model hertz tangential history primitive type 1 zplane 0.09
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant ${r}
fix pts2 all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant 0.002
fix pdd1 all particledistribution/discrete 32452843 2 pts1 0.5 pts2 0.5
region bc cylinder z 0.0 0.0 0.04 0.01 0.08 units box
fix ins all insert/pack seed 32452867 distributiontemplate pdd1 vel constant 0. 0. -1.5 &
    insert_every once overlapcheck yes all_in yes particles_in_region 40 region bc
fix integr all nve/sphere
shell touch shell-ran
write_restart restart.bin
dump d all custom 100 dump-ran id x y z
run 2000
""")
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LIGGGHTS-PUBLIC 3.8.0)")
    assert r["bodies"][1]["sizes"] == [0.002, 0.003]
    assert r["bodies"][1]["density"] == pytest.approx(2500.0, rel=1e-9)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.deck", "wall.stl"]
    listed = {n["text"].split()[0]: n["why"] for n in r["not_audited"]}
    for head in ("shell", "write_restart", "dump"):
        assert "never executed" in listed[head], (head, listed)
    cov = r["coverage"]
    assert cov["pairs"]["probed"] == cov["pairs"]["total"] == 3  # the smallest, largest and mass-weighted pairs
    assert cov["walls"]["probed"] == cov["walls"]["total"] == 6  # the mesh and the primitive wall × 3 sizes
    # the insertion velocity plus the fall from the region's top (0.08) to the box's bottom (-0.01): the plane wall
    # at 0.09 is a lid, not a floor (the mesh floor at 0 is not read: its facets are not)
    assert r["speed"] == pytest.approx(math.sqrt(1.5 ** 2 + 2 * 9.81 * 0.09), rel=1e-12)
    engine = A.read(deck)
    assert "its sizes those of the engine's 40 atom(s) of type 1, weighted by the distribution's mass fractions" \
        in engine.bodies[1].size_from
    assert any("the engine's atoms" in w for _, w in engine.speeds)


@pytest.mark.engine("liggghts")
def test_liggghts_error_reported_as_a_trap(tmp_path):
    """LIGGGHTS exits on `atom_modify map` after create_box (its Error::all ends the worker): demcheck reads the
    ERROR line from the worker's log, reports it as the trap engine-refuses naming the line — one line in the
    text report, no traceback — and audits the deck with its reader, read_by saying why."""
    deck = _deck(tmp_path, HEAD + "atom_modify map array\n" + MATERIALS + """fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.002
fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0
region bc block -0.04 0.04 -0.04 0.04 0.01 0.08 units box
fix ins all insert/pack seed 32452867 distributiontemplate pdd1 vel constant 0. 0. -1.5 insert_every once overlapcheck yes all_in yes particles_in_region 10 region bc
fix zw all wall/gran model hertz tangential history primitive type 1 zplane 0.0
run 100
""")
    r = A.audit(deck)
    assert r["read_by"].startswith("demcheck's reader") and "the engine stops here: ERROR: Atom_modify" in r["read_by"]
    refused = [f for f in r["findings"] if f["code"] == "engine-refuses"]
    assert refused and refused[0]["where"] == "in.deck:11" and refused[0]["kind"] == "trap"
    assert r["status"] == "traps" and r["coverage"]["walls"]["probed"] == 1
    p = subprocess.run([sys.executable, "-m", "demcheck", "audit", str(deck)], capture_output=True, text=True,
                       cwd=ROOT)
    assert p.returncode == 1 and "Traceback" not in p.stderr + p.stdout
    assert [line for line in p.stdout.splitlines() if "[engine-refuses]" in line] == [
        "  TRAP [engine-refuses]: the installed engine refuses the deck: in.deck:11: 'atom_modify map array': the "
        "engine stops here: ERROR: Atom_modify map command after simulation box is defined (./src/atom.cpp:538)"]


@pytest.mark.engine("liggghts")
def test_a_missing_restart_read_from_the_deck_that_writes_it(tmp_path):
    """The tutorials' pair of decks: in.init inserts the bodies and writes post/restart.* ; in.run reads
    post/restart.5000, which the folder lacks, redefines materials, contact law and walls (a restart keeps box,
    types and atoms, not fixes), sets the bodies' speed and ends in a long coupling loop of `run 1`; both include
    the same parameter file. The bodies come from in.init's set-up in LIGGGHTS,
    carried over by LIGGGHTS's own write_restart/read_restart in demcheck's scratch folder; in.run's own commands
    after read_restart apply; the report says where the bodies came from; no file appears in the folder."""
    (tmp_path / "post").mkdir()
    _deck(tmp_path, "variable rho equal 2000\nvariable vz equal -0.7\n", "in.params")
    _deck(tmp_path, "include in.params\n" + HEAD + MATERIALS + """fix zw all wall/gran model hertz tangential history primitive type 2 zplane 0.0
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant ${rho} radius constant 0.0015
fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0
region bc block -0.04 0.04 -0.04 0.04 0.01 0.08 units box
fix ins all insert/pack seed 32452867 distributiontemplate pdd1 vel constant 0. 0. -3 insert_every once overlapcheck yes all_in yes particles_in_region 12 region bc
fix integr all nve/sphere
run 5000
write_restart post/restart.*
""", "in.init")
    deck = _deck(tmp_path, """include in.params
atom_style granular
atom_modify map array
communicate single vel yes
boundary f f f
newton off
units si
read_restart post/restart.5000
neighbor 0.002 bin
neigh_modify delay 0
""" + MATERIALS.replace("0.5 0.5 0.5 0.5", "0.8 0.8 0.8 0.8") + """fix zw all wall/gran model hertz tangential history primitive type 2 zplane 0.0
velocity all set 0 0 ${vz}
fix integr all nve/sphere
label coupling
variable step loop 100000
run 1 post no
next step
jump SELF coupling
""", "in.run")
    r = A.audit(deck)
    assert "bodies from in.init, the deck that writes post/restart.5000" in r["read_by"]
    assert r["bodies"][1]["radius"] == pytest.approx(0.0015, rel=1e-12)
    assert r["bodies"][1]["density"] == pytest.approx(2000.0, rel=1e-9)
    assert r["speed"] == pytest.approx(0.7, rel=1e-12)  # in.run's own velocity, applied after read_restart
    assert r["coverage"]["pairs"]["probed"] == 1 and r["coverage"]["walls"]["probed"] == 1
    asked = r["pairs"][0]["asked"]
    assert asked["restitution"] == pytest.approx(0.8)  # in.run's property, not in.init's 0.5
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["in.init", "in.params", "in.run", "post"]
    assert any("more than 20000 commands followed" in n["why"] for n in r["not_audited"])  # its coupling loop
    assert json.dumps(r)  # the report is JSON as --json prints it
    latest = _deck(tmp_path, deck.read_text().replace("post/restart.5000", "post/restart.*"), "in.latest")
    assert "the deck that writes post/restart.*" in A.audit(latest)["read_by"]  # read_restart's latest-file form


@pytest.mark.engine("liggghts")
def test_a_long_loop_of_runs_after_the_set_up_keeps_the_engines_read(tmp_path):
    """A loop of 100 000 `run 1` after the set-up (the tutorials' coupling loops): LIGGGHTS follows it up to the
    budget of commands; what it read by then (bodies, contacts) is kept and audited, and the line where the read
    stopped is listed as not audited; a hostile file name (../) in a fix is refused, never read."""
    deck = _deck(tmp_path, HEAD + MATERIALS + """fix zw all wall/gran model hertz tangential history primitive type 2 zplane 0.0
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2000 radius constant 0.0015
fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0
region bc block -0.04 0.04 -0.04 0.04 0.01 0.08 units box
fix ins all insert/pack seed 32452867 distributiontemplate pdd1 vel constant 0. 0. -2 insert_every once overlapcheck yes all_in yes particles_in_region 5 region bc
label again
variable i loop 100000
run 1 post no
next i
jump SELF again
""")
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LIGGGHTS-PUBLIC 3.8.0)")
    assert r["bodies"][1]["radius"] == pytest.approx(0.0015, rel=1e-12) and r["speed"] == pytest.approx(2.0)
    assert r["coverage"]["pairs"]["probed"] == 1 and r["coverage"]["walls"]["probed"] == 1
    assert any("more than 20000 commands followed" in n["why"] for n in r["not_audited"])
    endless = _deck(tmp_path, deck.read_text().replace("next i\n", ""), "in.endless")
    with pytest.raises(ScriptError, match="control flow"):  # no next: the loop may never end — not kept
        A.read(endless)
    sets = _deck(tmp_path, deck.read_text().replace("next i\n", "next i\nset type 1 diameter 0.004\n"), "in.sets")
    with pytest.raises(ScriptError, match="control flow"):  # each pass may change the bodies — not kept
        A.read(sets)
    (tmp_path / "sub").mkdir()
    hostile = _deck(tmp_path / "sub", HEAD + "fix cad all mesh/surface file ../../etc/passwd type 2\n" + MATERIALS)
    from demcheck.engines.liggghts import read as R

    answer = R.engine_read(hostile)
    assert "'../../etc/passwd': the file lies outside the deck's directory" in answer.stopped
    assert not [rec for rec in answer.lines if rec["ran"] and "passwd" in rec["text"]]
