"""A reader of the LAMMPS-family input language (LIGGGHTS shares it), for auditing a user's own deck.

Nothing read here is ever executed: the reader turns a deck into a list of :class:`Command` (words after
quoting and substitution, with the file and line they came from). What it implements, as LAMMPS's input
reader does:

* a line ending in ``&`` continues onto the next; triple quotes (``\"\"\"``) span lines;
* ``#`` outside quotes starts a comment;
* ``variable NAME equal EXPR`` (evaluated when referenced), ``string TEXT``, ``index V1 V2 …`` (the first
  value; an index variable is not redefined), ``delete``; other variable styles are listed as not audited and
  their references make a command unreadable;
* ``$x``, ``${NAME}`` and ``$(EXPR)`` substitution outside quotes, with a small evaluator of arithmetic (numbers,
  ``+ - * / ^``, parentheses, ``PI``, ``v_NAME`` and a few functions) — never Python's ``eval``;
* ``include FILE`` relative to the deck's directory (a path that leaves it is refused);
* ``label``, ``jump``, ``next``, ``if`` and ``loop`` are refused: control flow decides which lines run.

:class:`ScriptError` (exit 2) names the file, line and command it cannot read.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import DemcheckError

CONTROL_FLOW = frozenset({"label", "jump", "next", "if", "loop"})
MAX_INCLUDE_DEPTH = 8
MAX_LINES = 200_000


class ScriptError(DemcheckError):
    """A deck the reader cannot read: names the file, the line and the command (exit 2)."""

    exit_code = 2


@dataclass
class Command:
    words: list[str]
    file: str
    line: int
    text: str  # the command as written (continuations joined), for messages
    problem: str = ""  # why its words could not be read exactly (an unknown variable): "" when read

    @property
    def name(self) -> str:
        return self.words[0] if self.words else ""

    def where(self) -> str:
        return f"{self.file}:{self.line}"


@dataclass
class Script:
    commands: list[Command] = field(default_factory=list)
    variables: dict = field(default_factory=dict)  # name → (style, value or expression)
    unread: list[tuple[Command, str]] = field(default_factory=list)  # variables the reader could not define


# ----------------------------------------------------------------------------- the safe evaluator

_TOKEN = re.compile(r"\s*(?:(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)|(v_[A-Za-z0-9_]+)|"
                    r"([A-Za-z_][A-Za-z0-9_]*)|(\*\*|[-+*/^(),]))")
_FUNCTIONS = {"sqrt": math.sqrt, "exp": math.exp, "ln": math.log, "log": math.log10, "abs": abs, "sin": math.sin,
              "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos, "atan": math.atan,
              "atan2": math.atan2, "floor": math.floor, "ceil": math.ceil, "round": round, "min": min, "max": max}
_CONSTANTS = {"PI": math.pi}


class _Unevaluable(Exception):
    pass


def evaluate(expr: str, variables: dict, depth: int = 0) -> float:
    """The value of an equal-style formula made of numbers, + - * / ^, parentheses, PI, v_NAME of other
    evaluable variables and the functions in _FUNCTIONS. Anything else (thermo keywords, atom values,
    comparisons) raises _Unevaluable: the reader never guesses a value."""
    if depth > 20:
        raise _Unevaluable("variables refer to each other too deeply")
    tokens, pos = [], 0
    expr = expr.strip()
    while pos < len(expr):
        m = _TOKEN.match(expr, pos)
        if not m or m.end() == pos:
            raise _Unevaluable(f"cannot read {expr[pos:pos + 20]!r}")
        num, var, name, op = m.groups()
        tokens.append(("num", float(num)) if num else ("var", var[2:]) if var else ("name", name) if name
                      else ("op", "^" if op == "**" else op))
        pos = m.end()
        while pos < len(expr) and expr[pos].isspace():
            pos += 1
    k = 0

    def peek():
        return tokens[k] if k < len(tokens) else ("end", None)

    def take(kind=None, value=None):
        nonlocal k
        t = peek()
        if (kind and t[0] != kind) or (value and t[1] != value):
            raise _Unevaluable(f"expected {value or kind} in {expr!r}")
        k += 1
        return t

    def add():
        x = mul()
        while peek() in (("op", "+"), ("op", "-")):
            op = take()[1]
            y = mul()
            x = x + y if op == "+" else x - y
        return x

    def mul():
        x = unary()
        while peek() in (("op", "*"), ("op", "/")):
            op = take()[1]
            y = unary()
            if op == "/" and y == 0:
                raise _Unevaluable("division by zero")
            x = x * y if op == "*" else x / y
        return x

    def unary():
        if peek() in (("op", "-"), ("op", "+")):
            sign = -1.0 if take()[1] == "-" else 1.0
            return sign * unary()
        return power()

    def power():
        x = atom()
        if peek() == ("op", "^"):
            take()
            y = unary()  # right-associative
            try:
                x = float(x) ** y
            except (OverflowError, ZeroDivisionError) as exc:
                raise _Unevaluable(str(exc)) from None
            if isinstance(x, complex):
                raise _Unevaluable("a negative number to a fractional power")
        return x

    def atom():
        kind, value = peek()
        if kind == "num":
            take()
            return value
        if kind == "op" and value == "(":
            take()
            x = add()
            take("op", ")")
            return x
        if kind == "var":
            take()
            return lookup(value, variables, depth + 1)
        if kind == "name":
            take()
            if value in _CONSTANTS:
                return _CONSTANTS[value]
            if value in _FUNCTIONS and peek() == ("op", "("):
                take()
                args = [add()]
                while peek() == ("op", ","):
                    take()
                    args.append(add())
                take("op", ")")
                try:
                    return float(_FUNCTIONS[value](*args))
                except (TypeError, ValueError, OverflowError) as exc:
                    raise _Unevaluable(f"{value}{tuple(args)}: {exc}") from None
            raise _Unevaluable(f"'{value}' is not a number the reader can know before a run")
        raise _Unevaluable(f"unexpected {value!r} in {expr!r}")

    x = add()
    if k != len(tokens):
        raise _Unevaluable(f"unexpected {tokens[k][1]!r} in {expr!r}")
    if not math.isfinite(x):
        raise _Unevaluable(f"{expr!r} is not finite")
    return x


def lookup(name: str, variables: dict, depth: int = 0) -> float:
    if name not in variables:
        raise _Unevaluable(f"variable '{name}' is not defined (before this line)")
    style, value = variables[name]
    if style == "equal":
        return evaluate(value, variables, depth)
    try:
        return float(value)
    except ValueError:
        raise _Unevaluable(f"variable '{name}' = {value!r} is not a number") from None


def number_text(x: float) -> str:
    return repr(int(x)) if float(x).is_integer() and abs(x) < 1e15 else f"{x:.15g}"


# ----------------------------------------------------------------------------- lines, quotes, substitution


def _logical_lines(text: str, name: str):
    """(line number, text) of each command: continuations joined, triple-quoted text kept whole."""
    lines = text.split("\n")
    if len(lines) > MAX_LINES:
        raise ScriptError(f"{name}: {len(lines)} lines: more than the {MAX_LINES} a deck may have")
    i = 0
    while i < len(lines):
        start, buf = i + 1, lines[i].rstrip("\r")
        i += 1
        while True:
            if buf.count('"""') % 2 == 1:  # inside a triple-quoted string: take the next line whole
                if i >= len(lines):
                    raise ScriptError(f"{name}:{start}: a triple quote is not closed: {buf[:60]!r}")
                buf += "\n" + lines[i].rstrip("\r")
                i += 1
                continue
            stripped = buf.rstrip()
            if stripped.endswith("&"):  # LAMMPS joins first and strips comments after: a comment's '&' continues it
                if i >= len(lines):
                    raise ScriptError(f"{name}:{start}: the last line continues ('&') onto nothing")
                buf = stripped[:-1] + " " + lines[i].rstrip("\r")
                i += 1
                continue
            break
        yield start, buf


