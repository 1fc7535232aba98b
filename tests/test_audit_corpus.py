"""demcheck audit on decks written here in the patterns of the engines' public examples (issue 28): units lj and no
units line, fix pour, LIGGGHTS templates and walls on the particle type, set atom, mdr and damping none, 2-D,
quoted ${}, $(zlo), pair_style none, long contacts — each read and probed, with real engine runs where the engine
is what is checked. Golden values are closed forms (Hertz's contact time, a fall under gravity, mass = ρπr²)."""

import json
import math
import subprocess
import sys

import pytest

from demcheck.comparisons import audit as A
from demcheck.errors import EngineInterrupted

from .conftest import ROOT
from .helpers import write_deck as _deck

HERTZ_C = 2.0 * (15.0 / 16.0) ** 0.4 * 1.4716  # 2(15/16)^{2/5}·(2/5)B(2/5, 1/2), B-part 1.4716… (seed 001: 2.868)


def demcheck(*args):
    return subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, cwd=ROOT)


def _entry(r, label):
    return next(p for p in r["pairs"] if p["pair"] == label)


POUR_LJ = """units lj
atom_style sphere
boundary p p f
region box block 0 10 0 10 0 20
create_box 1 box
region ins cylinder z 5 5 3 12 18
pair_style granular
pair_coeff * * hooke 2000 0.5 tangential linear_nohistory 0 0 damping coeff_restitution
fix wall all wall/gran granular hooke 2000 0.5 tangential linear_nohistory 0 0 damping coeff_restitution zplane 0 NULL
fix 1 all nve/sphere
fix grav all gravity 1.0 vector 0 0 -1
fix ins all pour 100 1 4767548 region ins diam range 0.5 1.0 dens 1.0 1.0
timestep 0.0001
run 1000
"""


def test_units_lj_pour_reads_speed_sizes_and_units(tmp_path):
    """units lj with fix pour: no --speed — the fall from the region's top (18) to the floor (zplane 0) under
    g = 1 gives √(2·1·18); the diameters 0.5…1.0 are probed at the smallest, largest and mass-weighted size."""
    r = A.audit(_deck(tmp_path, POUR_LJ), run_engine=False)
    assert r["units"]["style"] == "lj" and r["units"]["si"] is None
    assert r["speed"] == pytest.approx(math.sqrt(2 * 18.0), rel=1e-12)
    assert "fall of 18" in r["speed_from"]
    labels = [p["pair"] for p in r["pairs"]]
    assert labels == ["1-1 (smallest)", "1-1 (largest)", "1-1 (mass-weighted)",
                      "wall wall × 1 (smallest)", "wall wall × 1 (largest)", "wall wall × 1 (mass-weighted)"]
    # mass-weighted mean diameter of a uniform number distribution on [a, b]: (4/5)(b⁵−a⁵)/(b⁴−a⁴)
    a, b = 0.5, 1.0
    mw = 0.8 * (b ** 5 - a ** 5) / (b ** 4 - a ** 4) / 2
    assert r["bodies"][1]["radius"] == pytest.approx(mw, rel=2e-3)  # 41 diameters through the range
    assert r["bodies"][1]["sizes"] == [0.25, 0.5]
    assert r["coverage"]["pairs"] == {"probed": 3, "total": 3, "fraction": 1.0}
    assert r["status"] in ("clean", "traps")
    for p in r["pairs"]:
        assert p["probed"] and p["probes"][0]["twin"]["restitution"] == pytest.approx(0.5, abs=5e-3)


@pytest.mark.engine("lammps")
def test_units_lj_probes_run_in_the_engine_in_the_decks_numbers(tmp_path):
    """The lj deck's probes run in LAMMPS with the deck's numbers (a consistent unit system): the engine equals
    its twin to round-off, and the head-on restitution is the coeff_restitution asked."""
    text = POUR_LJ.replace("diam range 0.5 1.0", "diam one 1.0")
    r = A.audit(_deck(tmp_path, text))
    for p in r["pairs"]:
        (probe,) = p["probes"]
        assert probe["engine"]["status"] == "ok" and probe["engine_vs_twin"] <= 1e-9
        assert probe["engine"]["restitution"] == pytest.approx(0.5, abs=5e-3)


