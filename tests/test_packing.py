"""Packings: the case layouts, the N-body reference solver against the column's closed form, and the
packing metrics on lattices whose values are known exactly."""

import math

import numpy as np
import pytest

from demcheck import case as C
from demcheck.comparisons import packing_metrics as PM
from demcheck.errors import ConfigError
from demcheck.reference import packing as P

COLUMN = """
name = "column"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.05
[packing]
layout = "column"
count = 5
material = "glass"
radius = 1e-3
duration = 0.05
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
normal = "lsd"
kn = 2000.0
[run]
gravity = [0.0, 0.0, -9.81]
"""


def test_column_of_spheres_settles_to_the_static_closed_form():
    """Each contact carries the weight above it: δ = F/Kn (the pair's Kn, and the wall's), to 1e-6."""
    case = C.loads(COLUMN)
    sp, laws_n, _, wall_n, _ = P.resolve_laws(case)
    st = P.simulate(case, rest=0.0)
    z, r, m, g, n = st.x[:, 2], st.rad[0], st.mass[0], 9.81, 5
    for k in range(n):
        weight = (n - k) * m * g
        if k == 0:
            delta, kn = r - z[0], wall_n[0][1]
        else:
            delta, kn = 2 * r - (z[k] - z[k - 1]), laws_n[0, 0][1]
        assert delta == pytest.approx(weight / kn, rel=1e-6), k
    assert np.allclose(st.x[:, :2], 0.0)  # it stays a column
    assert st.n_contacts == n - 1


def test_column_hertz_overlaps():
    """Hertz: δ = (F/K_HZ)^{2/3}, K_HZ = (4/3)Ē√R̄ with R̄ = R/2 between spheres and R at the rigid floor."""
    case = C.loads(COLUMN.replace('normal = "lsd"\nkn = 2000.0', 'normal = "kk"\neta_n = 200.0')
                   .replace("duration = 0.05", "duration = 0.2"))
    st = P.simulate(case, rest=0.0)
    e, nu, r, m, g, n = 1e8, 0.3, 1e-3, st.mass[0], 9.81, 5
    for k in range(n):
        weight = (n - k) * m * g
        if k == 0:
            k_hz, delta = 4 / 3 * e / (1 - nu**2) * math.sqrt(r), r - st.x[0, 2]
        else:
            k_hz, delta = 4 / 3 * e / (2 * (1 - nu**2)) * math.sqrt(r / 2), 2 * r - (st.x[k, 2] - st.x[k - 1, 2])
        assert delta == pytest.approx((weight / k_hz) ** (2 / 3), rel=1e-6), k


def test_metrics_of_a_simple_cubic_lattice_are_exact():
    """Spheres touching on a simple cubic lattice: solid fraction π/6, coordination 6 in the bulk."""
    r, n = 1e-3, 6
    a = 2 * r
    g = np.arange(n) * a + r
    x = np.array([(i, j, k) for i in g for j in g for k in g])
    rad = np.full(len(x), r)
    m = PM.compute(x, rad, box=(n * a, n * a), floor=0.0, margin=1.0)
    assert m["solid_fraction"] == pytest.approx(math.pi / 6, rel=1e-12)
    assert m["coordination_number"] == 6.0
    assert m["bed_height"] == pytest.approx(n * a)


def test_metrics_of_a_face_centred_cubic_lattice():
    """FCC touching spheres: solid fraction π/(3√2), coordination 12."""
    r = 1e-3
    a = 2 * math.sqrt(2) * r
    base = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) * a
    cells = 5
    x = np.array([b + a * np.array([i, j, k]) for i in range(cells) for j in range(cells) for k in range(cells)
                  for b in base]) + r
    m = PM.compute(x, np.full(len(x), r), box=(cells * a, cells * a), floor=0.0, margin=1.5)
    # the slab cuts an integer number of periods only approximately: its planes cut layers anywhere
    assert m["solid_fraction"] == pytest.approx(math.pi / (3 * math.sqrt(2)), rel=0.02)
    assert m["coordination_number"] == 12.0


def test_force_distribution_is_a_density():
    f = np.random.default_rng(1).exponential(size=5000)
    d = PM.force_distribution(f)
    width = d["x"][1] - d["x"][0]
    assert sum(p * width for p in d["p"]) == pytest.approx(1.0, rel=1e-9)


