"""``demcheck audit``'s probes beyond sliding (comparisons/audit_beyond.py): rolling (incline, level plane),
twisting, pull-off and adhesive impact, conduction — at a deck's own parameters, in the engine, its twin and the
closed form. The golden values are closed forms written out here (Ai et al. 2011's incline angle atan μr and the
level-plane stop 7v0/(5μr g); the twist stop Iω0/(μtw m g); JKR's pull-off (3/2)πwR̄ and its breaks δ_c, δ_f;
Batchelor & O'Brien's conductance 2ks a and the lens 2ks√A; τ = 1/(H(1/C0 + 1/C1))), or reference/beyond.py's
closed forms, tested on their own (tests/test_laws_beyond.py)."""

from __future__ import annotations

import math

import pytest

from demcheck.comparisons import audit as A
from demcheck.engines import scenario as sc
from demcheck.errors import DemcheckError
from demcheck.reference.beyond import capture_velocity_closed

from .helpers import write_deck as _deck

LAMMPS_DECK = """# glass beads (type 1) and soft adhesive beads (type 2) poured onto a floor
units           si
atom_style      sphere
boundary        p p f
newton          off
comm_modify     vel yes
region          box block -0.01 0.01 -0.01 0.01 0 0.02 units box
create_box      2 box
pair_style      granular
pair_coeff      * * hertz/material 7e10 0.5 0.22 tangential linear_history 1e5 0 0.5 rolling sds 1e5 0 0.1 twisting sds 1e-3 0 5e-4 heat radius 45.0
pair_coeff      2 2 jkr 5e6 0 0.45 0.025 tangential linear_nohistory 0 0
fix             wall all wall/gran granular hertz/material 7e10 0.5 0.22 tangential linear_history 1e5 0 0.5 rolling sds 1e5 0 0.1 zplane 0 NULL
fix             prop all property/atom temperature heatflow
fix             heat all heat/flow constant 840.0
create_atoms    1 single 0 0 0.004 units box
create_atoms    2 single 0.004 0 0.004 units box
set             type 1 diameter 0.002 density 2500
set             type 2 diameter 0.002 density 1100
fix             gravity all gravity 9.81 vector 0 0 -1
fix             integrate all nve/sphere
timestep        1e-7
run             1000
"""

LIGGGHTS_DECK = """# glass beads rolling on a floor: a linear contact with rolling friction, conducting heat
atom_style	granular
atom_modify	map array
boundary	p p f
newton		off
communicate	single vel yes
units		si
region		reg block -0.05 0.05 -0.05 0.05 0. 0.05 units box
create_box	1 reg
neighbor	0.002 bin
neigh_modify	delay 0
fix 		m1 all property/global kn peratomtypepair 1 1e5
fix 		m2 all property/global kt peratomtypepair 1 1e5
fix 		m3 all property/global gamman peratomtypepair 1 0.0
fix 		m4 all property/global gammat peratomtypepair 1 0.0
fix 		m5 all property/global coefficientFriction peratomtypepair 1 0.3
fix 		m6 all property/global coefficientRollingFriction peratomtypepair 1 0.1
fix 		m7 all property/global youngsModulus peratomtype 5e6
fix 		m8 all property/global poissonsRatio peratomtype 0.3
fix 		m9 all property/global thermalConductivity peratomtype 1.0
fix 		m10 all property/global thermalCapacity peratomtype 840.
pair_style	gran model hooke/stiffness tangential history rolling_friction cdt
pair_coeff	* *
timestep	0.000001
fix		gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix		zwall all wall/gran model hooke/stiffness tangential history rolling_friction cdt primitive type 1 zplane 0.0
fix		heattransfer all heat/gran/conduction initial_temperature 300.
create_atoms	1 single 0.0 0.0 0.01
set		atom 1 diameter 0.00318 density 2500 vx 0.02
fix		integr all nve/sphere
run		1000
"""

G = 9.81