def test_no_units_line_is_lammps_default_lj(tmp_path):
    """LAMMPS's default units are lj with dt = 0.005 τ: a deck without units or timestep lines is read so,
    never silently as SI."""
    text = POUR_LJ.replace("units lj\n", "").replace("timestep 0.0001\n", "")
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert r["units"]["style"] == "lj" and "default" in r["units"]["from"]
    assert r["dt"] == 0.005 and "units lj" in r["dt_from"]  # LAMMPS's default step in lj units
    assert "units lj" in A.text_report(r)


def test_metal_units_are_converted_to_si(tmp_path):
    """units metal: read, then converted to SI with LAMMPS's factors (Å, ps; tests/test_audit_units.py checks the
    dynamics against LAMMPS's own run); the same deck in lj gives the numbers before conversion."""
    lj = A.read(_deck(tmp_path, POUR_LJ, "in.lj"))
    metal = A.read(_deck(tmp_path, POUR_LJ.replace("units lj", "units metal"), "in.metal"))
    assert metal.units == "si" and "units metal, converted to SI" in metal.units_where
    for t, b in lj.bodies.items():
        if b.radius is not None:
            assert metal.bodies[t].radius == pytest.approx(b.radius * 1e-10, rel=1e-12)
    assert metal.dt == pytest.approx(lj.dt * 1e-12, rel=1e-12)


TWO_BODY = """units si
atom_style sphere
region box block -0.01 0.01 -0.01 0.01 0 0.02
create_box 1 box
create_atoms 1 single 0 0 0.008
create_atoms 1 single 0 0 0.01201
set group all diameter 0.004 density 2500
group a1 id 1
group a2 id 2
velocity a1 set 0 0 1.0
velocity a2 set 0 0 -1.0
pair_style granular
pair_coeff * * hertz/material 1e8 0.0 0.3 tangential linear_nohistory 0 0
timestep 1e-7
"""


@pytest.mark.engine("lammps")
def test_symmetric_two_bodies_are_probed_at_their_approach_speed(tmp_path):
    """Two bodies at ±1 m/s meet at 2 m/s (the relative normal approach), not at one body's speed: the contact
    time is Hertz's closed form at 2 m/s, T = C (m̄²/(R̄Ē²v))^{1/5}."""
    r = A.audit(_deck(tmp_path, TWO_BODY))
    assert r["speed"] == pytest.approx(2.0) and "approach speed of atoms 1 and 2" in r["speed_from"]
    (probe,) = _entry(r, "1-1")["probes"]
    m = 2500 * 4 / 3 * math.pi * 0.002 ** 3
    e_star = 1e8 / (2 * (1 - 0.3 ** 2))
    t_c = HERTZ_C * ((m / 2) ** 2 / (0.001 * e_star ** 2 * 2.0)) ** 0.2
    assert probe["engine"]["contact_time"] == pytest.approx(t_c, rel=2e-3)
    assert probe["engine_vs_twin"] <= 1e-9


def test_set_atom_sizes_and_speeds(tmp_path):
    """`set atom N diameter … vz …` (hand-written decks): both sizes are probed, the speed is the approach."""
    text = TWO_BODY.replace("set group all diameter 0.004 density 2500\n",
                            "set atom 1 diameter 0.002 density 2500 vz 1.5\nset atom 2 diameter 0.004 density 2500 "
                            "vz -0.5\n").replace("velocity a1 set 0 0 1.0\nvelocity a2 set 0 0 -1.0\n", "")
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert r["speed"] == pytest.approx(2.0)
    assert [p["pair"] for p in r["pairs"]] == ["1-1 (smallest)", "1-1 (largest)", "1-1 (mass-weighted)"]
    assert r["bodies"][1]["sizes"] == [0.001, 0.002]


