"""Yade packings (engines/yade/packing.py): the script from its fixed template and its guard, the materials it
writes against the case's pair and wall values (Yade's series combination, as Ip2_ViscElMat_ViscElMat_ViscElPhys
computes it), what it refuses, the golden script, and on the binary: the column (a Wall) and the periodic layer
(the Box floor) settled to the static closed forms, the golden script run by hand, and a poured packing whose
contact dump matches its own positions and whose bulk values agree with the reference's."""

import ast
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.case import packing_run
from demcheck.comparisons import packing_metrics as PM
from demcheck.engines import dumps, registry
from demcheck.engines.mapping import pair_mapping
from demcheck.engines.yade import deck as YD, packing as YP
from demcheck.errors import DemcheckError, UnsupportedByEngine
from demcheck.inputs import packing_decks as PD
from demcheck.reference import packing as P

from .conftest import CASES

GOLDEN = Path(__file__).parent / "golden" / "packing-small.yade.py"
# the LAMMPS-family golden decks' small packing: three species (0.6, 0.68 and 1 mm), 30 spheres, 0.1 s
SMALL = (CASES / "optin" / "poured-small-poly.toml",
         ["packing.count=30", "packing.radii=[0.6e-3, 0.68e-3, 1e-3]", "packing.duration=0.1"])
LSD_LAYER = ('normal = "kk"\neta_n = 200.0', 'normal = "lsd"\nkn = 2000.0')


def small_case():
    return C.load(SMALL[0], SMALL[1])


def layer_case(*change):
    text = (CASES / "packing" / "layer-kk.toml").read_text()
    return C.loads(text.replace(*(change or LSD_LAYER)))


def script(case) -> str:
    return registry.get("yade").packing_deck(case).text


