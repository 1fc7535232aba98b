"""A settled packing written for viewers and the usual analysis tools (`demcheck pack --vtk DIR`, `--xyz FILE`).

* VTK, through meshio (binary, zlib-compressed VTU, every array at its own precision: float64 stays float64):
  ``particles.vtu`` — one vertex per particle at its centre, with point data ``id`` (the 0-based index of
  contacts.csv and of contacts.vtu's ``i`` and ``j``; an engine's atom id − 1), ``type`` (the species, 1-based
  as the engines' atom types), ``radius``, ``mass``, ``velocity``, ``angular_velocity`` and, where the source
  has it, ``force`` (the engines' final dump: the net force on the particle — contacts, walls and gravity
  together, a small fraction of the weight at rest; the reference's state keeps no per-particle force, so
  its file has no ``force`` rather than zeros). ``contacts.vtu`` — one line per particle–particle contact of the source's own contact
  table, from the centre of particle i along the branch vector (x_j − x_i by minimum image in a periodic box)
  to particle j: a contact across a periodic boundary ends at an extra point, the image of j beside i, so no
  line crosses the box; cell data ``normal_force``, ``tangential_force`` (magnitude), ``overlap``, ``i``,
  ``j`` and ``periodic`` (1 where the line ends at an image). The contact tables hold particle pairs only:
  wall contacts are not drawn.
* Extended XYZ, through ase: species ``X`` (no element), positions, ``Lattice`` and ``pbc`` from the packing's
  box (periodic x and y, z not: the cell's height is the highest sphere top; no lattice for a packing without
  a box), and per particle ``id``, ``species_id`` (the VTK ``type``), ``radius``, ``velo`` and ``omega``
  (names for OVITO's Radius and Velocity; its reader's column mapping says what it took them for). ase writes
  every real column with eight decimals (``%16.8f``): in SI units positions and velocities are rounded to
  5e-9 m and m/s — ample to look at a millimetre packing, not for analysis (``--vtk`` keeps float64, ``--csv``
  17 digits). Masses (~1e-5 kg) and a settled bed's net forces (~1e-6 N) would keep one to four digits, so
  the XYZ file leaves them out; particles.vtu has both.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

PARTICLES_VTU = "particles.vtu"
CONTACTS_VTU = "contacts.vtu"
VTK_FILES = (PARTICLES_VTU, CONTACTS_VTU)


@dataclass
class Settled:
    """A source's settled packing: centres ``x`` (N × 3), ``radius``, per-particle ``fields`` (name → array of
    N or N × 3 values: type, mass, velocity, angular_velocity, and force where the source has it), the
    contact table (packing_decks.CONTACT_COLUMNS; i, j are row indices) and the periodic box (lx, ly) or
    None."""

    x: np.ndarray
    radius: np.ndarray
    contacts: pd.DataFrame
    box: tuple | None
    fields: dict = field(default_factory=dict)


def from_reference(case, st) -> Settled:
    """The reference solver's final state (reference.packing.PackState): no per-particle force is kept."""
    from ..inputs.packing_decks import CONTACT_COLUMNS
    from ..reference import packing

    nc = min(st.n_contacts, len(st.contacts))
    contacts = pd.DataFrame(st.contacts[:nc], columns=list(CONTACT_COLUMNS)).astype({"i": np.int64, "j": np.int64})
    species, _ = packing.species_of(case)
    fields = {"type": np.asarray(species, np.int64) + 1, "mass": np.asarray(st.mass, float),
              "velocity": np.asarray(st.v, float), "angular_velocity": np.asarray(st.w, float)}
    return Settled(np.asarray(st.x, float), np.asarray(st.rad, float), contacts, _box(case), fields)


