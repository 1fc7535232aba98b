"""What the LAMMPS family's packing decks share (LAMMPS and LIGGGHTS; engines/family.py reads what they write): the
initial state as a LAMMPS data file (one atom type per species, each particle's exact mass through its density:
inputs/packing_decks.py's masses), the deck's opening block (units, atoms, box, data file, masses no density
carries), gravity, and velocity Verlet with the kinetic energy in thermo lines. Every block opens with a comment
saying what it is. The layout they write (species, box, step, length) is the neutral inputs/packing_decks.py's."""

from __future__ import annotations

import numpy as np

from ..case import Case
from ..inputs import common
from ..inputs.common import fmt
from ..inputs.packing_decks import CONTACT_DUMP, FINAL_DUMP, Layout

DATA_FILE = "data.lmp"


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
