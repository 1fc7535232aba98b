"""demcheck audit on decks written here, with real engine runs: the traps it must find with their measured sizes
(golden values: ENGINES' measured tables, closed forms), a plain deck passing, lines never run, bad lines."""

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from demcheck.comparisons import audit as A
from demcheck.engines.collide import collide
from demcheck.engines.lammps.audit import mixed
from demcheck.engines.base import Native
from demcheck.errors import ConfigError
from demcheck.inputs.script import ScriptError

from .conftest import ROOT
from .helpers import glass_case, write_deck as _deck

DECKS = Path(__file__).parent / "decks"
HEAD = """units si
atom_style sphere
boundary f f f
region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box
create_box {n} box
create_atoms 1 single 0 0 0.005 units box
set type 1 diameter 0.002 density 2500
velocity all set 0 0 -1
timestep 2e-8
"""


def demcheck(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, cwd=cwd)


def _codes(result, pair):
    entry = next(p for p in result["pairs"] if p["pair"] == pair)
    return {f["code"]: f for f in entry["findings"]}, entry


@pytest.mark.engine("lammps")
def test_tsuji_turns_06_into_070(tmp_path):
    """docs/lammps-users.md: LAMMPS 22Jul2025's tsuji gives e = 0.700 for an input of 0.6 (Marshall's α(e) without
    √2); the engine run matches its twin to round-off."""
    deck = _deck(tmp_path, HEAD.format(n=1) + "pair_style granular\npair_coeff * * hertz/material 63e9 0.6 0.24 "
                 "damping tsuji tangential linear_nohistory 0 0\n")
    r = A.audit(deck)
    found, entry = _codes(r, "1-1")
    assert found["tsuji"]["size"]["asked"] == 0.6
    # the table's 0.700 is an ODE value; at 2e-8 s (≈ 330 steps per contact) the scheme adds < 1e-3
    assert found["tsuji"]["size"]["realised"] == pytest.approx(0.700, abs=2e-3)
    assert entry["probes"][0]["engine_vs_twin"] <= 1e-9
    assert entry["probes"][0]["engine"]["version"]
    assert r["traps"] >= 1 and r["engine_version"]


@pytest.mark.engine("liggghts")
def test_limit_force_raises_the_restitution(tmp_path):
    """docs/liggghts-users.md: LIGGGHTS hertz with limitForce on gives 0.550 for an input of 0.5."""
    deck = _deck(tmp_path, HEAD.format(n=1).replace("atom_style sphere", "atom_style granular\ncommunicate single "
                 "vel yes") + "fix m1 all property/global youngsModulus peratomtype 5e8\n"
                 "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
                 "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
                 "pair_style gran model hertz tangential off limitForce on\npair_coeff * *\n")
    r = A.audit(deck)
    found, entry = _codes(r, "1-1")
    assert found["limit"]["size"]["realised"] == pytest.approx(0.550, abs=2e-3)
    assert entry["probes"][0]["engine_vs_twin"] <= 1e-9


@pytest.mark.engine("lammps")
def test_mixing_trap_is_measured(tmp_path):
    """Auto-mixed mindlin NULL between types 1 and 2: k_t too small by 1/(2(1−ν²)) (closed form from the mixing
    rule), and the measured rebound differs from the correctly mixed pair's."""
    text = HEAD.format(n=2) + ("set type 2 diameter 0.003 density 2500\npair_style granular\n"
                               "pair_coeff 1 1 hertz/material 63e9 0.6 0.24 damping coeff_restitution tangential "
                               "mindlin NULL 1.0 0.5\npair_coeff 2 2 hertz/material 63e9 0.6 0.24 damping "
                               "coeff_restitution tangential mindlin NULL 1.0 0.5\n")
    r = A.audit(_deck(tmp_path, text))
    found, entry = _codes(r, "1-2")
    assert found["mixing"]["size"]["kt_ratio"] == pytest.approx(1 / (2 * (1 - 0.24**2)), rel=1e-12)
    worst = max(abs(v) for q in found["mixing"]["size"]["probes"] for v in q["difference"].values())
    assert worst > 0.05  # a measured effect, not round-off
    assert "mixing" not in _codes(r, "1-1")[0]