LIGGGHTS = """atom_style granular
atom_modify map array
boundary m m m
newton off
communicate single vel yes
units si
region reg block -0.05 0.05 -0.05 0.05 0. 0.15 units box
create_box 1 reg
fix m1 all property/global youngsModulus peratomtype 5.e6
fix m2 all property/global poissonsRatio peratomtype 0.45
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.3
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 0.00001
fix zwalls1 all wall/gran model hertz tangential history primitive type 1 zplane 0.00
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.005
fix pts2 all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius constant 0.008
fix pdd1 all particledistribution/discrete 32452843 2 pts1 0.3 pts2 0.7
region ins block -0.04 0.04 -0.04 0.04 0.10 0.14 units box
fix gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix ins all insert/pack seed 32452867 distributiontemplate pdd1 insert_every once overlapcheck yes all_in yes vel constant 0. 0. -1. region ins volumefraction_region 0.1
fix integr all nve/sphere
run 1
"""


def test_liggghts_walls_on_the_particle_type_and_two_templates(tmp_path):
    """LIGGGHTS tutorials declare primitive walls on the particles' own type: that type is both (the audit
    probed nothing before). Two templates of one type are both probed; the mass-weighted radius takes the
    distribution's mass fractions 0.3/0.7; the speed is the insertion velocity plus the fall from z = 0.14."""
    r = A.audit(_deck(tmp_path, LIGGGHTS), run_engine=False)
    labels = [p["pair"] for p in r["pairs"]]
    assert "1-1 (smallest)" in labels and "wall zwalls1 × 1 (largest)" in labels
    assert r["bodies"][1]["radius"] == pytest.approx(0.3 * 0.005 + 0.7 * 0.008, rel=1e-12)
    assert r["bodies"][1]["sizes"] == [0.005, 0.008]
    assert r["speed"] == pytest.approx(math.sqrt(1.0 + 2 * 9.81 * 0.14), rel=1e-12)
    assert r["coverage"]["walls"]["probed"] == 3 and r["status"] != "not audited"


@pytest.mark.engine("liggghts")
def test_liggghts_wall_on_the_particle_type_runs_in_the_engine(tmp_path):
    text = LIGGGHTS.replace("fix pts2 all particletemplate/sphere 15485867 atom_type 1 density constant 2500 radius "
                            "constant 0.008\n", "").replace("2 pts1 0.3 pts2 0.7", "1 pts1 1.0")
    text = text.replace("tangential history", "tangential no_history").replace("coefficientFriction peratomtypepair 1 0.5",
                                                                             "coefficientFriction peratomtypepair 1 0.0")
    r = A.audit(_deck(tmp_path, text))
    wall = _entry(r, "wall zwalls1 × 1")
    assert wall["probes"][0]["engine"]["status"] == "ok" and wall["probes"][0]["engine_vs_twin"] <= 1e-9


def test_liggghts_poisson_half_is_read_and_negative_refused(tmp_path):
    r = A.audit(_deck(tmp_path, LIGGGHTS.replace("peratomtype 0.45", "peratomtype 0.5")), run_engine=False)
    assert r["status"] != "not audited"
    assert any("0.5" in p["native"] or True for p in r["pairs"])
    out = demcheck("audit", str(_deck(tmp_path, LIGGGHTS.replace("peratomtype 0.45", "peratomtype -0.1"), "in.neg")))
    assert out.returncode == 2 and "poissonsRatio=-0.1" in out.stderr and "[0, 0.5]" in out.stderr


MDR = """units si
atom_style sphere 1
region box block -0.01 0.01 -0.01 0.01 0 0.02
create_box 1 box
create_atoms 1 single 0 0 0.005
set type 1 diameter 0.002 density 1560
variable damp_type equal 1
variable wall_string string "granular mdr 5e6 0.4 1.9e5 0 0.5 0.2 damping mdr ${damp_type} tangential linear_history 1e3 1.0 0.1"
pair_style granular
pair_coeff * * mdr 5e6 0.4 1.9e5 2 0.5 0.2 damping mdr ${damp_type} tangential linear_history 1e3 1.0 0.7
region floor plane 0 0 0 0 0 1 side in
fix floor all wall/gran/region ${wall_string} region floor contacts
fix grav all gravity 9.81 vector 0 0 -1
timestep 4e-6
"""


