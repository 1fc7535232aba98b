"""The deck read as LIGGGHTS reads it (``demcheck audit``): the engine itself evaluates the deck's set-up.

``engine_read(path)`` runs ``python -m demcheck.engines.liggghts.read --library PATH`` — a worker process of its
own, loading Debian's ``libliggghts.so.3`` (the library the ``liggghts`` executable runs, as worker.py loads it)
— and reads back what LIGGGHTS made of the deck. The walk, the allow-list's rules, the budget and the caller's
side are the LAMMPS family's (engines/family_read.py); what differs is LIGGGHTS 3.8's C library:

* it exports ``lammps_open_no_mpi``, ``lammps_command``, ``lammps_extract_global`` (dt, the box, natoms,
  nlocal), ``lammps_extract_atom`` (id, type, radius, rmass, x, v, omega) and ``lammps_extract_variable``
  (``nm -D``), but no substitution and no exceptions: an error writes ``ERROR: …`` into the log and exits the
  process. So a line's substitution is LIGGGHTS's own ``print`` of the line's unquoted parts (the text LIGGGHTS
  itself substitutes before running a command) read back from the worker's log; and a worker that exits
  leaves its log and a progress file naming the line it stopped on, which the caller reads: the engine's ERROR
  and the line (the trap ``engine-refuses``), or — no ERROR — the worker's death, the reader taking over;
* a variable defined by a line that was not executed (or naming a fix or compute that was not) is never
  substituted: LIGGGHTS would exit on it, the deck would not;
* LIGGGHTS inserts the bodies of ``fix insert/*`` and ``fix pour`` on the first step of a run, not at ``run 0``:
  a deck's ``run N`` runs as ``run 1`` with no integrator executed (``fix nve/sphere`` and its kin are not on
  the list), so the inserted bodies keep the positions, sizes and velocities the insertion gave them;
* units and dimension are not exported: they are the deck's ``units`` and ``dimension`` lines as LIGGGHTS ran
  them (LIGGGHTS's default: lj, 3-D); the number of types is that of the ``create_box`` LIGGGHTS ran.
"""

from __future__ import annotations

import ctypes
import json
import re
import shutil
import sys
from pathlib import Path

from .. import family_read as F
from ..family_read import EngineRead, ReadFailed, script_of  # noqa: F401

MODULE = "demcheck.engines.liggghts.read"
MAX_SECONDS = 60.0
MARK = "@@demcheck@@"
IF_VARIABLE = "__demcheck_if"
GONE = "__demcheck_gone"

ALLOWED = frozenset({
    "units", "dimension", "boundary", "atom_style", "atom_modify", "newton", "communicate", "comm_modify",
    "neighbor", "neigh_modify", "lattice", "region", "create_box", "create_atoms", "delete_atoms",
    "displace_atoms", "set", "mass", "velocity", "group", "variable", "pair_style", "pair_coeff", "timestep",
    "fix", "unfix", "fix_modify", "compute", "uncompute", "run", "reset_timestep", "read_data", "read_restart",
    "hard_particles", "soft_particles", "next", "change_box", "run_style", "special_bonds"})
VARIABLE_STYLES = frozenset({"delete", "index", "loop", "equal", "string", "atom", "world", "uloop"})
PAIR_STYLES = frozenset({"gran", "none", "soft", "zero"})
# no integrator (nve/sphere, multisphere…): ``run 1`` inserts bodies and moves none
FIX_STYLES = frozenset({
    "property/global", "property/atom", "gravity", "wall/gran", "wall/region/sph", "mesh/surface",
    "mesh/surface/stress", "mesh/surface/planar", "particletemplate/sphere", "particletemplate/multisphere",
    "particledistribution/discrete", "particledistribution/discrete/massbased",
    "particledistribution/discrete/numberbased", "insert/pack", "insert/stream", "insert/rate/region", "pour",
    "enforce2d", "freeze", "setforce", "addforce", "viscous", "check/timestep/gran", "heat/gran",
    "multicontact/halfspace"})