def _strip_comment(text: str) -> str:
    """The text before the first '#' outside single, double or triple quotes."""
    i, quote = 0, ""
    while i < len(text):
        if quote:
            if text.startswith(quote, i):
                i += len(quote)
                quote = ""
                continue
        elif text.startswith('"""', i):
            quote = '"""'
            i += 3
            continue
        elif text[i] in "'\"":
            quote = text[i]
        elif text[i] == "#":
            return text[:i]
        i += 1
    return text


def _substitute(text: str, variables: dict) -> tuple[str, str]:
    """(text with $x, ${NAME} and $(EXPR) replaced outside quotes, the problem or "")."""
    out, i, quote, problem = [], 0, "", ""
    while i < len(text):
        ch = text[i]
        if quote:
            if text.startswith(quote, i):
                out.append(quote)
                i += len(quote)
                quote = ""
                continue
            out.append(ch)
            i += 1
            continue
        if text.startswith('"""', i):
            quote = '"""'
            out.append(quote)
            i += 3
            continue
        if ch in "'\"":
            quote = ch
            out.append(ch)
            i += 1
            continue
        if ch != "$" or i + 1 >= len(text):
            out.append(ch)
            i += 1
            continue
        nxt = text[i + 1]
        try:
            if nxt == "{":
                end = text.find("}", i + 2)
                if end < 0:
                    raise _Unevaluable("'${' is not closed")
                value = _value_text(text[i + 2:end], variables)
                i = end + 1
            elif nxt == "(":
                depth, j = 0, i + 1
                while j < len(text):
                    depth += text[j] == "("
                    depth -= text[j] == ")"
                    if depth == 0:
                        break
                    j += 1
                if depth:
                    raise _Unevaluable("'$(' is not closed")
                expr = text[i + 2:j]
                fmt = ""
                if ":" in expr:
                    expr, fmt = expr.rsplit(":", 1)
                x = evaluate(expr, variables)
                value = _format(x, fmt)
                i = j + 1
            else:
                value = _value_text(nxt, variables)
                i += 2
        except _Unevaluable as exc:
            problem = problem or str(exc)
            value = "?"
            i += 2 if nxt not in "{(" else 0
            if nxt in "{(":
                close = "}" if nxt == "{" else ")"
                end = text.find(close, i + 2)
                i = end + 1 if end >= 0 else len(text)
        out.append(value)
    return "".join(out), problem