def _rows(report, pair):
    entry = next(p for p in report["pairs"] if p["pair"] == pair)
    return entry, {r["probe"].split(" (")[0]: r for r in entry.get("beyond", [])}


def _codes(entry):
    return {f["code"]: f for f in entry["findings"]}


@pytest.fixture(scope="module")
def lammps_report(tmp_path_factory):
    return A.audit(_deck(tmp_path_factory.mktemp("lmp"), LAMMPS_DECK))


@pytest.mark.engine("lammps")
def test_lammps_rolling_sds_is_probed_on_an_incline_at_its_own_mu(lammps_report):
    """rolling sds k 0 μr (type C without its dashpot, LAMMPS's cap on spring + dashpot): the sphere starts to roll
    at tan θ = μr (Ai et al. 2011) — on the pair and on the wall, engine = twin to round-off."""
    for pair in ("1-1", "wall wall × 1"):
        entry, rows = _rows(lammps_report, pair)
        row = rows["incline"]
        assert row["status"] == "ok" and row["fidelity"] == "exact"
        m = row["metrics"]["incline_critical_angle"]
        assert m["reference"] == pytest.approx(math.atan(0.1), rel=1e-12)
        assert m["engine"] == pytest.approx(math.atan(0.1), rel=1e-3)  # the slope's acceleration, fitted
        assert row["engine_vs_twin"] <= 1e-9


@pytest.mark.engine("lammps")
def test_lammps_twisting_sds_stops_a_spin_at_the_closed_form(lammps_report):
    """twisting sds: a sphere spun at ω0 = v/R stops at t = (2/5)mR²ω0/(μtw m g) (the spring at its limit); LAMMPS's
    spring starts unstretched (docs/findings.md: 2e-4 later)."""
    _, rows = _rows(lammps_report, "1-1")
    row = rows["twist"]
    r, v = 0.001, lammps_report["speed"]
    t_stop = 0.4 * r * r * (v / r) / (5e-4 * G)
    assert row["status"] == "ok"
    assert row["metrics"]["twist_stop_time"]["reference"] == pytest.approx(t_stop, rel=1e-12)
    assert row["metrics"]["twist_stop_time"]["engine"] == pytest.approx(t_stop, rel=1e-3)
    assert row["engine_vs_twin"] <= 1e-9


@pytest.mark.engine("lammps")
def test_lammps_heat_radius_gives_batchelor_obrien_time_constant(lammps_report):
    """heat radius ks: H = 2ks√(R̄δ), τ = 1/(H(2/(m cp))) for the held like pair at the probe's overlap."""
    _, rows = _rows(lammps_report, "1-1")
    row = rows["conduction"]
    delta = row["case"]["run"]["overlap"]
    r = 0.001
    m = 2500 * 4 / 3 * math.pi * r ** 3
    tau = 1.0 / (2 * 45.0 * math.sqrt(r / 2 * delta) * 2 / (m * 840.0))
    assert row["status"] == "ok" and row["fidelity"] == "exact"
    assert row["metrics"]["heat_time_constant"]["engine"] == pytest.approx(tau, rel=1e-3)
    assert row["engine_vs_twin"] <= 1e-9


@pytest.mark.engine("lammps")
def test_lammps_jkr_pull_off_names_the_early_break_with_its_size(lammps_report):
    """jkr E 0 ν γ: the pull-off force (3/2)πwR̄ (w = 2γ) agrees; the contact breaks at the load-controlled δ_c, not
    at the displacement-controlled δ_f: δ_c/δ_f = (1/9)(a_c/a_f)² = 9^(−1/3) = 0.481 — a trap with that size."""
    entry, rows = _rows(lammps_report, "2-2")
    row = rows["pull-off"]
    w, r_eff = 0.05, 0.0005
    assert row["status"] == "ok" and row["fidelity"] == "approximate"
    assert row["metrics"]["pull_off_force"]["engine"] == pytest.approx(1.5 * math.pi * w * r_eff, rel=1e-6)
    assert row["engine_vs_reference"]["separation_at_pull_off"] == pytest.approx(9 ** (-1 / 3), rel=1e-3)
    trap = _codes(entry)["beyond-pull-off"]
    assert trap["size"]["ratios"]["separation_at_pull_off"] == pytest.approx(9 ** (-1 / 3), rel=1e-3)
    assert "0.481×" in trap["text"]