@pytest.mark.engine("lammps")
def test_the_mixing_rule_is_lammps_own():
    """The explicit equivalent of an auto-mixed pair computes what LAMMPS computes when it mixes (a deck with
    only the I I coefficients): same final velocities to round-off."""
    case = glass_case("hertz", {}, restitution=0.6, overrides=["impact.angle=30.0"])
    spec = {"normal": "hertz/material", "normal_coeffs": (71e9, 0.6, 0.22), "damping": "coeff_restitution",
            "tangential": "mindlin", "tangential_coeffs": (None, 1.0, 0.5), "limit_damping": False}
    own = Native("lammps", "hertz/material", (71e9, 0.22), damping="coeff_restitution", damping_coeff=0.6,
                 tangential="mindlin", tangential_args=(None, 1.0, 0.5))
    auto = collide(case, "lammps", native=own, explicit_pairs=False)
    nat, _, _ = mixed(spec, spec, "test")
    explicit = collide(case, "lammps", native=nat)
    a, b = auto.metrics(), explicit.metrics()
    for k in ("restitution", "tangential_restitution", "rebound_angular_velocity"):
        assert a[k] == pytest.approx(b[k], rel=1e-9), k


@pytest.mark.engine("lammps")
def test_wall_moduli_read_as_pair_values(tmp_path):
    """A wall given the particles' own E: LAMMPS's E* is half a rigid wall's, so the contact lasts 2^(2/5) =
    1.32 times longer (Hertz: t_c ∝ E*^(−2/5))."""
    text = HEAD.format(n=1) + ("pair_style granular\npair_coeff * * hertz/material 63e9 0.9 0.24 damping "
                               "coeff_restitution tangential linear_nohistory 0 0\n"
                               "fix w all wall/gran granular hertz/material 63e9 0.9 0.24 damping coeff_restitution "
                               "tangential linear_nohistory 0 0 zplane 0 NULL\n")
    r = A.audit(_deck(tmp_path, text))
    found, _ = _codes(r, "wall w × 1")
    probe = found["wall-moduli"]["size"]["probes"][0]
    assert probe["deck"]["contact_time"] / probe["intended"]["contact_time"] == pytest.approx(2 ** 0.4, rel=2e-3)


@pytest.mark.engine("lammps")
def test_a_plain_deck_passes_and_shell_lines_are_not_run(tmp_path):
    marker = tmp_path / "touched"
    text = (DECKS / "lammps-plain.in").read_text() + f"shell touch {marker}\npython f here \"\"\"\nimport os\n\"\"\"\n"
    deck = _deck(tmp_path, text)
    out = demcheck("audit", str(deck), "--json")
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr
    r = json.loads(out.stdout)
    assert r["status"] == "clean" and r["traps"] == 0
    entry = r["pairs"][0]
    assert entry["probes"][0]["engine"]["restitution"] == pytest.approx(0.9, abs=2e-3)
    assert entry["time_step"]["dt_error"] < 1e-2 and entry["time_step"]["stability_margin"] > 1
    assert [n["text"].split()[0] for n in r["not_audited"]] == ["shell", "python"]
    assert not marker.exists()


@pytest.mark.parametrize("line,what", [
    ("pair_coeff * * hertz/material 63e9 0.6 0.24 damping tsuji tangential bogus 1 2", "tangential bogus"),
    ("pair_coeff * * hertz/material 63e9 x 0.24 tangential linear_nohistory 0 0", "'x' is not a number"),
    ("jump SELF a", "control flow"), ("include ../../etc/passwd", "outside the deck's directory"),
    ("pair_coeff * * hertz/material 0 0.6 0.24 tangential mindlin NULL 1.0 0.5", "hertz/material E = 0: must be > 0"),
    ("pair_coeff * * hooke 1e5 0.5 tangential mindlin NULL 1.0 0.5", "mindlin NULL: k_t from E and ν needs a material")])
