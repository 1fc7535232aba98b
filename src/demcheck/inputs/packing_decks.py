"""What every engine's packing deck shares: the same initial state as the reference (a LAMMPS data file, one atom type per
particle species), the species pairs' coefficients from the mapping, plane walls, gravity, periodic x and
y where the packing has a box, a final dump of every particle in full precision, and a final dump of every
particle-particle contact (the engine's own per-contact output: LAMMPS ``compute pair/local`` with
``property/local``, LIGGGHTS ``compute pair/gran/local``) for the contact-force distribution."""

from __future__ import annotations

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


def data_file(case: Case, species, lo, hi, n_types: int | None = None) -> str:
    n_types = n_types or int(species.max()) + 1
    lines = [common.comment(f"demcheck packing: case {case.name} (hash {case.hash})"), "",
             f"{len(case.particles)} atoms", f"{n_types} atom types", "", f"{fmt(lo[0])} {fmt(hi[0])} xlo xhi",
             f"{fmt(lo[1])} {fmt(hi[1])} ylo yhi", f"{fmt(lo[2])} {fmt(hi[2])} zlo zhi", "", "Atoms", ""]
    for k, p in enumerate(case.particles):
        rho = case.materials[p.material].density
        lines.append(f"{k + 1} {species[k] + 1} {fmt(2 * p.radius)} {fmt(rho)} {' '.join(fmt(x) for x in p.position)}")
    lines += ["", "Velocities", ""]
    for k, p in enumerate(case.particles):
        lines.append(f"{k + 1} {' '.join(fmt(x) for x in p.velocity)} {' '.join(fmt(x) for x in p.angular_velocity)}")
    return "\n".join(lines) + "\n"


def head(case: Case, engine: str, note: str, n_species: int, dt: float, steps: int, periodic, setup: list[str]):
    """Header comments, units, the engine's atom setup (BOUNDS: the boundary line), the data file and the
    exact masses."""
    bounds = "boundary " + " ".join("p" if periodic[k] else "f" for k in range(2)) + " f"
    lines = [common.comment(f"demcheck packing deck for {engine} ({note})"),
             common.comment(f"case: {case.name} (hash {case.hash})"),
             common.comment(f"model: normal = {case.contact.normal}, tangential = {case.contact.tangential}"),
             common.comment(f"{len(case.particles)} particles of {n_species} species, dt = {fmt(dt)} s, {steps} "
                            f"steps; final state: {FINAL_DUMP}"), "", "units si",
             *[bounds if x == "BOUNDS" else x for x in setup],
             "read_data data.lmp"]
    for k in range(len(case.particles)):
        lines.append(f"set atom {k + 1} mass {fmt(case.mass(k))}")
    return lines


def layout(case: Case, duration, dt):
    """What both decks take from the case: species and their representatives, radii, the box (lo, hi,
    periodic), dt and the number of steps (case.packing_run: the reference solver's, refused past its bound
    before anything is built)."""
    if case.kind != "packing":
        raise UnsupportedByEngine(f"case '{case.name}' is not a packing")
    dt, _, steps = packing_run(case, duration, dt)
    species, rep = packing.species_of(case)
    x = np.array([p.position for p in case.particles], float)
    rad = np.array([p.radius for p in case.particles], float)
    lo, hi, periodic = packing.box_of(case, x, rad)
    return species, rep, rad, lo, hi, periodic, dt, steps


