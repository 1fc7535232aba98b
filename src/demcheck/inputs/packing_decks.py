"""What every engine's packing deck shares: the same initial state as the reference (a LAMMPS data file, one atom type per
particle species, carrying each particle's exact mass through its density), the species pairs' coefficients from the
mapping, plane walls, gravity, periodic x and y where the packing has a box, a final dump of every particle in full
precision, and a final dump of every particle-particle contact (the engine's own per-contact output: LAMMPS ``compute
pair/local`` with ``property/local``, LIGGGHTS ``compute pair/gran/local``) for the contact-force distribution. Every
block of a deck opens with a comment saying what it is."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..case import Case, packing_run
from ..errors import UnsupportedByEngine
from ..reference import packing
from . import common
from .common import fmt

FINAL_DUMP = "final.txt"
CONTACT_DUMP = "contacts.txt"
DATA_FILE = "data.lmp"
# the contact table every source yields: particle indices (0-based), overlap, normal force, |tangential force|
CONTACT_COLUMNS = ("i", "j", "overlap", "fn", "ft")
CONTACT_READER = 2  # in the engine-run cache key: cached contact tables are parsed ones (2: LIGGGHTS Fn signed)
FINAL_COLUMNS = ("id", "type", "radius", "mass", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
                 "fx", "fy", "fz")

# ----------------------------------------------------------------------------- the masses
#
# A data file line of atom_style sphere (LAMMPS) or granular (LIGGGHTS) gives a diameter and a density; both engines
# make the mass from them. Measured (LAMMPS 22 Jul 2025, LIGGGHTS-PUBLIC 3.8.0: the mass each dumps, for radii and
# densities drawn at random; tests/test_packing_decks.py keeps it measured): r = diameter / 2, then the product
# 4π/3 · r · r · r · ρ taken left to right in doubles, with 4π/3 the double (4·π)/3 = 4.1887902047863905 (one ulp
# below the double nearest 4π/3). The case's mass is ρ·4/3·π·r³ (Case.mass), which differs from it by an ulp or two
# for about half the radii: so the data file carries, for each species, the density (the material's when it already
# gives the case's mass, else the double nearest it that does) that makes the engine's mass the case's bit for bit.
# The product steps over some doubles: a species whose mass no density reaches (about one in ten radii) has its mass
# set in the deck, one ``set type`` line.
ENGINE_4PI_3 = 4.0 * math.pi / 3.0


def engine_mass(radius: float, density: float) -> float:
    """The mass LAMMPS and LIGGGHTS give a sphere of this radius and density read from a data file."""
    return ENGINE_4PI_3 * radius * radius * radius * density


def exact_density(mass: float, radius: float, density: float) -> float | None:
    """The density to write for a sphere of ``radius`` so that the engines' mass is ``mass`` exactly: ``density``
    itself when it already gives it, else the double nearest ``density`` that does, None when none does. A
    density that does lies within an ulp of mass / volume (|fl(V·d) − m| ≤ ulp(m)/2): three ulps either side
    are searched."""
    if engine_mass(radius, density) == mass:
        return density
    d0 = mass / (ENGINE_4PI_3 * radius * radius * radius)
    below = above = d0
    candidates = [d0]
    for _ in range(3):
        below, above = math.nextafter(below, 0.0), math.nextafter(above, math.inf)
        candidates += [below, above]
    hits = [d for d in candidates if engine_mass(radius, d) == mass]
    return min(hits, key=lambda d: (abs(d - density), d)) if hits else None


@dataclass(frozen=True)
class Species:
    """One species (material, radius): its atom type (1-based), representative particle, material, radius,
    the case's mass, the material's density, and the density the data file carries (None: the deck sets the
    mass, no density giving it exactly)."""

    type: int
    rep: int
    material: str
    radius: float
    mass: float
    density: float
    data_density: float | None

    @property
    def file_density(self) -> float:
        return self.density if self.data_density is None else self.data_density


def species_table(case: Case, rep) -> list[Species]:
    out = []
    for t, i in enumerate(rep):
        p = case.particles[i]
        rho = case.materials[p.material].density
        m = case.mass(i)
        out.append(Species(t + 1, i, p.material, p.radius, m, rho, exact_density(m, p.radius, rho)))
    return out


# ----------------------------------------------------------------------------- the layout and the data file


@dataclass
class Layout:
    """What both decks take from the case: each particle's species, the species, radii, the box (lo, hi,
    periodic in x and y), dt, the number of steps and the duration (case.packing_run: the reference solver's,
    refused past its bound before anything is built)."""

    species: np.ndarray
    table: list[Species]
    rad: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    periodic: np.ndarray
    dt: float
    steps: int
    duration: float

    @property
    def rep(self) -> list[int]:
        return [s.rep for s in self.table]


def layout(case: Case, duration, dt) -> Layout:
    if case.kind != "packing":
        raise UnsupportedByEngine(f"case '{case.name}' is not a packing")
    dt, duration, steps = packing_run(case, duration, dt)
    species, rep = packing.species_of(case)
    x = np.array([p.position for p in case.particles], float)
    rad = np.array([p.radius for p in case.particles], float)
    lo, hi, periodic = packing.box_of(case, x, rad)
    return Layout(species, species_table(case, rep), rad, lo, hi, periodic, dt, steps, duration)


def data_file(case: Case, lay: Layout, n_types: int | None = None) -> str:
    """The initial state both engines read (read_data): the box, every particle (id, type, diameter, density,
    position) and its velocities; the header says what each column is and why a density may not be the
    material's."""
    n_types = n_types or len(lay.table)
    title = common.comment(f"demcheck packing: case {case.name} (hash {case.hash})")
    about = ["the box (m), then per particle: id, atom type (its species), diameter (m), density (kg/m^3) and",
             "x y z (m); then its velocity (m/s) and angular velocity (rad/s). The engines make a mass",
             "4*pi/3 * r * r * r * density in doubles: a species' density is its material's, or the double",
             "nearest it that makes that mass the case's 4/3 pi r^3 rho bit for bit (the deck sets the mass",
             "of a species no density reaches)"]
    lines = [title, *[common.comment(a) for a in about], "", f"{len(case.particles)} atoms", f"{n_types} atom types",
             "", *(f"{fmt(lay.lo[k])} {fmt(lay.hi[k])} {a}lo {a}hi" for k, a in enumerate("xyz")), "", "Atoms", ""]
    for k, p in enumerate(case.particles):
        s = lay.table[lay.species[k]]
        lines.append(f"{k + 1} {s.type} {fmt(2 * p.radius)} {fmt(s.file_density)} "
                     f"{' '.join(fmt(x) for x in p.position)}")
    lines += ["", "Velocities", ""]
    for k, p in enumerate(case.particles):
        lines.append(f"{k + 1} {' '.join(fmt(x) for x in p.velocity)} {' '.join(fmt(x) for x in p.angular_velocity)}")
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- the deck's blocks


