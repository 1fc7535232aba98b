"""A sphere on a wall under gravity, run for real, against the beyond-sliding closed forms and solvers: an
approximate mapping, quantified (the engines' soft contact, dt = 1e-6 s, sampled every 1000 steps). R = 1 mm,
2500 kg/m³, linear normal spring 1e4 N/m (δ/R ≈ 1e-5), tangential spring with μ = 0.5 holding the roll."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from demcheck.engines import discovery
from demcheck.laws.twisting import MarshallTwisting
from demcheck.reference.beyond import rolling_stop_closed, twist_decay

R, RHO, G, KN, V0, MU_R = 1e-3, 2500.0, 9.81, 1e4, 0.2, 0.05
MASS = RHO * 4 / 3 * math.pi * R ** 3
Z0 = R - MASS * G / KN  # at rest on the wall
DISTANCE = 2e-5  # relative: δ/R = 1e-5 (the rolling arm and the contact point) and the 1 ms sampling


def run(tmp_path, engine, deck, data=None):
    (tmp_path / "in.deck").write_text(deck)
    if data:
        (tmp_path / "data.lmp").write_text(data)
    exe = discovery.find(engine).executable
    r = subprocess.run([exe, "-in", "in.deck", "-log", "log.txt", "-screen", "none"], cwd=tmp_path,
                       env=discovery.engine_env(), capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, (tmp_path / "log.txt").read_text(errors="replace")[-2000:]
    rows = np.loadtxt(tmp_path / "out.txt")
    return rows[rows[:, 0].argsort()]


def stop(rows, col):
    """(time, x) where the column (a velocity) first crosses 0, interpolated between samples."""
    k = int(np.argmax(rows[:, col] <= 0.0))
    assert k > 0, "never stopped"
    f = rows[k - 1, col] / (rows[k - 1, col] - rows[k, col])
    return rows[k - 1, 0] + f * (rows[k, 0] - rows[k - 1, 0]), rows[k - 1, 1] + f * (rows[k, 1] - rows[k - 1, 1])


PRINT = 'fix pr all print 1000 "$(step*dt) ${xx} ${vx} ${wz}" file out.txt screen no\n'


@pytest.mark.engine("liggghts")
def test_liggghts_cdt_rolling_stop_against_type_a_closed_form(tmp_path):
    data = (f"roll\n\n1 atoms\n2 atom types\n\n-0.2 0.2 xlo xhi\n-0.01 0.01 ylo yhi\n-0.01 0.01 zlo zhi\n\n"
            f"Atoms\n\n1 1 {2 * R!r} {RHO!r} 0 0 {Z0!r}\n\nVelocities\n\n1 {V0!r} 0 0 0 {V0 / R!r} 0\n")
    pairs = lambda v: f"peratomtypepair 2 {v} {v} {v} {v}"  # noqa: E731
    deck = "\n".join([
        "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
        "communicate single vel yes", "read_data data.lmp", "neighbor 0.001 bin", "neigh_modify delay 0",
        f"fix m1 all property/global kn {pairs(KN)}", f"fix m2 all property/global kt {pairs(2e3)}",
        f"fix m3 all property/global gamman {pairs(2e4)}", f"fix m4 all property/global gammat {pairs(0)}",
        f"fix m5 all property/global coefficientFriction {pairs(0.5)}",
        f"fix m6 all property/global coefficientRollingFriction {pairs(MU_R)}",
        "pair_style gran model hooke/stiffness tangential history rolling_friction cdt", "pair_coeff * *",
        "fix wall all wall/gran model hooke/stiffness tangential history rolling_friction cdt primitive type 2 "
        "zplane 0.0", "fix g all gravity 9.81 vector 0 0 -1", "fix integrate all nve/sphere", "timestep 1e-6",
        "variable xx equal x[1]", "variable vx equal vx[1]", "variable wz equal omegaz[1]", PRINT.strip(),
        "run 650000"]) + "\n"
    rows = run(tmp_path, "liggghts", deck.replace("$(step*dt)", "${tt}").replace(
        "variable xx", "variable tt equal step*dt\nvariable xx"), data)
    t_closed, s_closed = rolling_stop_closed(MU_R, R, R, V0, G)
    t, s = stop(rows, 2)
    assert abs(s / s_closed - 1) < DISTANCE and abs(t / t_closed - 1) < 2e-3
    # measured: s = 0.0570843 m against 0.0570846 m (−5e-6)


@pytest.mark.engine("lammps")
def test_lammps_rolling_sds_on_a_wall_stops_as_type_a(tmp_path):
    coeff = f"hooke {KN!r} 0.2 tangential linear_history 2e3 0 0.5 rolling sds 2e3 0 {MU_R!r} damping velocity"
    deck = "\n".join([
        "units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "comm_modify vel yes",
        "newton off", "region box block -0.2 0.2 -0.01 0.01 -0.01 0.01 units box", "create_box 1 box",
        f"create_atoms 1 single 0 0 {Z0!r} units box",
        f"set atom 1 diameter {2 * R!r} density {RHO!r} omega 0 {V0 / R!r} 0",
        f"velocity all set {V0!r} 0 0 units box", "pair_style granular", f"pair_coeff * * {coeff}",
        f"fix wall all wall/gran granular {coeff} zplane 0.0 NULL", "fix g all gravity 9.81 vector 0 0 -1",
        "fix integrate all nve/sphere", "timestep 1e-6", "variable tt equal step*dt", "variable xx equal x[1]",
        "variable vx equal vx[1]", "variable wz equal 0", PRINT.replace("$(step*dt)", "${tt}").strip(),
        "run 650000"]) + "\n"
    rows = run(tmp_path, "lammps", deck)
    t_closed, s_closed = rolling_stop_closed(MU_R, R, R, V0, G)
    t, s = stop(rows, 2)
    assert abs(s / s_closed - 1) < DISTANCE and abs(t / t_closed - 1) < 2e-3


@pytest.mark.engine("lammps")
def test_lammps_twisting_marshall_on_a_wall_against_the_solver(tmp_path):
    coeff = f"hooke {KN!r} 0.2 tangential linear_history 2e3 0 0.5 twisting marshall damping velocity"
    deck = "\n".join([
        "units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "comm_modify vel yes",
        "newton off", "region box block -0.2 0.2 -0.01 0.01 -0.01 0.01 units box", "create_box 1 box",
        f"create_atoms 1 single 0 0 {Z0!r} units box", f"set atom 1 diameter {2 * R!r} density {RHO!r} omega 0 0 10",
        "pair_style granular", f"pair_coeff * * {coeff}", f"fix wall all wall/gran granular {coeff} zplane 0.0 NULL",
        "fix g all gravity 9.81 vector 0 0 -1", "fix integrate all nve/sphere", "timestep 1e-6",
        "compute om all property/atom omegaz", "compute oms all reduce sum c_om", "variable tt equal step*dt",
        "variable xx equal x[1]", "variable vx equal 0", "variable wz equal c_oms",
        PRINT.replace("$(step*dt)", "${tt}").strip(), "run 450000"]) + "\n"
    rows = run(tmp_path, "lammps", deck)
    t, _ = stop(rows, 3)
    fn = MASS * G
    law = MarshallTwisting(2e3, 0.0, 0.5)
    solver = twist_decay(law.at(math.sqrt(R * fn / KN)), MASS, R, 10.0, fn, 2.0, preloaded=False)
    assert abs(t / solver["twist_stop_time"] - 1) < 1e-4  # measured 0.38218 s against 0.3821827 s
    preloaded = twist_decay(law.at(math.sqrt(R * fn / KN)), MASS, R, 10.0, fn, 2.0)["twist_stop_time"]
    assert t / preloaded - 1 > 1e-3  # the closed form's preloaded spring misses the wind-up


YADE_ROLL = r'''
import math
from yade import utils
O.materials.append(CohFrictMat(young=1e7, poisson=0.3, density=RHO, frictionAngle=math.atan(0.5), isCohesive=False,
                               momentRotationLaw=True, etaRoll=MU_R, alphaKr=2.0, label="m"))
O.bodies.append(utils.box(center=(0, 0, -0.01), extents=(1, 0.1, 0.01), fixed=True, material="m"))
sid = O.bodies.append(utils.sphere((0, 0, R - 1e-9), R, material="m"))
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(), Ig2_Box_Sphere_ScGeom6D()],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True,
                                                                        always_use_moment_law=True)]),
             NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.0)]
O.dt = 1e-6
b = O.bodies[sid]
b.state.vel = (V0, 0, 0)
b.state.angVel = (0, V0 / R, 0)
with open("out.txt", "w") as out:
    for k in range(650):
        O.run(1000, True)
        out.write(f"{O.time!r} {b.state.pos[0]!r} {b.state.vel[0]!r} {b.state.angVel[1]!r}\n")
'''


@pytest.mark.engine("yade")
def test_yade_cohesion_moment_rolls_to_the_type_a_stop_with_mu_r_equal_to_eta_roll(tmp_path):
    """Yade's CohesionMoment (incremental, no cohesion) on a sphere–box contact: its limit is etaRoll·R·|Fn|, so
    after mobilisation it stops as type A with μr = etaRoll (measured: 0.0570841 m against 0.0570846 m)."""
    (tmp_path / "run.py").write_text(f"R, RHO, MU_R, V0 = {R!r}, {RHO!r}, {MU_R!r}, {V0!r}\n" + YADE_ROLL)
    exe = discovery.find("yade").executable
    r = subprocess.run([exe, "-x", "-n", "run.py"], cwd=tmp_path, env=discovery.engine_env(), capture_output=True,
                       text=True, timeout=900)
    assert r.returncode == 0, (r.stdout + r.stderr)[-2000:]
    rows = np.loadtxt(tmp_path / "out.txt")
    t_closed, s_closed = rolling_stop_closed(MU_R, R, R, V0, G)
    t, s = stop(rows, 2)
    # measured: s −8.6e-6, t +2.0e-3 (its last millisecond creeps below 2e-4 m/s: not explained here)
    assert abs(s / s_closed - 1) < DISTANCE and abs(t / t_closed - 1) < 3e-3
