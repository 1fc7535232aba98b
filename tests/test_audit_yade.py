"""Issue 31 item 3: `demcheck audit` of a Yade script, read from its syntax tree (never run), in the patterns
Yade's own examples use (ViscElMat with kn/cn/ks/cs given through a dict, `O.bodies.append(sphere(…))`,
`O.bodies[b].state.vel`, `utils.wall`, `O.dt = k * PWaveTimeStep()`, NewtonIntegrator without damping=), probed
with real Yade runs from demcheck's own script. Golden values: Yade's defaults as Yade 2023.02a reports them
(ElastMat young 1e9, NewtonIntegrator damping 0.2) and closed forms written here."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from demcheck.comparisons import audit as A

from .conftest import ROOT

VISCEL = """from yade import utils
import math
R = 0.001
rho = 2500.0
kn = 2.0e4
param = {'kn': kn * 2.0, 'ks': kn * 2.0 * 0.5, 'cn': 0.05 * 2.0, 'cs': 0.0}
mat = O.materials.append(ViscElMat(density=rho, frictionAngle=math.atan(0.4), label='glass', **param))
b1 = O.bodies.append(sphere((0, 0, 0), R, material=mat))
b2 = O.bodies.append(sphere([0, 0, 3 * R], R, material=mat))
O.bodies.append(utils.wall(-2 * R, axis=2, sense=1, material=mat))
O.bodies[b2].state.vel = Vector3(0, 0, -1.0)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                    [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
    NewtonIntegrator(gravity=(0, 0, -9.81)),
]
O.dt = 0.2 * PWaveTimeStep()
O.run(100000, True)
"""

MINDLIN = """young = 7e10
O.materials.append(FrictMat(young=young, poisson=0.22, frictionAngle=0.4, density=2500, label='glass'))
O.bodies.append([sphere((0, 0, 0), 1.5e-3), sphere((0, 0, 3.2e-3), 1.5e-3)])
O.bodies.append(wall(-0.002, axis=2, sense=1))
O.bodies[1].state.vel = (0, 0, -1.0)
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                             [Ip2_FrictMat_FrictMat_MindlinPhys(betan=0.2)], [Law2_ScGeom_MindlinPhys_Mindlin()]),
             NewtonIntegrator(damping=0.0)]