def materials(text: str) -> list[dict]:
    """The keyword arguments of every O.materials.append(...) of a script, in order (material ids)."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "append"
                and ast.unparse(node.func.value) == "O.materials"):
            out.append({k.arg: ast.literal_eval(k.value) for k in node.args[0].keywords})
    return out


def assigned(text: str, name: str):
    for node in ast.parse(text).body:
        if isinstance(node, ast.Assign) and ast.unparse(node.targets[0]) == name:
            return ast.literal_eval(node.value)
    return None


# ----------------------------------------------------------------------------- the script and its guard


def test_packing_scripts_pass_their_guard_and_the_engine_dispatches_on_the_first_line():
    text = script(small_case())
    assert YP.is_packing_script(text)
    YP.check_script(text)
    registry.get("yade").check_deck(text)
    assert "NewtonIntegrator(damping=0.0, gravity=G)" in text
    assert f"DT = {float(P.packing_dt(small_case()))!r}\n" in text
    # the collision guard itself is unchanged: a packing script is not a collision script
    with pytest.raises(DemcheckError, match="name 'SAMPLES' is not in the template"):
        YD.check_script(text)


@pytest.mark.parametrize("bad,why", [
    ("import os", "Import"),
    ("__import__('os')", "name '__import__'"),
    ("O.bodies.__class__", "attribute '__class__'"),
    ("out = open('/etc/passwd', 'w')", "string"),
    ("x = 1e400", "finite"),
    ("exec('1')", "name 'exec'"),
    ("O.cell.setBox(1.0, 1.0, 1.0, wire=True)", "keyword 'wire'"),
    ("while True:\n    O.step()", "While"),
    ("x = False", "constant False"),
    ("x = lambda: 0", "Lambda"),
])
def test_the_engine_refuses_what_the_packing_template_does_not_write(bad, why):
    text = script(small_case())
    with pytest.raises(DemcheckError, match=why):
        registry.get("yade").check_deck(text + bad + "\n")


def test_the_guard_refuses_files_and_an_encoding_declaration():
    text = script(small_case())
    with pytest.raises(DemcheckError, match="files"):
        YP.check_script(text, {"data.lmp": "x"})
    lines = text.split("\n")
    with pytest.raises(DemcheckError, match="encoding"):
        YP.check_script("\n".join([lines[0], "# -*- coding: utf-7 -*-"] + lines[2:]))


# ----------------------------------------------------------------------------- materials against the case


def test_combine_is_a_series_combination_that_leaves_a_lone_nonzero_value():
    assert YP.combine(4.0, 4.0) == 2.0
    assert YP.combine(3.0, 6.0) == pytest.approx(2.0, rel=1e-15)
    assert YP.combine(0.0, 5.0) == 5.0 and YP.combine(0.0, 0.0) == 0.0


@pytest.mark.parametrize("which", ["column", "poured-poly"])
def test_materials_give_every_like_pair_and_the_floor_the_case_values(which):
    """Each species' material, combined as Yade combines two (in series), gives its like pair the case's kn,
    cn, ks, cs and μ; with the floor's material (the one its mask lets it touch), the case's wall values."""
    case = C.load(CASES / "packing" / ("column-lsd.toml" if which == "column" else "poured-poly.toml"))
    text = script(case)
    mats = materials(text)
    species, rep = P.species_of(case)
    ns = len(rep)
    masks = assigned(text, "MASK")
    floors = mats[ns:]
    assert len(floors) == (3 if which == "poured-poly" else 1)  # poured-poly: each species' wall cn differs
    for a in range(ns):
        p = pair_mapping(case, "yade", rep[a], rep[a]).native.props
        w = pair_mapping(case, "yade", rep[a], None).native.props
        mine = [g for g in range(len(floors)) if masks is None or masks[a] & (2 << g)]
        assert len(mine) == 1
        floor = floors[mine[0]]
        for k in ("kn", "cn", "ks", "cs"):
            assert YP.combine(mats[a][k], mats[a][k]) == pytest.approx(p[k], rel=1e-15, abs=0.0)
            assert YP.combine(mats[a][k], floor[k]) == pytest.approx(w[k], rel=1e-14, abs=0.0)
        assert math.tan(mats[a]["frictionAngle"]) == pytest.approx(p["mu"], rel=1e-15, abs=1e-300)
        assert math.tan(min(mats[a]["frictionAngle"], floor["frictionAngle"])) == pytest.approx(w["mu"], rel=1e-15,
                                                                                                abs=1e-300)


def test_cross_species_dashpots_are_the_series_combination_and_named_approximate():
    """poured-poly: cn of two species is 2β√(m̄ kn) with the pair's m̄; Yade's series combination of the like
    pairs' is not (+1.37 % for 0.8 mm with 1 mm): the script says so and keeps the like pairs and the floor exact."""
    case = C.load(CASES / "packing" / "poured-poly.toml")
    text = script(case)
    mats = materials(text)
    _, rep = P.species_of(case)
    want = pair_mapping(case, "yade", rep[0], rep[1]).native.props["cn"]
    got = YP.combine(mats[0]["cn"], mats[1]["cn"])
    # cn ∝ √m̄: like pairs √(m/2), the cross pair √(m0 m1/(m0 + m1)), masses as r³ (0.8 and 1 mm)
    q = 0.8**3
    like0, like1 = math.sqrt(q / 2), math.sqrt(1 / 2)
    assert got / want - 1.0 == pytest.approx(2 * like0 * like1 / (like0 + like1) / math.sqrt(q / (1 + q)) - 1.0,
                                             rel=1e-9)
    assert f"species 1 with 2 gets cn = {got:.10g}, the case's is {want:.10g} (+1.37 %)" in text


