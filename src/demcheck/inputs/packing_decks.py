"""What every engine's packing deck shares: the same initial state as the reference (the layout: one species per
material and radius, each with the case's exact mass, the box, periodic in x and y where the packing has one, the
step and the run's length), the comments on walls and laws, and the names of the final state's and the contacts'
files. The LAMMPS family's data file, opening block, gravity and integration lines are engines/family_packing.py's;
the masses' rule below (a density that gives the case's mass through the engines' 4π/3·r·r·r·ρ) is what a data file
must carry, and the layout's species hold it."""

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


# ----------------------------------------------------------------------------- the layout


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


# ----------------------------------------------------------------------------- comments


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
