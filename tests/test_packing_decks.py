"""Packing decks read like decks a person writes: the masses travel in the data file (a density per species chosen so
that the engine's mass is the case's bit for bit; a species no density reaches gets one ``set type`` line), a comment
opens every block, and the golden decks (tests/golden/packing-small.*) run by hand.

The golden values are the engines' own: the masses LAMMPS and LIGGGHTS dump after reading the data file, compared
with Case.mass (ρ·4/3·π·r³, written independently of the density search) with ==, and a brute-force scan of
densities for the search."""

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.engines import discovery, dumps, family_deck as FD, family_packing as FP, registry
from demcheck.errors import DemcheckError
from demcheck.inputs import common, packing_decks as PD

from .conftest import CASES

GOLDEN = Path(__file__).parent / "golden"
ENGINES = ("lammps", "liggghts")
HAND = {"lammps": "lmp -in", "liggghts": "liggghts -in"}
# a small packing whose three species take the three ways a mass travels: 0.6 mm (a density one ulp above 2500),
# 0.68 mm (no density reaches its mass: set in the deck), 1 mm (2500 itself)
SMALL = (CASES / "optin" / "poured-small-poly.toml",
         ["packing.count=30", "packing.radii=[0.6e-3, 0.68e-3, 1e-3]", "packing.duration=0.1"])


def small_case():
    return C.load(SMALL[0], SMALL[1])


def deck_of(case, engine, **kw):
    return registry.get(engine).packing_deck(case, **kw)


def commands(text):
    return [line for line in text.splitlines() if line.strip() and not line.startswith("#")]


def paths(table):
    return ["plain" if s.data_density == s.density else "set" if s.data_density is None else "nudged" for s in table]


# ----------------------------------------------------------------------------- the mass of a sphere


def test_the_density_search_agrees_with_a_brute_force_scan():
    """For each radius, the search's answer is the density nearest the material's among every double within 64
    ulps of m/V that gives the mass (scanned one by one), and None exactly when the scan finds none."""
    rho = 2500.0
    seen = set()
    for r in [k * 1e-5 for k in range(30, 130)]:
        m = rho * 4.0 / 3.0 * math.pi * r**3
        d = m / (PD.ENGINE_4PI_3 * r * r * r)
        scan, lo = [], d
        for _ in range(64):
            lo = math.nextafter(lo, 0.0)
        x = lo
        for _ in range(129):
            if PD.engine_mass(r, x) == m:
                scan.append(x)
            x = math.nextafter(x, math.inf)
        got = PD.exact_density(m, r, rho)
        if not scan:
            assert got is None, r
            seen.add("none")
        else:
            assert got == min(scan, key=lambda v: (abs(v - rho), v)), r
            assert abs(got - rho) <= 2 * math.ulp(rho), r  # an ulp or two: the case's and the engines' 4π/3 differ
            seen.add("plain" if got == rho else "nudged")
    assert seen == {"none", "plain", "nudged"}  # the radii above take all three ways


def test_the_engines_4pi_3_is_not_the_nearest_double():
    """The engines' 4π/3 is (4·π)/3 in doubles, one ulp below the double nearest 4π/3 (= 4.18879020478639098461…)."""
    assert PD.ENGINE_4PI_3 == 4.1887902047863905
    assert float("4.18879020478639098461") == math.nextafter(PD.ENGINE_4PI_3, 5.0)


# ----------------------------------------------------------------------------- the decks' text