def _format(x: float, fmt: str) -> str:
    m = re.fullmatch(r"%(\d*)(?:\.(\d+))?([fgeFGE])", fmt.strip()) if fmt else None
    if fmt and not m:
        raise _Unevaluable(f"format {fmt!r} is not %f, %g or %e")
    if m:
        return f"{x:{m.group(1) or ''}{'.' + m.group(2) if m.group(2) else ''}{m.group(3)}}"
    return f"{x:.15g}"


def _value_text(name: str, variables: dict) -> str:
    if name not in variables:
        raise _Unevaluable(f"variable '{name}' is not defined (before this line)")
    style, value = variables[name]
    if style == "equal":
        return f"{evaluate(value, variables):.15g}"
    return value


def split_words(text: str, where: str) -> list[str]:
    """Words separated by whitespace; single, double and triple quotes group words (and are removed)."""
    words, i = [], 0
    while i < len(text):
        if text[i].isspace():
            i += 1
            continue
        for q in ('"""', '"', "'"):
            if text.startswith(q, i):
                end = text.find(q, i + len(q))
                if end < 0:
                    raise ScriptError(f"{where}: a quote {q} is not closed: {text.strip()[:80]!r}")
                words.append(text[i + len(q):end])
                i = end + len(q)
                break
        else:
            j = i
            while j < len(text) and not text[j].isspace():
                j += 1
            words.append(text[i:j])
            i = j
    return words


# ----------------------------------------------------------------------------- the reader


def read(path: str | Path) -> Script:
    """Read a deck (and what it includes) into commands, defining variables as it goes."""
    path = Path(path)
    if not path.is_file():
        raise ScriptError(f"DECK = {str(path)!r}: no such file")
    root = path.resolve().parent
    script = Script()
    _read_file(path.resolve(), root, script, 0)
    return script