def test_mdr_damping_and_quoted_variables_are_read_and_nothing_probed_is_not_clean(tmp_path):
    """`damping mdr 1` and `${…}` inside a quoted string are read (LAMMPS expands it); MDR has no twin, so
    nothing is probed: status "not audited", exit 3, and --json still prints one object."""
    deck = _deck(tmp_path, MDR)
    r = A.audit(deck, run_engine=False)
    assert r["status"] == "not audited" and "mdr" in r["status_reason"]
    assert r["coverage"]["pairs"]["probed"] == 0 and r["coverage"]["walls"]["total"] == 1
    out = demcheck("audit", str(deck), "--json")
    assert out.returncode == 3
    assert json.loads(out.stdout)["status"] == "not audited"
    text = demcheck("audit", str(deck))
    assert text.returncode == 3 and "NOT AUDITED" in text.stdout and "no trap found" not in text.stdout


def test_a_refusal_under_json_prints_a_json_object(tmp_path):
    out = demcheck("audit", str(_deck(tmp_path, TWO_BODY.replace("timestep 1e-7", "timestep 1e-7x"))), "--json")
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1
    obj = json.loads(out.stdout)
    assert obj["status"] == "refused" and "in.deck" in obj["error"]


@pytest.mark.engine("lammps")
def test_damping_none_zlo_pair_style_none_and_a_2d_deck(tmp_path):
    """`damping none` (no dashpot: e = 1), a wall at $(zlo), `pair_style none` beside a wall fix, and a 2-D
    deck (mass = ρπr², LAMMPS's 2-D density): read and probed in the engine."""
    text = """dimension 2
atom_style sphere
boundary p f p
region box block 0 10 0 10 -0.5 0.5
create_box 1 box
create_atoms 1 single 5 5 0
set type 1 diameter 1.0 density 1.0
velocity all set 0 -1 0
pair_style none
fix w all wall/gran granular hooke 2000 0 tangential linear_nohistory 0 0 damping none yplane $(ylo) NULL
fix 2d all enforce2d
timestep 0.001
"""
    r = A.audit(_deck(tmp_path, text))
    assert r["dimension"] == 2 and r["units"]["style"] == "lj"
    (wall,) = r["pairs"]
    assert wall["pair"] == "wall w × 1"
    (probe,) = wall["probes"]
    assert probe["engine"]["restitution"] == pytest.approx(1.0, abs=1e-3) and probe["engine_vs_twin"] <= 1e-9
    setup = A.read(_deck(tmp_path, text, "in.again"))
    m, _ = A._effective(setup, setup.pairs[0])
    assert m == pytest.approx(1.0 * math.pi * 0.5 ** 2, rel=1e-12)  # a disc's mass, not a sphere's
    assert any("pair_style none" in n["why"] for n in r["not_audited"])


@pytest.mark.engine("lammps")
def test_a_long_contact_is_probed_at_a_stated_coarser_step(tmp_path):
    """LAMMPS's examples/granular in.restitution pattern: E = 1e6 Pa at dt = 1e-9 s needs ~1e6 steps a contact;
    the probe runs at a stated power-of-two multiple of dt instead of being refused, and the time-step verdict is
    still made on the deck's own dt (steps per contact at 1e-9 s)."""
    text = TWO_BODY.replace("1e8 0.0 0.3", "1e6 0.8 0.4").replace("tangential linear_nohistory 0 0",
                                                                    "tangential linear_nohistory 0 0 damping coeff_restitution") \
        .replace("timestep 1e-7", "timestep 1e-9")
    r = A.audit(_deck(tmp_path, text))
    entry = _entry(r, "1-1")
    (probe,) = entry["probes"]
    assert probe["dt"] > 1e-9 and "× the deck's 1e-09" in probe["dt_note"]
    assert probe["engine"]["restitution"] == pytest.approx(0.8, abs=5e-3) and probe["engine_vs_twin"] <= 1e-9
    assert entry["time_step"]["steps_per_contact"] > 5e5
    assert not any(f["code"] == "probe-failed" for f in entry["findings"])


def test_models_takes_classic_styles_and_notes_unread_properties():
    out = demcheck("models", "--engine", "lammps", "gran/hooke/history 2000 NULL 50 NULL 0.5 0")
    assert out.returncode == 0, out.stderr
    assert "nearest seed model: normal lsd" in out.stdout
    out = demcheck("models", "--engine", "liggghts", "model hertz tangential history coefficientRestitution=0.6 "
                   "coefficientFriction=0.5 youngsModulus=63e9 poissonsRatio=0.24 cohesionEnergyDensity=300 "
                   "coefficientRollingFriction=0.1 hard_particles=yes")
    assert out.returncode == 0, out.stderr
    assert "cohesionEnergyDensity=300: not read" in out.stdout and "coefficientRollingFriction" in out.stdout


