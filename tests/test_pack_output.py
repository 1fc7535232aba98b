"""The contact network's fabric tensor (packing_metrics) and verify's comparison of it (packing_suite), and the
MDAnalysis reading of an engine's packing run (engines.packing.universe)."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from demcheck.comparisons import packing_metrics as PM
from demcheck.comparisons import packing_suite

R = 1e-3
BOX = 0.006  # three diameters: many contacts cross the periodic boundary
# 40 spheres poured into a periodic 6 mm × 6 mm box: seconds in every source
SMALL = f"""
name = "small-pour"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.3
friction = 0.5
[packing]
layout = "poured"
count = 40
material = "glass"
radius = {R}
box = [{BOX}, {BOX}]
seed = 3
duration = 0.1
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
normal = "lsd"
kn = 2000.0
tangential = "spring_sliding"
[run]
gravity = [0.0, 0.0, -9.81]
"""


# ----------------------------------------------------------------------------- the fabric tensor: closed forms


def _cubic(n):
    g = (np.arange(n) + 0.5) * 2 * R
    return np.array([(i, j, k) for i in g for j in g for k in g])


def test_fabric_of_a_simple_cubic_lattice_is_isotropic():
    """n³ touching spheres, no box: n²(n − 1) contacts along each axis, φ = I/3 exactly, anisotropy 0."""
    x = _cubic(4)
    m = PM.compute(x, np.full(len(x), R))
    assert np.array_equal(np.array(m["fabric"]), np.eye(3) / 3)
    assert m["fabric_anisotropy"] == 0.0


def test_fabric_of_a_periodic_simple_cubic_lattice_counts_the_contacts_across_the_boundary():
    """In a periodic n × n box the x and y rows close on themselves (n³ contacts each), the columns do not
    (n²(n − 1)): φ_xx = φ_yy = n/(3n − 1), φ_zz = (n − 1)/(3n − 1) — without the periodic contacts it would be
    I/3."""
    n = 4
    x = _cubic(n)
    m = PM.compute(x, np.full(len(x), R), box=(n * 2 * R, n * 2 * R))
    np.testing.assert_allclose(np.array(m["fabric"]), np.diag([n, n, n - 1]) / (3 * n - 1), rtol=1e-15, atol=0)
    # symmetric about z: the anisotropy is 45/4 (φ_zz − 1/3)
    assert m["fabric_anisotropy"] == pytest.approx(45 / 4 * abs((n - 1) / (3 * n - 1) - 1 / 3), rel=1e-12)


def test_fabric_of_a_column_is_vertical():
    x = np.array([[0.0, 0.0, (2 * k + 1) * R] for k in range(5)])
    m = PM.compute(x, np.full(5, R))
    assert np.array_equal(np.array(m["fabric"]), np.diag([0.0, 0.0, 1.0]))
    assert m["fabric_anisotropy"] == pytest.approx(7.5, rel=1e-14)  # 45/4 · 2/3


def test_fabric_of_a_square_layer_in_a_periodic_box_is_planar():
    """A 4 × 4 layer of touching spheres in a periodic box: four contacts each, half of them across the
    boundary, every branch vector one diameter long; φ_xx = φ_yy = 1/2, φ_zz = 0, anisotropy 45/4 · 1/3."""
    g = (np.arange(4) + 0.5) * 2 * R
    x = np.array([(i, j, R) for i in g for j in g])
    box = (8 * R, 8 * R)
    pairs = PM.contacts(x, np.full(16, R), box)
    assert len(pairs) == 32
    b = PM.branch_vectors(x, pairs, box)
    np.testing.assert_allclose(np.linalg.norm(b, axis=1), 2 * R, rtol=1e-15)
    m = PM.compute(x, np.full(16, R), box=box)
    assert np.array_equal(np.array(m["fabric"]), np.diag([0.5, 0.5, 0.0]))
    assert m["fabric_anisotropy"] == pytest.approx(3.75, rel=1e-14)


def test_no_contacts_no_fabric():
    m = PM.compute(np.array([[0.0, 0.0, R], [5 * R, 0.0, R]]), np.full(2, R))
    assert all(math.isnan(v) for row in m["fabric"] for v in row)
    assert math.isnan(m["fabric_zz"]) and math.isnan(m["fabric_anisotropy"])


@given(hnp.arrays(np.float64, st.tuples(st.integers(1, 40), st.just(3)),
                  elements=st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)))
def test_fabric_is_symmetric_with_trace_one(b):
    b = b[np.linalg.norm(b, axis=1) > 1e-3]
    if not len(b):
        return
    phi = PM.fabric(b)
    assert np.trace(phi) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(phi, phi.T, rtol=0, atol=1e-16)
    eig = np.linalg.eigvalsh(phi)
    assert eig.min() >= -1e-14 and eig.max() <= 1 + 1e-14
    # a rotation turns the tensor, not its anisotropy
    c, s = math.cos(0.7), math.sin(0.7)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    assert PM.fabric_anisotropy(PM.fabric(b @ rot.T)) == pytest.approx(PM.fabric_anisotropy(phi), abs=1e-12)


def test_fabric_zz_critical_difference_is_its_sampling_error():
    """The verify comparison's critical value: z(α/2)·√(s_a²/N_a + s_b²/N_b), z(5e-4) = 3.2905."""
    a, b = np.array([0.0, 1.0] * 50), np.array([0.0, 0.0, 1.0] * 40)
    d, crit = packing_suite.fabric_zz_distance(a, b)
    assert d == pytest.approx(0.5 - 1 / 3, rel=1e-12)
    se = math.sqrt(a.var(ddof=1) / 100 + b.var(ddof=1) / 120)
    assert crit == pytest.approx(3.2905267 * se, rel=1e-7)
    assert all(math.isnan(v) for v in packing_suite.fabric_zz_distance([1.0], b))


