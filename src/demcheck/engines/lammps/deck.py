"""LAMMPS decks (`pair_style granular`, `fix wall/gran granular`), for LAMMPS 22Jul2025.

One atom type per particle and an explicit ``pair_coeff`` for every type pair (auto-mixing gets
``mindlin NULL`` wrong between types, docs/lammps-users.md, Mixing). Masses are set exactly (``set atom … mass``), so the
engine and the reference share m to the last bit. Walls are ``fix wall/gran granular`` with the contact's own
coefficients computed for the particle (m̄ = m, R̄ = R): its E and ν are pair values (docs/lammps-users.md, Walls), and
demcheck passes the Hertz stiffness directly (``hertz k``), which sidesteps that trap.
"""

from __future__ import annotations

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common
from ...inputs.common import fmt
from .. import family_deck as FD
from ..mapping import contact_mapping, pair_mapping
from ..base import Engine, Native
from ..family import DUMP_COLUMNS

VERSION_NOTE = "written for LAMMPS 22 Jul 2025 (pair_style granular)"


def _arg(x) -> str:
    return "NULL" if x is None else fmt(x)


def coeff_args(nat: Native) -> str:
    if nat.normal in ("hooke", "hertz"):  # hooke k damp / hertz k damp: the damping coefficient is 2nd
        normal = f"{nat.normal} {fmt(nat.normal_args[0])} {fmt(nat.damping_coeff)}"
    else:  # hertz/material E damp ν
        normal = f"{nat.normal} {fmt(nat.normal_args[0])} {fmt(nat.damping_coeff)} {fmt(nat.normal_args[1])}"
    text = (f"{normal} damping {nat.damping} tangential {nat.tangential} "
            + " ".join(_arg(x) for x in nat.tangential_args))
    if nat.limit:
        text += " limit_damping"
    return text


def deck(engine: Engine, case: Case, dt: float | None = None, length: float = 1.0, native: Native | None = None,
         explicit_pairs: bool = True, copies: int = 1) -> common.Deck:
    """The deck of a collision case, written with ``engine``'s mapping (the Engine that runs it). ``native``: one
    configuration for every type pair instead of the case's mapped model; ``explicit_pairs=False`` writes only the
    I I coefficients and lets LAMMPS mix the rest (to show its mixing trap — never what demcheck writes otherwise);
    ``copies``: that many independent copies of the collision in one run, far apart, each body with its own type
    (atom ids k·n + 1 … k·n + n for copy k), so that engine start-up is paid once."""
    sc = common.scene(case, dt, length)
    mp = contact_mapping(case, engine, native)
    mp.require()
    n = len(case.particles)
    lo, hi = sc.box
    batch_axis, spacing = 0, 0.0
    if copies > 1:
        batch_axis, spacing, (lo, hi) = FD.batch_layout(sc, copies)
    lines = common.header("lammps", sc, mp, VERSION_NOTE, "lmp -in") + common.notes(mp.native.comments)
    lines += ["", "units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "newton off",
              "comm_modify vel yes",
              f"region box block {fmt(lo[0])} {fmt(hi[0])} {fmt(lo[1])} {fmt(hi[1])} {fmt(lo[2])} {fmt(hi[2])} "
              "units box",
              f"create_box {n * copies} box"]
    for c in range(copies):
        for i, p in enumerate(case.particles):
            k = c * n + i + 1
            pos = FD.offset(p.position, batch_axis, spacing, c)
            lines += [f"create_atoms {k} single {' '.join(fmt(x) for x in pos)} units box",
                      f"set atom {k} diameter {fmt(2 * p.radius)}",
                      f"set atom {k} mass {fmt(case.mass(i))}",
                      f"set atom {k} vx {fmt(p.velocity[0])} vy {fmt(p.velocity[1])} vz {fmt(p.velocity[2])}",
                      f"set atom {k} omega {' '.join(fmt(x) for x in p.angular_velocity)}"]
    rmax = max(p.radius for p in case.particles)
    lines += ["", f"neighbor {fmt(rmax)} bin", "neigh_modify delay 0 every 1 check yes",
              "pair_style granular"]
    coeffs = {}
    for i, j in common.type_pairs(case):
        if j is None:
            continue
        pm = pair_mapping(case, engine, i, j, native)
        if pm.native is None:
            raise UnsupportedByEngine(f"type pair {i + 1} {j + 1}: {'; '.join(pm.reasons)}")
        coeffs[(i, j)] = coeffs[(j, i)] = coeff_args(pm.native)
    ntypes = n * copies
    for a in range(ntypes):
        for b in range(a, ntypes):
            if a != b and not explicit_pairs:
                continue
            lines.append(f"pair_coeff {a + 1} {b + 1} {coeffs[(a % n, b % n)]}")
    if case.walls:
        pm = pair_mapping(case, engine, 0, None, native)
        axis = "xyz"[sc.wall_axis]
        where = f"{fmt(sc.wall_position)} NULL" if sc.wall_side == "lo" else f"NULL {fmt(sc.wall_position)}"
        if n > 1:
            raise UnsupportedByEngine("a wall case has one particle")
        lines += ["", "# the wall: coefficients of the particle–wall pair (m̄ = m, R̄ = R)",
                  f"fix wall all wall/gran granular {coeff_args(pm.require())} {axis}plane {where}"]
    g = list(case.run.gravity)
    gn = sum(x * x for x in g) ** 0.5
    if gn > 0:
        lines.append(f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(x / gn) for x in g)}")
    lines += ["", "fix integrate all nve/sphere", f"timestep {fmt(sc.dt)}",
              f"dump state all custom 1 {common.DUMP_FILE} {' '.join(DUMP_COLUMNS)}",
              "dump_modify state format float %.17g sort id",
              "thermo_style custom step atoms ke", f"thermo {max(sc.steps // 10, 1)}",
              f"run {sc.steps}", ""]
    return common.Deck("lammps", "\n".join(lines), {}, dt=sc.dt, check=FD.check_deck)