def _read_file(path: Path, root: Path, script: Script, depth: int) -> bool:
    """Read one file of the deck into ``script``; True when a ``quit`` ended the whole input (in an included
    file too, as in LAMMPS)."""
    name = path.name if path.parent == root else str(path.relative_to(root))
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ScriptError(f"{name}: not a text file (UTF-8)") from None
    for line_no, raw in _logical_lines(text, name):
        body = _strip_comment(raw).strip()
        if not body:
            continue
        where = f"{name}:{line_no}"
        head = body.split(None, 1)[0]
        if head in CONTROL_FLOW:
            raise ScriptError(f"{where}: {body[:60]!r}: not audited: control flow ('{head}' decides which lines "
                              "run; unroll it, or audit each branch as its own deck)")
        substituted, problem = _substitute(body, script.variables)
        words = split_words(substituted, where)
        if not words:
            continue
        cmd = Command(words, name, line_no, body, problem)
        if cmd.name == "quit":
            script.commands.append(cmd)
            return True
        if cmd.name == "variable" and not problem:
            _define(cmd, script)
        if cmd.name == "include":
            if problem or len(words) != 2:
                raise ScriptError(f"{where}: {body[:60]!r}: include takes one file name"
                                  + (f" ({problem})" if problem else ""))
            target = (path.parent / words[1]).resolve()
            if not target.is_relative_to(root):
                raise ScriptError(f"{where}: include {words[1]!r}: the file lies outside the deck's directory "
                                  f"{str(root)!r} (refused)")
            if not target.is_file():
                raise ScriptError(f"{where}: include {words[1]!r}: no such file")
            if depth >= MAX_INCLUDE_DEPTH:
                raise ScriptError(f"{where}: include {words[1]!r}: more than {MAX_INCLUDE_DEPTH} nested includes")
            script.commands.append(cmd)
            if _read_file(target, root, script, depth + 1):
                return True
            continue
        script.commands.append(cmd)
    return False


def _define(cmd: Command, script: Script) -> None:
    w = cmd.words
    if len(w) < 3:
        raise ScriptError(f"{cmd.where()}: {cmd.text[:60]!r}: variable needs a name and a style")
    name, style, rest = w[1], w[2], w[3:]
    if style == "delete":
        script.variables.pop(name, None)
    elif style == "equal":
        script.variables[name] = ("equal", " ".join(rest))
    elif style == "string":
        script.variables[name] = ("string", " ".join(rest))
    elif style == "index":
        if not rest:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:60]!r}: an index variable needs a value")
        script.variables.setdefault(name, ("index", rest[0]))
    else:  # loop, world, universe, atom, vector, python, file, getenv, format, internal, …
        script.variables.pop(name, None)
        script.unread.append((cmd, f"variable style '{style}' is not read (its value is known only in a run)"))


# ----------------------------------------------------------------------------- what an engine's reader makes of a deck


@dataclass
class Finding:
    """A trap the deck falls into (``trap``: exit 1) or a remark (``note``), with its measured size."""

    kind: str  # "trap" | "note"
    code: str  # tsuji, limit, mixing, wall-moduli, hard-particles, dt-unstable, dt-coarse, attraction, …
    text: str
    where: str = ""
    size: dict = field(default_factory=dict)


@dataclass
class Body:
    """One atom type's particles as the deck makes them (None where the deck does not say)."""

    type: int
    radius: float | None = None
    density: float | None = None
    mass: float | None = None
    youngs_modulus: float | None = None  # what the engine's contact settings give the type (for the seed model)
    poisson_ratio: float | None = None


@dataclass
class PairSetting:
    """One type pair (``j`` None: a wall with type ``i``) as the engine computes it."""

    label: str
    i: int
    j: int | None
    native: object  # the engine's Native: exactly what it computes for this pair (an explicit equivalent)
    where: str
    asked: dict = field(default_factory=dict)  # what the deck asks for: restitution, friction
    intended: object = None  # what the deck most likely means, where the engine reads it otherwise
    findings: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    wall: dict = field(default_factory=dict)  # a wall's own properties (youngs_modulus, poisson_ratio)
    probe: bool = True  # False: listed, not run (no twin for its law)