def test_bad_lines_exit_2_with_one_line(tmp_path, line, what):
    deck = _deck(tmp_path, HEAD.format(n=1) + "pair_style granular\n" + line + "\n")
    out = demcheck("audit", str(deck))
    assert out.returncode == 2
    assert len(out.stderr.strip().splitlines()) == 1 and what in out.stderr
    assert "in.deck:11" in out.stderr


def test_no_speed_is_bad_input(tmp_path):
    deck = _deck(tmp_path, HEAD.format(n=1).replace("velocity all set 0 0 -1\n", "") + "pair_style granular\n"
                 "pair_coeff * * hooke 1e5 0.5 tangential linear_nohistory 0 0\n")
    out = demcheck("audit", str(deck))
    assert out.returncode == 2 and "--speed" in out.stderr
    assert math.isfinite(A.characteristic_speed(A.read(deck), 2.0)[0])


def test_models_reverse_lookup():
    """The issue's LAMMPS line: TTIn/TTIt, E* = E/(2(1−ν²)) and k_t = 8G* = 8E/(4(2−ν)(1+ν)) (closed forms), tsuji."""
    out = demcheck("models", "--engine", "lammps", "--json",
                   "hertz/material 63e9 0.6 0.24 damping tsuji tangential mindlin NULL 1.0 0.5")
    assert out.returncode == 0, out.stderr
    r = json.loads(out.stdout)
    assert (r["seed"]["normal"], r["seed"]["tangential"]) == ("tti", "tti")
    assert r["implied"]["E*"] == pytest.approx(63e9 / (2 * (1 - 0.24**2)), rel=1e-12)
    assert float(r["implied"]["kt"].split()[0]) == pytest.approx(8 * 63e9 / (4 * 1.76 * 1.24), rel=1e-5)
    assert [f["code"] for f in r["findings"]] == ["tsuji"]
    bad = demcheck("models", "--engine", "lammps", "hertz/material 63e9 0.6 damping")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1


# ----------------------------------------------------------------------------- every normal family's seed probe

LIGGGHTS_HEAD = HEAD.format(n=1).replace("atom_style sphere", "atom_style granular\ncommunicate single vel yes")
# (pair_coeff or LIGGGHTS's material lines, the seed normal and tangential models it is nearest to, its traps)
PLAIN = {
    "lammps-default-damping": ("pair_style granular\npair_coeff * * hertz/material 63e9 0.6 0.24 tangential mindlin "
                               "NULL 1.0 0.5\n", ("kk", "ddt"), set()),
    "lammps-undamped": ("pair_style granular\npair_coeff * * hertz/material 63e9 0 0.24 tangential mindlin NULL 1.0 "
                        "0.5\n", ("hertz", "ddt"), set()),
    "lammps-coeff-restitution": ("pair_style granular\npair_coeff * * hertz/material 63e9 0.6 0.24 damping "
                                 "coeff_restitution tangential mindlin NULL 1.0 0.5\n", ("tti", "tti"),
                                 # mindlin's Maw history at contact onset has no limit as dt → 0 (docs/benchmarks.md):
                                 # a gap that does not shrink with dt is a model difference, never a dt trap
                                 set()),
    "lammps-hooke-mindlin": ("pair_style granular\npair_coeff * * hooke 1e7 0.5 tangential mindlin 1e9 1.0 0.5\n",
                             ("lsd", "ddt"), set()),
    "liggghts-hertz-e1": ("fix m1 all property/global youngsModulus peratomtype 5e8\n"
                          "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
                          "fix m3 all property/global coefficientRestitution peratomtypepair 1 1.0\n"
                          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n"
                          "pair_style gran model hertz tangential history\npair_coeff * *\n", ("hertz", "ddt"),
                          set()),
    "liggghts-hertz-stiffness": ("fix m1 all property/global kn peratomtypepair 1 4e10\n"
                                 "fix m2 all property/global kt peratomtypepair 1 5e10\n"
                                 "fix m3 all property/global gamman peratomtypepair 1 1e3\n"
                                 "fix m4 all property/global gammat peratomtypepair 1 1e3\n"
                                 "fix m5 all property/global coefficientFriction peratomtypepair 1 0.5\n"
                                 "pair_style gran model hertz/stiffness tangential history\npair_coeff * *\n",
                                 ("kk", "ddt"), set()),
}


