"""`demcheck pack --vtk DIR --xyz FILE` (packing_output), the contact network's fabric tensor (packing_metrics) and
the MDAnalysis reading of an engine's packing run (engines.packing.universe)."""

import json
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from demcheck.comparisons import packing_metrics as PM
from demcheck.comparisons import packing_suite

from .conftest import ROOT

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
# ase writes every real extended-XYZ column with eight decimals: a value read back is within half the last one
XYZ_ROUNDING = 0.5e-8


def demcheck(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=900)


def _one_line_exit_2(p, needle):
    assert p.returncode == 2, (p.returncode, p.stderr[-2000:])
    assert p.stdout == ""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("demcheck: error: ") and needle in lines[0], p.stderr[-2000:]


def _pack(tmp, engine="reference"):
    """`demcheck pack` of the small pour writing --csv, --vtk and --xyz: (JSON, the output directory)."""
    case = tmp / "small.toml"
    case.write_text(SMALL)
    p = demcheck("pack", case, "--engine", engine, "--json", "--csv", tmp / "csv", "--vtk", tmp / "vtk",
                 "--xyz", tmp / "state.xyz", cwd=tmp)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout), tmp


@pytest.fixture(scope="module")
def reference_pack(tmp_path_factory):
    return _pack(tmp_path_factory.mktemp("ref"))


def _read_back(out):
    import meshio

    parts = pd.read_csv(out / "csv" / "particles.csv")  # 17 digits: the float64 state, by another writer
    contacts = pd.read_csv(out / "csv" / "contacts.csv")
    return parts, contacts, meshio.read(out / "vtk" / "particles.vtu"), meshio.read(out / "vtk" / "contacts.vtu")


def _check_vtk(out, forces: bool):
    parts, contacts, pv, cv = _read_back(out)
    x = parts[["x", "y", "z"]].to_numpy()
    # float64 end to end: the points and the fields are the state's own doubles
    assert pv.points.dtype == np.float64 and np.array_equal(pv.points, x)
    assert np.array_equal(pv.point_data["radius"], parts["radius"].to_numpy())
    assert np.array_equal(pv.point_data["id"], parts["id"].to_numpy())
    assert pv.point_data["velocity"].shape == (len(x), 3) and pv.point_data["angular_velocity"].shape == (len(x), 3)
    assert ("force" in pv.point_data) == forces  # omitted, not zeros, where the source keeps no per-particle force
    # one line per contact, the normal forces, overlaps and |Ft| of the contact table bit for bit
    assert [c.type for c in cv.cells] == ["line"] and len(cv.cells[0].data) == len(contacts) > 0
    for name, col in (("normal_force", "fn"), ("tangential_force", "ft"), ("overlap", "overlap"), ("i", "i"),
                      ("j", "j")):
        assert cv.cell_data[name][0].dtype == contacts[col].dtype
        assert np.array_equal(cv.cell_data[name][0], contacts[col].to_numpy()), name
    lines = cv.cells[0].data
    start, end = cv.points[lines[:, 0]], cv.points[lines[:, 1]]
    i, j = contacts["i"].to_numpy(), contacts["j"].to_numpy()
    assert np.array_equal(start, x[i])
    # every line is short — a contact, never a segment across the box: at most r_i + r_j (they overlap, up to
    # the rounding of x_i + b − x_i) ≤ 2 R_max
    length = np.linalg.norm(end - start, axis=1)
    rad = parts["radius"].to_numpy()
    assert np.all(length <= (rad[i] + rad[j]) * (1 + 1e-12)) and length.max() <= 2 * rad.max() * (1 + 1e-12)
    # and it ends at j or at an image of j: a whole number of box lengths away in x and y, none in z
    periodic = cv.cell_data["periodic"][0].astype(bool)
    assert periodic.any() and not periodic.all()  # this packing has contacts across the boundary, and inside
    assert np.array_equal(end[~periodic], x[j[~periodic]])
    shift = (end[periodic] - x[j[periodic]]) / BOX
    whole = np.round(shift[:, :2])
    assert np.abs(shift[:, :2] - whole).max() < 1e-9 and np.all(np.abs(whole).sum(axis=1) >= 1)
    assert np.abs(end[periodic, 2] - x[j[periodic], 2]).max() < 1e-18
    return parts


