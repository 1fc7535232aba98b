"""Every LAMMPS unit style the audit probes (lj, si, cgs, micro, nano): one physical collision — two 1 mm spheres of
2500 kg/m³, a Hooke spring of 1e5 N/m, e = 0.9, 1 m/s each, dt 20 ns — written in each style's own numbers, read
by the engine and probed in the engine in the deck's units. Dimensionless results agree across styles; the
report's SI values (new: each probe's "si") agree with the SI deck's; lj's numbers are the deck's own (no SI).
Golden conversions: LAMMPS's unit definitions (cgs: cm, g, s; micro: µm, pg, µs; nano: nm, ag, ns); metal and real
are refused with the reason (their force–mass–time constants)."""

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


@pytest.mark.parametrize("style", ["metal", "real"])
def test_metal_and_real_refused_with_the_reason(tmp_path, style):
    p = tmp_path / "in.deck"
    p.write_text(deck("si").replace("units si", f"units {style}"))
    out = subprocess.run([sys.executable, "-m", "demcheck", "audit", "--json", str(p)], capture_output=True, text=True,
                         cwd=ROOT)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert f"units {style}: not audited" in json.loads(out.stdout)["error"]