@dataclass
class Setup:
    engine: str
    bodies: dict = field(default_factory=dict)  # type → Body
    pairs: list = field(default_factory=list)  # PairSetting
    dt: float | None = None
    dt_where: str = ""
    speeds: list = field(default_factory=list)  # (speed, where) the deck gives its bodies
    not_audited: list = field(default_factory=list)  # (where, text, why)
    findings: list = field(default_factory=list)
    ntypes: int = 0


# ----------------------------------------------------------------------------- what both engines' decks share

# commands that set nothing a two-body contact depends on (output, neighbour lists, bookkeeping)
MAX_TYPES = 10_000  # atom types the audit reads (a deck's type count builds one record each)
NO_CONTACT_EFFECT = frozenset({
    "atom_style", "atom_modify", "boundary", "newton", "comm_modify", "communicate", "region", "neighbor",
    "neigh_modify", "thermo", "thermo_style", "thermo_modify", "dump", "dump_modify", "undump", "compute",
    "compute_modify", "run", "print", "log", "echo", "processors", "variable", "include", "quit", "write_restart",
    "write_data", "write_dump", "reset_timestep", "group", "lattice", "restart", "info", "clear", "suffix",
    "package", "partition", "plugin", "units", "create_box", "create_atoms", "set", "read_data", "velocity",
    "timestep", "pair_style", "pair_coeff", "fix", "unfix", "hard_particles", "soft_particles", "delete_atoms",
    "mass"})
NEVER_RUN = frozenset({"shell", "python", "plugin", "labelmap", "read_restart", "read_dump", "rerun", "kim",
                       "mdi", "fitpod", "message", "server", "quit"})


def note_unread(setup, cmd: "Command", quiet_fixes=frozenset()) -> None:
    """What every engine's reader does with a command it does not read: nothing for a fix style in
    ``quiet_fixes`` or a command without effect on the contacts (NO_CONTACT_EFFECT); else it is listed as not
    audited — a fix that runs code (python, shell) as never run by demcheck."""
    w = cmd.words
    if cmd.name == "fix":
        style = w[3] if len(w) > 3 else ""
        if style in quiet_fixes:
            return
        if style.startswith("python") or style == "shell":
            setup.not_audited.append((cmd.where(), cmd.text, "not audited (never run by demcheck)"))
        else:
            setup.not_audited.append((cmd.where(), cmd.text, f"fix {style}: not read by the audit"))
    elif cmd.name not in NO_CONTACT_EFFECT:
        setup.not_audited.append((cmd.where(), cmd.text, "not audited: not a command the audit reads"))


def _num(cmd: Command, k: int, what: str) -> float:
    if cmd.problem:
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {cmd.problem}")
    try:
        x = float(cmd.words[k])
    except (IndexError, ValueError):
        got = cmd.words[k] if k < len(cmd.words) else "(missing)"
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {what} = {got!r} is not a number") from None
    if not math.isfinite(x):
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {what} = {cmd.words[k]!r} is not finite")
    return x


def type_range(word: str, n: int, cmd: Command) -> list[int]:
    """The types of ``*``, ``i``, ``i*``, ``*j``, ``i*j`` (1-based, up to n types)."""
    m = re.fullmatch(r"(\d*)\*(\d*)|(\d+)", word)
    if not m:
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {word!r} is not a type or a type range")
    if m.group(3):
        lo = hi = int(m.group(3))
    else:
        lo, hi = int(m.group(1) or 1), int(m.group(2) or n)
    if n and (lo < 1 or hi > n or lo > hi):
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: types {word} lie outside 1..{n}")
    return list(range(lo, hi + 1))


def body(setup: Setup, t: int) -> Body:
    return setup.bodies.setdefault(t, Body(t))


