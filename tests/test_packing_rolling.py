"""The packing solver's rolling slot (reference/packing.py, packing_rolling.py): a case naming no rolling law runs
bit for bit as before the slot (a golden written by the solver before it, tests/data/make_packing_golden.py); a
sphere rolling on the floor under type A stops where the closed form says, under type B its speed decays as the
closed form's exponential; a pair's rolling torques are equal and opposite (the spins' angular momentum is kept)."""

import math
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference import packing as P
from demcheck.reference import packing_rolling as PR
from demcheck.reference.beyond import rolling_stop_closed, rolling_viscous_closed

GOLDEN = Path(__file__).parent / "data" / "packing_golden.npz"
ARMS = {"slip_arm": "radius", "torque_arm": "radius", "wall_torque_arm": "radius"}  # lever arms R: the closed forms'


@pytest.mark.parametrize("name", ["spring_1", "spring_2", "tti_1"])
@pytest.mark.parametrize("rolling", [None, "none"])
def test_no_rolling_law_is_the_solver_before_the_slot_bit_for_bit(name, rolling):
    """Three pours of 150 spheres (the spring's fast path on one and on two threads, Tsuji–Mindlin's traits path),
    0.03 s: every position, velocity and spin the same bits as the solver before the rolling slot and segment walls
    (main at 7b9469c) gave — with no rolling key and with rolling = "none"."""
    gold = np.load(GOLDEN)
    text = str(gold[f"{name}_case"])
    if rolling:
        text = text.replace("[contact]\n", f'[contact]\nrolling = "{rolling}"\n')
    st = P.simulate(C.loads(text), rest=0.0, threads=int(gold[f"{name}_threads"]))
    for key in ("x", "v", "w"):
        assert np.array_equal(getattr(st, key), gold[f"{name}_{key}"]), key


SPHERE = """
name = "rolling-sphere"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.5
tangential_restitution = 0.3
friction = 0.5
[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 1e-3]
velocity = [{v0}, 0.0, 0.0]
angular_velocity = [0.0, {w0}, 0.0]
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
normal = "lsd"
kn = {kn}
tangential = "lsd_sliding"
{rolling}
[run]
dt = {dt}
gravity = [0.0, 0.0, -9.81]
"""
G, R, KN = 9.81, 1e-3, 1e6


def _rolling_sphere(rolling: str, v0: float, duration: float, every: int = 250, dt: float = 2e-7):
    """A sphere set rolling without slip (ω = v0/R) on the floor, started at its static overlap mg/kn (the state set
    after loading: a case may not start overlapping), run by the packing solver with the lever arms R; (t, v_x, x,
    ω_y) every ``every`` steps, and the sphere's mass."""
    case = C.loads(SPHERE.format(v0=v0, w0=v0 / R, kn=KN, rolling=rolling, dt=dt))
    st = P.PackState(case)
    st.x[0, 2] = R - st.mass[0] * G / KN
    rows = []

    def look(s):
        rows.append((s.steps * dt, s.v[0, 0], s.x[0, 0], s.w[0, 1]))

    steps = int(round(duration / dt))
    P.simulate(case, duration=duration, state=st, rules=ARMS, observe=(range(0, steps + 1, every), look))
    return np.array(rows), float(st.mass[0])