@pytest.mark.parametrize("name", ["poured", "poured-poly"])
@pytest.mark.parametrize("engine", ENGINES)
def test_a_packing_deck_is_short_and_says_what_each_block_is(name, engine):
    """2000 particles and no per-particle line: the deck stays under 100 lines, every run of commands opens with
    a comment, and the data file's header says what its columns are."""
    case = C.load(CASES / "packing" / f"{name}.toml")
    dk = deck_of(case, engine)
    lines = dk.text.splitlines()
    assert len(case.particles) == 2000
    assert len(lines) < 100, len(lines)
    assert not [line for line in lines if line.startswith("set ")]  # every species' density reaches its mass
    for k, line in enumerate(lines):
        if line.strip() and not line.startswith("#") and (k == 0 or not lines[k - 1].strip()):
            pytest.fail(f"line {k + 1} opens a block without a comment: {line!r}")
    must = ["# SI units", "# the box: periodic in x and y, not in z (its extent is in data.lmp)", "# the initial state:",
            "# species 1: glass, radius", "# neighbour lists:", "# wall 0: the plane z = 0, facing +z (a floor)",
            "# gravity: 9.81 m/s^2 along (0, 0, -1)", "# time integration:", "# the run:", "# the final state",
            f"# run by hand: {HAND[engine]} <this file> (it reads data.lmp"]
    for start in must:
        assert any(line.startswith(start) for line in lines), start
    assert any(line.startswith(("# every species pair", "# species 1 with 1:")) for line in lines)
    data = dk.files[FP.DATA_FILE].splitlines()
    header = data[:data.index("Atoms")]
    assert header[0].startswith("# demcheck packing: case ") and sum(h.startswith("#") for h in header) > 3
    assert f"{len(case.particles)} atoms" in header
    assert len(data) < 2 * len(case.particles) + 30


@pytest.mark.parametrize("engine", ENGINES)
def test_the_data_file_carries_every_mass(engine):
    """poured-poly: each particle's data-file density gives the case's mass under the engines' product; the
    1.2 mm species needs a density one ulp above 2500 (2500 itself gives one ulp less)."""
    case = C.load(CASES / "packing" / "poured-poly.toml")
    data = deck_of(case, engine).files[FP.DATA_FILE].splitlines()
    atoms = data[data.index("Atoms") + 2:data.index("Velocities") - 1]
    assert len(atoms) == len(case.particles)
    for k, line in enumerate(atoms):
        words = line.split()
        assert int(words[0]) == k + 1
        r, rho = float(words[2]) / 2, float(words[3])
        assert r == case.particles[k].radius
        assert PD.engine_mass(r, rho) == case.mass(k), k
    r12 = 1.2e-3
    assert PD.engine_mass(r12, 2500.0) == math.nextafter(2500.0 * 4.0 / 3.0 * math.pi * r12**3, 0.0)
    assert {w.split()[3] for w in atoms if w.split()[2] == "0.0024"} == {"2500.0000000000005"}


def test_a_species_no_density_reaches_has_its_mass_set_in_the_deck():
    case = small_case()
    for engine in ENGINES:
        dk = deck_of(case, engine)
        assert paths(PD.layout(case, None, None).table) == ["nudged", "set", "plain"]
        assert [line for line in dk.text.splitlines() if line.startswith("set ")] == [
            f"set type 2 mass {common.fmt(case.mass(1))}"]
        assert "(set here: no density gives it exactly in doubles)" in dk.text


def test_data_file_comments_are_allowed_in_the_header_only():
    ok = "# title\n# what the columns are\n\n1 atoms\n1 atom types\n\nAtoms\n\n1 1 0.002 2500 0 0 0\n"
    FD.check_data(ok)
    with pytest.raises(DemcheckError, match="line 10 is not a number"):
        FD.check_data(ok + "# a comment among the atoms\n")


# ----------------------------------------------------------------------------- the engines' masses


