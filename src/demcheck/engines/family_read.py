"""The LAMMPS family's deck read (LAMMPS and its fork LIGGGHTS): the engine itself evaluates a deck's set-up.

An engine's ``read`` module (engines/lammps/read.py, engines/liggghts/read.py) runs a worker process of its own —
which a hostile deck may crash, exhaust or end (LIGGGHTS 3.8 exits on an error) without taking demcheck down —
and reads back what the engine made of the deck. What is the same for the whole family lives here:

* :func:`run_worker`, the caller's side: the worker started in its own session under a wall-clock budget, its
  answer (JSON) read back, a dead worker turned into ReadFailed — or, where the engine's read module can tell
  from the worker's scratch folder that the engine itself stopped on a line (LIGGGHTS's ERROR), an answer
  saying so;
* :class:`Walker`: the deck's lines followed through the engine under an ALLOW-LIST (each engine gives its
  :class:`Lists`), never a deny-list; ``label``/``jump``/``next``/``if``/``include`` followed with the engine's
  own values; ``include``, ``jump FILE``, ``read_data``, ``molecule`` and ``read_restart`` only inside the deck's
  directory; a budget of commands and atoms. The engine is reached through a small protocol (``expand``,
  ``command``, ``exhausted``, ``truth``, ``natoms``, ``pair_styles``) each read module implements;
* ``read_restart`` of a file the folder lacks: where a deck of the same folder writes it (``write_restart`` of
  that name, ``*`` the timestep), that deck's set-up runs in its place and the engine's own ``write_restart``
  and ``read_restart`` (into the worker's scratch folder) carry over what a restart keeps; the reading deck's
  commands before ``read_restart`` are run again after the engine's ``clear``, as a fresh run would;
* :func:`script_of` and :func:`apply`: the engine's answer into the reader's Script and Setup.
"""

from __future__ import annotations

import fnmatch
import json
import os
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

MAX_COMMANDS = 20_000  # lines followed, loops included
MAX_ATOMS = 200_000
MAX_MEMORY = 3 << 30  # bytes of address space for the worker (the engine, MPI and Python included)
MAX_WRITER_BYTES = 1 << 20  # a deck of the folder looked at for the write_restart of a missing restart file
RESTART_FILE = "demcheck-restart.bin"  # in the worker's scratch folder, never the deck's
NOT_REPLAYED = frozenset({"variable", "next", "label", "jump", "if", "include", "run", "print", "quit",
                          "read_restart", "clear"})


@dataclass(frozen=True)
class Lists:
    """An engine's allow-list: the commands, and the styles of variable, pair, fix and compute, that only set
    up a simulation in memory; the word of each file-reading command that names its file."""

    allowed: frozenset
    variable_styles: frozenset
    pair_styles: frozenset
    fix_styles: frozenset
    compute_styles: frozenset
    file_args: dict
    molecule_keys: frozenset = frozenset()


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
    lines: list = field(default_factory=list)  # {file, line, text, words, ran, why[, restart]}
    state: dict = field(default_factory=dict)  # units, dt, dimension, box, ntypes, atoms
    stopped: str = ""  # why the engine's read stopped before the end ("" when it read the whole deck)
    engine_error: bool = False  # it stopped because the engine itself refused a set-up line (the deck fails there)
    budget: bool = False  # it stopped at the budget of commands (the state so far is the engine's)
    restart: str = ""  # the deck whose set-up stood in for a missing restart file, and the file


class ReadFailed(Exception):
    """The engine could not read the deck (its error, a budget, a crash): the message says which."""