@pytest.mark.parametrize("change,message", [
    (("layout = \"column\"", "layout = \"heap\""), "packing.layout = 'heap': must be one of column, layer, poured"),
    (("count = 5", "count = 0"), "packing.count = 0: must be an integer >= 1"),
    (("radius = 1e-3", "radius = -1e-3"), "packing.radius = -0.001: must be > 0 (m)"),
    (("layout = \"column\"", "layout = \"poured\"\nbox = [1e-3, 1e-2]"),
     "packing.box = [0.001, 0.01]: must be larger than a particle's diameter (0.002 m) in x and y"),
    (("layout = \"column\"", "layout = \"poured\""), "packing.box = (missing): missing: a poured packing needs"),
    (("material = \"glass\"", "material = \"steel\""), "packing.material = 'steel': is not a defined material"),
])
def test_bad_packing_input_is_one_clear_line(change, message):
    with pytest.raises(ConfigError) as info:
        C.loads(COLUMN.replace(*change))
    assert str(info.value).startswith(message)


def test_poured_layout_is_seeded_and_does_not_overlap():
    text = COLUMN.replace('layout = "column"', 'layout = "poured"\nbox = [0.012, 0.012]\nseed = 7').replace(
        "count = 5", "count = 200").replace("radius = 1e-3", "radii = [0.8e-3, 1.0e-3, 1.2e-3]")
    a, b = C.loads(text), C.loads(text)
    assert [p.position for p in a.particles] == [p.position for p in b.particles]
    assert sorted({p.radius for p in a.particles}) == [0.8e-3, 1.0e-3, 1.2e-3]
    assert len(a.particles) == 200  # the loader rejects any overlap, so none


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ("lammps", "liggghts")])
@pytest.mark.parametrize("normal", ["lsd", "kk"])
def test_engines_settle_the_column_to_the_closed_form(engine, normal):
    """The same data file, coefficients from the mapping, the engine's final dump (float64): every overlap
    within 1e-6 of the closed form, as the reference."""
    from demcheck.inputs.packing_decks import run_engine

    text = COLUMN if normal == "lsd" else COLUMN.replace('normal = "lsd"\nkn = 2000.0', 'normal = "kk"\neta_n = 200.0') \
        .replace("duration = 0.05", "duration = 0.2")
    case = C.loads(text)
    table, ke, version = run_engine(case, engine)
    assert ke and ke[-1][1] < 1e-20 and version
    z, r, m, g, n = table["z"].to_numpy(), 1e-3, case.mass(0), 9.81, 5
    e, nu = 1e8, 0.3
    _, laws_n, _, wall_n, _ = P.resolve_laws(case)
    for k in range(n):
        weight = (n - k) * m * g
        delta = r - z[0] if k == 0 else 2 * r - (z[k] - z[k - 1])
        if normal == "lsd":
            expected = weight / (wall_n[0][1] if k == 0 else laws_n[0, 0][1])
        else:
            k_hz = 4 / 3 * e / (1 - nu**2) * math.sqrt(r) if k == 0 else 4 / 3 * e / (2 * (1 - nu**2)) * math.sqrt(r / 2)
            expected = (weight / k_hz) ** (2 / 3)
        assert delta == pytest.approx(expected, rel=1e-6), k