@pytest.mark.parametrize("change,message", [
    (('eta_n = 200.0', 'eta_n = 200.0'), "yade cannot express this model: Yade's Hertz–Mindlin dashpots grow as δ^¼"),
    (('normal = "kk"\neta_n = 200.0', 'normal = "tti"\nlimit_force = true'),
     "Yade cannot express this packing: Yade's Mindlin gives a wall the sphere's radius (R̄ = R/2) and combines the "
     "moduli in series, so the wall's kno is below twice the like pair's"),
    (('normal = [0.0, 0.0, 1.0]\n\n[contact]\nnormal = "kk"\neta_n = 200.0',
      'normal = [1.0, 0.0, 0.0]\n\n[contact]\nnormal = "lsd"\nkn = 2000.0'),
     "walls.0: a wall normal to a periodic axis (x) is not written for Yade's periodic cell"),
])
def test_what_yade_cannot_express_is_one_clear_line(change, message):
    with pytest.raises(UnsupportedByEngine) as info:
        script(layer_case(*change))
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_the_periodic_floor_is_a_box_and_the_open_floor_a_wall():
    layer = script(layer_case())
    assert "O.periodic = True" in layer and "utils.box(" in layer and "utils.wall(" not in layer
    assert "allowBiggerThanPeriod=True, sortAxis=2" in layer
    assert "a fixed Box whose face is the plane" in layer and "its slip and torque arm" not in layer  # no friction
    assert "its slip and torque arm is R \\u2212 \\u03b4/2" in script(C.load(CASES / "packing" / "poured.toml"))
    column = script(C.load(CASES / "packing" / "column-lsd.toml"))
    assert "utils.wall(0.0, axis=2, sense=1, material=1)" in column and "O.periodic" not in column


# ----------------------------------------------------------------------------- the golden script


def test_generated_packing_script_matches_the_golden_file():
    """The script is reviewed text: a change shows up here (regenerate with DEMCHECK_UPDATE_GOLDEN=1 after
    reading the new script and running it by hand)."""
    text = script(small_case())
    if os.environ.get("DEMCHECK_UPDATE_GOLDEN") == "1":
        GOLDEN.write_text(text)
    assert GOLDEN.read_text() == text


def test_demcheck_deck_writes_the_golden_yade_script(tmp_path):
    sets = [a for s in SMALL[1] for a in ("--set", s)]
    p = subprocess.run([sys.executable, "-m", "demcheck", "deck", str(SMALL[0]), "--engine", "yade", *sets, "-o",
                        str(tmp_path / "run.py")], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "run.py").read_text() == GOLDEN.read_text()
    assert sorted(f.name for f in tmp_path.iterdir()) == ["run.py"]