@pytest.mark.engine("lammps")
def test_lammps_jkr_impact_captures_at_the_load_controlled_loop(lammps_report):
    """The adhesive impact at the deck's characteristic speed: the engine's capture velocity is the JKR loop's
    closed to δ_c (Thornton & Ning's energy with LAMMPS's break), 0.70× the textbook's (closed to δ_f)."""
    entry, rows = _rows(lammps_report, "2-2")
    row = rows["adhesive impact"]
    r_eff, w, e_star = 0.0005, 0.05, 5e6 / (2 * (1 - 0.45 ** 2))
    m_eff = 1100 * 4 / 3 * math.pi * 0.001 ** 3 / 2
    v_load = capture_velocity_closed(r_eff, e_star, w, m_eff, "load")
    v_disp = capture_velocity_closed(r_eff, e_star, w, m_eff, "displacement")
    assert row["status"] == "ok"
    assert row["metrics"]["capture_velocity"]["engine"] == pytest.approx(v_load, rel=2e-2)
    assert row["engine_vs_reference"]["capture_velocity"] == pytest.approx(v_load / v_disp, rel=2e-2)
    assert "beyond-adhesive-impact" in _codes(entry)


@pytest.mark.engine("lammps")
def test_lammps_beyond_probes_in_the_text_and_json_report(lammps_report):
    import json

    text = A.text_report(lammps_report)
    assert "beyond: incline (1-1)" in text and "beyond: pull-off (2-2)" in text
    assert "beyond-sliding probes" in text
    cov = json.loads(json.dumps(lammps_report, default=str))["coverage"]["beyond-sliding probes"]
    assert cov["probed"] >= 7 and cov["failed"] == 0


@pytest.mark.engine("liggghts")
def test_liggghts_cdt_rolls_to_its_stop_and_heat_gran_conducts_sqrt_2pi_faster(tmp_path):
    """rolling_friction cdt on hooke/stiffness: the sphere rolling at v0 stops at 7v0/(5μr g) after 7v0²/(10μr g);
    fix heat/gran/conduction: H = 2ks√A over the intersection circle (A = π(Rδ − δ²/4) for like spheres), against
    Batchelor & O'Brien's 2ks√(R̄δ): τ shorter by √A/√(R̄δ) ≈ √(2π) — a trap with that size."""
    r = A.audit(_deck(tmp_path, LIGGGHTS_DECK))
    v0, mu_r = 0.02, 0.1
    for pair in ("1-1", "wall zwall × 1"):
        _, rows = _rows(r, pair)
        row = rows["rolling"]
        assert row["status"] == "ok" and row["engine_vs_twin"] <= 1e-9
        assert row["metrics"]["rolling_stop_time"]["engine"] == pytest.approx(7 * v0 / (5 * mu_r * G), rel=2e-3)
        assert row["metrics"]["rolling_distance"]["engine"] == pytest.approx(7 * v0 ** 2 / (10 * mu_r * G), rel=2e-3)
    entry, rows = _rows(r, "1-1")
    row = rows["conduction"]
    delta, radius = row["case"]["run"]["overlap"], 0.00159
    lens, bo = math.sqrt(math.pi * (radius * delta - delta * delta / 4)), math.sqrt(radius / 2 * delta)
    assert row["status"] == "ok" and row["engine_vs_twin"] <= 1e-9
    assert row["engine_vs_reference"]["heat_time_constant"] == pytest.approx(bo / lens, rel=1e-3)
    assert 1 / row["engine_vs_reference"]["heat_time_constant"] == pytest.approx(math.sqrt(2 * math.pi), rel=1e-2)
    assert _codes(entry)["beyond-conduction"]["size"]["ratios"]["heat_time_constant"] == pytest.approx(bo / lens,
                                                                                                      rel=1e-3)