@pytest.mark.parametrize("name", list(PLAIN))
def test_a_plain_deck_of_every_normal_family_probes_clean(tmp_path, name):
    """The seed probe of each normal family (Hertz undamped, KK's δ^½ dashpot, TTIn's δ^¼, a linear spring) with a
    δ½-stiffness tangential spring: DDt takes no truncation (Maw's is its only one), TTIt does; every probe runs and
    a deck without a trap reports none (the twin here; the engine in the next test)."""
    text, (normal, tangential), traps = PLAIN[name]
    deck = _deck(tmp_path, (LIGGGHTS_HEAD if name.startswith("liggghts") else HEAD.format(n=1)) + text)
    r = A.audit(deck, run_engine=False)
    (entry,) = r["pairs"]
    assert [p.get("error") for p in entry["probes"]] == [None] * 3, entry["probes"]
    assert (entry["seed"]["normal"], entry["seed"]["tangential"]) == (normal, tangential)
    assert {f["code"] for f in entry["findings"] if f["kind"] == "trap"} == traps, entry["findings"]
    assert r["status"] == ("traps" if traps else "clean")
    if name == "lammps-coeff-restitution":  # issue 28: named a model difference, with both errors
        note = next(n for n in entry["notes"] if n.startswith("model difference"))
        assert "does not shrink" in note and entry["time_step"]["error_shrinks_with_dt"] is False


@pytest.mark.engine("lammps")
def test_audit_of_a_plain_deck_with_default_damping_exits_0(tmp_path):
    """The review's deck: hertz/material with LAMMPS's default damping and mindlin NULL, run in LAMMPS."""
    deck = _deck(tmp_path, HEAD.format(n=1) + PLAIN["lammps-default-damping"][0])
    out = demcheck("audit", str(deck), "--json")
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr
    r = json.loads(out.stdout)
    assert r["status"] == "clean"
    assert all(p["engine_vs_twin"] <= 1e-9 and p["engine"]["status"] == "ok" for p in r["pairs"][0]["probes"])


@pytest.mark.engine("liggghts")
def test_audit_of_liggghts_hertz_and_hertz_stiffness_decks_in_the_engine(tmp_path):
    for name in ("liggghts-hertz-e1", "liggghts-hertz-stiffness"):
        r = A.audit(_deck(tmp_path, LIGGGHTS_HEAD + PLAIN[name][0], name=f"{name}.deck"))
        assert r["status"] == "clean", (name, r["pairs"][0]["findings"])
        assert all(p["engine_vs_twin"] <= 1e-9 for p in r["pairs"][0]["probes"]), name