def from_engine(case, run) -> Settled:
    """An engine's final dump (engines.packing.PackingRun: rows sorted by atom id) and its contact table."""
    t = run.table
    fields = {"type": t["type"].to_numpy(np.int64), "mass": t["mass"].to_numpy(float),
              "velocity": t[["vx", "vy", "vz"]].to_numpy(float),
              "angular_velocity": t[["omegax", "omegay", "omegaz"]].to_numpy(float)}
    if {"fx", "fy", "fz"} <= set(t.columns):
        fields["force"] = t[["fx", "fy", "fz"]].to_numpy(float)
    return Settled(t[["x", "y", "z"]].to_numpy(float), t["radius"].to_numpy(float), run.contacts, _box(case),
                   fields)


def _box(case):
    box = case.packing.box if case.packing else None
    return None if box is None else (float(box[0]), float(box[1]))


def contact_lines(x, contacts: pd.DataFrame, box=None):
    """(points, lines, periodic): the particle centres followed by one extra point per contact that crosses a
    periodic boundary (x_i plus the minimum-image branch vector: the image of j beside i); ``lines`` (N_c × 2)
    joins i to j, or i to j's image; ``periodic`` flags the latter."""
    from .packing_metrics import branch_vectors

    x = np.asarray(x, float)
    ij = contacts[["i", "j"]].to_numpy(np.int64).reshape(-1, 2)
    b = branch_vectors(x, ij, box)
    periodic = np.any(b != x[ij[:, 1]] - x[ij[:, 0]], axis=1)
    lines = ij.copy()
    lines[periodic, 1] = len(x) + np.arange(int(periodic.sum()))
    points = np.vstack([x, x[ij[periodic, 0]] + b[periodic]])
    return points, lines, periodic


def write_vtk(state: Settled, directory) -> list[Path]:
    """particles.vtu and contacts.vtu in ``directory`` (created), as the module docstring describes."""
    import meshio

    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    n = len(state.x)
    point_data = {"id": np.arange(n, dtype=np.int64), "radius": state.radius, **state.fields}
    particles = meshio.Mesh(state.x, [("vertex", np.arange(n, dtype=np.int64).reshape(-1, 1))],
                            point_data=point_data)
    points, lines, periodic = contact_lines(state.x, state.contacts, state.box)
    c = state.contacts
    cell_data = {"normal_force": [c["fn"].to_numpy(float)], "tangential_force": [c["ft"].to_numpy(float)],
                 "overlap": [c["overlap"].to_numpy(float)], "i": [c["i"].to_numpy(np.int64)],
                 "j": [c["j"].to_numpy(np.int64)], "periodic": [periodic.astype(np.int64)]}
    contacts = meshio.Mesh(points, [("line", lines)], cell_data=cell_data)
    paths = [out / PARTICLES_VTU, out / CONTACTS_VTU]
    meshio.write(paths[0], particles, file_format="vtu")
    meshio.write(paths[1], contacts, file_format="vtu")
    return paths


def xyz_atoms(state: Settled):
    """The packing as an ase Atoms: cell from the box (z: from 0 to the highest sphere top, not periodic)."""
    from ase import Atoms

    n = len(state.x)
    if state.box is not None:
        top = float((state.x[:, 2] + state.radius).max())
        atoms = Atoms(["X"] * n, positions=state.x, cell=np.diag([state.box[0], state.box[1], max(top, 0.0)]),
                      pbc=[True, True, False])
    else:
        atoms = Atoms(["X"] * n, positions=state.x, pbc=False)
    # mass and force left out: eight decimals keep too few of their digits (module docstring)
    names = {"type": "species_id", "velocity": "velo", "angular_velocity": "omega"}
    atoms.new_array("id", np.arange(n, dtype=np.int64))
    atoms.new_array("radius", np.asarray(state.radius, float))
    for key, name in names.items():
        if key in state.fields:
            atoms.new_array(name, np.asarray(state.fields[key]))
    return atoms


def write_xyz(state: Settled, path) -> Path:
    """The packing as one extended XYZ frame (ase), as the module docstring describes."""
    import ase.io

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ase.io.write(path, xyz_atoms(state), format="extxyz")
    return path