def _run_by_hand(engine, deck_path, files, tmp_path):
    shutil.copy(deck_path, tmp_path / "in.deck")
    for name, src in files.items():
        shutil.copy(src, tmp_path / name)
    p = subprocess.run([discovery.find(engine).executable, "-in", "in.deck"], cwd=tmp_path, capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    return dumps.read_dump(tmp_path / PD.FINAL_DUMP, columns=PD.FINAL_COLUMNS).sort_values("id").reset_index(drop=True)


@pytest.mark.parametrize("density", [2500.0, 2650.0])
@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ENGINES])
def test_the_engine_dumps_the_case_masses_bit_for_bit(engine, density, tmp_path):
    """24 radii, 0.3 to 0.6 mm: the mass each engine dumps (%.17g, read back exactly) is Case.mass (ρ·4/3·π·r³)
    to the last bit, for species whose density is the material's, one nudged by an ulp or two, and one whose
    mass is set in the deck. A short run (1e-4 s): the masses are read, not the packing."""
    radii = [float(f"{0.3e-3 + 0.013e-3 * k:.6g}") for k in range(24)]
    case = C.load(SMALL[0], [f"packing.radii={radii}", "packing.count=48", "packing.duration=1e-4",
                             f"materials.glass.density={density!r}"])
    assert {"plain", "nudged", "set"} <= set(paths(PD.layout(case, None, None).table))
    dk = deck_of(case, engine)
    dk.write(tmp_path / "deck.in")
    table = _run_by_hand(engine, tmp_path / "deck.in", {}, tmp_path)
    assert table["id"].tolist() == list(range(1, len(case.particles) + 1))
    masses = table["mass"].to_numpy()
    wrong = [(k, masses[k], case.mass(k)) for k in range(len(case.particles)) if masses[k] != case.mass(k)]
    assert not wrong
    assert np.array_equal(table["radius"].to_numpy(), [p.radius for p in case.particles])


# ----------------------------------------------------------------------------- golden decks


@pytest.mark.parametrize("engine", ENGINES)
def test_generated_packing_decks_match_the_golden_files(engine):
    """The decks are reviewed text: a change shows up here (regenerate with DEMCHECK_UPDATE_GOLDEN=1 after
    reading the new deck and running it by hand)."""
    dk = deck_of(small_case(), engine)
    path = GOLDEN / f"packing-small.{engine}.in"
    if os.environ.get("DEMCHECK_UPDATE_GOLDEN") == "1":
        path.write_text(dk.text)
        for name, text in dk.files.items():
            (GOLDEN / f"packing-small.{engine}.{name}").write_text(text)
    assert path.read_text() == dk.text
    for name, text in dk.files.items():
        assert (GOLDEN / f"packing-small.{engine}.{name}").read_text() == text


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ENGINES])
def test_golden_packing_decks_run_by_hand(engine, tmp_path):
    """A person runs the golden deck (lmp -in / liggghts -in) beside its data file: it runs to the end, every
    particle's mass is the case's to the last bit, no particle is below the floor, and the contact dump reads."""
    from demcheck.engines import registry
    from demcheck.engines.family import read_contact_dump

    case = small_case()
    table = _run_by_hand(engine, GOLDEN / f"packing-small.{engine}.in",
                         {FP.DATA_FILE: GOLDEN / f"packing-small.{engine}.{FP.DATA_FILE}"}, tmp_path)
    assert len(table) == len(case.particles)
    assert [m == case.mass(k) for k, m in enumerate(table["mass"])] == [True] * len(case.particles)
    assert (table["z"] > 0).all() and np.isfinite(table.drop(columns="step").to_numpy(float)).all()
    contacts = read_contact_dump(registry.get(engine), tmp_path / PD.CONTACT_DUMP, table["radius"].to_numpy(),
                             table[["x", "y", "z"]].to_numpy(), case.packing.box)
    assert list(contacts.columns) == list(PD.CONTACT_COLUMNS)


def test_demcheck_deck_writes_the_golden_packing_deck(tmp_path):
    """`demcheck deck CASE --engine E -o FILE` writes the deck and its data file beside it, as in the golden files."""
    sets = [a for s in SMALL[1] for a in ("--set", s)]
    p = subprocess.run([sys.executable, "-m", "demcheck", "deck", str(SMALL[0]), "--engine", "lammps", *sets, "-o",
                        str(tmp_path / "in.small")], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "in.small").read_text() == (GOLDEN / "packing-small.lammps.in").read_text()
    assert (tmp_path / FP.DATA_FILE).read_text() == (GOLDEN / f"packing-small.lammps.{FP.DATA_FILE}").read_text()