@pytest.mark.parametrize("engine, line, seed", [
    ("lammps", "hertz/material 63e9 0.6 0.24 tangential mindlin NULL 1.0 0.5", ("kk", "ddt")),
    ("lammps", "hertz/material 63e9 0.6 0.24 damping coeff_restitution tangential mindlin NULL 1.0 0.5", ("tti", "tti")),
    ("lammps", "* * hertz 1e9 0 tangential mindlin 1e9 1.0 0.5", ("hertz", "ddt")),
    ("lammps", "hertz 1e9 0.5 tangential mindlin 1e9 1.0 0.5", ("kk", "ddt")),
    ("lammps", "hooke 1e5 0.5 tangential mindlin 1e5 1.0 0.5", ("lsd", "ddt")),
    ("liggghts", "model hertz tangential history coefficientRestitution=1 coefficientFriction=0.5 "
                 "youngsModulus=63e9 poissonsRatio=0.24 hard_particles=yes", ("hertz", "ddt")),
    ("liggghts", "model hertz/stiffness tangential history kn=1e5 kt=1e5 gamman=1 gammat=1 coefficientFriction=0.5",
     ("kk", "ddt")),
])
def test_reverse_lookup_of_every_normal_family(engine, line, seed):
    r = A.reverse(engine, line)
    assert (r["seed"]["normal"], r["seed"]["tangential"]) == seed
    assert ("truncation" in r["seed"]["params"]) == (seed[1] == "tti")
    assert len(r["probes"]) == 3 and all(math.isfinite(p["gap"]) for p in r["probes"])


# ----------------------------------------------------------------------------- numbers out of range


@pytest.mark.parametrize("line, words", [
    ("hertz/material 0 0.6 0.24 tangential mindlin NULL 1.0 0.5", "hertz/material E = 0: must be > 0"),
    ("hooke 0 0.5 tangential linear_history 1e5 1 0.5", "hooke k_n = 0: must be > 0"),
    ("hooke -1e5 0.5 tangential linear_history 1e5 1 0.5", "hooke k_n = -100000: must be > 0"),
    ("hooke 1e5 -1 tangential linear_history 1e5 1 0.5", "damping viscoelastic η_n0 (the 2nd hooke coefficient) = -1"),
    ("hertz/material 63e9 0 0.24 damping coeff_restitution tangential mindlin NULL 1.0 0.5",
     "damping coeff_restitution e (the 2nd hertz/material coefficient) = 0: must be in (0, 1]"),
    ("hertz/material 63e9 0.6 0.5 damping tsuji tangential mindlin NULL 1.0 0.5", "hertz/material ν = 0.5"),
    ("hertz/material 63e9 0.6 0.24 tangential mindlin NULL -1 0.5", "tangential mindlin x_γ,t = -1: must be >= 0"),
    ("hertz/material 63e9 0.6 0.24 tangential mindlin NULL 1 -0.5", "tangential mindlin μ_s = -0.5: must be >= 0"),
    ("hooke 1e5 0.5 tangential linear_history 0 1 0.5", "tangential linear_history k_t = 0: must be > 0"),
])
def test_lammps_numbers_out_of_range_are_refused_by_their_names(line, words):
    """What would divide by zero or make a law without meaning (a stiffness ≤ 0, a damping or friction < 0, an e
    outside (0, 1], ν outside (−1, 0.5)) is one ConfigError naming LAMMPS's own coefficient and value."""
    with pytest.raises(ConfigError) as err:
        A.reverse("lammps", line)
    assert words in err.value.rule, err.value.rule


def test_lammps_classic_style_numbers_out_of_range(tmp_path):
    text = HEAD.format(n=1) + "pair_style gran/hooke/history 0 NULL 50 NULL 0.5 1\npair_coeff * *\n"
    with pytest.raises(ScriptError, match=r"in.deck:10: .*gran/hooke/history Kn = 0: must be > 0"):
        A.read(_deck(tmp_path, text))
    text = HEAD.format(n=1) + "pair_style gran/hooke 2e5 0 50 NULL 0.5 2\npair_coeff * *\n"
    with pytest.raises(ScriptError, match="dampflag = 2: must be 0 or 1"):
        A.read(_deck(tmp_path, text))
    text = HEAD.format(n=1) + "pair_style gran/hooke 2e5 0 50 NULL 0.5 1\npair_coeff * *\n"  # Kt unread: fine
    assert A.read(_deck(tmp_path, text)).pairs[0].probe