COMPUTE_STYLES = frozenset({"erotate/sphere", "ke", "temp", "reduce", "com", "contact/atom", "property/atom",
                            "pair/gran/local", "wall/gran/local", "rigid", "ke/atom"})
FILE_ARGS = {"read_data": 1, "include": 1, "read_restart": 1}
LISTS = F.Lists(ALLOWED, VARIABLE_STYLES, PAIR_STYLES, FIX_STYLES, COMPUTE_STYLES, FILE_ARGS)
# the files a fix or region reads (fix mesh/surface … file F, particletemplate/multisphere … file F, region
# mesh/tet file F): inside the folder
FILE_KEYS = ("file",)
_VAR = re.compile(r"\$\{([^}]*)\}|\$\((.*?)\)|\$([A-Za-z0-9_])|v_(\w+)")
_REF = re.compile(r"\b([cf])_([A-Za-z0-9_]+)")
_ERROR = re.compile(r"^ERROR(?: on proc \d+)?: (.*)$", re.M)


def executable() -> str | None:
    return shutil.which("liggghts")


def available() -> bool:
    """Whether LIGGGHTS's library (the one the ``liggghts`` executable loads) is installed."""
    from .worker import library

    exe = executable()
    return exe is not None and library(exe) is not None


def engine_read(path: str | Path, timeout: float | None = None) -> EngineRead:
    """Run the worker on ``path``; the answer, or — the engine exited on its error — an answer naming the line
    and LIGGGHTS's ERROR; ReadFailed when there is neither."""
    from .worker import library

    lib = library(executable() or "liggghts")
    if lib is None:
        raise ReadFailed("LIGGGHTS's library is not installed")
    return F.run_worker(MODULE, Path(path), MAX_SECONDS if timeout is None else timeout,
                        ["--library", lib], _died)


def _died(scratch: Path, rc: int) -> EngineRead | None:
    """A worker LIGGGHTS exited (its Error::all): the ERROR line of its log and the line it stopped on."""
    log = scratch / "log.txt"
    text = log.read_text(encoding="utf-8", errors="replace") if log.is_file() else ""
    error = _ERROR.findall(text)
    progress = scratch / "progress.jsonl"
    lines = [json.loads(x) for x in progress.read_text(encoding="utf-8").splitlines() if x.strip()] \
        if progress.is_file() else []
    if not lines:
        return None
    last = lines[-1]
    where = f"{last['file']}:{last['line']}"
    if not error:  # Error::one aborts MPI before its message reaches the log: the line, not the engine's words
        raise ReadFailed(f"the engine's worker died at {where} {last['text'][:60]!r} (exit status {rc}; LIGGGHTS "
                         "aborted without an ERROR line in its log)")
    return EngineRead(_version(text), lines, {}, f"{where}: {last['text'][:70]!r}: the engine stops here: "
                      f"ERROR: {error[-1].strip()[:300]}", engine_error=True)


def _version(log: str) -> str:
    m = re.search(r"LIGGGHTS \(Version (LIGGGHTS-PUBLIC [^,)]+)", log)
    return m.group(1) if m else "LIGGGHTS"


def apply(setup, answer: EngineRead, script) -> None:
    """The engine's state into the Setup (family_read.apply)."""
    F.apply(setup, answer, script, "LIGGGHTS (run N as run 1 with no integrator: the insertions made, no body "
                                   "moved)")


# ----------------------------------------------------------------------------- the worker side