def test_a_rolling_resistance_above_friction_is_listed_with_its_reason(tmp_path):
    """μr ≥ μs: a sphere slides before it rolls; no incline measures the rolling resistance — listed, never ok."""
    deck = LAMMPS_DECK.replace("rolling sds 1e5 0 0.1 twisting", "rolling sds 1e5 0 0.6 twisting")
    r = A.audit(_deck(tmp_path, deck), run_engine=False)
    _, rows = _rows(r, "1-1")
    assert rows["incline"]["status"] == "not probed"
    assert "slides before it rolls" in rows["incline"]["why"]


COHESION = ("fix 		m10 all property/global thermalCapacity peratomtype 840.",
            "fix 		m10 all property/global thermalCapacity peratomtype 840.\n"
            "fix 		m11 all property/global cohesionEnergyDensity peratomtypepair 1 3e5\n"
            "fix 		m12 all property/global coefficientRestitution peratomtypepair 1 0.9")


def _cohesive(law: str, model: str = "hertz") -> str:
    """The LIGGGHTS deck with ``cohesion LAW`` (kc = 3e5 J/m³) on its pair style, of ``model``."""
    return LIGGGHTS_DECK.replace(*COHESION).replace(
        "rolling_friction cdt\npair_coeff", f"rolling_friction cdt cohesion {law}\npair_coeff").replace(
        "pair_style	gran model hooke/stiffness", f"pair_style	gran model {model}")


def test_sjkr_on_a_linear_law_is_listed_with_its_reason(tmp_path):
    """sjkr's pull-off has its closed form on an elastic Hertz law only: on hooke/stiffness it is listed, with the
    set-up check of its pull."""
    r = A.audit(_deck(tmp_path, _cohesive("sjkr", "hooke/stiffness")), run_engine=False)
    entry, rows = _rows(r, "1-1")
    assert rows["pull-off"]["status"] == "not probed"
    assert "elastic Hertz law" in rows["pull-off"]["why"] and "δ^1" in rows["pull-off"]["why"]
    # the set-up check: kc × the lens π(Rδ − δ²/4) of two like spheres at the head-on probe's largest overlap
    delta, radius = entry["probes"][0]["twin"]["max_overlap"], 0.00159
    pull = 3e5 * math.pi * (radius * delta - delta * delta / 4)
    assert f"the cohesion pulls {pull:.4g}" in rows["pull-off"]["notes"][0]


def test_sjkr_is_probed_by_a_pull_off_at_the_decks_parameters(tmp_path):
    """cohesion sjkr on model hertz: two spheres of the deck's radius, E* = E/(2(1 − ν²)) and kc pulled apart; the
    largest tension against the closed form written out here — (kcπ/2)s² + (3/2)k_H s − kcπR = 0 for s = √δ*,
    F = kcπ(Rs² − s⁴/4) − k_H s³, k_H = (4/3)E*√(R/2) — to 1e-7 (the pull's samples straddle the maximum: 8e-9
    measured); the contact ends at δ = 0, met within 1e-3 of the pull's overlap scale (before: listed, not probed)."""
    r = A.audit(_deck(tmp_path, _cohesive("sjkr")), run_engine=False)
    entry, rows = _rows(r, "1-1")
    row = rows["pull-off"]
    assert row["status"] == "ok", row
    radius, kc, e_star = 0.00159, 3e5, 5e6 / (2.0 * (1.0 - 0.3 ** 2))
    k_h = 4.0 / 3.0 * e_star * math.sqrt(radius / 2.0)
    a, b, c = 0.5 * math.pi * kc, 1.5 * k_h, -math.pi * kc * radius
    s = (-b + math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)
    tension = kc * math.pi * (radius * s * s - s ** 4 / 4.0) - k_h * s ** 3
    assert row["metrics"]["pull_off_force"]["twin"] == pytest.approx(tension, rel=1e-7)
    assert row["metrics"]["pull_off_force"]["reference"] == pytest.approx(tension, rel=1e-12)
    assert row["twin_vs_reference"]["separation_at_pull_off"] == 1.0
    assert not [f for f in entry["findings"] if f["code"].startswith("beyond") and "pull-off" in f["text"]]