def run_worker(module: str, path: Path, timeout: float, extra: list | None = None, on_death=None) -> EngineRead:
    """Run the worker ``python -m module --deck PATH --out ANSWER --scratch DIR [extra]`` and return its answer;
    ReadFailed when there is none (the worker's exit signal, the time budget, or the engine's error).
    ``on_death(scratch, rc)`` may turn a worker that died into an answer (an engine that exits on its error)."""
    path = Path(path).resolve()
    with tempfile.TemporaryDirectory(prefix="demcheck-read-") as tmp:
        out, log = Path(tmp) / "answer.json", Path(tmp) / "stderr.txt"
        with log.open("wb") as err:
            proc = subprocess.Popen([sys.executable, "-m", module, "--deck", str(path), "--out", str(out),
                                     "--scratch", tmp, *(extra or [])],
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
            answer = on_death(Path(tmp), rc) if on_death is not None else None
            if answer is not None:
                return answer
            tail = log.read_text(encoding="utf-8", errors="replace").strip().splitlines()[-3:]
            how = f"killed by signal {-rc}" if rc < 0 else f"exit status {rc}"
            raise ReadFailed(f"the engine's worker died ({how}; memory budget {MAX_MEMORY >> 30} GiB)"
                             + (f": {' | '.join(t[:160] for t in tail)}" if tail else ""))
        data = json.loads(out.read_text(encoding="utf-8"))
    if data.get("failed"):
        raise ReadFailed(data["failed"])
    return EngineRead(data["version"], data["lines"], data["state"], data.get("stopped", ""),
                      data.get("engine_error", False), data.get("budget", False), data.get("restart", ""))


def _kill(proc: subprocess.Popen) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.wait()


# ----------------------------------------------------------------------------- the worker side


def limit_memory() -> None:
    """The worker's address space capped at MAX_MEMORY (or the hard limit where lower)."""
    import resource

    hard = resource.getrlimit(resource.RLIMIT_AS)[1]
    soft = MAX_MEMORY if hard == resource.RLIM_INFINITY else min(MAX_MEMORY, hard)
    resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


class Refused(Exception):
    """The read stops on a line (the message names it); not the engine's own refusal."""

    engine_error = False
    budget = False


class EngineError(Refused):
    engine_error = True  # the engine itself stops on the line: so would the deck's own run


class _Budget(Refused):
    budget = True


class Walker:
    """Follows a deck's lines through the engine: the allow-list, control flow, the budget.

    ``engine`` answers ``expand(text)`` (the line with the engine's substitution, quotes kept; an Exception when
    it cannot), ``command(text)`` (an Exception carrying the engine's message when it refuses), ``exhausted(v)``
    (after ``next v``: the variable ran out), ``truth(cond)`` (an if condition, by the engine's if),
    ``natoms()`` and ``pair_styles(words)`` (the styles a pair_style line names). ``run_as`` is the command a
    deck's ``run N`` becomes; ``scratch`` the worker's own folder (a stand-in restart file goes there)."""

    def __init__(self, engine, deck: Path, lists: Lists, run_as: str, scratch: Path | None = None, progress=None):
        self.lmp, self.root, self.lists, self.run_as = engine, deck.parent, lists, run_as
        self.scratch, self.progress = scratch, progress
        self.files: dict = {}
        self.frames = [[self._lines(deck), 0, "file"]]  # (name, lines), next index, file | branch | restart
        self.out: list = []
        self.count = 0
        self.skip_jump = False
        self.skipped_ids: set = set()
        self.restart: dict | None = None  # a writing deck standing in for a missing restart file

    def _lines(self, path: Path) -> tuple[str, list]:
        from ..inputs.script import _logical_lines, _strip_comment

        name = path.name if path.parent == self.root else str(path.relative_to(self.root))
        if name not in self.files:
            text = path.read_bytes().decode("utf-8")
            self.files[name] = [(n, _strip_comment(raw).strip()) for n, raw in _logical_lines(text, name)]
            self.files[name] = [(n, b) for n, b in self.files[name] if b]
        return name, self.files[name]

    def _inside(self, word: str) -> Path:
        target = (self.root / word).resolve()
        if not target.is_relative_to(self.root.resolve()):
            raise Refused(f"{word!r}: the file lies outside the deck's directory (refused)")
        if not target.is_file():
            raise Refused(f"{word!r}: no such file")
        return target

    def walk(self) -> str:
        while self.frames:
            frame = self.frames[-1]
            (name, lines), k, _ = frame
            if k >= len(lines):
                self.frames.pop()
                if frame[2] == "restart" and self.restart and not self.restart.get("done"):
                    raise Refused(f"{self.restart['at']}: read_restart {self.restart['target']}: the deck that "
                                  f"writes it, {name}, ends before its write_restart")
                continue
            frame[1] += 1
            self.count += 1
            if self.count > MAX_COMMANDS:
                why = (f"{name}:{lines[k][0]}: more than {MAX_COMMANDS} commands followed (control flow that does "
                       "not end within the budget: not audited beyond this line)")
                raise (_Budget if self._repeats_only_runs() else Refused)(why)
            if self.one(name, *lines[k]) == "quit":
                return ""
        return ""

    def _repeats_only_runs(self) -> bool:
        """At the budget: whether what is left is only more passes of a loop that sets nothing the audit reads —
        every line of the deck's files already followed; the last half of the lines followed all followed before
        (passes of a loop) and only runs, output, ``set`` of per-atom values the contacts do not depend on,
        loop/index variables and the loop's own ``label``/``next``/``jump`` (the reader's rule for a loop read once,
        inputs/script.py); and a ``next`` among them (the loop ends). Then the set-up read so far is the deck's."""
        from ..inputs.script import LOOP_SAFE, SET_READ

        seen: dict = {}
        for rec in self.out:
            key = (rec["file"], rec["line"])
            seen[key] = seen.get(key, 0) + 1
        if any((name, n) not in seen for name, lines in self.files.items() for n, _ in lines):
            return False
        heads = set()
        for rec in self.out[len(self.out) // 2:]:  # the last half: passes of the loop (an include read twice is not)
            if seen[(rec["file"], rec["line"])] < 2:
                return False
            w = rec["words"] or rec["text"].split()
            heads.add(w[0])
            if w[0] == "variable" and w[2:3] not in (["loop"], ["index"]):
                return False
            if w[0] == "set" and SET_READ & set(w[3::2]):
                return False
            if w[0] not in LOOP_SAFE | {"label", "jump", "variable", "set"}:
                return False
        return "next" in heads

    def one(self, name: str, line: int, text: str):
        rec = {"file": name, "line": line, "text": text, "words": None, "ran": False, "why": ""}
        if self.restart and not self.restart.get("done"):
            rec["restart"] = self.restart["writer"]  # a line of the writing deck, standing in for the restart file
        self.out.append(rec)
        head = text.split(None, 1)[0]
        if head == "label":
            rec["ran"], rec["words"] = True, text.split()
            return None
        self._note(rec)
        try:
            expanded = self.lmp.expand(text) or ""
        except Exception as exc:  # noqa: BLE001 — the engine raises its own message as an Exception
            rec["why"] = f"the engine cannot substitute it: {message(exc)}"
            if head in self.lists.allowed or head in ("jump", "if", "include"):
                raise Refused(f"{name}:{line}: {text[:70]!r}: {rec['why']}") from None
            return None
        from ..inputs.script import ScriptError, split_words

        try:
            words = split_words(expanded, f"{name}:{line}")
        except ScriptError as exc:
            raise Refused(str(exc)) from None
        rec["words"] = words
        return self.dispatch(rec, words, expanded, name, line)

    def _note(self, rec) -> None:
        """The line about to reach the engine, in the progress file (an engine that exits on its error leaves
        it as the line it stopped on)."""
        if self.progress is not None:
            self.progress.write(json.dumps(rec) + "\n")
            self.progress.flush()

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
        if head == "write_restart" and self.restart and (name, line) == self.restart["line"]:
            return self._restart_written(rec)
        if head == "read_restart" and len(words) > 1 and not self._exists(words[1]):
            return self._read_restart(rec, words, name, line)
        why = self._refusal(words)
        if why:
            rec["why"] = why
            if head in ("fix", "compute", "variable") and len(words) > 1:
                self.skipped_ids.add((head, words[1]))
            return None
        self._run(rec, self.run_as if head == "run" else expanded, name, line)
        if head in ("fix", "compute", "variable") and len(words) > 1:
            self.skipped_ids.discard((head, words[1]))  # defined again, now executed
        if head == "next":
            self._next(words)
        natoms = self.lmp.natoms()
        if natoms > MAX_ATOMS:
            raise Refused(f"{name}:{line}: {natoms} atoms: more than the {MAX_ATOMS} the audit's read takes")
        return None

    def _exists(self, word: str) -> bool:
        """A restart file of the deck's folder (``*``: any timestep's, as read_restart searches for the latest)."""
        if "*" in word:
            return any(p.is_file() for p in self.root.glob(word))
        return (self.root / word).resolve().is_file()

    def _run(self, rec, text, name, line) -> None:
        try:
            self.lmp.command(text)
        except Exception as exc:  # noqa: BLE001
            raise EngineError(f"{name}:{line}: {rec['text'][:70]!r}: the engine stops here: {message(exc)}") from None
        rec["ran"], rec["sent"] = True, text

    def _refusal(self, words: list) -> str:
        """Why a command is not executed ("" when it is on the allow-list and its arguments are)."""
        head, lists = words[0], self.lists
        if head not in lists.allowed:
            return f"{head}: not executed (not on the audit's list of set-up commands)"
        if head == "variable" and (len(words) < 3 or words[2] not in lists.variable_styles):
            return f"variable style {words[2] if len(words) > 2 else '(none)'}: not executed"
        if head == "pair_style" and len(words) > 1:
            bad = [s for s in self.lmp.pair_styles(words) if s not in lists.pair_styles]
            if bad:
                return f"pair_style {bad[0]}: not executed (not on the audit's list)"
        if head == "fix" and (len(words) < 4 or words[3] not in lists.fix_styles):
            return f"fix {words[3] if len(words) > 3 else ''}: not executed (not on the audit's list)"
        if head == "compute" and (len(words) < 4 or words[3] not in lists.compute_styles):
            return f"compute {words[3] if len(words) > 3 else ''}: not executed"
        if head in ("unfix", "fix_modify") and len(words) > 1 and ("fix", words[1]) in self.skipped_ids:
            return f"{head} {words[1]}: the fix was not executed"
        if head in ("uncompute", "compute_modify") and len(words) > 1 and ("compute", words[1]) in self.skipped_ids:
            return f"{head} {words[1]}: the compute was not executed"
        if head in lists.file_args:
            k = lists.file_args[head]
            if len(words) <= k:
                return f"{head}: names no file"
            self._inside(words[k])
            if head == "molecule":  # molecule ID FILE [keywords] [FILE …]: every file it names
                for word in words[k + 1:]:
                    if word not in lists.molecule_keys and not _is_number(word):
                        self._inside(word)
        if head == "create_atoms" and "random" in words:
            i = words.index("random")
            n = words[i + 1] if i + 1 < len(words) else ""
            if not n.isdigit() or int(n) > MAX_ATOMS:
                raise Refused(f"create_atoms random {n}: more than the {MAX_ATOMS} atoms the audit's read takes")
        return ""

    def _next(self, words: list) -> None:
        if any(self.lmp.exhausted(v) for v in words[1:]):
            self.skip_jump = True  # an exhausted variable: the engine skips the next jump

    def _jump(self, rec, words, name):
        rec["ran"] = True
        if self.skip_jump:
            self.skip_jump = False
            rec["why"] = "skipped (a loop variable ran out)"
            return None
        if len(words) < 2:
            raise Refused(f"{name}: jump needs a file")
        target = name if words[1] == "SELF" else None
        if target is None:
            target = self._lines(self._inside(words[1]))[0]
        lines = self.files[target]
        start = 0
        if len(words) > 2:
            found = [i for i, (_, body) in enumerate(lines) if body.split()[:2] == ["label", words[2]]]
            if not found:
                raise Refused(f"{name}: jump {words[1]} {words[2]}: no such label")
            start = found[0] + 1
        while self.frames[-1][2] == "branch":  # a jump inside an if's branch leaves the branch and its file
            self.frames.pop()
        # the jump ends the file it was in, as the engine does (a writing deck stays one)
        self.frames[-1] = [(target, lines), start, "restart" if self.frames[-1][2] == "restart" else "file"]
        return None

    def _if(self, rec, words, name, line):
        """if "C" then A… [elif "C" A…]… [else A…]: each condition evaluated by the engine's own if; the chosen
        branch's commands are followed line by line through the allow-list."""
        branches, k = [], 1
        cond = words[1] if len(words) > 1 else ""
        if words[2:3] != ["then"]:
            raise Refused(f"{name}:{line}: if needs 'then'")
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
            raise Refused(f"{name}:{line}: an if condition with a double quote is not followed")
        try:
            return bool(self.lmp.truth(cond))
        except Exception as exc:  # noqa: BLE001
            raise Refused(f"{name}:{line}: the if condition {cond[:60]!r}: {message(exc)}") from None

    # a restart file the folder lacks, written by a deck of the folder
    def _read_restart(self, rec, words, name, line):
        target = words[1]
        where = f"{name}:{line}"
        if self.restart is not None or self.scratch is None:
            raise Refused(f"{where}: read_restart {target}: no such file")
        writer = find_writer(self.root, target, exclude=set(self.files))
        if writer is None:
            raise Refused(f"{where}: read_restart {target}: no such file, and no deck in its folder writes it")
        path, wline = writer
        replay = [r["sent"] for r in self.out if r.get("sent") and (r["words"] or [""])[0] not in NOT_REPLAYED]
        self.restart = {"writer": path.name, "line": (path.name, wline), "target": target, "at": where,
                        "replay": replay}
        self._run(rec, "clear", name, line)
        rec["why"] = f"bodies from {path.name}, the deck that writes {target} (its set-up read in its place)"
        self.frames.append([self._lines(path), 0, "restart"])
        return None

    def _restart_written(self, rec):
        """The writing deck reached its write_restart: the engine writes its state into the scratch folder, clears,
        runs the reading deck's commands before read_restart again, and reads the state back."""
        own = self.scratch / RESTART_FILE
        name, line = self.restart["line"]
        self._run(rec, f"write_restart {own}", name, line)
        self._run(rec, "clear", name, line)
        for text in self.restart["replay"]:
            self._run(rec, text, name, line)
        self._run(rec, f"read_restart {own}", name, line)
        rec["why"] = "the state written into demcheck's scratch folder and read back by the reading deck"
        self.restart["done"] = True
        while self.frames and self.frames[-1][2] != "restart":
            self.frames.pop()
        self.frames.pop()
        return None


def find_writer(root: Path, target: str, exclude: set) -> tuple[Path, int] | None:
    """The deck of ``root`` (not one of ``exclude``) whose ``write_restart`` names ``target`` (``*`` the
    timestep), and that line's number: the first, by file name."""
    from ..inputs.script import _logical_lines, _strip_comment

    for path in sorted(p for p in root.iterdir() if p.is_file() and p.name not in exclude):
        try:
            if path.stat().st_size > MAX_WRITER_BYTES:
                continue
            text = path.read_bytes().decode("utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        if "write_restart" not in text:
            continue
        for n, raw in _logical_lines(text, path.name):
            words = _strip_comment(raw).split()
            if words[:1] == ["write_restart"] and len(words) > 1 and "$" not in words[1] and (
                    words[1] == target or fnmatch.fnmatchcase(target, words[1].replace("*", "[0-9]*"))):
                return path, n
    return None


def message(exc: Exception) -> str:
    text = str(exc).replace("\n", " ")
    return text.split(" For more information")[0][:300]


def answer_of(version: str, walker: Walker, state_of, out: str) -> None:
    """The worker's answer (JSON, written atomically into ``out``): the lines, the engine's state, why it
    stopped."""
    answer = {"version": version}
    try:
        answer["stopped"] = walker.walk()
    except Refused as exc:
        answer["stopped"], answer["engine_error"], answer["budget"] = str(exc), exc.engine_error, exc.budget
    except Exception as exc:  # noqa: BLE001 — any failure of the engine's read is an answer, never a traceback
        answer["failed"] = f"the engine's read failed: {type(exc).__name__}: {message(exc)}"
    answer["lines"] = walker.out
    if walker.restart and walker.restart.get("done"):
        answer["restart"] = f"{walker.restart['writer']}, the deck that writes {walker.restart['target']}"
    if "failed" not in answer:
        try:
            answer["state"] = state_of(walker)
        except Exception as exc:  # noqa: BLE001
            answer["failed"] = f"the engine's state cannot be read: {message(exc)}"
    tmp = Path(out).with_suffix(".part")
    tmp.write_text(json.dumps(answer), encoding="utf-8")
    tmp.replace(out)


# ----------------------------------------------------------------------------- the caller's side: a Script and a Setup

WRITERS = frozenset({"shell", "python", "plugin", "write_data", "write_restart", "write_dump", "write_coeff",
                     "write_file", "dump", "log", "restart", "print", "thermo_modify", "fitpod", "mdi", "kim",
                     "partition"})  # partition runs the command it is given


def script_of(answer: EngineRead, root: Path):
    """The deck's commands as the engine substituted them (inputs.script.Script), for the engine's contact
    vocabulary reader; the engine's control flow already followed (labels, jumps, ifs, loops are gone)."""
    from ..inputs.script import Command, Script, _geometry

    script = Script()
    script.engine_types = {a["type"] for a in answer.state.get("atoms", [])}
    for rec in answer.lines:
        words = rec["words"]
        head = (words or rec["text"].split() or [""])[0]
        if head in ("label", "jump", "next", "if", "include") and rec["ran"] or rec.get("restart"):
            continue  # control flow followed; a writing deck's lines (their effect is the engine's state)
        if head == "read_restart" and rec["ran"] and answer.state.get("ntypes"):
            words = ["create_box", str(answer.state["ntypes"])]  # the restart's box and types, as the engine has them
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


def _of_distribution(b, sizes: dict) -> bool:
    """Whether the reader gave type ``b`` several sizes with weights (a LIGGGHTS distribution of templates, fix
    pour's range or poly) among which are all the sizes the engine's atoms have: the engine inserted a first
    sample of that distribution, whose mass fractions are the deck's own statement of the mix."""
    import math

    return len(b.sizes) > 1 and all(any(math.isclose(r, x, rel_tol=1e-9) for x, _ in b.sizes) for r in sizes)


def apply(setup, answer: EngineRead, script, how: str = "") -> None:
    """The engine's state into a Setup the reader built from the engine's lines: units, dt, dimension, box, and
    each type's bodies (their radii with mass weights, density, positions, velocities, spins)."""
    import math

    from ..inputs.script import Body

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
        setup.populated.add(t)
        if _of_distribution(b, sizes):  # an insertion's first sample: the distribution's own mass fractions
            b.size_from += (f"; its sizes those of the engine's {len(rows)} atom(s) of type {t}, weighted by the "
                            "distribution's mass fractions")
            continue
        if len(sizes) == 1:
            b.radius, b.sizes = rows[0][0], []
        else:
            b.sizes = sorted(sizes.items())
            b.radius = sum(r * m for r, m in b.sizes) / total
        b.size_from = f"the engine's {len(rows)} atom(s) of type {t}"
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
    setup.read_by = (f"the engine ({answer.version}): the deck's set-up evaluated in {how}, "
                     f"{ran} of {len(answer.lines)} lines executed, the rest listed")
    if answer.restart:
        setup.read_by += f"; bodies from {answer.restart} (its set-up read in place of the missing restart file)"