def head(case: Case, engine: str, note: str, hand: str, lay: Layout, mappings, atom_style: str, comm: str) -> list[str]:
    """The opening comments (what the deck is, the case, the model and its mapping, the run, how to run it by
    hand), units, the atoms and the box, the data file and the masses no density carries."""
    fidelities = sorted({mp.fidelity for mp in mappings})
    reasons = list(dict.fromkeys(r for mp in mappings for r in mp.reasons))
    periodic = "".join("xy"[k] for k in range(2) if lay.periodic[k])
    box = {"xy": "periodic in x and y, not in z", "x": "periodic in x only", "y": "periodic in y only",
           "": "not periodic"}[periodic]
    lines = [common.comment(f"demcheck packing deck for {engine} ({note})"),
             common.comment(f"case: {case.name} (hash {case.hash})"),
             common.comment(f"model: normal = {case.contact.normal}, tangential = {case.contact.tangential}; "
                            f"mapping fidelity: {', '.join(fidelities)}"),
             *common.notes(reasons),
             common.comment(f"{len(case.particles)} particles of {len(lay.table)} species; {lay.steps} steps of dt = "
                            f"{fmt(lay.dt)} s ({fmt(lay.duration)} s); final state: {FINAL_DUMP} (every particle), "
                            f"{CONTACT_DUMP} (every contact)"),
             common.comment(f"run by hand: {hand} <this file> (it reads {DATA_FILE}, written beside it)"), "",
             common.comment("SI units (m, kg, s)"), "units si",
             common.comment("spheres with their own radius, mass and spin; one atom type per species (material, "
                            "radius)"),
             f"atom_style {atom_style}", "atom_modify map array",
             common.comment(f"the box: {box} (its extent is in {DATA_FILE})"),
             "boundary " + " ".join("p" if lay.periodic[k] else "f" for k in range(2)) + " f",
             common.comment("a pair across a periodic or process boundary is computed on both sides, and ghost "
                            "particles carry their velocities (the dashpots use them)"),
             "newton off", comm,
             common.comment("on several MPI ranks (mpirun -np N), cut the box across x and y only: the bed gathers at "
                            "the bottom, and ranks cut along the height would leave it to one rank"),
             "processors * * 1",
             common.comment("the initial state: every particle's type, diameter, density, position and velocity"),
             f"read_data {DATA_FILE}"]
    for s in lay.table:
        how = (f"its density in {DATA_FILE}, {fmt(s.file_density)}, gives it exactly" if s.data_density is not None
               else "set here: no density gives it exactly in doubles")
        lines.append(common.comment(f"species {s.type}: {s.material}, radius {fmt(s.radius)} m, mass {fmt(s.mass)} kg "
                                    f"({how})"))
        if s.data_density is None:
            lines.append(f"set type {s.type} mass {fmt(s.mass)}")
    return lines