def _check_xyz(out, parts):
    import ase.io

    a = ase.io.read(out / "state.xyz", format="extxyz")
    x = parts[["x", "y", "z"]].to_numpy()
    assert len(a) == len(x)
    assert np.abs(a.positions - x).max() <= XYZ_ROUNDING * (1 + 1e-9)
    assert np.abs(a.arrays["radius"] - parts["radius"].to_numpy()).max() <= XYZ_ROUNDING * (1 + 1e-9)
    assert list(a.pbc) == [True, True, False]
    top = float((x[:, 2] + parts["radius"]).max())
    np.testing.assert_allclose(np.asarray(a.cell), np.diag([BOX, BOX, top]), rtol=1e-15, atol=0)
    assert np.array_equal(a.arrays["id"], parts["id"].to_numpy())
    assert a.arrays["velo"].shape == (len(x), 3) and a.arrays["omega"].shape == (len(x), 3)
    assert "force" not in a.arrays and "mass" not in a.arrays  # too few digits at 8 decimals: in the VTU only
    return a


def test_pack_writes_vtk_and_extended_xyz_that_read_back(reference_pack):
    out, tmp = reference_pack
    parts = _check_vtk(tmp, forces=False)
    assert len(parts) == out["particles"] == 40
    a = _check_xyz(tmp, parts)
    import meshio

    pv = meshio.read(tmp / "vtk" / "particles.vtu")
    assert np.abs(a.arrays["velo"] - pv.point_data["velocity"]).max() <= XYZ_ROUNDING * (1 + 1e-9)


def test_pack_reports_the_fabric_of_its_own_positions(reference_pack):
    """The metrics' fabric is that of the written positions' contacts (branch vectors by minimum image)."""
    out, tmp = reference_pack
    parts = pd.read_csv(tmp / "csv" / "particles.csv")
    x, rad = parts[["x", "y", "z"]].to_numpy(), parts["radius"].to_numpy()
    b = PM.branch_vectors(x, PM.contacts(x, rad, (BOX, BOX)), (BOX, BOX))
    n = b / np.linalg.norm(b, axis=1)[:, None]
    m = out["metrics"]
    np.testing.assert_allclose(m["fabric"], n.T @ n / len(n), rtol=0, atol=1e-15)
    assert m["fabric_zz"] == m["fabric"][2][2]
    assert m["fabric_anisotropy"] == pytest.approx(PM.fabric_anisotropy(np.array(m["fabric"])), rel=1e-12)


@pytest.mark.parametrize("option,make,needle", [
    ("--vtk", lambda t: t / "a-file" / "out", "{t}/a-file/out': {t}/a-file is a file, not a directory"),
    ("--vtk", lambda t: t / "a-file", "{t}/a-file': is a file, not a directory"),
    ("--vtk", lambda t: t / "v", "{t}/v': {t}/v/contacts.vtu is a directory, not a file"),
    ("--xyz", lambda t: t / "a-file" / "s.xyz", "{t}/a-file/s.xyz': {t}/a-file is a file, not a directory"),
    ("--xyz", lambda t: t / "v", "{t}/v': is a directory, not a file"),
])
def test_bad_output_paths_are_refused_before_any_work(option, make, needle, tmp_path):
    (tmp_path / "a-file").write_text("x")
    (tmp_path / "v" / "contacts.vtu").mkdir(parents=True)
    before = sorted(str(p) for p in tmp_path.rglob("*"))
    p = demcheck("pack", ROOT / "cases" / "packing" / "column-lsd.toml", option, make(tmp_path), cwd=tmp_path)
    _one_line_exit_2(p, f"{option} = '" + needle.format(t=tmp_path))
    assert sorted(str(p) for p in tmp_path.rglob("*")) == before  # nothing written


def test_the_cli_and_the_writer_name_the_same_vtk_files():
    from demcheck import cli
    from demcheck.comparisons import packing_output

    assert cli.PACK_VTK_DIR.files == packing_output.VTK_FILES


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