def read_common(cmd: Command, setup: Setup, root: Path) -> bool:
    """The commands both engines share that define bodies, their speeds and the step; True when read."""
    w, name = cmd.words, cmd.name
    if name == "units":
        if len(w) < 2 or w[1] != "si":
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: audit reads decks in units si "
                              f"(got {w[1] if len(w) > 1 else 'none'})")
        return True
    if name == "timestep":
        dt = _num(cmd, 1, "timestep")
        if not dt > 0:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: the time step must be > 0 s")
        setup.dt, setup.dt_where = dt, cmd.where()
        return True
    if name == "create_box":
        setup.ntypes = int(_num(cmd, 1, "number of atom types"))
        if not 1 <= setup.ntypes <= MAX_TYPES:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {setup.ntypes} atom types; the audit reads 1 to "
                              f"{MAX_TYPES}")
        for t in range(1, setup.ntypes + 1):
            body(setup, t)
        return True
    if name == "create_atoms":
        t = int(_num(cmd, 1, "atom type"))
        body(setup, t)
        return True
    if name == "set" and len(w) >= 5 and w[1] in ("type", "group"):
        if w[1] == "group" and w[2] != "all":
            setup.not_audited.append((cmd.where(), cmd.text, "set group other than all: the audit reads "
                                                              "properties per type"))
            return True
        types = (type_range(w[2], setup.ntypes, cmd) if w[1] == "type"
                 else list(range(1, setup.ntypes + 1)) or list(setup.bodies))
        k = 3
        while k + 1 < len(w):
            key = w[k]
            if key in ("diameter", "density", "mass"):
                x = _num(cmd, k + 1, key)
                if not x > 0:
                    raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {key} must be > 0")
                for t in types:
                    b = body(setup, t)
                    if key == "diameter":
                        b.radius = x / 2
                    elif key == "density":
                        b.density = x
                    else:
                        b.mass = x
            elif key in ("vx", "vy", "vz"):
                setup.speeds.append((abs(_num(cmd, k + 1, key)), cmd.where()))
            k += 2
        return True
    if name == "velocity" and len(w) >= 6 and w[2] == "set":
        v = [0.0 if x == "NULL" else _num(cmd, 3 + i, "velocity") for i, x in enumerate(w[3:6])]
        setup.speeds.append((math.sqrt(sum(x * x for x in v)), cmd.where()))
        return True
    if name == "read_data":
        _read_data(cmd, setup, root)
        return True
    return False


def _read_data(cmd: Command, setup: Setup, root: Path) -> None:
    if len(cmd.words) < 2 or cmd.problem:
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: read_data needs a file name")
    path = (root / cmd.words[1]).resolve()
    if not path.is_relative_to(root):
        raise ScriptError(f"{cmd.where()}: read_data {cmd.words[1]!r}: the file lies outside the deck's directory "
                          "(refused)")
    if not path.is_file():
        raise ScriptError(f"{cmd.where()}: read_data {cmd.words[1]!r}: no such file")
    section = ""
    for n, raw in enumerate(path.read_text(encoding="utf-8", errors="replace").split("\n")[1:], 2):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        where = f"{path.name}:{n}"
        if words[0] in ("Atoms", "Velocities", "Masses") or (words[0][0].isalpha() and len(words) <= 2
                                                              and not words[-1].replace(".", "").isdigit()):
            section = words[0]
            continue
        try:
            nums = [float(x) for x in words if not x.isalpha()]
        except ValueError:
            raise ScriptError(f"{where}: {line[:60]!r}: not a number") from None
        if not section:
            if words[-2:] == ["atom", "types"]:
                setup.ntypes = int(nums[0])
                if not 1 <= setup.ntypes <= MAX_TYPES:
                    raise ScriptError(f"{where}: {line[:60]!r}: {setup.ntypes} atom types; the audit reads 1 to "
                                      f"{MAX_TYPES}")
                for t in range(1, setup.ntypes + 1):
                    body(setup, t)
            continue
        if section == "Masses" and len(nums) >= 2:
            body(setup, int(nums[0])).mass = nums[1]
        elif section == "Atoms" and len(nums) >= 7:  # atom_style sphere/granular: id type diameter density x y z
            b = body(setup, int(nums[1]))
            b.radius, b.density = nums[2] / 2, nums[3]
        elif section == "Velocities" and len(nums) >= 4:
            setup.speeds.append((math.sqrt(sum(x * x for x in nums[1:4])), where))
