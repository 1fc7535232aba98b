"""Segment walls and timed walls in the packing solver (reference/packing.py: wall_table, _segment_contact,
PackState.remove_walls) and their case keys (case.py: along, extent, until): the force of a sphere on a strip's face
and on its edge line against the Hertz closed form, a corner shared by two strips as one contact, a sphere dropped
on an edge against the central-force scattering integral, a gate's removal against free fall, and bad input."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference import packing as P
from demcheck.reference.collision3d import rules_array

E, NU, RHO, R = 1e8, 0.3, 2500.0, 1e-3
K_WALL = 4.0 / 3.0 * E / (1.0 - NU * NU) * math.sqrt(R)  # Hertz on a rigid wall: F = K δ^{3/2}, R̄ = R, E* = E/(1 − ν²)

HEAD = f"""
name = "segments"
kind = "packing"
[materials.glass]
density = {RHO}
youngs_modulus = {E}
poisson_ratio = {NU}
[contact]
normal = "hertz"
[run]
dt = 1e-7
"""


def _case(walls: str, particles: str = "position = [0.0, 0.0, 0.5]") -> C.Case:
    return C.loads(HEAD + f'[[particles]]\nmaterial = "glass"\nradius = {R}\n{particles}\n' + walls)


def _forces(case, x):
    """The contact forces and torques of the state x (every contact: the walls'), by the loop's own force pass."""
    st = P.PackState(case)
    st.x[:] = x
    sp, laws_n, laws_t, wall_n, wall_t = P.resolve_laws(case)
    lawn, lawt = P.law_table(laws_n, laws_t, wall_n, wall_t)
    walls = P.wall_table(case.walls)
    n = len(st.x)
    hist, dmax = np.zeros((n * walls.shape[0], st.hist.shape[1])), np.zeros(n * walls.shape[0])
    f, tq = np.zeros((n, 3)), np.zeros((n, 3))
    P._contact_forces(np.int64(0), n, st.x, st.v, st.w, st.rad, sp, laws_n.shape[0], lawn, lawt, walls, (0.0, 0.0),
                      np.zeros(n + 1, np.int64), np.zeros(0, np.int64), hist, dmax, f, tq, f, tq, np.zeros((0, 3)),
                      1e-7, np.bool_(False), rules_array(None), *P.NO_ROLLING)
    return f, tq


STRIP = """
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
along = [1.0, 0.0, 0.0]
extent = [-1e-3, 1e-3]
"""
PLANE = """
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""


def test_a_sphere_beyond_the_strip_touches_its_edge_line_with_the_hertz_force():
    """Centre 0.6 mm beyond the edge x = 1 mm and 0.7 mm over the plane: ρ = √(0.6² + 0.7²) mm from the edge line,
    δ = R − ρ, F = K δ^{3/2} along the line's normal through the centre (x, z both pushed away), to 1e-13."""
    case = _case(STRIP)
    f, _ = _forces(case, np.array([[1.6e-3, 0.0, 0.7e-3]]))
    q = np.array([0.6e-3, 0.0, 0.7e-3])
    rho = float(np.linalg.norm(q))
    assert np.allclose(f[0], K_WALL * (R - rho) ** 1.5 * q / rho, rtol=1e-13, atol=0.0)


def test_a_sphere_on_the_face_near_the_edge_gets_the_planes_force():
    """Centre 0.1 R inside the edge, 0.9 R over the face: the plane's force, the same bits as an unbounded wall's, and
    K (0.1 R)^{3/2} straight up; just past the edge (0.1 R beyond) the edge line's, tilted outwards."""
    x = np.array([[0.9e-3, 0.0, 0.9e-3]])
    f_strip, _ = _forces(_case(STRIP), x)
    f_plane, _ = _forces(_case(PLANE), x)
    assert np.array_equal(f_strip, f_plane)
    assert f_strip[0] == pytest.approx([0.0, 0.0, K_WALL * (0.1 * R) ** 1.5], rel=1e-13, abs=0.0)
    past, _ = _forces(_case(STRIP), np.array([[1.1e-3, 0.0, 0.9e-3]]))
    rho = math.hypot(0.1e-3, 0.9e-3)
    assert past[0] == pytest.approx(K_WALL * (R - rho) ** 1.5 * np.array([0.1e-3, 0.0, 0.9e-3]) / rho, rel=1e-13)


def test_a_strip_is_a_thin_plate_touched_from_either_side_and_far_things_behind_it_are_free():
    """Behind the strip (centre 0.9 R under it) the mirror force pushes the sphere back down; a sphere far behind (an
    unbounded plane would bury it) feels nothing."""
    f, _ = _forces(_case(STRIP), np.array([[0.0, 0.0, -0.9e-3]]))
    assert f[0] == pytest.approx([0.0, 0.0, -K_WALL * (0.1 * R) ** 1.5], rel=1e-13, abs=0.0)
    f, _ = _forces(_case(STRIP), np.array([[0.0, 0.0, -0.5]]))
    assert not f.any()


# a step: the upper level's top (x ≤ 0, z = 0) and its riser (x = 0, z from -5 mm to 0) share the edge line x = z = 0
STEP = """
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
along = [1.0, 0.0, 0.0]
extent = [-5e-3, 0.0]
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
along = [0.0, 0.0, 1.0]
extent = [-5e-3, 0.0]
"""


def test_a_corner_shared_by_two_strips_is_one_contact():
    """In the wedge past both strips the sphere touches the shared edge once (the force of one edge, not two); on the
    riser's face near the corner it touches the face only, though the corner is within R of its centre."""
    step = _case(STEP, "position = [3e-3, 0.0, 3e-3]")
    q = np.array([0.5e-3, 0.0, 0.6e-3])
    f, _ = _forces(step, q[None, :])
    rho = float(np.linalg.norm(q))
    assert np.allclose(f[0], K_WALL * (R - rho) ** 1.5 * q / rho, rtol=1e-13, atol=0.0)
    f, _ = _forces(step, np.array([[0.9e-3, 0.0, -0.3e-3]]))
    assert f[0] == pytest.approx([K_WALL * (0.1 * R) ** 1.5, 0.0, 0.0], rel=1e-13, abs=0.0)
    assert math.hypot(0.9e-3, 0.3e-3) < R  # the corner is within reach: only the rule leaves it out
    table = P.wall_table(step.walls)
    assert table[0, P.W_EDGES + P.W_EDGE] == 1.0 and table[1, P.W_EDGES + P.W_EDGE] == 0.0  # its first wall's


def _deflection(b: float, v0: float, mass: float) -> float:
    """The angle by which a sphere of speed v0 and impact parameter b (from the edge line) is turned by the Hertz
    potential V(ρ) = (2/5) K (R − ρ)^{5/2} of a fixed line: χ = π − 2 ∫_{ρmin}^{∞} (b/ρ²) dρ / √(1 − b²/ρ² − 2V/(m v0²))
    (a central force: scipy's quad, an independent path), the part beyond R being asin(b/R)."""
    def g(rho):
        return 1.0 - (b / rho) ** 2 - 2.0 * (0.4 * K_WALL * max(R - rho, 0.0) ** 2.5) / (mass * v0 * v0)

    rmin = brentq(g, 1e-9 * R, R, xtol=1e-22, rtol=1e-15)
    # ρ = rmin + u²: the inverse square root at rmin is integrable, smooth in u
    inner = quad(lambda u: 2.0 * u * (b / (rmin + u * u) ** 2) / math.sqrt(g(rmin + u * u)), 0.0,
                 math.sqrt(R - rmin), epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return math.pi - 2.0 * (inner + math.asin(b / R))


def test_a_sphere_dropped_on_an_edge_is_scattered_as_by_a_central_force():
    """A sphere moving down at v0 (no gravity, no friction, elastic Hertz) with its centre 0.5 R beyond a strip's edge:
    untouched until its centre is √(R² − b²) over the plane and touching a step later (the onset), it leaves at its
    speed to 1e-8 (energy: Verlet's O(dt²)), its angular momentum about the edge line kept to round-off, 1e-11 (the
    force is central about the line, and velocity Verlet keeps a central force's angular momentum exactly), turned by
    the scattering integral's angle (an independent path: scipy's quad) to 1e-8 at dt 1e-8 s, ~10 000 steps a
    contact (measured 1.1e-10)."""
    b, v0, dt = 0.5 * R, 0.5, 1e-8
    z0 = math.sqrt(R * R - b * b) + 2e-5
    case = C.loads(HEAD.replace("dt = 1e-7", f"dt = {dt}") + f'[[particles]]\nmaterial = "glass"\nradius = {R}\n'
                   f'position = [{1e-3 + b}, 0.0, {z0}]\nvelocity = [0.0, 0.0, {-v0}]\n' + STRIP)
    st = P.PackState(case)
    mass = float(st.mass[0])
    onset = 2e-5 / v0  # the free flight to the touch
    before = int(onset / dt * (1 - 1e-9))  # the last step that ends before it
    rows = []
    P.simulate(case, duration=onset + 3e-4, state=st, chunk=10 ** 9,
               observe=([before, before + 2, *range(0, 34001, 100)], lambda s: rows.append(
                   (s.steps, *s.x[0], *s.v[0]))))
    rows = {int(r[0]): np.array(r[1:]) for r in rows}
    assert rows[before][3] == 0.0 and rows[before + 2][3] > 0.0  # vx: untouched, then pushed away from the strip
    last = rows[max(rows)]
    assert np.hypot(last[0] - 1e-3, last[2]) > R  # gone
    vx, vz = last[3], last[5]
    assert math.hypot(vx, vz) == pytest.approx(v0, rel=1e-8)
    lever = [(r[2] - 0.0) * r[3] - (r[0] - 1e-3) * r[5] for r in rows.values()]  # (x − edge) × v about the edge line
    assert np.allclose(lever, b * v0, rtol=1e-11, atol=0.0)  # measured 1.4e-12: 34 000 steps' round-off
    chi = math.atan2(vx, -vz)  # the turn from straight down
    assert chi == pytest.approx(_deflection(b, v0, mass), rel=1e-8)  # measured 1.1e-10


def test_a_timed_wall_goes_at_its_time_and_the_sphere_then_falls_freely():
    """A sphere resting on a floor removed at 2 ms (its until): held up to then, after it z(t) = z_T + v_T (t − T) −
    g (t − T)²/2 — velocity Verlet integrates a constant acceleration exactly, to round-off (1e-12)."""
    case = C.loads(HEAD.replace("[run]", "[run]\ngravity = [0.0, 0.0, -9.81]") + f'[[particles]]\nmaterial = "glass"\n'
                   f'radius = {R}\nposition = [0.0, 0.0, {R}]\n' + PLANE.replace('normal = [0.0, 0.0, 1.0]',
                   'normal = [0.0, 0.0, 1.0]\nuntil = 2e-3'))
    rows = []
    st = P.simulate(case, duration=5e-3, observe=(range(0, 50001, 1000), lambda s: rows.append(
        (s.steps, s.x[0, 2], s.v[0, 2], len(s.walls)))))
    rows = np.array(rows)
    t_gate = P.removal_step(2e-3, 1e-7)
    assert t_gate == 20000 and not st.walls
    held = rows[rows[:, 0] < t_gate]
    assert (held[:, 3] == 1).all() and (held[:, 1] > 0.99 * R).all()
    at = rows[rows[:, 0] == t_gate][0]  # the state the step the wall goes after ends in (its force in the last kick)
    assert at[3] == 0
    z_t, v_t = at[1], at[2]
    after = rows[rows[:, 0] > t_gate]
    tau = (after[:, 0] - t_gate) * 1e-7
    assert np.allclose(after[:, 1], z_t + v_t * tau - 0.5 * 9.81 * tau ** 2, rtol=1e-12, atol=1e-15)
    assert (after[:, 3] == 0).all()


def test_removing_a_wall_keeps_the_other_contacts_states():
    """Each particle's state row with the remaining walls and every pair's row keep their values; the removed wall's
    rows go."""
    case = _case(STEP.replace("extent = [-5e-3, 0.0]\n[[walls]]", "extent = [-5e-3, 0.0]\nuntil = 1e-6\n[[walls]]"),
                 "position = [3e-3, 0.0, 3e-3]")
    st = P.PackState(case)
    st.hist = np.arange(2 * st.hist.shape[1] + 3 * st.hist.shape[1], dtype=float).reshape(5, -1)  # 1 × 2 walls, 3 pairs
    st.dmax = np.arange(5.0)
    before = st.hist.copy()
    st.steps = 10
    assert st.remove_walls(1e-7)
    assert len(st.walls) == 1 and st.walls[0].normal == (1.0, 0.0, 0.0)
    assert np.array_equal(st.hist, before[[1, 2, 3, 4]]) and np.array_equal(st.dmax, [1.0, 2.0, 3.0, 4.0])


def test_step_at_takes_a_time_one_round_off_past_a_step_as_that_step():
    assert P.step_at(0.1 * 3, 0.1) == 3 and math.ceil(0.1 * 3 / 0.1) == 4  # 0.30000000000000004 s
    assert P.step_at(4.5, 2e-5) == 225000 and P.step_at(4.5 + 1e-5, 2e-5) == 225001 and P.step_at(0.0, 2e-5) == 0


@pytest.mark.parametrize("wall, key, words", [
    ('along = [1.0, 0.1, 0.0]\nextent = [0.0, 1.0]', "walls.0.along", "unit vector"),
    ('along = [0.0, 0.0, 1.0]\nextent = [0.0, 1.0]', "walls.0.along", "in the wall's plane"),
    ('along = [1.0, 0.0, 0.0]\nextent = [1.0, 1.0]', "walls.0.extent", "s0 < s1"),
    ('along = [1.0, 0.0, 0.0]\nextent = [1.0]', "walls.0.extent", "[s0, s1]"),
    ('extent = [0.0, 1.0]', "walls.0.extent", "needs along"),
    ('along = [1.0, 0.0, 0.0]', "walls.0.along", "extent"),
    ('until = 0.0', "walls.0.until", "> 0"),
    ('until = -1.0', "walls.0.until", "> 0"),
])
def test_bad_segment_and_timed_wall_keys_are_one_line_naming_the_key(wall, key, words):
    with pytest.raises(ConfigError) as err:
        _case(PLANE + wall + "\n")
    assert err.value.key == key and words in err.value.rule
    assert "\n" not in str(err.value) and err.value.exit_code == 2


def test_a_collision_takes_no_segment_or_timed_wall():
    text = HEAD.replace('kind = "packing"', 'kind = "collision"') + (
        f'[[particles]]\nmaterial = "glass"\nradius = {R}\nposition = [0.0, 0.0, 2e-3]\nvelocity = [0.0, 0.0, -1.0]\n'
        + PLANE + "until = 1.0\n")
    with pytest.raises(ConfigError) as err:
        C.loads(text)
    assert err.value.key == "walls.0.until" and "packing cases only" in err.value.rule


def test_a_sphere_may_start_beside_a_strip_below_its_plane():
    """The start's overlap check takes the strip's distance: a sphere beside the strip, under its plane, is clear."""
    _case(STRIP, "position = [5e-3, 0.0, -2e-3]")
    with pytest.raises(ConfigError) as err:
        _case(STRIP, "position = [1.2e-3, 0.0, 0.5e-3]")
    assert "wall 0" in err.value.rule