@pytest.mark.engine("lammps")
def test_pack_in_lammps_writes_the_dumped_forces(tmp_path):
    out, tmp = _pack(tmp_path, "lammps")
    parts = _check_vtk(tmp, forces=True)
    _check_xyz(tmp, parts)
    import meshio

    f = meshio.read(tmp / "vtk" / "particles.vtu").point_data["force"]
    assert np.all(np.isfinite(f)) and np.abs(f).max() > 0
    assert out["contacts"] == len(pd.read_csv(tmp / "csv" / "contacts.csv"))
    assert out["mpi"] == 1 and out["source"] == "lammps"  # the ranks it ran on, as the reference's JSON its threads


@pytest.fixture(scope="module")
def lammps_run(tmp_path_factory):
    from demcheck.case import loads
    from demcheck.engines.packing import run_engine

    wd = tmp_path_factory.mktemp("lammps-run")
    case = loads(SMALL)
    return case, run_engine(case, "lammps", workdir=wd / "run"), wd / "run"


@pytest.mark.engine("lammps")
def test_engine_vtk_forces_are_the_final_dump_s(lammps_run, tmp_path):
    """particles.vtu's force is the final dump's fx, fy, fz (read again by demcheck's float64 parser)."""
    import meshio

    from demcheck.comparisons import packing_output
    from demcheck.engines import dumps
    from demcheck.inputs.packing_decks import FINAL_DUMP

    case, run, wd = lammps_run
    packing_output.write_vtk(packing_output.from_engine(case, run), tmp_path)
    dump = dumps.read_dump(wd / FINAL_DUMP).sort_values("id")
    pv = meshio.read(tmp_path / "particles.vtu")
    assert np.array_equal(pv.point_data["force"], dump[["fx", "fy", "fz"]].to_numpy())
    assert np.array_equal(pv.point_data["velocity"], dump[["vx", "vy", "vz"]].to_numpy())


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
    difference of the two sources' own samples of n_z². The value and its reference are the sources' own
    fabric_zz; the tolerance is checked for its size: an isotropic fabric has var(n_z²) = 1/5 − 1/9 = 4/45,
    so with some 50 contacts a source z(α/2)·√(2·(4/45)/50) = 3.29 × 0.060 ≈ 0.2 (0.05–0.5 allows for the
    sample's own variance and size)."""
    from demcheck.comparisons import suite

    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    s = suite.run_suite([path], tmp_path / "r", suite.Options(engines=("lammps",), cache=None), quiet=True).to_json()
    (c,) = s["cases"]
    (k,) = [k for k in c["comparisons"] if k["metric"] == "fabric_zz"]
    assert k["source"] == "lammps"
    ref, eng = c["sources"]["reference"]["metrics"], c["sources"]["lammps"]["metrics"]
    assert k["value"] == eng["fabric_zz"] and k["reference"] == ref["fabric_zz"]
    assert k["abs_diff"] == pytest.approx(abs(eng["fabric_zz"] - ref["fabric_zz"]), abs=1e-15)
    # the tolerance is z(α/2)·√(s_a²/N_a + s_b²/N_b): a few tenths for some 50 contacts a source
    assert 0.05 < k["tolerance"] < 0.5
    assert k["verdict"] == ("agree" if k["abs_diff"] <= k["tolerance"] else "unexpected")


@pytest.mark.engine("lammps")
def test_a_packing_s_engine_row_says_how_long_its_run_took_and_whether_the_cache_answered(tmp_path):
    """An engine's packing row carries its run's wall time and `cached`, as a collision's row does: a cold verify
    runs the deck (cached false, the time the run took), a second reads it from the run cache (cached true, a
    read's time, shorter than the run's). Before, a packing's engine rows had no wall time: a cold suite's time
    in its engines' packing loops was nowhere in its results."""
    from demcheck.comparisons import suite
    from demcheck.engines.cache import Cache

    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    rows = []
    for _ in range(2):
        opts = suite.Options(engines=("lammps",), cache=Cache(tmp_path / "cache"))
        s = suite.run_suite([path], tmp_path / "r", opts, quiet=True).to_json()
        rows.append(s["cases"][0]["sources"]["lammps"])
    cold, warm = rows
    assert cold["status"] == warm["status"] == "ok"
    assert cold["cached"] is False and warm["cached"] is True
    assert 0 < warm["wall_time"] < cold["wall_time"] < 600
    assert cold["metrics"] == warm["metrics"]