def test_type_a_sphere_stops_at_the_closed_form_time_and_distance():
    """Type A (constant_torque, μr = 0.05, Rr = R on the wall): a = (5/7) μr g, t = 7 v0/(5 μr g), s = 7 v0²/(10 μr g)
    (beyond.rolling_stop_closed, docs/models.md), at dt 2e-7 s (kn 1e6 N/m: 160 steps a normal period). Uniform
    deceleration is integrated exactly by velocity Verlet, so the tolerances are the solver's against an exact
    solution: the deceleration fitted over the middle of the roll to 1e-9 (measured 7.5e-12), the stop — the last
    sample before it plus v/a, samples 50 µs apart — to 1e-9 (1.7e-11), the distance to 3e-9 (3.2e-10: a
    picometre, the start's slip while the tangential spring loads; the closed form rolls without slip from t = 0).
    After the stop the torque's direction flips with the spin each step: the sphere stays (v ~ 1e-8 m/s)."""
    mu_r, v0 = 0.05, 0.05
    t_stop, s_stop = rolling_stop_closed(mu_r, R, R, v0, G)
    rows, _ = _rolling_sphere(f'rolling = "constant_torque"\nmu_r = {mu_r}', v0, 1.05 * t_stop)
    t, v, x = rows[:, 0], rows[:, 1], rows[:, 2]
    mid = (t > 0.2 * t_stop) & (t < 0.8 * t_stop)
    a = -np.polyfit(t[mid], v[mid], 1)[0]
    assert a == pytest.approx(5.0 / 7.0 * mu_r * G, rel=1e-9)
    k = int(np.flatnonzero(v <= 0.0)[0])  # the first sample past the stop; the one before rolls on the line
    assert t[k - 1] + v[k - 1] / a == pytest.approx(t_stop, rel=1e-9)
    assert x[k - 1] + v[k - 1] ** 2 / (2.0 * a) == pytest.approx(s_stop, rel=3e-9)
    assert np.abs(v[k:]).max() < 1e-7  # stopped


def test_type_b_speed_decays_as_the_closed_form():
    """Type B (viscous, Cr): v = v0 e^{−t/T}, T = (7/5) m R²/Cr (beyond.rolling_viscous_closed). T from the slope of
    ln v to 1e-6 and v(t)/v0 against e^{−t/T} to 1e-6 at every sample: the torque −Cr ω is evaluated at the
    half-kicked spin, as fix nve/sphere evaluates every velocity-dependent force, a first-order bias of the decay
    rate of dt/(2T) = 3.3e-7 at dt 2e-7 s (measured: T 3.3e-7, v 1.6e-7). Cr holds the roll without slip: the
    friction m v0/T is 1/30 of μ m g."""
    v0 = 0.05
    mass = 2500.0 * 4.0 / 3.0 * math.pi * R ** 3
    c_r = 1.4 * 0.5 * mass * G * R * R / v0 / 30.0  # rolling_grip's bound over 30
    tau, _ = rolling_viscous_closed(c_r, mass, R, v0)
    rows, _ = _rolling_sphere(f'rolling = "viscous"\nc_r = {c_r!r}', v0, 0.5 * tau)
    t, v = rows[:, 0], rows[:, 1]
    late = t > 0.05 * tau
    rate = -np.polyfit(t[late], np.log(v[late]), 1)[0]
    assert 1.0 / rate == pytest.approx(tau, rel=1e-6)
    assert np.allclose(v / v0, np.exp(-t / tau), rtol=1e-6, atol=0.0)


def test_type_c_fully_mobilised_decelerates_as_type_a_beside_a_history_tangential_law():
    """Type C (epsd, Ai et al.'s: the dashpot off at the limit) with a stiff spring is fully mobilised within 0.1 ms
    of the start; from then on its torque is μr R |Fn|, type A's, and the sphere decelerates at (5/7) μr g — to 1e-9
    over the middle of the roll. Its spring torque rides in the contact's state row after Tsuji–Mindlin's tangential
    history (the traits' path, which reads its own columns only), Hertz's static overlap (mg/K)^{2/3} at the start."""
    mu_r, v0, dt = 0.05, 0.05, 1e-6
    t_stop, _ = rolling_stop_closed(mu_r, R, R, v0, G)
    mass = 2500.0 * 4.0 / 3.0 * math.pi * R ** 3
    k_hz = 4.0 / 3.0 * 1e8 / (1.0 - 0.3 ** 2) * math.sqrt(R)
    case = C.loads(SPHERE.format(v0=v0, w0=v0 / R, kn=KN, rolling=f'rolling = "epsd"\nmu_r = {mu_r}\nk_r = 1e-6\n'
                                 'c_r = 1e-9', dt=dt).replace('normal = "lsd"\nkn = 1000000.0\ntangential = '
                                                              '"lsd_sliding"', 'normal = "tti"\ntangential = "tti"'))
    st = P.PackState(case)
    assert st.roll_col >= 3 and st.hist.shape[1] == st.roll_col + 3
    st.x[0, 2] = R - (mass * G / k_hz) ** (2.0 / 3.0)
    rows = []
    P.simulate(case, duration=0.8 * t_stop, state=st, rules=ARMS, observe=(range(0, 200001, 500), lambda s: rows.append(
        (s.steps * dt, s.v[0, 0]))))
    t, v = np.array(rows).T
    mid = (t > 0.2 * t_stop) & (t < 0.7 * t_stop)
    assert -np.polyfit(t[mid], v[mid], 1)[0] == pytest.approx(5.0 / 7.0 * mu_r * G, rel=1e-9)


