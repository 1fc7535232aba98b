"""LAMMPS's rolling, twisting, adhesion and heat sub-models against the beyond-sliding laws, run for real: two
spheres (R = 1 mm, 2500 kg/m³) on the x axis, stepped by the engine and by reference.beyond.verlet_pair (the
engine's scheme) at the same dt; every per-atom position, velocity, angular velocity, force, torque, temperature
and heat flow agrees to ≤ 1e-9 relative (measured: ≤ 3e-12; the JKR contact radius is found by Newton in the
reference and in closed form in the engine). Each run reaches the sub-model's limit where it has one (asserted),
so the limiting rule is compared, not only the spring."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from demcheck.engines import discovery
from demcheck.laws.adhesion import BREAK_LOAD, DmtAdhesion, JkrAdhesion
from demcheck.laws.heat import AreaHeat, RadiusHeat
from demcheck.laws.rolling import CAP_TOTAL, EpsdRolling
from demcheck.laws.twisting import MarshallTwisting, SdsTwisting
from demcheck.reference.beyond import verlet_pair

pytestmark = pytest.mark.engine("lammps")

R, RHO, RBAR, DT = 1e-3, 2500.0, 5e-4, 1e-7
E, NU, GAMMA = 1e8, 0.3, 0.05  # LAMMPS's γ: the work of adhesion is w = 2γ
E_STAR = E / (2 * (1 - NU * NU))


def run_lammps(tmp_path, coeff, x1, v1, w0, w1, steps, heat_cp=None):
    heat = heat_cp is not None
    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "comm_modify vel yes",
             "newton off", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
             *(["fix prop all property/atom temperature heatflow ghost yes"] if heat else []),
             "create_atoms 1 single 0 0 0", f"create_atoms 1 single {x1!r} 0 0",
             f"set atom 1 diameter {2 * R!r} density {RHO!r} omega {w0[0]!r} {w0[1]!r} {w0[2]!r}",
             f"set atom 2 diameter {2 * R!r} density {RHO!r} omega {w1[0]!r} {w1[1]!r} {w1[2]!r}",
             "velocity all set 0 0 0", f"set atom 2 vx {v1!r}",
             *(["set atom 1 temperature 300", "set atom 2 temperature 400"] if heat else []),
             "pair_style granular", f"pair_coeff * * {coeff}", "fix 1 all nve/sphere",
             *([f"fix 2 all heat/flow constant {heat_cp!r}",
                "compute th all property/atom temperature heatflow"] if heat else []),
             f"timestep {DT!r}",
             "dump d all custom 1 out.dump id x y z vx vy vz omegax omegay omegaz fx fy fz tqx tqy tqz"
             + (" c_th[1] c_th[2]" if heat else ""),
             "dump_modify d format float %.17g sort id", f"run {steps}"]
    (tmp_path / "in.deck").write_text("\n".join(lines) + "\n")
    exe = discovery.find("lammps").executable
    r = subprocess.run([exe, "-in", "in.deck", "-log", "log.txt", "-screen", "none"], cwd=tmp_path,
                       env=discovery.engine_env(), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (tmp_path / "log.txt").read_text()[-2000:]
    frames = []
    for block in (tmp_path / "out.dump").read_text().split("ITEM: TIMESTEP\n")[1:]:
        rows = block.strip().split("\n")
        k = next(i for i, row in enumerate(rows) if row.startswith("ITEM: ATOMS"))
        frames.append(np.array([[float(v) for v in row.split()] for row in rows[k + 1:]]))
    return np.array(frames)[1:]  # the steps after the set-up


def assert_twin(engine, ref, heat=False):
    cols = {"x": 1, "v": 4, "omega": 7, "f": 10, "torque": 13}
    for key, c in cols.items():
        got, want = engine[:, :, c:c + 3], ref[key]
        scale = R if key == "x" else max(np.abs(got).max(), 1e-300)
        assert np.abs(got - want).max() <= 1e-9 * scale, key
    if heat:
        assert np.abs(engine[:, :, 16] - ref["T"]).max() <= 1e-9 * 100.0
        assert np.abs(engine[:, 0, 17] - ref["Q"]).max() <= 1e-9 * np.abs(engine[:, 0, 17]).max()


def test_rolling_sds_is_type_c_with_the_limit_on_spring_and_dashpot(tmp_path):
    w0, w1, mu = [0.0, 30.0, 5.0], [0.0, -10.0, 40.0], 0.002
    eng = run_lammps(tmp_path, f"hooke 1e4 0 tangential linear_nohistory 0 0 rolling sds 2e3 0.3 {mu}",
                     0.0019, 0.0, w0, w1, 300)
    law = EpsdRolling(mu, RBAR, 2e3 * RBAR ** 2, 0.3 * RBAR ** 2, CAP_TOTAL, slack_zero=True)
    ref = verlet_pair(R, RHO, 0.0019, 0.0, w0, w1, DT, 300, kn=1e4, rolling=law)
    fn = np.abs(ref["f"][:, 0, 0])
    assert np.any(np.linalg.norm(ref["torque"][:, 0], axis=1) >= mu * RBAR * fn * (1 - 1e-12))  # at its limit
    assert_twin(eng, ref)
    # without the engine's set-up rule (no torque while the unstretched spring is over the limit) it is not exact
    plain = verlet_pair(R, RHO, 0.0019, 0.0, w0, w1, DT, 300, kn=1e4,
                        rolling=EpsdRolling(mu, RBAR, 2e3 * RBAR ** 2, 0.3 * RBAR ** 2, CAP_TOTAL))
    assert np.abs(plain["omega"] - eng[:, :, 7:10]).max() > 1e-6 * np.abs(eng[:, :, 7:10]).max()


@pytest.mark.parametrize("marshall", [False, True])
def test_twisting_sds_and_marshall(tmp_path, marshall):
    w0, w1 = ([3000.0, 0, 0], [-2000.0, 0, 0]) if marshall else ([300.0, 0, 0], [-200.0, 0, 0])
    twist = "tangential linear_history 200 0 0.001 twisting marshall" if marshall else \
        "tangential linear_nohistory 0 0 twisting sds 1e-4 1e-8 2e-6"
    eng = run_lammps(tmp_path, f"hooke 1e4 0 {twist}", 0.0019, 0.0, w0, w1, 300)
    kw = {"twisting": MarshallTwisting(200.0, 0.0, 0.001) if marshall else SdsTwisting(1e-4, 1e-8, 2e-6)}
    ref = verlet_pair(R, RHO, 0.0019, 0.0, w0, w1, DT, 300, kn=1e4, **kw)
    assert_twin(eng, ref)
    fn = np.abs(ref["f"][:, 0, 0])
    delta = 2 * R - (ref["x"][:, 1, 0] - ref["x"][:, 0, 0])
    limit = (2 / 3 * np.sqrt(RBAR * delta) * 0.001 if marshall else 2e-6) * fn
    assert np.any(np.abs(ref["torque"][:, 0, 0]) >= limit * (1 - 1e-12))


@pytest.mark.parametrize("model,v1,break_at", [("jkr", -0.003, BREAK_LOAD), ("jkr", -0.02, BREAK_LOAD),
                                               ("dmt", -0.02, 0)])
def test_jkr_and_dmt_impacts(tmp_path, model, v1, break_at):
    steps = 6000 if v1 == -0.003 else 4000
    eng = run_lammps(tmp_path, f"{model} {E!r} 0 {NU!r} {GAMMA!r} tangential linear_nohistory 0 0",
                     2 * R + 1e-6, v1, [0, 0, 0], [0, 0, 0], steps)
    law = (JkrAdhesion(RBAR, E_STAR, 2 * GAMMA, break_at) if model == "jkr" else DmtAdhesion(RBAR, E_STAR, 2 * GAMMA))
    ref = verlet_pair(R, RHO, 2 * R + 1e-6, v1, [0, 0, 0], [0, 0, 0], DT, steps, adhesion=law)
    assert_twin(eng, ref)
    assert np.any(ref["f"][:, 1, 0] < 0)  # the attraction acted


def test_jkr_breaks_at_the_load_controlled_pull_off_not_at_the_displacement_controlled_one(tmp_path):
    """The engine ends a JKR contact at δ_c = −a_c²/(3R̄) (F = −(3/2)πwR̄), not at δ_f = −3a_f²/R̄: the twin with
    the textbook break (δ_f) differs, and the engine's restitution sits near the closed form for δ_c."""
    from demcheck.reference.beyond import adhesive_restitution_closed, capture_velocity_closed

    eng = run_lammps(tmp_path, f"jkr {E!r} 0 {NU!r} {GAMMA!r} tangential linear_nohistory 0 0",
                     2 * R + 1e-6, -0.02, [0, 0, 0], [0, 0, 0], 4000)
    textbook = verlet_pair(R, RHO, 2 * R + 1e-6, -0.02, [0, 0, 0], [0, 0, 0], DT, 4000,
                           adhesion=JkrAdhesion(RBAR, E_STAR, 2 * GAMMA))
    e_engine = (eng[-1, 1, 4] - eng[-1, 0, 4]) / 0.02
    e_textbook = (textbook["v"][-1, 1, 0] - textbook["v"][-1, 0, 0]) / 0.02
    m_eff = RHO * 4 / 3 * math.pi * R ** 3 / 2
    closed = {b: adhesive_restitution_closed(0.02, capture_velocity_closed(RBAR, E_STAR, 2 * GAMMA, m_eff, b))
              for b in ("displacement", "load")}
    assert abs(e_engine - closed["load"]) < 5e-4 and abs(e_textbook - closed["displacement"]) < 5e-4
    assert e_engine - e_textbook > 0.009