@pytest.mark.engine("liggghts")
@pytest.mark.parametrize("law", ["sjkr", "sjkr2"])
def test_liggghts_sjkr_pull_off_probe_meets_its_twin_and_closed_form(tmp_path, law):
    """The probe run in LIGGGHTS: engine = twin ≤ 1e-9 (the mapping's tolerance; 0 and 6e-16 measured), the pull-off
    force within 1e-7 of the closed form (reference/beyond.sjkr_pull_off_closed, tested on its own), no trap."""
    r = A.audit(_deck(tmp_path, _cohesive(law)), run_engine=True)
    entry, rows = _rows(r, "1-1")
    row = rows["pull-off"]
    assert row["status"] == "ok" and row["fidelity"] == "exact", row
    assert row["engine_vs_twin"] <= 1e-9
    f = row["metrics"]["pull_off_force"]
    assert f["engine"] == pytest.approx(f["reference"], rel=1e-7)
    assert not [f for f in entry["findings"] if f["code"].startswith("beyond") and "pull-off" in f["text"]]


def test_sjkr_between_unlike_types_is_listed(tmp_path):
    """Two types of other sizes: the closed form is of like spheres — listed, never probed."""
    deck = _cohesive("sjkr").replace("create_box	1 reg", "create_box	2 reg").replace(
        "peratomtypepair 1 ", "peratomtypepair 2 ")
    deck = (deck.replace("peratomtypepair 2 1e5", "peratomtypepair 2 1e5 1e5 1e5 1e5")
            .replace("peratomtypepair 2 0.0", "peratomtypepair 2 0.0 0.0 0.0 0.0")
            .replace("peratomtypepair 2 0.3", "peratomtypepair 2 0.3 0.3 0.3 0.3")
            .replace("peratomtypepair 2 0.1", "peratomtypepair 2 0.1 0.1 0.1 0.1")
            .replace("peratomtypepair 2 3e5", "peratomtypepair 2 3e5 3e5 3e5 3e5")
            .replace("peratomtypepair 2 0.9", "peratomtypepair 2 0.9 0.9 0.9 0.9")
            .replace("peratomtype 5e6", "peratomtype 5e6 5e6").replace("peratomtype 0.3", "peratomtype 0.3 0.3")
            .replace("peratomtype 1.0", "peratomtype 1.0 1.0").replace("peratomtype 840.", "peratomtype 840. 840.")
            .replace("set		atom 1 diameter 0.00318 density 2500 vx 0.02",
                     "set		atom 1 diameter 0.00318 density 2500 vx 0.02\ncreate_atoms	2 single 0.01 0.0 0.01\n"
                     "set		atom 2 diameter 0.004 density 2500"))
    r = A.audit(_deck(tmp_path, deck), run_engine=False)
    _, rows = _rows(r, "1-2")
    assert rows["pull-off"]["status"] == "not probed"
    assert "like spheres" in rows["pull-off"]["why"]


def test_a_failed_beyond_probe_is_a_trap_never_clean(tmp_path, monkeypatch):
    """A probe whose run fails is a failure: a trap, the deck never clean."""
    def boom(case, engine):
        raise DemcheckError("the engine stopped")

    monkeypatch.setattr(sc, "twin", boom)
    deck = LAMMPS_DECK.replace(" rolling sds 1e5 0 0.1 twisting sds 1e-3 0 5e-4", "").replace(
        " rolling sds 1e5 0 0.1 zplane", " zplane").replace("pair_coeff      2 2 jkr 5e6 0 0.45 0.025 tangential "
                                                            "linear_nohistory 0 0\n", "")
    r = A.audit(_deck(tmp_path, deck), run_engine=False)
    entry, rows = _rows(r, "1-1")
    assert rows["conduction"]["status"] == "failed"
    assert "beyond-probe-failed" in _codes(entry)
    assert r["status"] != "clean"