PAIR = """
name = "rolling-pair"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.5
[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 0.0]
angular_velocity = [0.0, 300.0, 40.0]
[[particles]]
material = "glass"
radius = 1.5e-3
position = [2.5e-3, 0.0, 0.0]
angular_velocity = [10.0, -200.0, 0.0]
[contact]
normal = "lsd"
kn = 1e4
{rolling}
[run]
dt = 1e-7
"""


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("rolling", ['rolling = "constant_torque"\nmu_r = 0.5',
                                     'rolling = "epsd"\nmu_r = 0.5\nk_r = 1e-2\nc_r = 1e-9',
                                     'rolling = "ai_epsd"\nmu_r = 0.5\nk_ratio = 3.0\neta_r = 0.1'])
def test_a_pairs_rolling_torques_are_equal_and_opposite(rolling, threads):
    """Two spheres of unequal size pressed together (the second moved in by 5 µm after loading), spinning against
    each other, no friction and no gravity: the normal force is central, so the spins change by the rolling torques
    alone, and those being equal and opposite keep Σ I ω to round-off (1e-12 of its change's scale) while each spin
    changes by a good part of itself — on two threads across the shares' cut too (the second sphere's torque through
    the far buffer); ai_epsd with the loop's kn per contact (Hooke's: its secant is k) too."""
    case = C.loads(PAIR.format(rolling=rolling))
    st = P.PackState(case)
    st.x[1, 0] -= 5e-6
    inertia = 0.4 * st.mass * st.rad ** 2
    before = (inertia[:, None] * st.w).sum(axis=0)
    w0 = st.w.copy()
    P.simulate(case, duration=1e-4, state=st, threads=threads)
    after = (inertia[:, None] * st.w).sum(axis=0)
    change = np.abs(inertia[:, None] * (st.w - w0)).max()
    assert change > 0.05 * np.abs(inertia[:, None] * w0).max()  # the torques acted
    assert np.abs(after - before).max() <= 1e-12 * change
    # and they resist the relative rolling (a torque applied with i and j swapped would also conserve Σ I ω): the
    # rolling part of ω0 − ω1 (across the normal, x here) has shrunk
    rel0, rel = (w0[0] - w0[1])[1:], (st.w[0] - st.w[1])[1:]
    assert np.linalg.norm(rel) < np.linalg.norm(rel0)


def test_the_switch_is_written_from_the_registry_and_every_law_has_its_place():
    """The rolling switch has one branch per registered law, in registration order, none by id; kind_of gives each
    record its place, -1 for none."""
    from demcheck.laws import rolling
    from demcheck.laws.rolling_laws.slot import KERNELS

    text = PR.source()
    assert text.count("    if kind == ") == len(KERNELS)
    for kind, record in enumerate(KERNELS):
        assert PR.kind_of(record()) == kind
        assert f"# {kind}: {record.__name__}" in text
    assert PR.kind_of(None) == -1
    assert "constant_torque" not in text.split("def rolling_torque")[1]  # the switch names no law
    assert rolling.KERNELS is KERNELS


def test_a_collision_naming_a_rolling_law_is_still_refused():
    with pytest.raises(ConfigError) as err:
        C.loads("""
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.5
[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]
[[particles]]
material = "glass"
radius = 1e-3
position = [2.1e-3, 0.0, 0.0]
[contact]
normal = "hertz"
rolling = "constant_torque"
mu_r = 0.1
""")
    assert err.value.key == "contact.rolling" and "packings" in err.value.rule