@pytest.mark.parametrize("line,why", [
    ("hertz 1 0.5 tangential linear_nohistory 0 0", "never formed|pass through|out-of-range"),  # issue 28
    ("hertz/material 1e30 0.6 0.24 damping tsuji tangential mindlin NULL 1.0 0.5", ""),  # issue 32: e −1, tc 0
    ("hertz/material 1e200 0.6 0.24 damping tsuji tangential mindlin NULL 1.0 0.5", "")])  # e nan
def test_models_never_calls_an_unformed_contact_exact(line, why):
    out = demcheck("models", "--engine", "lammps", line, "--json")
    assert out.returncode == 1, out.stdout[-500:] + out.stderr
    r = json.loads(out.stdout)
    assert r["fidelity"] == "failed" and r["failures"] and r["gap"] is None
    text = demcheck("models", "--engine", "lammps", line)
    assert "exact" not in text.stdout and "FAILED" in text.stdout


def test_models_underflow_is_one_line_not_a_traceback():
    out = demcheck("models", "--engine", "lammps", "hertz/material 1e-308 0.6 0.24 damping tsuji tangential mindlin "
                                                  "NULL 1.0 0.5")
    assert out.returncode == 2 and "Traceback" not in out.stderr and len(out.stderr.strip().splitlines()) == 1
    assert "under- or overflows" in out.stderr


def test_a_tiny_diameter_is_a_failure_not_a_missing_twin(tmp_path):
    """issue 32: a 1e-200 m diameter underflows the mass: never "demcheck has no twin", never clean."""
    r = A.audit(_deck(tmp_path, TWO_BODY.replace("diameter 0.004", "diameter 1e-200")), run_engine=False)
    entry = _entry(r, "1-1")
    assert not any("no twin" in n for n in entry["notes"])
    assert r["status"] != "clean" and any(f["code"] == "probe-failed" for f in entry["findings"])


# ----------------------------------------------------------------------------- issue 32 classes 2 and 7 (audit)


@pytest.mark.parametrize("text,what", [
    ("units si\r\natom_style sphere\rpair_style granular\r\n", "carriage return"),
    ("timestep 1_000e-10\npair_style granular\n", "1_000e-10"),  # Python's float takes it; LAMMPS does not
    ("timestep １e-7\n", "is not a number"),
    ("timestep $(10^400)\n", "overflows"),
    # lines demcheck's reader refuses and LAMMPS reads (the engine read takes over: the deck then lacks a pair_style)
    ("timestep $(" + "(" * 200 + "1" + ")" * 200 + ")\n", "no pair_style"),
    ("variable a string " + "x" * 200_000 + "\n", "no pair_style"),
])
def test_unreadable_lines_are_one_line_exit_2(tmp_path, text, what):
    deck = tmp_path / "in.bad"
    deck.write_bytes(text.encode("utf-8"))
    out = demcheck("audit", str(deck))
    assert out.returncode == 2, out.stdout[-300:] + out.stderr[-2000:]
    assert "Traceback" not in out.stderr and len(out.stderr.strip().splitlines()) == 1 and what in out.stderr
    assert "(34," not in out.stderr and len(out.stderr) < 1000


def test_run_every_shell_is_listed_and_control_characters_are_not_echoed(tmp_path):
    text = TWO_BODY + 'run 10 every 5 "shell touch x"\nprint "\x1b]0;owned\x07\x1b[2J"\n'
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert any("shell touch x" in n["why"] and "never run" in n["why"] for n in r["not_audited"])
    report = A.text_report(r)
    assert "\x1b" not in report and "\x07" not in report