def test_cli_pack_reference(tmp_path):
    import json
    import subprocess
    import sys

    from .conftest import CASES

    p = subprocess.run([sys.executable, "-m", "demcheck", "pack", str(CASES / "packing" / "column-lsd.toml"), "--json"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["particles"] == 5 and out["contacts"] == 4
    assert out["metrics"]["coordination_number"] == 2.0
    bad = subprocess.run([sys.executable, "-m", "demcheck", "pack", str(CASES / "glass-pair.toml")],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "kind = 'collision': demcheck pack runs packing cases" in bad.stderr


@pytest.mark.parametrize("tangential,params", [("spring_sliding", None),
                                               ("lsd_sliding", {"truncation": "overlap", "tangential_restitution": 0.5}),
                                               ("lsd_sliding", {"truncation": "spring", "tangential_restitution": 0.5}),
                                               ("lsd_sliding", {"truncation": "force", "tangential_restitution": 0.5}),
                                               ("viscous_sliding", {"eta_t": 2.0}), ("none", {}),
                                               ("lth", {"eta_t": 0.5}), ("zzy", {"eta_1": 1e-4}), ("sliding", {}),
                                               ("viscous", {"eta_t": 2.0})])
def test_the_packing_solver_is_the_two_body_verlet_method_for_two_bodies(tangential, params):
    """An oblique spinning pair through the N-body solver (cell lists, slots, its scalar spring law) and
    through the two-body verlet method (kernels3d, seed rules): the same collision to round-off."""
    from demcheck.reference.collision import auto_dt

    from .helpers import oblique_case

    from demcheck.inputs.mapping import RULES

    case = oblique_case(tangential, params, wall=False, angle=30.0, spin=500.0,
                        overrides=["contact.reference_velocity=1.0"])  # one species pair: calibrate explicitly
    dt = auto_dt(case)
    # the seed's rules, and each engine twin's for the laws the engines express (LTH, ZZYt and the slider's
    # stick have no engine twin)
    engine_laws = tangential not in ("lth", "zzy")
    for rules in (None, RULES["lammps"], RULES["liggghts"]) if engine_laws else (None,):
        _same_as_two_body(case, dt, rules)


def _same_as_two_body(case, dt, rules):
    from demcheck.reference import collision3d
    from demcheck.reference.model import resolve

    two = collision3d.collide(case, resolve(case), "verlet", dt=dt, rules=rules)
    steps = int(round(two.contact["t"].iloc[-1] / dt))
    st = P.PackState(case)
    sp, ln, lt, wn, wt = P.resolve_laws(case)
    lo, hi, periodic = P.box_of(case, st.x, st.rad)
    P.run(st.x, st.v, st.w, st.rad, st.mass, sp, ln, lt, wn, wt, np.zeros((0, 6)), lo, hi, periodic, np.zeros(3), dt,
          steps, steps, st.partner, st.hist, st.dmax, st.contacts, collision3d.rules_array(rules))
    last = two.particles.groupby("id").last()
    for i in (0, 1):
        np.testing.assert_allclose(st.v[i], last.loc[i, ["vx", "vy", "vz"]].to_numpy(), rtol=0, atol=1e-12)
        np.testing.assert_allclose(st.w[i], last.loc[i, ["wx", "wy", "wz"]].to_numpy(), rtol=0, atol=1e-9)


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_verify_runs_the_small_packings_in_every_source(tmp_path):
    from pathlib import Path

    from demcheck.comparisons import suite

    from .conftest import CASES

    files = sorted((CASES / "packing").glob("*.toml"))
    s = suite.run_suite(files, tmp_path / "r", suite.Options(jobs=2, cache=None), quiet=True)
    assert s["failed"] == 0 and {c["case"] for c in s["cases"]} == {"column-lsd", "layer-kk"}
    for c in s["cases"]:
        static = {k["source"]: k for k in c["comparisons"] if k["metric"] == "static_overlap"}
        assert set(static) == {"reference", "lammps", "liggghts"}
        assert all(k["verdict"] == "agree" and k["value"] < 1e-6 for k in static.values())
    md = (Path(s["report"]) / "report.md").read_text()
    assert "## Packings" in md and "| column-lsd | lammps |" in md
    assert "packing column-lsd" in (Path(s["report"]) / "report.html").read_text()


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ("lammps", "liggghts")])
def test_engines_run_packings_under_mpi(engine):
    """Two MPI ranks (each engine's own launcher and domain decomposition): the same settled column."""
    from demcheck.inputs.packing_decks import run_engine

    case = C.loads(COLUMN)
    table, ke, _ = run_engine(case, engine, mpi=2)
    z, r = table["z"].to_numpy(), 1e-3
    _, laws_n, _, wall_n, _ = P.resolve_laws(case)
    assert r - z[0] == pytest.approx(5 * case.mass(0) * 9.81 / wall_n[0][1], rel=1e-6)


@pytest.mark.engine("lammps")
def test_polydisperse_species_pairs_run_in_the_reference_and_lammps():
    from demcheck.inputs.packing_decks import lammps_deck, run_engine

    from .conftest import CASES

    case = C.load(CASES / "optin" / "poured-small-poly.toml", ["packing.duration=0.01"])
    sp, rep = P.species_of(case)
    assert len(rep) == 3
    assert lammps_deck(case).text.count("pair_coeff") == 6  # every species pair, explicitly
    st = P.simulate(case, rest=0.0)
    assert np.all(np.isfinite(st.x)) and st.x[:, 2].min() > 0
    table, _, _ = run_engine(case, "lammps")
    assert len(table) == 150 and np.all(np.isfinite(table["z"]))


def test_default_suite_leaves_the_optin_cases_out():
    from demcheck.cli import CASES_DIR, _case_files

    files = _case_files([])
    assert any(f.parent.name == "packing" for f in files)
    assert not any("optin" in f.parts for f in files)
    assert _case_files([str(CASES_DIR / "optin")])  # named explicitly, they run