@pytest.mark.parametrize("mode,law", [("area 10", AreaHeat(10.0, RBAR)), ("radius 10", RadiusHeat(10.0, RBAR))])
def test_heat_area_and_radius(tmp_path, mode, law):
    eng = run_lammps(tmp_path, f"hooke 1e4 0 tangential linear_nohistory 0 0 heat {mode}", 0.0019, 0.0,
                     [0, 0, 0], [0, 0, 0], 300, heat_cp=800.0)
    ref = verlet_pair(R, RHO, 0.0019, 0.0, [0, 0, 0], [0, 0, 0], DT, 300, kn=1e4, heat=law, cp=800.0)
    assert_twin(eng, ref, heat=True)


def test_jkr_quasi_static_pull_off(tmp_path):
    """Body 1 pulled away at 1 mm/s (fix move: the overlap is imposed) from δ = 1e-7 m: the largest tension is
    (3/2)πwR̄ (measured 7e-10 from it) and the contact breaks at δ_c = −a_c²/(3R̄) = −9.1506e-8 m (between two
    samples 1e-10 m apart), where the textbook's imposed-displacement break is δ_f = −1.903e-7 m: the pull_off
    scenario solved by reference.beyond.pull_off with break_at = load."""
    from demcheck.reference.beyond import pull_off

    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "comm_modify vel yes",
             "newton off", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
             "create_atoms 1 single 0 0 0", f"create_atoms 1 single {2 * R - 1e-7!r} 0 0",
             f"set atom * diameter {2 * R!r} density {RHO!r}", "group a1 id 1", "group a2 id 2",
             "pair_style granular", f"pair_coeff * * jkr {E!r} 0 {NU!r} {GAMMA!r} tangential linear_nohistory 0 0",
             "fix m1 a1 move linear 0 0 0", "fix m2 a2 move linear 0.001 0 0", "timestep 1e-8",
             "dump d all custom 10 out.dump id x fx", "dump_modify d format float %.17g sort id", "run 21000"]
    (tmp_path / "in.deck").write_text("\n".join(lines) + "\n")
    r = subprocess.run([discovery.find("lammps").executable, "-in", "in.deck", "-log", "log.txt", "-screen", "none"],
                       cwd=tmp_path, env=discovery.engine_env(), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (tmp_path / "log.txt").read_text()[-2000:]
    rows = []
    for block in (tmp_path / "out.dump").read_text().split("ITEM: TIMESTEP\n")[1:]:
        lines_ = block.strip().split("\n")
        k = next(i for i, row in enumerate(lines_) if row.startswith("ITEM: ATOMS"))
        atoms = np.array([[float(v) for v in row.split()] for row in lines_[k + 1:]])
        rows.append((2 * R - (atoms[1, 1] - atoms[0, 1]), atoms[1, 2]))
    rows = np.array(rows)
    touching = np.nonzero(rows[:, 1])[0]
    assert touching[-1] + 1 < len(rows)  # it broke within the run
    ref = pull_off(JkrAdhesion(RBAR, E_STAR, 2 * GAMMA, BREAK_LOAD))
    assert abs(-rows[:, 1].min() / ref["pull_off_force"] - 1) < 1e-8
    assert rows[touching[-1], 0] >= ref["separation_at_pull_off"] > rows[touching[-1] + 1, 0]
    textbook = JkrAdhesion(RBAR, E_STAR, 2 * GAMMA).separation_at_pull_off()  # δ_f
    assert abs(ref["separation_at_pull_off"] / textbook - 9 ** (-1 / 3)) < 1e-12  # δ_c/δ_f = (1/9)(a_c/a_f)²
    assert rows[touching[-1] + 1, 0] > textbook  # the engine broke well before δ_f


def test_heat_time_constant_of_two_held_spheres(tmp_path):
    """Two spheres held at δ = 1e-4 m (fix move), `heat radius 10`, c_p = 800: the temperature difference decays
    by (1 − dt/τ) a step (explicit Euler, to 1e-12) and so follows the conduction scenario's exp(−t/τ),
    τ = 1/(H(1/C0 + 1/C1)) = 0.937 s, to dt/(2τ)·t/τ (here < 2e-4)."""
    from demcheck.reference.beyond import conduction, heat_time_constant_closed

    dt, steps, every = 1e-4, 20000, 1000
    lines = ["units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "comm_modify vel yes",
             "newton off", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 1 box",
             "fix prop all property/atom temperature heatflow ghost yes",
             "create_atoms 1 single 0 0 0", f"create_atoms 1 single {2 * R - 1e-4!r} 0 0",
             f"set atom * diameter {2 * R!r} density {RHO!r}", "set atom 1 temperature 300",
             "set atom 2 temperature 400", "pair_style granular",
             "pair_coeff * * hooke 1e4 0 tangential linear_nohistory 0 0 heat radius 10",
             "fix m all move linear 0 0 0", "fix h all heat/flow constant 800",
             "compute th all property/atom temperature", f"timestep {dt!r}",
             f"dump d all custom {every} out.dump id c_th", "dump_modify d format float %.17g sort id",
             f"run {steps}"]
    (tmp_path / "in.deck").write_text("\n".join(lines) + "\n")
    r = subprocess.run([discovery.find("lammps").executable, "-in", "in.deck", "-log", "log.txt", "-screen", "none"],
                       cwd=tmp_path, env=discovery.engine_env(), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (tmp_path / "log.txt").read_text()[-2000:]
    diff = []
    for block in (tmp_path / "out.dump").read_text().split("ITEM: TIMESTEP\n")[1:]:
        lines_ = block.strip().split("\n")
        k = next(i for i, row in enumerate(lines_) if row.startswith("ITEM: ATOMS"))
        temps = [float(row.split()[1]) for row in lines_[k + 1:]]
        diff.append(temps[1] - temps[0])
    diff = np.array(diff)
    mass = RHO * 4 / 3 * math.pi * R ** 3
    law = RadiusHeat(10.0, RBAR)
    scenario = conduction(law, 1e-4, mass * 800, mass * 800, 300.0, 400.0, 10.0)
    tau = heat_time_constant_closed(scenario["conductance"], mass * 800, mass * 800)
    assert abs(scenario["heat_time_constant"] / tau - 1) < 1e-9
    n = np.arange(len(diff)) * every
    np.testing.assert_allclose(diff, 100.0 * (1 - dt / tau) ** n, rtol=1e-12)
    t = n * dt
    assert np.abs(diff / (100.0 * np.exp(-t / tau)) - 1).max() < dt / (2 * tau) * t.max() / tau * 1.01


def test_the_rolling_limit_uses_the_total_normal_force_with_its_dashpot(tmp_path):
    """`damping velocity 0.05` (F = kδ + 0.05 δ̇): the rolling limit is μ|F_ntot| with the dashpot, not μkδ."""
    w0, w1, mu = [0.0, 30.0, 5.0], [0.0, -10.0, 40.0], 0.002
    coeff = f"hooke 1e4 0.05 tangential linear_nohistory 0 0 rolling sds 2e3 0.3 {mu} damping velocity"
    eng = run_lammps(tmp_path, coeff, 0.0019, 0.0, w0, w1, 300)
    law = EpsdRolling(mu, RBAR, 2e3 * RBAR ** 2, 0.3 * RBAR ** 2, CAP_TOTAL, slack_zero=True)
    assert_twin(eng, verlet_pair(R, RHO, 0.0019, 0.0, w0, w1, DT, 300, kn=1e4, eta_n=0.05, rolling=law))
    elastic = verlet_pair(R, RHO, 0.0019, 0.0, w0, w1, DT, 300, kn=1e4, eta_n=0.05, rolling=law, elastic_limit=True)
    assert np.abs(elastic["torque"] - eng[:, :, 13:16]).max() > 1e-6 * np.abs(eng[:, :, 13:16]).max()