class _Engine:
    """LIGGGHTS's C library behind the walker's protocol (family_read.Walker)."""

    def __init__(self, path: str, scratch: Path):
        lib = ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
        lib.lammps_open_no_mpi.argtypes = [ctypes.c_int, ctypes.POINTER(ctypes.c_char_p),
                                           ctypes.POINTER(ctypes.c_void_p)]
        lib.lammps_open_no_mpi.restype = None
        lib.lammps_command.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
        lib.lammps_command.restype = ctypes.c_char_p
        for name in ("lammps_extract_global", "lammps_extract_atom"):
            getattr(lib, name).argtypes = [ctypes.c_void_p, ctypes.c_char_p]
            getattr(lib, name).restype = ctypes.c_void_p
        lib.lammps_extract_variable.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p]
        lib.lammps_extract_variable.restype = ctypes.c_void_p
        self.lib, self.libc = lib, ctypes.CDLL(None)
        self.log = scratch / "log.txt"
        # the screen into a file: LIGGGHTS writes to it unchecked (a region's reset_random, with -screen none, crashes)
        words = [b"liggghts", b"-screen", str(scratch / "screen.txt").encode(), b"-log", str(self.log).encode(),
                 b"-echo", b"none"]
        argv = (ctypes.c_char_p * len(words))(*words)
        self.handle = ctypes.c_void_p()
        lib.lammps_open_no_mpi(len(words), argv, ctypes.byref(self.handle))
        self.walker = None  # set by main: the ids the walk did not execute

    def command(self, text: str) -> None:
        self.lib.lammps_command(self.handle, text.encode())
        self.libc.fflush(None)  # the log as far as this command: an error exit leaves it whole

    def _printed(self, text: str) -> str:
        """LIGGGHTS's own substitution of ``text`` (no quote in it): its print, read back from the log."""
        start = self.log.stat().st_size
        self.command(f'print "{MARK} {text}"')
        out = self.log.read_bytes()[start:].decode("utf-8", errors="replace")
        found = [line for line in out.splitlines() if line.startswith(MARK + " ")]
        if not found:
            raise RuntimeError(f"LIGGGHTS printed nothing for {text[:60]!r}")
        return found[-1][len(MARK) + 1:]

    def expand(self, text: str) -> str:
        """The line as LIGGGHTS substitutes it before running it: its unquoted parts, the quoted ones as they
        are (LIGGGHTS substitutes those only where the command itself does)."""
        parts = re.split(r"(\"[^\"]*\"|'[^']*')", text)
        out = []
        for k, part in enumerate(parts):
            if k % 2 == 0 and "$" in part:
                self._checked(part)
                pad = part[len(part.rstrip()):]
                lead = part[:len(part) - len(part.lstrip())]
                part = lead + self._printed(part.strip()) + pad if part.strip() else part
            out.append(part)
        return "".join(out)

    def _checked(self, text: str) -> None:
        """Refuses (an Exception, as LAMMPS's expand raises) a substitution LIGGGHTS would exit on for a reason the
        deck does not have: a variable whose definition was not executed, or that names a fix or compute that
        was not (the deck's own run defines them)."""
        skipped = self.walker.skipped_ids if self.walker else set()
        for m in _VAR.finditer(text):
            name = m.group(1) or m.group(3) or m.group(4)
            formula = m.group(2) or ""
            if name and ("variable", name) in skipped:
                raise RuntimeError(f"variable {name} was not executed (its style is not on the audit's list)")
            for kind, ident in _REF.findall(formula + " " + self._formula(name)):
                if (("fix" if kind == "f" else "compute"), ident) in skipped:
                    raise RuntimeError(f"{kind}_{ident}: the {'fix' if kind == 'f' else 'compute'} was not executed")

    def _formula(self, name: str | None) -> str:
        """The words of the last executed definition of variable ``name`` (the walk's records)."""
        for rec in reversed(self.walker.out if self.walker else []):
            w = rec.get("words") or []
            if rec["ran"] and w[:2] == ["variable", name]:
                return " ".join(w[2:])
        return ""

    def exhausted(self, name: str) -> bool:
        """After ``next NAME``: LIGGGHTS deletes a variable that ran out. An index definition leaves an existing
        variable as it is and defines a missing one, which is then deleted again."""
        self.command(f"variable {name} index {GONE}")
        if self._printed("${" + name + "}") != GONE:
            return False
        self.command(f"variable {name} delete")
        return True

    def truth(self, cond: str) -> bool:
        self._checked(cond)
        self.command(f'if "{cond}" then "variable {IF_VARIABLE} equal 1" else "variable {IF_VARIABLE} equal 0"')
        ptr = self.lib.lammps_extract_variable(self.handle, IF_VARIABLE.encode(), None)
        value = ctypes.cast(ptr, ctypes.POINTER(ctypes.c_double))[0]
        return bool(value)

    def global_(self, name: str, kind=ctypes.c_double):
        ptr = self.lib.lammps_extract_global(self.handle, name.encode())
        return None if not ptr else ctypes.cast(ptr, ctypes.POINTER(kind))[0]

    def natoms(self) -> int:
        return int(self.global_("natoms", ctypes.c_int64) or 0)

    def pair_styles(self, words: list) -> list:
        return [words[1]]

    def atom(self, name: str, kind, rows: bool = False):
        ptr = self.lib.lammps_extract_atom(self.handle, name.encode())
        if not ptr:
            return None
        return ctypes.cast(ptr, ctypes.POINTER(ctypes.POINTER(kind) if rows else kind))