O.dt = 1e-7
"""


def _script(tmp_path, text, name="run.py"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_a_yade_script_is_read_without_running_it(tmp_path):
    """ViscElMat values combined in series (each body carries twice the pair's), μ = tan(frictionAngle), the
    step from PWaveTimeStep (Yade's min r/√(E/ρ) with ElastMat's default young 1e9), NewtonIntegrator's default
    damping 0.2 named, the approach speed of the two placed spheres; the script is never run (it ends with
    O.run, and a marker file it would write stays absent)."""
    marker = tmp_path / "ran"
    setup = A.read(_script(tmp_path, VISCEL + f"open({str(marker)!r}, 'w').write('x')\n"))
    assert not marker.exists()
    assert setup.engine == "yade"
    assert setup.dt == pytest.approx(0.2 * 0.001 / math.sqrt(1e9 / 2500.0), rel=1e-12)
    pair, wall = setup.pairs
    assert (pair.j, wall.j) == (1, None)
    for ps in (pair, wall):
        assert ps.native.normal == "ViscElPhys" and ps.native.tangential == "spring"
        assert ps.native.props["kn"] == pytest.approx(2.0e4) and ps.native.props["cn"] == pytest.approx(0.05)
        assert ps.native.props["ks"] == pytest.approx(1.0e4) and ps.native.props["mu"] == pytest.approx(0.4)
    assert wall.asked == {"friction": pytest.approx(0.4)} and pair.asked == {}  # pair: head-on only (its note)
    damping = [f for f in setup.findings if f.code == "newton-damping"]
    assert damping and damping[0].size["damping"] == 0.2 and "default" in damping[0].text
    assert A.characteristic_speed(setup, None)[0] == pytest.approx(1.0)


@pytest.mark.engine("yade")
def test_a_yade_script_is_audited_with_yade_runs(tmp_path):
    """Real Yade runs: every probe of the ViscElPhys pair (head-on) and wall (0°, 30°, 60°) equals its twin to
    1e-9; the realised restitution is the linear spring-dashpot's held at ≥ 0 (closed form here, to 2e-3)."""
    r = A.audit(_script(tmp_path, VISCEL))
    assert r["coverage"]["pairs"]["probed"] == 1 and r["coverage"]["walls"]["probed"] == 1
    wall = next(p for p in r["pairs"] if p["wall"])
    assert [q["angle"] for q in wall["probes"]] == [0.0, 30.0, 60.0]
    for p in r["pairs"]:
        for q in p["probes"]:
            assert q["engine"]["status"] == "ok" and q["engine_vs_twin"] <= 1e-9, (p["pair"], q)
    # a sphere on the wall: m = ρ 4/3 π R³, k = 2e4, c = 0.05; e of a spring-dashpot held at ≥ 0
    m = 2500.0 * 4.0 / 3.0 * math.pi * 1e-9
    assert wall["probes"][0]["engine"]["restitution"] == pytest.approx(_held_restitution(2.0e4, 0.05, m), abs=2e-3)


def _held_restitution(k: float, c: float, m: float) -> float:
    """A linear spring-dashpot (k, c) on a body of mass m whose force is held at ≥ 0: the closed form (the body
    leaves where k δ + c δ' = 0 on unloading, with the speed it has then)."""
    w0, g = math.sqrt(k / m), c / (2.0 * m)
    w = math.sqrt(w0 * w0 - g * g)
    t_end = (math.pi - math.atan2(2 * g * w, w0 * w0 - 2 * g * g)) / w
    return abs(math.exp(-g * t_end) * (math.cos(w * t_end) * w - g * math.sin(w * t_end)) / w)


@pytest.mark.engine("yade")
def test_viscelmat_tc_en_on_a_wall_is_found_as_a_restitution_trap(tmp_path):
    """ViscElMat(tc, en) calibrates with m̄ = m/2 on a wall (Yade gives the wall the sphere's mass): the audit
    asks for en = 0.5 and finds the wall's realised e — the closed form of kn = m̄(π² + ln²en)/tc², cn =
    −2m̄ ln en/tc on the whole mass m, held at ≥ 0: 0.646 (docs/yade.md measured 0.6458) — a restitution trap;
    the engine equals its twin to 1e-9."""
    text = VISCEL.replace("param = {'kn': kn * 2.0, 'ks': kn * 2.0 * 0.5, 'cn': 0.05 * 2.0, 'cs': 0.0}",
                          "param = {'tc': 5e-5, 'en': 0.5, 'et': 1.0}")
    r = A.audit(_script(tmp_path, text))
    wall = next(p for p in r["pairs"] if p["wall"])
    q = wall["probes"][0]
    assert q["engine_vs_twin"] <= 1e-9
    m = 2500.0 * 4.0 / 3.0 * math.pi * 1e-9
    ln = math.log(0.5)
    e_closed = _held_restitution(m / 2 * (math.pi ** 2 + ln * ln) / 5e-5 ** 2, -2 * (m / 2) * ln / 5e-5, m)
    assert e_closed == pytest.approx(0.646, abs=1e-3)
    assert q["engine"]["restitution"] == pytest.approx(e_closed, abs=2e-3)
    trap = [f for f in wall["findings"] if f["code"] == "restitution"]
    assert trap and trap[0]["size"]["asked"] == 0.5


@pytest.mark.engine("yade")
def test_yade_mindlin_is_audited_with_its_normal_law(tmp_path):
    """FrictMat + Ip2_FrictMat_FrictMat_MindlinPhys(betan) + Law2_ScGeom_MindlinPhys_Mindlin: kno = (4/3)E*√R̄
    with Yade's R̄ (a wall: R/2), probed head-on; the engine equals its twin to 1e-9; friction not probed."""
    setup = A.read(_script(tmp_path, MINDLIN))
    pair, wall = setup.pairs
    e_star = 7e10 / (2 * (1 - 0.22 ** 2))
    assert pair.native.props["kno"] == pytest.approx(4 / 3 * e_star * math.sqrt(0.75e-3), rel=1e-12)
    assert wall.native.props["kno"] == pytest.approx(4 / 3 * e_star * math.sqrt(0.75e-3), rel=1e-12)
    r = A.audit(_script(tmp_path, MINDLIN))
    for p in r["pairs"]:
        assert p["probed"] and len(p["probes"]) == 1
        assert p["probes"][0]["engine_vs_twin"] <= 1e-9


CUNDALL = MINDLIN.replace("Ip2_FrictMat_FrictMat_MindlinPhys(betan=0.2)", "Ip2_FrictMat_FrictMat_FrictPhys()") \
    .replace("Law2_ScGeom_MindlinPhys_Mindlin()", "Law2_ScGeom_FrictPhys_CundallStrack()") \
    .replace("young = 7e10", "young = 1e7").replace("O.dt = 1e-7", "O.dt = 1e-6")


@pytest.mark.engine("yade")
def test_cundall_strack_normal_law_is_probed_with_yades_own_stiffness(tmp_path):
    """Law2_ScGeom_FrictPhys_CundallStrack: the reader's kn and ks are the ones Yade's Ip2_FrictMat_FrictMat_
    FrictPhys computes — read from Yade itself (a script of this test, stepped once, printing each interaction's
    phys.kn and phys.ks) for the pair and the wall; the head-on probes equal their twin to 1e-9; the shear law is
    listed, not probed (no twin of it matches a Yade run yet)."""
    from demcheck.engines import discovery

    probe = tmp_path / "kn.py"
    probe.write_text(CUNDALL.replace("sphere((0, 0, 3.2e-3), 1.5e-3)", "sphere((0, 0, 2.99e-3), 1.5e-3)")
                     .replace("wall(-0.002,", "wall(-1.49e-3,") + "O.step()\nfor i in O.interactions:\n"
                     "    print('PHYS', min(i.id1, i.id2), max(i.id1, i.id2), repr(i.phys.kn), repr(i.phys.ks))\n")
    out = subprocess.run([discovery.find("yade").executable, "-x", "-n", str(probe)], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    phys = {(int(w[1]), int(w[2])): (float(w[3]), float(w[4])) for w in (ln.split() for ln in out.stdout.splitlines())
            if w and w[0] == "PHYS"}
    assert set(phys) == {(0, 1), (0, 2)}, out.stdout + out.stderr
    setup = A.read(_script(tmp_path, CUNDALL))
    pair, wall = setup.pairs
    assert (pair.native.props["kn"], pair.native.props["ks"]) == pytest.approx(phys[(0, 1)], rel=1e-12)
    assert (wall.native.props["kn"], wall.native.props["ks"]) == pytest.approx(phys[(0, 2)], rel=1e-12)
    r = A.audit(_script(tmp_path, CUNDALL))
    for p in r["pairs"]:
        assert p["probed"] and len(p["probes"]) == 1 and p["probes"][0]["engine_vs_twin"] <= 1e-9
        assert any("CundallStrack" in n and "not" in n for n in p["notes"])


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, cwd=ROOT)


@pytest.mark.parametrize("text, word", [("O.dt = = 1\n", "parse"), (VISCEL.replace("0.2 * PWaveTimeStep()", "-1e-6"),
                                                                     "O.dt"),
                                        (VISCEL.replace("'cs': 0.0", "'cs': -1.0"), "cs")])
def test_a_bad_script_is_one_line_and_exit_2(tmp_path, text, word):
    out = _cli("audit", str(_script(tmp_path, text)))
    assert out.returncode == 2, out.stdout + out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and word in out.stderr


@pytest.mark.engine("yade")
def test_newton_damping_is_measured_in_yade(tmp_path):
    """NewtonIntegrator() without damping= is Yade's damping 0.2: the audit runs the head-on probe again in Yade
    with it. For an undamped linear contact (cn = 0) the energy argument — the force ×1.2 while approaching,
    ×0.8 while separating — gives e = √(0.8/1.2) = 0.8165 (to the step's O(dt): 3e-3); the trap carries both."""
    text = VISCEL.replace("'cn': 0.05 * 2.0", "'cn': 0.0")
    r = A.audit(_script(tmp_path, text))
    for p in r["pairs"]:
        trap = [f for f in p["findings"] if f["code"] == "newton-damping"]
        assert trap and trap[0]["kind"] == "trap", p["findings"]
        size = trap[0]["size"]
        assert size["damping"] == 0.2 and size["restitution"] == pytest.approx(1.0, abs=3e-3)
        assert size["with_damping"] == pytest.approx(math.sqrt(0.8 / 1.2), abs=3e-3)
    assert r["traps"] >= 2