# ----------------------------------------------------------------------------- engines


@pytest.fixture(scope="module")
def lammps_run(tmp_path_factory):
    from demcheck.case import loads
    from demcheck.engines.packing import run_engine

    wd = tmp_path_factory.mktemp("lammps-run")
    case = loads(SMALL)
    return case, run_engine(case, "lammps", workdir=wd / "run"), wd / "run"


@pytest.mark.engine("lammps")
def test_universe_reads_a_lammps_packing_to_float32_precision(lammps_run):
    """MDAnalysis's float32 positions against the float64 reader's. Each coordinate is rounded to float32 once
    when read (≤ |x|·2⁻²⁴); where the box's lower corner lo is not 0 (z here) MDAnalysis moves it to lo, in
    float32, and universe() moves it back with lo rounded to float32: ≤ 2⁻²⁴(|x| + |x − lo| + |lo| + |x|)."""
    pytest.importorskip("MDAnalysis")
    from demcheck.engines.packing import _box_lo, universe
    from demcheck.inputs.packing_decks import FINAL_DUMP

    case, run, wd = lammps_run
    u = universe(wd)
    x = run.table[["x", "y", "z"]].to_numpy()
    lo = _box_lo(wd / FINAL_DUMP)
    assert lo[0] == lo[1] == 0.0 and lo[2] < 0.0
    p = u.atoms.positions
    assert p.dtype == np.float32 and len(p) == len(x)
    eps = 2.0**-24 * (1 + 2.0**-20)  # the float64 steps between the roundings add a few 2⁻⁵³
    bound = eps * np.where(lo != 0.0, 2 * np.abs(x) + np.abs(x - lo) + np.abs(lo), np.abs(x))
    err = np.abs(p.astype(float) - x)
    assert np.all(err <= bound)
    assert err.max() > 0  # float32, not the dump's doubles: the bound is what is being tested
    v = run.table[["vx", "vy", "vz"]].to_numpy()
    assert np.all(np.abs(u.atoms.velocities.astype(float) - v) <= eps * np.abs(v))
    # radius and mass are read as doubles (additional columns), exactly
    assert np.array_equal(u.atoms.radii, run.table["radius"].to_numpy())
    assert np.array_equal(u.atoms.masses, run.table["mass"].to_numpy())


@pytest.mark.engine("lammps")
def test_verify_compares_a_poured_packing_s_fabric_by_its_sampling_error(tmp_path):
    """verify's packing entry holds fabric_zz per engine: |φ_zz − φ_zz(reference)| against the critical
    difference of the two sources' own samples of n_z² (recomputed here from the written positions)."""
    from demcheck.comparisons import suite

    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    s = suite.run_suite([path], tmp_path / "r", suite.Options(engines=("lammps",), cache=None), quiet=True)
    (c,) = s["cases"]
    (k,) = [k for k in c["comparisons"] if k["metric"] == "fabric_zz"]
    assert k["source"] == "lammps"
    ref, eng = c["sources"]["reference"]["metrics"], c["sources"]["lammps"]["metrics"]
    assert k["value"] == eng["fabric_zz"] and k["reference"] == ref["fabric_zz"]
    assert k["abs_diff"] == pytest.approx(abs(eng["fabric_zz"] - ref["fabric_zz"]), abs=1e-15)
    # the tolerance is z(α/2)·√(s_a²/N_a + s_b²/N_b): a few tenths for some 50 contacts a source
    assert 0.05 < k["tolerance"] < 0.5
    assert k["verdict"] == ("agree" if k["abs_diff"] <= k["tolerance"] else "unexpected")