# ----------------------------------------------------------------------------- ai_epsd: kn and Ir from the loop
AI = """
name = "ai-epsd-{what}"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.5
{particles}
[contact]
normal = "tti"
tangential = "none"
rolling = "ai_epsd"
mu_r = 0.1
k_ratio = 3.0
eta_r = 0.1
{extra}
[run]
dt = 1e-7
gravity = {gravity}
"""
ON_WALL = """
[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 1e-3]
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
TWO = """
[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 0.0]
[[particles]]
material = "glass"
radius = 1.5e-3
position = [2.5e-3, 0.0, 0.0]
"""
E_, NU, RHO = 1e8, 0.3, 2500.0


def _ai_case(what: str, extra: str = ""):
    particles, gravity = (ON_WALL, "[0.0, 0.0, -9.81]") if what == "wall" else (TWO, "[0.0, 0.0, 0.0]")
    return C.loads(AI.format(what=what, particles=particles, extra=extra, gravity=gravity))


def _one_force_call(case, st, dt):
    """The loop's forces of ``st`` once, histories updated (its set-up builds the list and the states without
    storing, as a run's does; then one updating call of the force loop): (torques, state rows)."""
    from demcheck.reference.collision3d import rules_array

    sp, laws_n, laws_t, wall_n, wall_t = P.resolve_laws(case)
    lawn, lawt = P.law_table(laws_n, laws_t, wall_n, wall_t)
    walls = P.wall_table(st.walls)
    lo, hi, periodic = P.box_of(case, st.x, st.rad)
    rules = rules_array(None)
    kind, _, laws_r, kn_col = st.rolling
    roll = (laws_r, np.int64(kind), np.int64(st.roll_col), np.int64(kn_col))
    n = len(st.rad)
    _, period, _, _, _, _, _, _, start, nbj, hist, dmax, _ = P._setup(
        st.x, st.v, st.w, st.rad, st.mass, sp, laws_n.shape[0], lawn, lawt, walls, lo, hi, periodic, dt, 1, 1,
        st.start, st.nbj, st.hist, st.dmax, rules, *roll)
    f, tq = np.zeros((n, 3)), np.zeros((n, 3))
    P._contact_forces(np.int64(0), n, st.x, st.v, st.w, st.rad, sp, laws_n.shape[0], lawn, lawt, walls, period,
                      start, nbj, hist, dmax, f, tq, f, tq, np.zeros((0, 3)), dt, np.bool_(True), rules, *roll)
    return tq, hist


@pytest.mark.parametrize("what", ["wall", "pair"])
def test_ai_epsd_in_the_loop_takes_each_contacts_hertz_kn_and_its_pairs_ir(what):
    """Ai's model C in the packing loop, kr = ε kn (μr R̄)² with kn the contact's Hertz secant (4/3)E*√(R̄δ) at its
    overlap, Cr = ηr·2√(Ir kr) with Ir = 1.4 m R² (a sphere on a rigid wall) or 1/Ir = 1/(1.4 m0 R0²) + 1/(1.4 m1
    R1²) (a pair), all by hand here: after one step dt of a spin w (its rolling part w_t, across the normal) the
    spring torque (the contact's history) is −kr w_t dt = −kr Δθ, and the torque on the sphere (no friction:
    tangential none) Mk − Cr w_t, to 1e-9. The sphere on the wall sits at Hertz's equilibrium overlap (mg = K δ^{3/2},
    K = (4/3)E*√R), and approaches at 1 cm/s: the normal dashpot's force is several times the spring's, so a kn
    from the damped total would miss by as much."""
    case = _ai_case(what)
    st = P.PackState(case)
    dt = 1e-7
    if what == "wall":
        r_bar, r0 = 1e-3, 1e-3
        m0 = RHO * 4.0 / 3.0 * math.pi * r0 ** 3
        e_star = E_ / (1.0 - NU ** 2)  # a rigid wall
        delta = (m0 * G / (4.0 / 3.0 * e_star * math.sqrt(r_bar))) ** (2.0 / 3.0)
        st.x[0, 2] = r0 - delta
        st.v[0] = (0.0, 0.0, -0.01)
        st.w[0] = (0.0, 0.1, 0.0)
        w_t = np.array([0.0, 0.1, 0.0])  # n = −z
        i_r = 1.4 * m0 * r0 ** 2
    else:
        r0, r1 = 1e-3, 1.5e-3
        r_bar = r0 * r1 / (r0 + r1)
        m0, m1 = (RHO * 4.0 / 3.0 * math.pi * r ** 3 for r in (r0, r1))
        e_star = E_ / (2.0 * (1.0 - NU ** 2))
        delta = 5e-6
        st.x[1, 0] = r0 + r1 - delta
        st.v[0] = (0.01, 0.0, 0.0)  # approaching
        st.w[0], st.w[1] = (0.2, 0.2, 0.05), (0.3, -0.1, 0.0)
        w_t = np.array([0.0, 0.3, 0.05])  # ω0 − ω1 less its part along n = +x
        i_r = 1.0 / (1.0 / (1.4 * m0 * r0 ** 2) + 1.0 / (1.4 * m1 * r1 ** 2))
    kn = 4.0 / 3.0 * e_star * math.sqrt(r_bar * delta)
    k_r = 3.0 * kn * (0.1 * r_bar) ** 2
    c_r = 0.1 * 2.0 * math.sqrt(i_r * k_r)
    tq, hist = _one_force_call(case, st, dt)
    row = 0 if what == "wall" else len(st.rad) * len(case.walls)  # the wall contact's state, or the pair's
    spring = hist[row, st.roll_col:st.roll_col + 3]
    assert np.allclose(spring, -k_r * w_t * dt, rtol=1e-9, atol=0.0)
    assert np.linalg.norm(spring) == pytest.approx(k_r * np.linalg.norm(w_t) * dt, rel=1e-9)
    assert np.allclose(tq[0], -k_r * w_t * dt - c_r * w_t, rtol=1e-9, atol=0.0)
    if what == "pair":
        assert np.allclose(tq[1], -tq[0], rtol=1e-12, atol=0.0)