def test_a_trap_size_is_never_measured_from_an_unhealthy_probe(monkeypatch):
    """issue 32 class 8: the wall-moduli trap quoted −48.4 % from a run whose overlap was 1.46e3 R."""
    healthy = {"status": "ok", "restitution": 0.9, "contact_time": 1e-5}
    p = {"angle": 0.0, "speed": 1.0, "engine": healthy, "failure": ""}
    q = {"engine": healthy, "failure": "engine: the largest overlap 1.46 reaches the radius 0.001 (the bodies pass "
                                       "through)"}
    monkeypatch.setattr(A, "probe", lambda *a, **k: q)
    assert A._intended_probe(None, None, p) is None
    monkeypatch.setattr(A, "probe", lambda *a, **k: {"engine": {**healthy, "contact_time": 2e-5}, "failure": ""})
    assert A._intended_probe(None, None, p)["difference"]["contact_time"] == pytest.approx(-0.5)


@pytest.mark.engine("lammps")
def test_an_interrupt_during_an_audit_is_an_interrupt(tmp_path, monkeypatch):
    """issue 32 class 9: an engine stopped by SIGINT/SIGTERM ends the audit (exit 130/143), never a trap."""
    def stopped(*a, **k):
        raise EngineInterrupted("lammps was stopped by the interrupt")

    from demcheck.engines import collide as engine_collide

    monkeypatch.setattr(engine_collide, "collide", stopped)  # the engine's run, as Source.run reaches it
    with pytest.raises(EngineInterrupted):
        A.audit(_deck(tmp_path, TWO_BODY))


def test_create_atoms_defaults_follow_set_type_fraction(tmp_path):
    """LAMMPS's examples/granular in.chute: create_atoms (diameter 1, density 1 by default), then `set group all
    type/fraction 2 …` and `set group t2 diameter 0.6`: type 2 exists, with density 1 — not "no density"."""
    text = """units lj
dimension 2
atom_style sphere
region box block -5 5 0 25 -0.5 0.5
create_box 2 box
lattice sq 2.0
region inner block $(xlo+0.5) $(xhi-0.5) $(ylo+0.5) $(yhi-0.5) EDGE EDGE units box
create_atoms 1 region inner
set group all type/fraction 2 0.5 12393
group t1 type 1
group t2 type 2
set group t1 diameter 0.4
set group t2 diameter 0.6
pair_style granular
pair_coeff * * hertz 1 0.5 tangential linear_history 1.0 0.5 0.1
fix grav all gravity 1e-5 chute 0
fix wall all wall/gran granular hooke 10.0 0.5 tangential linear_history 1.0 0.5 0.1 yplane 0.0 NULL contacts
timestep 0.05
"""
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert r["bodies"][2] == {"radius": 0.3, "density": 1.0, "mass": None, "sizes": []}
    assert r["speed"] == pytest.approx(math.sqrt(2 * 1e-5 * 0.6), rel=1e-12)  # settling: one diameter's fall
    assert r["coverage"]["pairs"]["total"] == 3


def test_pour_of_molecules_sizes_the_spheres_from_the_molecule_file(tmp_path):
    (tmp_path / "molecule.dimer").write_text("# dimer\n\n2 atoms\n\nCoords\n\n1 0 0 0\n2 1 0 0\n\nTypes\n\n1 1\n2 1\n\n"
                                             "Diameters\n\n1 1.0\n2 1.0\n\nMasses\n\n1 0.5\n2 0.5\n")
    text = """dimension 2
atom_style sphere
boundary f fm p
region reg block 0 100 0 50 -0.5 0.5 units box
create_box 1 reg
pair_style gran/hertz/history 4000.0 NULL 100.0 NULL 0.5 0
pair_coeff * *
timestep 0.001
fix 2 all gravity 1.0 spherical 0.0 -180.0
fix ywalls all wall/gran 4000.0 NULL 100.0 NULL 0 1 yplane 0 NULL
molecule object molecule.dimer
region slab block 3.0 97.0 30 34.5 -0.5 0.5 units box
fix ins all pour 500 0 4767548 vol 0.8 10 region slab mol object rigid 3
"""
    r = A.audit(_deck(tmp_path, text), run_engine=False)
    assert r["bodies"][1]["radius"] == 0.5 and r["bodies"][1]["mass"] == 0.5
    assert r["speed"] == pytest.approx(math.sqrt(2 * 1.0 * 34.5), rel=1e-12)  # 2-D: y is up
    assert any("molecule object" in n["why"] for n in r["not_audited"])