class _Walker(F.Walker):
    """The family's walk, with the files LIGGGHTS's fixes read confined to the deck's folder."""

    def _refusal(self, words: list) -> str:
        why = super()._refusal(words)
        if not why and words[0] == "set" and "property/atom" in words:
            return "set … property/atom: not executed (a per-atom property of a fix the audit does not run)"
        if not why and words[0] in ("fix", "region"):  # fix mesh/surface … file F, region … mesh/tet file F
            for key in FILE_KEYS:
                if key in words[3:]:
                    k = words.index(key, 3) + 1
                    self._inside(words[k] if k < len(words) else "")
        return why


def _state(engine: _Engine, walker: F.Walker) -> dict:
    """Units and dimension as the deck's lines ran them; dt, box and every atom from the engine."""
    ran = {}
    for rec in walker.out:
        w = rec.get("words") or []
        if rec["ran"] and w[:1] in (["units"], ["dimension"], ["create_box"]) and len(w) > 1:
            ran[w[0]] = w[1]
    state = {"units": ran.get("units", "lj"), "dt": engine.global_("dt"),
             "dimension": int(ran.get("dimension", 3)), "atoms": []}
    boxed = {"create_box", "read_restart", "read_data"}
    state["box_exist"] = any((r.get("words") or [""])[0] in boxed and r["ran"] for r in walker.out)
    if state["box_exist"]:
        state["box"] = [engine.global_(f"box{a}{b}") for a in "xyz" for b in ("lo", "hi")]
    n = int(engine.global_("nlocal", ctypes.c_int) or 0)
    cols = {"id": engine.atom("id", ctypes.c_int), "type": engine.atom("type", ctypes.c_int),
            "radius": engine.atom("radius", ctypes.c_double), "rmass": engine.atom("rmass", ctypes.c_double)}
    for name in ("x", "v", "omega"):
        cols[name] = engine.atom(name, ctypes.c_double, rows=True)
    for i in range(n if cols["type"] else 0):
        row = {"id": int(cols["id"][i]) if cols["id"] else i + 1, "type": int(cols["type"][i]),
               "radius": float(cols["radius"][i]) if cols["radius"] else None,
               "mass": float(cols["rmass"][i]) if cols["rmass"] else None}
        for name in ("x", "v", "omega"):
            row[name] = [float(cols[name][i][k]) for k in range(3)] if cols[name] else None
        state["atoms"].append(row)
    types = [a["type"] for a in state["atoms"]]
    state["ntypes"] = int(ran["create_box"]) if ran.get("create_box", "").isdigit() else max(types, default=0)
    return state


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog=MODULE)
    for key in ("--deck", "--out", "--scratch", "--library"):
        ap.add_argument(key, required=True)
    args = ap.parse_args(argv)
    deck, scratch = Path(args.deck).resolve(), Path(args.scratch)
    F.limit_memory()
    engine = _Engine(args.library, scratch)
    with (scratch / "progress.jsonl").open("w", encoding="utf-8") as progress:
        walker = _Walker(engine, deck, LISTS, "run 1 post no", scratch, progress)
        engine.walker = walker
        engine.libc.fflush(None)
        version = _version(engine.log.read_text(encoding="utf-8", errors="replace"))
        F.answer_of(version, walker, lambda w: _state(engine, w), args.out)
    engine.lib.MPI_Finalize()  # the answer written; MPI ended as LIGGGHTS's own main ends it
    return 0


if __name__ == "__main__":
    sys.exit(main())
