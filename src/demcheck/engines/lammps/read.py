"""The deck read as LAMMPS reads it (``demcheck audit``): the engine itself evaluates the deck's set-up.

The walk, the budget, the answer and the caller's side are the LAMMPS family's, shared with LIGGGHTS
(engines/family_read.py); this module gives LAMMPS's allow-list, its Python module behind the walk's protocol
and the state it reads back.

``engine_read(path)`` runs ``python -m demcheck.engines.lammps.read`` — a worker process of its own, which a
hostile deck may crash or exhaust without taking demcheck down — and reads back what the engine made of the
deck. The worker walks the deck's lines (comments stripped and continuations joined by inputs/script.py) and,
for each, asks LAMMPS to substitute its variables (``lammps_expand``: the engine's own substitution). What it then
does is decided by an ALLOW-LIST, never a deny-list:

* commands that only set up the simulation in memory (units, box, atoms, set, velocity, groups, regions,
  variables of the in-memory styles, pair and fix styles of the list below, ``timestep``…) run in the engine;
* ``run N`` runs as ``run 0 post no`` (the set-up is checked by LAMMPS, no step is taken);
* ``label``/``jump``/``next``/``if``/``include`` are followed by the worker with the engine's values (``next``
  runs in LAMMPS; an ``if`` condition is evaluated by LAMMPS's ``if``, whose branches are then read line by line
  through the same allow-list), ``include``, ``jump FILE``, ``read_data`` and ``molecule`` only inside the deck's
  directory;
* everything else (``shell``, ``python``, ``write_*``, ``dump``, ``log``, ``restart``, ``print``, computes and
  fixes off the list…) is never executed and comes back as such.

A budget bounds it: commands followed (control flow that does not end within it is refused with the reason),
atoms, the worker's memory (an address-space limit) and the wall clock. The worker writes its answer (the lines
with the engine's substitution, units, dt, dimension, box and every atom's type, radius, mass, position,
velocity and spin) as JSON into a file; a worker that dies leaves no answer and the caller says why.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .. import family_read as F
from ..family_read import MAX_ATOMS, MAX_COMMANDS, MAX_MEMORY, EngineRead, ReadFailed, script_of  # noqa: F401

MODULE = "demcheck.engines.lammps.read"
MAX_SECONDS = 60.0
IF_VARIABLE = "__demcheck_if"

# commands that only set up a simulation in memory (not `processors`: the read runs on one rank, where a layout
# for several stops LAMMPS at create_box; a layout changes no contact)
ALLOWED = frozenset({
    "units", "dimension", "boundary", "atom_style", "atom_modify", "newton", "comm_modify",
    "comm_style", "neighbor", "neigh_modify", "lattice", "region", "create_box", "create_atoms", "delete_atoms",
    "displace_atoms", "set", "mass", "velocity", "group", "variable", "pair_style", "pair_coeff", "pair_modify",
    "timestep", "fix", "unfix", "fix_modify", "compute", "uncompute", "run", "reset_timestep",
    "read_data", "molecule", "special_bonds", "change_box", "run_style", "min_style", "next", "timer"})
VARIABLE_STYLES = frozenset({"delete", "index", "loop", "equal", "string", "atom", "vector", "format", "internal"})
PAIR_STYLES = frozenset({"granular", "gran/hooke", "gran/hooke/history", "gran/hertz/history", "hybrid",
                         "hybrid/overlay", "none", "zero", "soft", "lj/cut"})
FIX_STYLES = frozenset({
    "nve/sphere", "nve", "nve/limit", "nve/asphere", "gravity", "wall/gran", "wall/gran/region", "pour",
    "deposit", "enforce2d", "freeze", "viscous", "setforce", "addforce", "aveforce", "move", "rigid",
    "rigid/small", "rigid/nve", "rigid/small/nve", "property/atom", "langevin", "momentum", "spring/self",
    "wall/reflect", "wall/region", "heat/flow", "temp/rescale", "adapt", "recenter", "granular/mdr",
    "nve/sphere/bpm", "store/state", "balance"})
COMPUTE_STYLES = frozenset({
    "property/atom", "erotate/sphere", "ke", "temp", "temp/sphere", "pe", "reduce", "count/type", "com",
    "contact/atom", "pair/local", "property/local", "stress/atom", "coord/atom", "ke/atom", "erotate/sphere/atom",
    "fabric", "rigid/local", "fragment/atom", "granular/mdr"})
FILE_ARGS = {"read_data": 1, "molecule": 2, "include": 1}  # the word that names a file read
MOLECULE_KEYS = frozenset({"offset", "toff", "boff", "aoff", "doff", "ioff", "scale", "json"})


LISTS = F.Lists(ALLOWED, VARIABLE_STYLES, PAIR_STYLES, FIX_STYLES, COMPUTE_STYLES, FILE_ARGS, MOLECULE_KEYS)


def available() -> bool:
    """Whether this Python has the LAMMPS module the worker loads."""
    import importlib.util

    try:
        return importlib.util.find_spec("lammps") is not None
    except (ImportError, ValueError):
        return False


def engine_read(path: str | Path, timeout: float | None = None) -> EngineRead:
    """Run the worker on ``path`` and return its answer; ReadFailed when there is none (the message names the
    cause: the worker's exit signal, the time budget, or the engine's error)."""
    return F.run_worker(MODULE, Path(path), MAX_SECONDS if timeout is None else timeout)


def apply(setup, answer: EngineRead, script) -> None:
    """The engine's state into the Setup (family_read.apply)."""
    F.apply(setup, answer, script, "LAMMPS (run N as run 0)")