@pytest.mark.engine("lammps")
def test_a_soft_adhesive_rebound_stays_in_the_lammps_box():
    """in.pour.flatwall's jkr 1000 50 0.3 10 at its pour speed (24.5 σ/τ, R 0.41 σ): the rebound travels far beyond
    4R during the run; the scenario box holds it (LAMMPS stopped with 'Lost atoms' before)."""
    from demcheck.case import from_dict

    r = 24.4949 / 59.265
    case = from_dict({"name": "soft-jkr-impact", "kind": "collision",
                      "materials": {"a": {"density": 1.0, "youngs_modulus": 1000.0, "poisson_ratio": 0.3,
                                          "restitution": 0.9}},
                      "particles": [{"material": "a", "radius": r}, {"material": "a", "radius": r}],
                      "impact": {"speed": 24.4949}, "contact": {"normal": "hertz", "adhesion": "jkr", "w": 20.0},
                      "run": {"scenario": "adhesive_impact"}})
    res = sc.run(case, "lammps")
    assert res.ok, res.message
    assert res.metrics()["restitution"] == pytest.approx(sc.twin(case, "lammps").metrics()["restitution"], rel=1e-9)


def test_a_metal_deck_lists_its_sub_models_unconverted(tmp_path):
    """units metal: the collision probes' coefficients are converted to SI; a rolling sds's are not — listed with
    that reason, never probed with the style's numbers taken as SI."""
    deck = ("units metal\natom_style sphere\nboundary f f f\nregion box block -50 50 -50 50 -50 50 units box\n"
            "create_box 1 box\ncreate_atoms 1 single 0 0 10 units box\nset type 1 diameter 4 density 2.5\n"
            "velocity all set 0 0 -1\nfix gravity all gravity 1e-3 vector 0 0 -1\ntimestep 0.001\n"
            "pair_style granular\npair_coeff * * hertz/material 100 0.5 0.3 tangential linear_history 10 0 0.5 "
            "rolling sds 10 0 0.1\n")
    r = A.audit(_deck(tmp_path, deck), run_engine=False)
    _, rows = _rows(r, "1-1")
    (row,) = rows.values()
    assert row["status"] == "not probed" and "units metal" in row["why"]


@pytest.mark.engine("lammps")
def test_lammps_dmt_pull_off_meets_the_closed_form_and_names_its_sample_tie(tmp_path):
    """dmt E 0 ν γ: pull-off 2πwR̄ at δ = 0 (Derjaguin, Muller & Toporov 1975). The pull's samples land on δ = 0
    exactly, where round-off decides the last touching one: engine and twin one sample apart, noted, never a
    trap of 1e290 (a relative gap against 0) nor an engine − twin of 0 over nothing."""
    deck = LAMMPS_DECK.replace("2 2 jkr 5e6 0 0.45 0.025", "2 2 dmt 5e6 0 0.45 0.025")
    r = A.audit(_deck(tmp_path, deck))
    entry, rows = _rows(r, "2-2")
    row = rows["pull-off"]
    assert row["status"] == "ok" and row["fidelity"] == "exact"
    assert row["metrics"]["pull_off_force"]["engine"] == pytest.approx(2 * math.pi * 0.05 * 0.0005, rel=2e-6)
    assert "beyond-engine-vs-twin" not in _codes(entry) and "beyond-pull-off" not in _codes(entry)
    assert not math.isinf(row["engine_vs_twin"])
    if math.isnan(row["engine_vs_twin"]):
        assert "one sample of the pull apart" in row["notes_run"][0]