@pytest.mark.engine("yade")
def test_golden_yade_script_runs_by_hand(tmp_path):
    """A person runs the golden script (yade -x -n run.py): it runs to the end, Yade holds every particle's
    radius and mass as the case's (its own state, dumped), every sphere stays above the floor of its species,
    and the kinetic energy lines and the contact dump read."""
    from demcheck.engines import discovery
    from demcheck.engines.yade.packing import contacts as read_contacts

    case = small_case()
    exe = discovery.find("yade").executable
    shutil.copy(GOLDEN, tmp_path / "run.py")
    p = subprocess.run([exe, "-x", "-n", "run.py"], cwd=tmp_path, capture_output=True, text=True, timeout=600,
                       stdin=subprocess.DEVNULL)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    table = dumps.read_dump(tmp_path / PD.FINAL_DUMP, columns=PD.FINAL_COLUMNS)
    assert table["id"].tolist() == list(range(1, len(case.particles) + 1))
    assert [m == case.mass(k) for k, m in enumerate(table["mass"])] == [True] * len(case.particles)
    assert np.array_equal(table["radius"].to_numpy(), [q.radius for q in case.particles])
    species, _ = P.species_of(case)
    assert table["type"].tolist() == [int(s) + 1 for s in species]
    assert (table["z"] > 0.99 * table["radius"]).all()
    assert ((table[["x", "y"]] >= 0) & (table[["x", "y"]] < case.packing.box[0])).all().all()
    steps = [int(line.split()[0]) for line in p.stdout.splitlines() if line.count(" ") == 2 and line[0].isdigit()]
    n = packing_run(case)[2]
    every = n // 50  # as the LAMMPS-family decks' thermo: every multiple of n // 50 and the last step
    assert steps == [k * every for k in range(n // every + 1)] + ([n] if n % every else [])
    # a monolayer (0 or 1 contacts in every source): most spheres rest on the floor alone, δ = m g / kn
    kn_wall = P.resolve_laws(case)[3]
    for t, group in table.groupby("type"):
        ratio = (group["radius"] - group["z"]) * kn_wall[t - 1][1] / (group["mass"] * 9.81)
        assert np.median(ratio) == pytest.approx(1.0, rel=1e-6), t
    contacts = read_contacts(tmp_path / PD.CONTACT_DUMP)
    assert list(contacts.columns) == list(PD.CONTACT_COLUMNS)


# ----------------------------------------------------------------------------- on the binary


@pytest.mark.engine("yade")
@pytest.mark.parametrize("layout", ["column", "layer"])
def test_yade_settles_the_column_and_the_layer_to_the_closed_form(layout):
    """The column (a Wall; spheres stacked) and the periodic layer (the Box floor; spheres side by side): every
    overlap is the weight it carries over the case's stiffness, δ = F/kn, within 1e-6 — Yade's ViscElPhys at rest
    is kn δ exactly (the clamp and the dashpot act only in motion). The contact dump: each particle pair once,
    the weight above it, the overlap of its own positions."""
    from demcheck.engines.packing import run_engine

    case = C.load(CASES / "packing" / "column-lsd.toml") if layout == "column" else layer_case()
    run = run_engine(case, "yade")
    table, ke = run.table, run.ke
    assert run.version == "2023.02a" and ke and ke[-1][1] < 1e-20
    assert [s for s, _ in ke][:2] == [0, max(1, packing_run(case)[2] // 50)]
    z, r, m, g = table["z"].to_numpy(), 1e-3, case.mass(0), 9.81
    _, laws_n, _, wall_n, _ = P.resolve_laws(case)
    kn_pair, kn_wall = laws_n[0, 0][1], wall_n[0][1]
    if layout == "column":
        n = len(z)
        for k in range(n):
            delta = r - z[0] if k == 0 else 2 * r - (z[k] - z[k - 1])
            assert delta == pytest.approx((n - k) * m * g / (kn_wall if k == 0 else kn_pair), rel=1e-6), k
        c = run.contacts
        assert [tuple(p) for p in c[["i", "j"]].to_numpy()] == [(k, k + 1) for k in range(n - 1)]
        for k in range(n - 1):
            assert c["fn"][k] == pytest.approx((n - 1 - k) * m * g, rel=1e-6), k
            assert c["overlap"][k] == pytest.approx(2 * r - (z[k + 1] - z[k]), rel=1e-9, abs=1e-18), k
            assert c["ft"][k] < 1e-12 * c["fn"][k]
    else:
        assert len(z) == 16 and run.contacts.empty  # side by side, just apart: the floor carries each alone
        np.testing.assert_allclose(r - z, m * g / kn_wall, rtol=1e-6)
        assert (table[["x", "y"]].to_numpy() == np.array([q.position[:2] for q in case.particles])).all()


@pytest.mark.engine("yade")
def test_yade_poured_packing_reads_right_and_agrees_with_the_reference():
    """The opt-in 150-sphere poured packing (periodic, friction): Yade's contact dump against its own final
    positions (an independent path: the same touching pairs by minimum image, each overlap R_i + R_j − |x_j −
    x_i| to 1e-15 m, Fn ≈ kn δ at rest), settled, and its bulk values within verify's tolerances of the
    reference's (solid fraction 0.02, coordination 0.5, the force distributions within the KS critical distance)."""
    from demcheck.comparisons.packing_suite import SETTLED, ks_distance
    from demcheck.engines.packing import run_engine

    case = C.load(CASES / "optin" / "poured-small.toml")
    run = run_engine(case, "yade")
    x, rad = run.table[["x", "y", "z"]].to_numpy(), run.table["radius"].to_numpy()
    box = case.packing.box
    c = run.contacts
    assert len(c) > 200
    pairs = PM.contacts(x, rad, box=tuple(box), tol=0.0)
    assert [tuple(p) for p in c[["i", "j"]].to_numpy()] == [tuple(p) for p in pairs]
    raw = x[c["j"].to_numpy()] - x[c["i"].to_numpy()]
    d = raw.copy()
    for k in range(2):
        d[:, k] -= box[k] * np.floor(d[:, k] / box[k] + 0.5)
    assert (d[:, :2] != raw[:, :2]).any(axis=1).sum() > 5  # contacts across the periodic boundary among them
    np.testing.assert_allclose(c["overlap"], rad[c["i"]] + rad[c["j"]] - np.linalg.norm(d, axis=1), rtol=0,
                               atol=1e-15)
    kn = P.resolve_laws(case)[1][0, 0][1]
    assert np.median(c["fn"] / (kn * c["overlap"])) == pytest.approx(1.0, abs=0.05)
    lift = sum(case.mass(i) for i in range(len(case.particles))) * 9.81 * 2e-3
    assert run.ke[-1][1] / lift < SETTLED
    mine = PM.compute(x, rad, box=box, forces=c["fn"].to_numpy(), overlaps=c["overlap"].to_numpy())
    st = P.simulate(case, rest=0.0)
    nc = min(st.n_contacts, len(st.contacts))
    ref = PM.compute(st.x, st.rad, box=box, forces=st.contacts[:nc, 3], overlaps=st.contacts[:nc, 2])
    assert abs(mine["solid_fraction"] - ref["solid_fraction"]) <= 0.02
    assert abs(mine["coordination_number"] - ref["coordination_number"]) <= 0.5
    dist, crit = ks_distance(c["fn"].to_numpy(), st.contacts[:nc, 3])
    assert dist <= crit


# ----------------------------------------------------------------------------- ViscElMat's tc, en on a wall
#
# Issue 15 item 5. ViscElMat(tc, en, et) calibrates kn, cn from a reduced mass m̄: Yade's ViscoelasticPM.cpp
# gives a body of mass 0 (a wall) the other body's mass, so m̄ = m·m/(m + m) = m/2 on a wall, and each material
# kn = 2 m̄ (π² + ln²e)/tc², cn = −4 m̄ ln e/tc, combined in series: kn = m̄ (π² + ln²e)/tc², cn = −2 m̄ ln e/tc.
# A sphere of mass m on a wall then has half the stiffness and half the dashpot it needs for (tc, en).


def _clamped_lsd(k: float, c: float, m: float) -> tuple[float, float, float]:
    """A linear spring-dashpot m δ'' = −k δ − c δ' whose force is held at ≥ 0 (ViscElPhys), struck at v:
    (restitution, the time its force ends, the time its overlap ends), in closed form. δ = (v/ω) e^{−γt} sin ωt
    (γ = c/2m, ω² = k/m − γ²); the force k δ + c δ' first returns to 0 where tan ωt = −2γω/(ω0² − 2γ²); the body
    leaves with the velocity it has then, and the overlap closes at that speed."""
    g = c / (2.0 * m)
    w0 = math.sqrt(k / m)
    w = math.sqrt(w0 * w0 - g * g)
    t_force = (math.pi - math.atan2(2.0 * g * w, w0 * w0 - 2.0 * g * g)) / w
    delta = math.exp(-g * t_force) * math.sin(w * t_force) / w  # per unit impact speed
    speed = -math.exp(-g * t_force) * (math.cos(w * t_force) - g / w * math.sin(w * t_force))
    return speed, t_force, t_force + delta / speed


@pytest.mark.engine("yade")
@pytest.mark.parametrize("path", ["hertz-wall.toml", "glass-pair.toml"])
@pytest.mark.parametrize("en", [0.5, 0.9])
def test_viscelmat_tc_en_calibrates_a_wall_with_half_the_mass(path, en):
    """ViscElMat(tc, en, et = 1) for a sphere on a wall and for two equal spheres, tc the case's own contact time.
    The rule above, put in a twin (kn, cn of m̄ = m/2 in both cases), runs as Yade does to round-off (≤ 1e-9;
    measured ≤ 2.5e-14); the closed form of that law held at ≥ 0 gives Yade's e within 3e-3 and its times within
    2 dt (its O(dt)). On a wall that is not the calibration's: e 0.646 for en = 0.5 (0.929 for 0.9), the contact
    1.39 tc (1.41 tc) — two spheres get the (held) law they were calibrated for, contact tc within 0.6 %."""
    from demcheck.engines import collide as CO
    from demcheck.engines.base import Native
    from demcheck.engines.mapping import contact_mapping
    from demcheck.engines.yade.mapping import VISCEL

    case = C.load(CASES / path, ["contact.normal=lsd", "contact.limit_force=true", "contact.stiffness_method=duration"])
    wall = len(case.particles) == 1
    m = case.mass(0)
    m_true = m if wall else m / 2.0  # the contact's reduced mass
    tc = math.pi / math.sqrt(contact_mapping(case, "yade").require().props["kn"] / m_true)
    m_yade, le = m / 2.0, math.log(en)  # Yade's m̄: m/2 for both
    k, c = (math.pi**2 + le * le) * m_yade / tc**2, -2.0 * le * m_yade / tc
    nat = Native("yade", normal=VISCEL, tangential="none", limit=True,
                 props={"kn": k, "cn": c, "ks": 0.0, "cs": 0.0, "mu": 0.0, "tc": tc, "en": en, "et": 1.0})
    assert f"ViscElMat(tc={tc!r}, en={en!r}, et=1.0, frictionAngle=0.0, density=1.0)" in CO.deck(case, "yade",
                                                                                                 native=nat).text
    run = CO.collide(case, "yade", native=nat)
    assert run.ok, run.message
    twin = CO.twin_states(case, "yade", run.dt, native=nat)
    a, b = run.metrics(), twin.metrics()
    for q in ("restitution", "contact_time", "force_contact_time", "peak_force", "max_overlap"):
        assert a[q] == pytest.approx(b[q], rel=1e-9), q
    e, t_force, t_contact = _clamped_lsd(k, c, m_true)
    print(f"{path} en = {en}: e {a['restitution']:.6f} (closed form {e:.6f}), force {a['force_contact_time'] / tc:.6f} tc "
          f"({t_force / tc:.6f}), overlap {a['contact_time'] / tc:.6f} tc ({t_contact / tc:.6f})")
    assert a["restitution"] == pytest.approx(e, abs=3e-3)
    assert abs(a["force_contact_time"] - t_force) <= 2.0 * run.dt
    assert abs(a["contact_time"] - t_contact) <= 2.0 * run.dt
    if wall:  # far from what the calibration promises
        assert a["restitution"] - en >= 0.025 and a["contact_time"] / tc >= 1.39
    else:
        assert a["contact_time"] / tc == pytest.approx(1.0, abs=6e-3)


def test_free_text_stays_in_ascii_comments(tmp_path):
    """A case name that tries to end its comment line, and a material name outside ASCII (both in comments), change
    no code line of the script; it still passes its guard."""
    import dataclasses

    text = (CASES / "packing" / "column-lsd.toml").read_text().replace("glass", "gl\u00e4ss")
    case = C.loads(text.replace("[materials.gl\u00e4ss]", '[materials."gl\u00e4ss"]'))
    benign = script(C.load(CASES / "packing" / "column-lsd.toml"))
    for name in ("x\nimport os #", "x\r\nexec('1') #", "x \\", "x\u2028O.run(1) #"):
        bad = script(dataclasses.replace(case, name=name))
        YP.check_script(bad)
        code = [line for line in bad.split("\n") if not line.startswith("#")]
        assert code == [line for line in benign.split("\n") if not line.startswith("#")]