# ----------------------------------------------------------------------------- the worker side


class _Engine:
    """The LAMMPS Python module behind the walker's protocol (family_read.Walker)."""

    def __init__(self, lmp):
        self.lmp = lmp

    def expand(self, text: str) -> str:
        return self.lmp.expand(text)

    def command(self, text: str) -> None:
        self.lmp.command(text)

    def exhausted(self, name: str) -> bool:
        return not self.lmp.has_id("variable", name)  # LAMMPS deletes a variable that ran out

    def truth(self, cond: str) -> bool:
        self.lmp.command(f'if "{cond}" then "variable {IF_VARIABLE} equal 1" else "variable {IF_VARIABLE} equal 0"')
        return bool(self.lmp.extract_variable(IF_VARIABLE))

    def natoms(self) -> int:
        return self.lmp.get_natoms()

    def pair_styles(self, words: list) -> list:
        if words[1].startswith("hybrid"):
            return [w for w in words[1:] if self.lmp.has_style("pair", w)]
        return [words[1]]


def _open():
    import ctypes

    from .worker import libmpi

    F.limit_memory()
    mpi = libmpi()
    if mpi is not None:
        ctypes.CDLL(mpi, mode=ctypes.RTLD_GLOBAL)
    import lammps

    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    if not lmp.has_exceptions:
        raise RuntimeError("this LAMMPS library is built without C++ exceptions")
    return lmp


def _state(lmp) -> dict:
    """Units, dt, dimension, box and every atom (id, type, radius, rmass, x, v, omega) as the engine has them."""
    state = {"units": lmp.extract_global("units"), "dt": lmp.extract_global("dt"),
             "dimension": lmp.extract_setting("dimension"), "ntypes": lmp.extract_setting("ntypes"),
             "box_exist": bool(lmp.extract_setting("box_exist")), "atoms": []}
    if not state["box_exist"]:
        return state
    lo, hi = lmp.extract_global("boxlo"), lmp.extract_global("boxhi")
    state["box"] = [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]
    n = lmp.extract_setting("nlocal")
    if n == 0:
        return state
    cols = {}
    for name in ("id", "type", "radius", "rmass", "x", "v", "omega"):
        try:
            cols[name] = lmp.extract_atom(name)
        except Exception:  # noqa: BLE001 — an atom style without it
            cols[name] = None
    mass = lmp.extract_atom("mass")  # per type (atom styles without per-atom mass)
    for i in range(n):
        t = int(cols["type"][i])
        row = {"id": int(cols["id"][i]) if cols["id"] else i + 1, "type": t,
               "radius": float(cols["radius"][i]) if cols["radius"] else None,
               "mass": float(cols["rmass"][i]) if cols["rmass"] else (float(mass[t]) if mass else None)}
        for name in ("x", "v", "omega"):
            row[name] = [float(cols[name][i][k]) for k in range(3)] if cols[name] else None
        state["atoms"].append(row)
    return state


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog=MODULE)
    ap.add_argument("--deck", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--scratch", required=True)
    args = ap.parse_args(argv)
    deck = Path(args.deck).resolve()
    lmp = _open()
    walker = F.Walker(_Engine(lmp), deck, LISTS, "run 0 post no", Path(args.scratch))
    F.answer_of(f"LAMMPS {lmp.version()}", walker, lambda w: _state(lmp), args.out)
    try:
        lmp.close()
    except Exception:  # noqa: BLE001
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