def test_ai_epsd_table_holds_each_pairs_ir_and_no_kn():
    """packing_rolling's table for ai_epsd: Ir of each species pair and of each species on the walls, by hand (1.4 m
    R², 1/Ir the sum of the two), the kn column NaN (the loop writes it per contact: a contact it missed would not
    run on a made-up kn), and the kn column handed to the loop; the other laws have none (-1)."""
    from demcheck.laws.rolling_laws.ai_epsd import I_R, K_N

    case = C.loads(AI.format(what="table", particles=TWO + """
[[walls]]
point = [0.0, 0.0, -2e-3]
normal = [0.0, 0.0, 1.0]
""", extra="", gravity="[0.0, 0.0, -9.81]"))
    sp, rep = P.species_of(case)
    kind, cols, table, kn_col = PR.rolling_laws(case, rep)
    assert cols == 3 and kn_col == K_N == 2 and I_R == 5
    j = [1.4 * RHO * 4.0 / 3.0 * math.pi * r ** 5 for r in (1e-3, 1.5e-3)]  # 1.4 m R²
    assert table[0, I_R] == pytest.approx(j[0] / 2.0, rel=1e-14)
    assert table[1, I_R] == table[2, I_R] == pytest.approx(j[0] * j[1] / (j[0] + j[1]), rel=1e-14)
    assert table[3, I_R] == pytest.approx(j[1] / 2.0, rel=1e-14)
    assert table[4, I_R] == pytest.approx(j[0], rel=1e-14) and table[5, I_R] == pytest.approx(j[1], rel=1e-14)
    assert np.isnan(table[:, K_N]).all()
    other = C.loads(PAIR.format(rolling='rolling = "epsd"\nmu_r = 0.5\nk_r = 1e-2\nc_r = 1e-9'))
    assert PR.rolling_laws(other, P.species_of(other)[1])[3] == -1
    assert PR.rolling_laws(C.loads(PAIR.format(rolling="")), [0, 1])[3] == -1


@pytest.mark.parametrize("key", ["k_n = 1e3", "i_r = 1e-9"])
def test_a_packing_may_not_set_what_the_loop_supplies(key):
    """k_n and i_r of ai_epsd are the loop's in a packing: a case setting one is refused by name, not ignored."""
    case = _ai_case("wall", key)
    with pytest.raises(ConfigError) as err:
        P.PackState(case)
    assert err.value.key == f"contact.{key.split()[0]}" and "packing loop supplies" in err.value.rule
