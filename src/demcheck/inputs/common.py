"""What both deck writers share: the scene (types, box, wall, run length) and the dump."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..case import Case
from ..errors import UnsupportedByEngine
from ..reference.collision import characteristic_time
from ..reference.model import ResolvedModel, resolve
from . import mapping

DUMP_COLUMNS = ("id", "type", "radius", "mass", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
                "fx", "fy", "fz", "tqx", "tqy", "tqz")
DUMP_FILE = "dump.txt"


@dataclass
class Scene:
    case: Case
    model: ResolvedModel  # the contact of interest (particle 0 with particle 1 or the wall)
    dt: float
    steps: int
    box: tuple[np.ndarray, np.ndarray]
    wall_axis: int | None  # 0, 1, 2
    wall_side: str | None  # "lo" (normal +axis) or "hi"
    wall_position: float | None


def fmt(x: float) -> str:
    return f"{x:.17g}"


def scene(case: Case, dt: float | None = None, length: float = 1.0) -> Scene:
    """The two-body scene of a collision case: dt (the case's, or auto), the number of steps (free flight to
    contact plus ``length`` × 6 elastic contact times), a box that holds both bodies for the whole run."""
    if case.kind != "collision":
        raise UnsupportedByEngine(f"case '{case.name}' is a {case.kind}; decks are written for collisions here")
    model = resolve(case)
    t_c = characteristic_time(model)
    from ..reference.collision import auto_dt

    dt = dt or case.run.dt or auto_dt(case, model)
    v = model.pair.impact_speed
    from ..reference.collision3d import geometry, initial_state, rules_array
    from ..reference import kernels3d as k3

    y0 = initial_state(case)
    gap = max(-k3.kinematics(y0, geometry(case, t_c), rules_array())[0], 0.0)
    t_end = gap / v + 6.0 * t_c * length
    steps = int(math.ceil(t_end / dt))
    pos = [np.asarray(p.position, float) for p in case.particles]
    vel = [np.asarray(p.velocity, float) for p in case.particles]
    g = np.asarray(case.run.gravity, float)
    reach = [np.abs(vv) * t_end + 0.5 * np.abs(g) * t_end**2 for vv in vel]
    rmax = max(p.radius for p in case.particles)
    lo = np.min([x - d for x, d in zip(pos, reach)], axis=0) - 3 * rmax
    hi = np.max([x + d for x, d in zip(pos, reach)], axis=0) + 3 * rmax
    axis = side = wpos = None
    if case.walls:
        if len(case.walls) > 1:
            raise UnsupportedByEngine("decks are written for one wall")
        w = case.walls[0]
        axis, side = wall_axis(w, 0)
        wpos = float(w.point[axis])
        if side == "lo":
            lo[axis] = min(lo[axis], wpos - 3 * rmax)
        else:
            hi[axis] = max(hi[axis], wpos + 3 * rmax)
    return Scene(case, model, dt, steps, (lo, hi), axis, side, wpos)


def wall_axis(w, k: int) -> tuple[int, str]:
    """(axis, "lo" | "hi") of an axis-aligned plane wall: the engines' flat walls (fix wall/gran
    xplane|yplane|zplane) are axis-aligned, and a wall that is not gets one clear refusal."""
    nvec = np.asarray(w.normal, float)
    axes = np.flatnonzero(np.abs(nvec) > 1e-15)
    if len(axes) != 1:
        raise UnsupportedByEngine(f"walls.{k}.normal = {list(w.normal)}: the engines' flat walls (fix wall/gran "
                                  "xplane|yplane|zplane) are axis-aligned; rotate the case so the wall normal is a "
                                  "coordinate axis")
    axis = int(axes[0])
    return axis, "lo" if nvec[axis] > 0 else "hi"


def type_pairs(case: Case) -> list[tuple[int, int | None]]:
    """(i, j) particle indices of every type pair (types are particle index + 1; j None = the wall)."""
    n = len(case.particles)
    pairs: list[tuple[int, int | None]] = [(i, j) for i in range(n) for j in range(i, n)]
    if case.walls:
        pairs += [(i, None) for i in range(n)]
    return pairs


def pair_mapping(case: Case, engine: str, i: int, j: int | None, native: mapping.Native | None = None
                 ) -> mapping.Mapping:
    """The mapping of one type pair. Pairs that never touch in this case (a particle with itself) are
    resolved at the contact's own impact speed, where a model calibrates its stiffness at one. A ``native``
    configuration given directly (tests of engine traps, twins of configurations no seed model maps to)
    is used for every pair as it is."""
    if native is not None:
        return mapping.Mapping(engine, mapping.NATIVE, ["a native engine configuration, given directly"], native)
    params = case.contact.params
    if (i, j) != _contact_pair(case) and "reference_velocity" not in params:
        v = resolve(case).pair.impact_speed
        case = replace(case, contact=replace(case.contact, params={**params, "reference_velocity": v}))
    return mapping.map_model(resolve(case, i, j), engine, params)


def _contact_pair(case: Case) -> tuple[int, int | None]:
    return (0, 1) if len(case.particles) == 2 else (0, None)


def contact_mapping(case: Case, engine: str, native: mapping.Native | None = None) -> mapping.Mapping:
    """The mapping of the contact of interest (particle 0 with particle 1, or with the wall)."""
    return pair_mapping(case, engine, *_contact_pair(case), native=native)


def header(engine: str, sc: Scene, mp: mapping.Mapping, version_note: str) -> list[str]:
    case = sc.case
    lines = [f"# demcheck deck for {engine} ({version_note})",
             f"# case: {case.name} (hash {case.hash})",
             f"# model: normal = {case.contact.normal}, tangential = {case.contact.tangential}, "
             f"limit_force = {str(case.contact.limit_force).lower()}",
             f"# mapping fidelity: {mp.fidelity}"]
    for r in mp.reasons:
        lines.append(f"#   {r}")
    lines.append(f"# dt = {fmt(sc.dt)} s, {sc.steps} steps; dump: {DUMP_FILE} (every step, %.17g)")
    lines.append(f"# run by hand: {'lmp' if engine == 'lammps' else 'liggghts'} -in <this file>")
    return lines


@dataclass
class Deck:
    """An input deck and the files it reads (written beside it)."""

    engine: str
    text: str
    files: dict

    def write(self, path) -> list:
        from pathlib import Path

        from ..io import write_text

        path = Path(path)
        write_text(path, self.text)
        written = [path]
        for name, text in self.files.items():
            write_text(path.parent / name, text)
            written.append(path.parent / name)
        return written


def data_file(case: Case, ntypes: int, box, title: str, copies: int = 1, axis: int = 0,
              spacing: float = 0.0) -> str:
    """A LAMMPS data file (atom_style sphere / granular: id type diameter density x y z; velocities with
    angular velocities), which both engines read."""
    lo, hi = box
    n = len(case.particles)
    lines = [f"# {title}", "", f"{n * copies} atoms", f"{ntypes} atom types", "",
             f"{fmt(lo[0])} {fmt(hi[0])} xlo xhi", f"{fmt(lo[1])} {fmt(hi[1])} ylo yhi",
             f"{fmt(lo[2])} {fmt(hi[2])} zlo zhi", "", "Atoms", ""]
    for c in range(copies):
        for i, p in enumerate(case.particles):
            k = c * n + i + 1
            rho = case.materials[p.material].density
            pos = offset(p.position, axis, spacing, c)
            lines.append(f"{k} {k} {fmt(2 * p.radius)} {fmt(rho)} {' '.join(fmt(x) for x in pos)}")
    lines += ["", "Velocities", ""]
    for c in range(copies):
        for i, p in enumerate(case.particles):
            k = c * n + i + 1
            lines.append(f"{k} {' '.join(fmt(x) for x in p.velocity)} "
                         f"{' '.join(fmt(x) for x in p.angular_velocity)}")
    return "\n".join(lines) + "\n"


def batch_layout(sc: "Scene", copies: int) -> tuple[int, float, tuple]:
    """Copies of a two-body scene, far apart, side by side along an axis the motion (and a wall's normal)
    does not use: (axis, spacing, enlarged box). Each copy's bodies get their own atom types."""
    case = sc.case
    lo, hi = (np.array(b, float) for b in sc.box)
    motion = np.zeros(3)
    for p in case.particles:
        motion += np.abs(np.asarray(p.velocity, float))
    if sc.wall_axis is not None:
        motion[sc.wall_axis] = np.inf
    axis = int(np.argmin(motion))
    rmax = max(p.radius for p in case.particles)
    spacing = (hi[axis] - lo[axis]) + 4.0 * rmax
    hi = hi.copy()
    hi[axis] += spacing * (copies - 1)
    return axis, spacing, (lo, hi)


def offset(position, axis: int, spacing: float, copy: int) -> list:
    x = list(position)
    x[axis] += spacing * copy
    return x