def wall_comment(w, k: int) -> str:
    """What a plane wall is: ``the plane z = 0, facing +z (a floor)``."""
    ax, side = common.wall_axis(w, k)
    what = " (a floor)" if (ax, side) == (2, "lo") else " (a lid)" if ax == 2 else ""
    return f"wall {k}: the plane {'xyz'[ax]} = {fmt(w.point[ax])}, facing {'+' if side == 'lo' else '-'}{'xyz'[ax]}{what}"


def law_comments(laws) -> list[str]:
    """Comment lines for the contact laws, given as (who, mapping): one line when every pair's mapping reads
    the same (``every species pair and the wall: …``), else one per pair (``species 1 with 2: …``)."""
    texts = [(who, "; ".join(mp.native.comments) or "as mapped") for who, mp in laws]
    if len({t for _, t in texts}) == 1:
        walls = " and the walls" if any(w.endswith("the walls") for w, _ in texts) else ""
        return [common.comment(f"every species pair{walls}: {texts[0][1]}")]
    return [common.comment(f"{who}: {t}") for who, t in texts]


def gravity(case: Case) -> list[str]:
    g = np.asarray(case.run.gravity, float)
    gn = float(np.linalg.norm(g))
    if gn == 0:
        return []
    return [common.comment(f"gravity: {fmt(gn)} m/s^2 along ({', '.join(fmt(c / gn) for c in g)})"),
            f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(c / gn) for c in g)}"]


def integration(lay: Layout) -> list[str]:
    """Velocity Verlet (positions and spins) at dt, the kinetic energy printed 50 times, and the run."""
    every = max(1, lay.steps // 50)
    return ["", common.comment(f"time integration: velocity Verlet for positions and spins, dt = {fmt(lay.dt)} s; "
                               f"the total translational kinetic energy every {every} steps"),
            "fix integrate all nve/sphere", f"timestep {fmt(lay.dt)}", "thermo_style custom step ke atoms",
            "thermo_modify norm no", f"thermo {every}",
            common.comment(f"the run: {lay.steps} steps, the {fmt(lay.duration)} s of the case in whole steps"),
            f"run {lay.steps}"]