LIGGGHTS_MATERIALS = ("fix m1 all property/global youngsModulus peratomtype 5e8\n"
                      "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
                      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
                      "fix m4 all property/global coefficientFriction peratomtypepair 1 {mu}\n"
                      "pair_style gran model {model} tangential history\npair_coeff * *\n")


def test_liggghts_deck_numbers_out_of_range_name_the_property_line(tmp_path):
    deck = _deck(tmp_path, LIGGGHTS_HEAD + LIGGGHTS_MATERIALS.format(mu=-0.5, model="hertz"))
    out = demcheck("audit", str(deck))
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert "in.deck:14" in out.stderr and "coefficientFriction=-0.5 (types 1 1): must be >= 0" in out.stderr
    # a */stiffness model without its kn, kt, gamman, gammat: LIGGGHTS stops; so does the reader (no silent 0)
    deck = _deck(tmp_path, LIGGGHTS_HEAD + "fix m1 all property/global kn peratomtypepair 1 1e5\n"
                 + LIGGGHTS_MATERIALS.split("\n", 3)[3].format(mu=0.5, model="hooke/stiffness"))
    with pytest.raises(ScriptError, match="model hooke/stiffness needs kt, gamman, gammat"):
        A.read(deck)
    deck = _deck(tmp_path, LIGGGHTS_HEAD + "fix m1 all property/global kn peratomtypepair 1 1e5\n"
                 "fix m2 all property/global kt peratomtypepair 1 1e5\nfix m3 all property/global gamman "
                 "peratomtypepair 1 0\nfix m4 all property/global gammat peratomtypepair 1 1\n"
                 "fix m5 all property/global coefficientFriction peratomtypepair 1 0.5\n"
                 "pair_style gran model hertz/stiffness tangential history\npair_coeff * *\n")
    r = A.audit(deck, run_engine=False)  # gammat > 0 with gamman = 0: no twin; listed, not probed
    assert r["pairs"][0]["probes"] == [] and "no twin" in " ".join(r["pairs"][0]["notes"])


@pytest.mark.engine("lammps")
def test_the_converged_answer_is_the_limit_of_the_twin_with_the_engine_s_rules(tmp_path):
    """The probe's converged answer is the twin's law solved by the adaptive method with LAMMPS's own kinematic rules
    (slip arm at the radius, the history rescaled when significant): the twin stepped at dt/16 lands on it (a first-order
    scheme: ~dt/16 of the twin's own error), where the seed's rules left a floor of 2.4e-4 that no step removed — and
    the audit's time-step error carried it."""
    from demcheck.comparisons.sources import ADAPTIVE, Source
    from demcheck.engines import registry
    from demcheck.engines.mapping import twin_model
    from demcheck.laws.model import resolve

    deck = _deck(tmp_path, HEAD.format(n=1) + "pair_style granular\npair_coeff * * hertz/material 63e9 0.6 0.24 "
                 "damping tsuji tangential mindlin NULL 1.0 0.5\n")
    setup = A.read(deck)
    ps = setup.pairs[0]
    eng = registry.get("lammps")
    nl, tl = eng.twin(ps.native, *A._effective(setup, ps))
    case, dt, _ = A.case_at_step(setup, ps, 1.0, 60.0, nl, tl, A.seed_of(nl, tl, ps.asked))
    conv = A._converged(case, eng, ps.native, dt)
    assert conv.meta["converged_by"] == "the adaptive solver, with the engine's kinematic rules"
    fine = Source.of(eng, twin=True).run(case, dt / 16, native=ps.native).metrics()
    seed_rules = ADAPTIVE.run(case, model=twin_model(resolve(case), ps.native)).metrics()
    for k in ("tangential_restitution", "rebound_angular_velocity"):
        assert abs(fine[k] / conv.metrics()[k] - 1) < 1e-4, k
        assert abs(fine[k] / seed_rules[k] - 1) > 2e-4, k  # what the seed's rules answered (the old converged answer)
