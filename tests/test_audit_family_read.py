"""The LAMMPS family's walk (engines/family_read.py) serves LAMMPS decks as it serves LIGGGHTS's: a LAMMPS deck whose
read_restart names a file the folder lacks is read with the set-up of the folder's deck that writes it, LAMMPS's
own write_restart/read_restart carrying over what a restart keeps (atoms, box, types), the reading deck's own
commands after read_restart applied. Fails on main 47e91d4 (the restart's deck: nothing probed)."""

import pytest

from demcheck.comparisons import audit as A

INIT = """units si
atom_style sphere
comm_modify vel yes
boundary f f f
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box 1 box
create_atoms 1 single 0 0 0.002 units box
create_atoms 1 single 0 0 -0.002 units box
set type 1 diameter 0.002 density 2500
pair_style granular
pair_coeff * * hertz/material 63e9 0.9 0.3 damping coeff_restitution tangential linear_nohistory 0 0
timestep 2e-8
run 1000
write_restart restart.*
"""
RUN = """units si
atom_style sphere
read_restart restart.1000
comm_modify vel yes
group one id 1
group two id 2
velocity one set 0 0 -1
velocity two set 0 0 1
pair_style granular
pair_coeff * * hertz/material 63e9 0.8 0.3 damping coeff_restitution tangential linear_nohistory 0 0
timestep 2e-8
run 1000
"""


@pytest.mark.engine("lammps")
def test_a_lammps_restart_the_folder_lacks_read_from_the_deck_that_writes_it(tmp_path):
    (tmp_path / "in.init").write_text(INIT)
    deck = tmp_path / "in.run"
    deck.write_text(RUN)
    r = A.audit(deck)
    assert r["read_by"].startswith("the engine (LAMMPS")
    assert "bodies from in.init, the deck that writes restart.1000" in r["read_by"]
    assert r["bodies"][1]["radius"] == pytest.approx(0.001, rel=1e-12)
    assert r["bodies"][1]["density"] == pytest.approx(2500.0, rel=1e-12)
    assert r["speed"] == pytest.approx(2.0) and "approach speed of atoms" in r["speed_from"]
    assert r["coverage"]["pairs"]["probed"] == 1 and r["pairs"][0]["asked"]["restitution"] == pytest.approx(0.8)
    assert r["pairs"][0]["probes"][0]["engine"]["restitution"] == pytest.approx(0.8, abs=2e-3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.init", "in.run"]
