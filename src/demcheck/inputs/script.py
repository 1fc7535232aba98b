"""A reader of the LAMMPS-family input language (LIGGGHTS shares it), for auditing a user's own deck.

Nothing read here is ever executed (this reader serves LIGGGHTS decks, and LAMMPS decks where LAMMPS itself
cannot read them: engines/lammps/read.py): the reader turns a deck into a list of :class:`Command` (words after
quoting and substitution, with the file and line they came from). What it implements, as LAMMPS's input
reader does:

* a line ending in ``&`` continues onto the next; triple quotes (``\"\"\"``) span lines;
* ``#`` outside quotes starts a comment;
* ``variable NAME equal EXPR`` (evaluated when referenced), ``string TEXT``, ``index V1 V2 …`` (the first
  value; an index variable is not redefined), ``delete``; other variable styles are listed as not audited and
  their references make a command unreadable;
* ``$x``, ``${NAME}`` and ``$(EXPR)`` substitution, inside quotes too (as LAMMPS 22Jul2025 does: checked with its
  library; inside quotes a reference the reader cannot evaluate stays as written), with a small evaluator of
  arithmetic (ASCII numbers, ``+ - * / ^``, parentheses, ``PI``, ``v_NAME``, the box bounds ``xlo … zhi``, ``lx``,
  ``ly``, ``lz`` once a box is defined, and a few functions) — never Python's ``eval``;
* a bare carriage return (a CR-only file) is refused: LAMMPS reads it as a space, so the lines are one command;
* ``include FILE`` relative to the deck's directory (a path that leaves it is refused);
* a ``label … jump SELF`` loop whose body sets nothing the audit reads, ended by a ``next`` of a loop or index
  variable, is read once (_loop_end); any other ``jump``, ``next``, ``if`` and ``loop`` is refused: control flow
  decides which lines run (a LAMMPS deck's control flow is followed by the engine itself: engines/lammps/read.py).

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
MAX_LINE_CHARS = 100_000  # a command (after substitution) or a string variable longer than this is refused
MAX_NESTING = 50  # parentheses in one formula (LAMMPS's own parser recurses too)
MAX_MESSAGE = 400  # characters of deck text an error message quotes
NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")  # what LAMMPS's numeric() takes
BOX_KEYS = ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")


class ScriptError(DemcheckError):
    """A deck the reader cannot read: names the file, the line and the command (exit 2). The message quotes at
    most MAX_MESSAGE characters of deck text (a 100 KB value is cut, never echoed whole)."""

    exit_code = 2

    def __init__(self, message: str = ""):
        message = str(message)
        if len(message) > MAX_MESSAGE:
            message = message[:MAX_MESSAGE // 2] + f" … [{len(message) - MAX_MESSAGE} characters cut] … " + \
                message[-MAX_MESSAGE // 2:]
        super().__init__(message)


def to_number(text: str) -> float | None:
    """A number as LAMMPS reads one (ASCII digits, optional sign, point and exponent), else None: Python's float
    would also take '63_000_000_000', full-width digits, 'inf' and 'nan', which LAMMPS stops on."""
    return float(text) if NUMBER.fullmatch(text) else None


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
    regions: dict = field(default_factory=dict)  # region id → (xlo, xhi, ylo, yhi, zlo, zhi) or None (other shapes)
    atom_formulas: dict = field(default_factory=dict)  # atom-style variable → its formula (for fix adapt's growth)
    radius_computes: dict = field(default_factory=dict)  # compute id → "radius" | "diameter" (property/atom)
    engine_types: set = field(default_factory=set)  # types with atoms in the engine's own read of the set-up


# ----------------------------------------------------------------------------- the safe evaluator

_TOKEN = re.compile(r"\s*(?:([0-9]+\.?[0-9]*(?:[eE][+-]?[0-9]+)?|\.[0-9]+(?:[eE][+-]?[0-9]+)?)|(v_[A-Za-z0-9_]+)|"
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
    expr = expr.strip()
    parser = _Formula(expr, _tokens(expr), variables, depth)
    x = parser.add()
    if parser.k != len(parser.tokens):
        raise _Unevaluable(f"unexpected {parser.tokens[parser.k][1]!r} in {expr!r}")
    if not math.isfinite(x):
        raise _Unevaluable(f"{expr!r} is not finite")
    return x


def _tokens(expr: str) -> list[tuple]:
    """The formula's tokens: ("num", value), ("var", NAME), ("name", word), ("op", symbol)."""
    nest = 0
    for ch in expr:  # the parser recurses per parenthesis: bound it before parsing (never a RecursionError)
        nest += (ch == "(") - (ch == ")")
        if nest > MAX_NESTING:
            raise _Unevaluable(f"parentheses nested more than {MAX_NESTING} deep")
    tokens, pos = [], 0
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
    return tokens


class _Formula:
    """A recursive-descent reading of an equal-style formula's tokens, with LAMMPS's precedence."""

    def __init__(self, expr: str, tokens: list, variables: dict, depth: int):
        self.expr, self.tokens, self.variables, self.depth, self.k = expr, tokens, variables, depth, 0

    def peek(self):
        return self.tokens[self.k] if self.k < len(self.tokens) else ("end", None)

    def take(self, kind=None, value=None):
        t = self.peek()
        if (kind and t[0] != kind) or (value and t[1] != value):
            raise _Unevaluable(f"expected {value or kind} in {self.expr!r}")
        self.k += 1
        return t

    def add(self):
        x = self.mul()
        while self.peek() in (("op", "+"), ("op", "-")):
            op = self.take()[1]
            y = self.mul()
            x = x + y if op == "+" else x - y
        return x

    def mul(self):
        x = self.power()
        while self.peek() in (("op", "*"), ("op", "/")):
            op = self.take()[1]
            y = self.power()
            if op == "/" and y == 0:
                raise _Unevaluable("division by zero")
            x = x * y if op == "*" else x / y
        return x

    def power(self):  # as LAMMPS evaluates it (checked with its library): left to right, 2^3^2 = 64, -2^2 = 4
        x = self.unary()
        while self.peek() == ("op", "^"):
            self.take()
            y = self.unary()
            try:
                x = float(x) ** y
            except OverflowError:
                raise _Unevaluable(f"{x:g}^{y:g} overflows (larger than 1.8e308)") from None
            except ZeroDivisionError:
                raise _Unevaluable(f"{x:g}^{y:g}: zero to a negative power") from None
            if isinstance(x, complex):
                raise _Unevaluable("a negative number to a fractional power")
        return x

    def unary(self):  # a sign binds tighter than ^ in LAMMPS
        if self.peek() in (("op", "-"), ("op", "+")):
            sign = -1.0 if self.take()[1] == "-" else 1.0
            return sign * self.unary()
        return self.atom()

    def atom(self):
        kind, value = self.peek()
        if kind == "num":
            self.take()
            return value
        if kind == "op" and value == "(":
            self.take()
            x = self.add()
            self.take("op", ")")
            return x
        if kind == "var":
            self.take()
            return lookup(value, self.variables, self.depth + 1)
        if kind == "name":
            self.take()
            return self.name(value)
        raise _Unevaluable(f"unexpected {value!r} in {self.expr!r}")

    def name(self, value: str) -> float:
        """A constant, a box extent or a function call."""
        if value in _CONSTANTS:
            return _CONSTANTS[value]
        box = self.variables.get("__box__", (None, None))[1]
        if box and value in BOX_KEYS + ("lx", "ly", "lz"):
            if value.startswith("l"):
                axis = "xyz".index(value[1])
                return box[2 * axis + 1] - box[2 * axis]
            return box[BOX_KEYS.index(value)]
        if value in _FUNCTIONS and self.peek() == ("op", "("):
            self.take()
            args = [self.add()]
            while self.peek() == ("op", ","):
                self.take()
                args.append(self.add())
            self.take("op", ")")
            try:
                return float(_FUNCTIONS[value](*args))
            except (TypeError, ValueError, OverflowError, ZeroDivisionError) as exc:
                raise _Unevaluable(f"{value}{tuple(args)}: {exc}") from None
        raise _Unevaluable(f"'{value}' is not a number the reader can know before a run")


def lookup(name: str, variables: dict, depth: int = 0) -> float:
    if name not in variables or name == "__box__":
        raise _Unevaluable(f"variable '{name}' is not defined (before this line)")
    style, value = variables[name]
    if style == "equal":
        return evaluate(value, variables, depth)
    x = to_number(value.strip())
    if x is None:
        raise _Unevaluable(f"variable '{name}' = {value[:60]!r} is not a number")
    return x


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
    """(text with $x, ${NAME} and $(EXPR) replaced, the problem or ""). LAMMPS 22Jul2025 substitutes inside single,
    double and triple quotes too (checked with its library); there a reference the reader cannot evaluate (a
    ``fix print`` of a compute) stays as written and is no problem of the line."""
    out, i, quote, problem, grown = [], 0, "", "", len(text)
    while i < len(text):
        ch = text[i]
        if quote and text.startswith(quote, i):
            out.append(quote)
            i += len(quote)
            quote = ""
            continue
        if not quote and (text.startswith('"""', i) or ch in "'\""):
            quote = '"""' if text.startswith('"""', i) else ch
            out.append(quote)
            i += len(quote)
            continue
        if ch != "$" or i + 1 >= len(text):
            out.append(ch)
            i += 1
            continue
        start, nxt = i, text[i + 1]
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
            i = start + (2 if nxt not in "{(" else 0)
            if nxt in "{(":
                close = "}" if nxt == "{" else ")"
                end = text.find(close, start + 2)
                i = end + 1 if end >= 0 else len(text)
            if quote:  # as written: the command that reads the quoted text is not one the audit reads
                value = text[start:i]
            else:
                problem = problem or str(exc)
                value = "?"
        out.append(value)
        grown += len(value)
        if grown > MAX_LINE_CHARS:
            raise ScriptError(f"a command grows past {MAX_LINE_CHARS} characters by substitution: {text[:80]!r}")
    return "".join(out), problem


def _format(x: float, fmt: str) -> str:
    m = re.fullmatch(r"%(\d*)(?:\.(\d+))?([fgeFGE])", fmt.strip()) if fmt else None
    if fmt and not m:
        raise _Unevaluable(f"format {fmt!r} is not %f, %g or %e")
    if m:
        return f"{x:{m.group(1) or ''}{'.' + m.group(2) if m.group(2) else ''}{m.group(3)}}"
    return f"{x:.15g}"


def _value_text(name: str, variables: dict) -> str:
    if name not in variables or name == "__box__":
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
        text = path.read_bytes().decode("utf-8")  # as written: read_text would turn a bare CR into a line end
    except UnicodeDecodeError:
        raise ScriptError(f"{name}: not a text file (UTF-8)") from None
    bare_cr = text.replace("\r\n", "").find("\r")
    if bare_cr >= 0:
        line = text[:bare_cr].count("\n") + 1
        raise ScriptError(f"{name}:{line}: a carriage return without a line feed (CR-only line endings): LAMMPS reads "
                          "it as a space, so these lines are one command to the engine; convert the file to LF or "
                          "CRLF line endings")
    labels: dict = {}  # label → (index of the next command, its line)
    for line_no, raw in _logical_lines(text, name):
        body = _strip_comment(raw).strip()
        if not body:
            continue
        where = f"{name}:{line_no}"
        head = body.split(None, 1)[0]
        if head == "label" and len(body.split()) == 2:  # a jump back to it is read as a loop (_loop_end)
            labels[body.split()[1]] = (len(script.commands), line_no)
            continue
        if head in ("jump", "next") and _loop_end(body, labels, script, path, name, where):
            continue
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
        _geometry(cmd, script, root)
        if cmd.name == "run" and "every" in words:
            for text in words[words.index("every") + 2:]:
                if text not in ("NULL", "pre", "post", "start", "stop", "upto", "every") and not NUMBER.fullmatch(text):
                    script.unread.append((cmd, f"run … every: {text[:60]!r} runs between the chunks of the run: "
                                               "not audited (never run by demcheck)"))
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
    if labels.get(PENDING):
        raise ScriptError(f"{name}:{labels[PENDING][0]}: 'next' outside a loop the reader can read: not audited: "
                          "control flow ('next' changes a variable's value for the lines after it)")
    return False


PENDING = "\0next"  # labels' key for the lines of `next` not yet inside a closed loop
LOOP_SAFE = frozenset({"run", "print", "thermo", "thermo_style", "thermo_modify", "dump", "dump_modify", "undump",
                       "write_dump", "write_restart", "write_data", "reset_timestep", "next"})
SET_READ = frozenset({"type", "type/fraction", "type/ratio", "type/subset", "diameter", "density", "mass", "vx", "vy",
                      "vz", "omega", "angmom", "x", "y", "z", "image", "shape", "quat"})


def _loop_end(body: str, labels: dict, script: Script, path: Path, name: str, where: str) -> bool:
    """``next V …`` (read as nothing) or a backward ``jump SELF|this-file LABEL`` that closes a loop whose body
    sets nothing the audit reads — runs, output, ``next`` of a loop or index variable, ``set … property/atom``
    and other per-atom values the contacts do not depend on, loop/index variables (LAMMPS keeps the first
    definition) — and that ``next`` ends: then the set-up after any number of passes is the set-up after one,
    and the reader goes on after the jump (noted). Any other jump is control flow (refused by the caller)."""
    w = body.split()
    if w[0] == "next":  # only inside a label … jump loop, checked when its jump closes it (else refused at the end)
        if len(w) < 2 or not any(k != PENDING for k in labels):
            return False
        labels.setdefault(PENDING, []).append(int(where.rsplit(":", 1)[1]))
        return True
    if len(w) != 3 or w[2] not in labels or (w[1] != "SELF" and (path.parent / w[1]).resolve() != path):
        return False
    start, label_line = labels[w[2]]
    loop = script.commands[start:]
    counters = set()
    for cmd in loop:
        if cmd.name == "variable" and cmd.words[2:3] in (["loop"], ["index"]):
            counters.add(cmd.words[1])
            continue
        if cmd.name == "set" and not SET_READ & set(cmd.words[3::2]):
            continue
        if cmd.name not in LOOP_SAFE:
            return False
    nexts = [b for b in _bodies_between(path, label_line, where) if b.split()[:1] == ["next"]]
    defined = {n for n, (style, _) in script.variables.items() if style == "index"} | counters \
        | {c.words[1] for c in script.commands if c.name == "variable" and c.words[2:3] == ["loop"]}
    if w[2] == PENDING or not any(set(b.split()[1:]) & defined for b in nexts):
        return False  # no loop variable runs out: the loop may never end
    last = int(where.rsplit(":", 1)[1])
    labels[PENDING] = [n for n in labels.get(PENDING, []) if not label_line < n < last]
    for b in nexts:  # the loop ran its variables out: LAMMPS deletes them
        for v in b.split()[1:]:
            script.variables.pop(v, None)
    script.unread.append((Command(w, name, label_line, f"label {w[2]} … {body}"),
                          f"a loop (lines {label_line}–{where.rsplit(':', 1)[1]}) read once: its body sets nothing the "
                          "audit reads, so every pass leaves the same set-up; its runs are not audited"))
    return True


def _bodies_between(path: Path, first: int, where: str) -> list[str]:
    last = int(where.rsplit(":", 1)[1])
    text = path.read_bytes().decode("utf-8")
    return [_strip_comment(raw).strip() for n, raw in _logical_lines(text, path.name) if first < n < last]


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
        value = " ".join(rest)
        if len(value) > MAX_LINE_CHARS:
            raise ScriptError(f"{cmd.where()}: variable {name}: a string of {len(value)} characters, more than the "
                              f"{MAX_LINE_CHARS} the audit reads")
        script.variables[name] = ("string", value)
    elif style == "index":
        if not rest:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:60]!r}: an index variable needs a value")
        script.variables.setdefault(name, ("index", rest[0]))
    else:  # loop, world, universe, atom, vector, python, file, getenv, format, internal, …
        if style == "atom":
            script.atom_formulas[name] = " ".join(rest)
        script.variables.pop(name, None)
        script.unread.append((cmd, f"variable style '{style}' is not read (its value is known only in a run)"))


def _bound(word: str, default: float) -> float:
    x = to_number(word)
    return default if x is None else x


def _geometry(cmd: Command, script: Script, root: Path) -> None:
    """Regions (block and cylinder bounds, for insertion heights) and the box (its bounds become the thermo
    keywords xlo … zhi in later formulas, as in LAMMPS once create_box or read_data has run)."""
    w = cmd.words
    if cmd.name == "compute" and len(w) == 5 and w[3] == "property/atom" and w[4] in ("radius", "diameter"):
        script.radius_computes[w[1]] = w[4]
    if cmd.name == "region" and len(w) >= 3:
        bounds = None
        inf = math.inf
        box = script.variables.get("__box__", (None, None))[1] or (-inf, inf, -inf, inf, -inf, inf)
        if w[2] == "block" and len(w) >= 9:
            bounds = tuple(_bound(x, box[k]) for k, x in enumerate(w[3:9]))
        elif w[2] == "cylinder" and len(w) >= 9 and w[3] in ("x", "y", "z"):
            c1, c2, r = (to_number(x) for x in w[4:7])
            axis = "xyz".index(w[3])
            if None not in (c1, c2, r):
                lo, hi = _bound(w[7], box[2 * axis]), _bound(w[8], box[2 * axis + 1])
                others = [(c1 - r, c1 + r), (c2 - r, c2 + r)]
                spans = others[:axis] + [(lo, hi)] + others[axis:]
                bounds = tuple(x for span in spans for x in span)
        if w[2] != "delete":
            script.regions[w[1]] = bounds
    elif cmd.name == "create_box" and len(w) >= 3 and script.regions.get(w[2]):
        script.variables["__box__"] = ("box", script.regions[w[2]])
    elif cmd.name == "read_data" and len(w) >= 2:
        path = (root / w[1]).resolve()
        if path.is_relative_to(root) and path.is_file():
            box = [0.0] * 6
            with path.open(encoding="utf-8", errors="replace") as f:
                for _, line in zip(range(60), f):
                    parts = line.split("#", 1)[0].split()
                    if len(parts) == 4 and parts[2:] in (["xlo", "xhi"], ["ylo", "yhi"], ["zlo", "zhi"]):
                        k = "xyz".index(parts[2][0])
                        box[2 * k:2 * k + 2] = [_bound(parts[0], 0.0), _bound(parts[1], 0.0)]
            script.variables["__box__"] = ("box", tuple(box))


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
    sizes: list = field(default_factory=list)  # (radius, mass fraction) when the type comes in several sizes
    size_from: str = ""  # where the sizes come from (fix pour, templates, per-atom data)


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
    radii: tuple | None = None  # the radii probed (i, j) where a type comes in several sizes; None: the type's own
    size: str = ""  # which of the sizes: smallest, largest, mass-weighted
    # the sub-models beyond sliding the deck sets on it: slot (rolling, twisting, adhesion, heat) → {"law": the
    # engine's word, "args": its coefficients, "words": as written}; probed by comparisons/audit_beyond.py
    beyond: dict = field(default_factory=dict)


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
    units: str | None = None  # the deck's unit style (None: no units line — LAMMPS's default, lj)
    units_where: str = ""
    dimension: int = 3
    gravity: tuple | None = None  # (magnitude, axis 0|1|2, where) of fix gravity
    atoms: dict = field(default_factory=dict)  # id → [type, position or None, velocity or None] (single bodies)
    groups: dict = field(default_factory=dict)  # group → set of atom ids, or ("type", types)
    populated: set = field(default_factory=set)  # types the deck gives bodies (create_atoms, data, pour, insert)
    insertions: list = field(default_factory=list)  # (region id, initial velocity, types, where) of pour/insert
    floors: list = field(default_factory=list)  # (axis, coordinate) of plane walls
    regions: dict = field(default_factory=dict)  # the script's regions (bounds or None)
    box: tuple | None = None
    created: set = field(default_factory=set)  # types create_atoms makes (LAMMPS's default diameter 1, density 1)
    molecules: dict = field(default_factory=dict)  # molecule id → its file (inside the deck's directory)
    script: object = None  # the Script read (its atom-style formulas and computes, for growth_speed)
    growth: list = field(default_factory=list)  # (every N steps, atom variable, where) of fix adapt … atom diameter
    read_by: str = "demcheck's reader (inputs/script.py)"
    heat: dict = field(default_factory=dict)  # the deck's heat set-up: capacities per type, conductivities, where
    units_text: str = ""  # the units line as written  # which path read the deck: the engine or the reader


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
    x = to_number(cmd.words[k]) if k < len(cmd.words) else None
    if x is None:
        got = cmd.words[k] if k < len(cmd.words) else "(missing)"
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {what} = {got[:60]!r} is not a number (as LAMMPS "
                          "reads one: ASCII digits, a sign, a point and an exponent)")
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


# LAMMPS's unit styles and the default time step of each (its `units` command); metal and real convert between
# their mass, force and time units with constants of LAMMPS's own, so a probe written in them is not read here
UNITS = {"lj": 0.005, "si": 1e-8, "cgs": 1e-8, "micro": 2.0, "nano": 0.00045, "metal": 0.001, "real": 1.0}
INCONSISTENT_UNITS = ("metal", "real")  # their force unit is not mass·length/time²: converted (engine's to_si)
# each consistent style's units of length, mass and time in SI (lj has none: σ, m and τ are the deck's own)
SI_OF = {"si": (1.0, 1.0, 1.0), "cgs": (1e-2, 1e-3, 1.0), "micro": (1e-6, 1e-15, 1e-6), "nano": (1e-9, 1e-21, 1e-9)}
SIZE_STEPS = 41  # a diameter range (fix pour diam range) is probed through this many diameters, mass-weighted


def finish(setup: Setup, default_dt_where: str) -> None:
    """What every reader does after the last command: the units (LAMMPS's default lj without a units line),
    the default step of the units, each type's representative (mass-weighted) radius where it has several."""
    if setup.units is None:
        setup.units, setup.units_where = "lj", "no units line: LAMMPS's default, lj"
    if setup.dt is None:
        setup.dt, setup.dt_where = UNITS[setup.units], f"{default_dt_where} for units {setup.units} (no timestep command)"
    for t in setup.created:  # atom_style sphere: create_atoms makes diameter 1 and density 1 until `set` changes it
        b = setup.bodies[t]
        if b.radius is None:
            b.radius = 0.5
        if b.density is None and b.mass is None:
            b.density = 1.0
    for b in setup.bodies.values():
        if not b.sizes:
            continue
        radii = sorted({r for r, _ in b.sizes})
        total = sum(w for _, w in b.sizes)
        if len(radii) == 1 or not total > 0:
            b.radius, b.sizes = radii[0], []
            continue
        b.radius = sum(r * w for r, w in b.sizes) / total


def size_variants(b: Body) -> list[tuple[str, float]]:
    """(label, radius) of the sizes a type's probes take: the smallest, the largest and the mass-weighted mean —
    or its one radius."""
    if not b.sizes:
        return [("", b.radius)]
    radii = [r for r, _ in b.sizes]
    return [("smallest", min(radii)), ("largest", max(radii)), ("mass-weighted", b.radius)]


def _group(cmd: Command, setup: Setup) -> None:
    w = cmd.words
    values = set()
    for word in w[3:]:
        lo, _, hi = word.partition(":")
        if to_number(lo) is None or (hi and to_number(hi) is None):
            return  # a group by a formula or a region: not read (velocity on it reads no atom)
        values.update(range(int(float(lo)), int(float(hi or lo)) + 1))
    setup.groups[w[1]] = ("type", values) if w[2] == "type" else values


def _group_atoms(setup: Setup, group: str) -> list:
    if group == "all":
        return list(setup.atoms)
    g = setup.groups.get(group)
    if isinstance(g, tuple):
        return [a for a, rec in setup.atoms.items() if rec[0] in g[1]]
    return [a for a in (g or ()) if a in setup.atoms]


def _gravity(cmd: Command, setup: Setup) -> None:
    """fix ID group gravity MAG vector x y z | spherical φ θ | chute angle: the magnitude and the axis bodies fall
    along (the vector's largest component; z — y in 2-D — for spherical and chute)."""
    w = cmd.words
    if cmd.problem:
        setup.not_audited.append((cmd.where(), cmd.text, f"fix gravity: {cmd.problem}"))
        return
    g = abs(_num(cmd, 4, "gravity magnitude"))
    axis = 1 if setup.dimension == 2 else 2
    if w[5:6] == ["vector"] and len(w) >= 9:
        v = [abs(_num(cmd, 6 + k, "gravity vector")) for k in range(3)]
        axis = max(range(3), key=lambda k: v[k])
    setup.gravity = (g, axis, cmd.where())


def _set(cmd: Command, setup: Setup) -> None:
    """set type T | group G | atom N … diameter/density/mass/vx/vy/vz: per type (a group by type, an atom by its
    type where the deck placed it; the sizes of a type set atom by atom are all probed)."""
    w = cmd.words
    kind, target = w[1], w[2]
    atoms = []
    if kind == "type":
        types = type_range(target, setup.ntypes, cmd)
        if any(x in w for x in ("diameter", "density", "mass")):
            setup.populated.update(types)  # a type the deck sizes is one it means to have bodies of
    elif kind == "atom":
        ids = type_range(target, max(len(setup.atoms), 1), cmd) if setup.atoms else []
        atoms = [a for a in ids if a in setup.atoms]
        types = sorted({setup.atoms[a][0] for a in atoms})
        if not types:
            setup.not_audited.append((cmd.where(), cmd.text, "set atom: the deck places no such atom where the "
                                                              "audit can see it (create_atoms single, read_data)"))
            return
    else:
        g = setup.groups.get(target)
        if target == "all":
            types = sorted(setup.populated) or sorted(setup.bodies) or list(range(1, setup.ntypes + 1))
            atoms = list(setup.atoms)
        elif isinstance(g, tuple):
            types = sorted(g[1])
        elif g:
            atoms = [a for a in g if a in setup.atoms]
            types = sorted({setup.atoms[a][0] for a in atoms})
        else:
            setup.not_audited.append((cmd.where(), cmd.text, f"set group {target}: a group the audit cannot resolve "
                                                              "to types (by a region or a formula)"))
            return
    k = 3
    while k + 1 < len(w):
        key = w[k]
        if key in ("type", "type/fraction", "type/ratio", "type/subset") and to_number(w[k + 1]) is not None:
            t = int(float(w[k + 1]))
            setup.populated.add(t)
            for a in atoms:
                setup.atoms[a][0] = t
            source = [setup.bodies.get(x) for x in types]
            if setup.created & set(types):
                setup.created.add(t)  # the moved atoms keep create_atoms's defaults
            new = body(setup, t)
            for b in source:  # the moved atoms keep what was set on them
                if b is not None and b is not new:
                    new.radius = new.radius if new.radius is not None else b.radius
                    new.density = new.density if new.density is not None else b.density
            if key == "type" and kind == "atom":
                types = [t]
            k += 2 if key == "type" else 4 if key == "type/fraction" else 4
            continue
        if key in ("diameter", "density", "mass"):
            x = _num(cmd, k + 1, key)
            if not x > 0:
                raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {key} must be > 0")
            for t in types:
                b = body(setup, t)
                if key == "diameter":
                    if kind == "atom" and b.radius is not None and b.radius != x / 2:
                        b.sizes = b.sizes or [(b.radius, 1.0)]
                        b.sizes.append((x / 2, 1.0))
                        b.size_from = "set atom"
                    b.radius = x / 2
                elif key == "density":
                    b.density = x
                else:
                    b.mass = x
        elif key in ("vx", "vy", "vz"):
            x = _num(cmd, k + 1, key)
            for a in atoms:
                v = setup.atoms[a][2] or [0.0, 0.0, 0.0]
                v["xyz".index(key[1])] = x
                setup.atoms[a][2] = v
            setup.speeds.append((abs(x), cmd.where()))
        k += 2


def pour(cmd: Command, setup: Setup) -> None:
    """fix ID group pour N type seed … (LAMMPS): the type, its diameters (diam one D | range lo hi | poly N d p …,
    number fractions; a range is probed through SIZE_STEPS diameters), density (dens lo hi: the mean), the
    insertion region and initial velocity (vel … vz) — what the characteristic speed and the sizes need."""
    w = cmd.words
    t = int(_num(cmd, 5, "pour type"))
    if "mol" in w:
        _pour_molecule(cmd, setup, w[w.index("mol") + 1] if w.index("mol") + 1 < len(w) else "", t)
        region = w[w.index("region") + 1] if "region" in w and w.index("region") + 1 < len(w) else None
        setup.insertions.append((region, [0.0, 0.0, 0.0], [], cmd.where()))
        return
    b = body(setup, t)
    setup.populated.add(t)
    diams, dens, vel, region = [(1.0, 1.0)], (1.0, 1.0), [0.0, 0.0, 0.0], None
    k = 7
    while k < len(w):
        key = w[k]
        if key == "diam" and w[k + 1:k + 2] == ["one"]:
            diams, k = [(_num(cmd, k + 2, "diam one"), 1.0)], k + 3
        elif key == "diam" and w[k + 1:k + 2] == ["range"]:
            diams = _uniform(_num(cmd, k + 2, "diam lo"), _num(cmd, k + 3, "diam hi"))
            k += 4
        elif key == "diam" and w[k + 1:k + 2] == ["poly"]:
            n = int(_num(cmd, k + 2, "diam poly N"))
            diams = [(_num(cmd, k + 3 + 2 * i, "diam"), _num(cmd, k + 4 + 2 * i, "fraction")) for i in range(n)]
            k += 3 + 2 * n
        elif key == "diam" and to_number(w[k + 1] if k + 1 < len(w) else "") is not None:  # old: diam lo hi
            diams = _uniform(_num(cmd, k + 1, "diam lo"), _num(cmd, k + 2, "diam hi"))
            k += 3
        elif key == "dens":
            dens, k = (_num(cmd, k + 1, "dens lo"), _num(cmd, k + 2, "dens hi")), k + 3
        elif key == "vel":
            n = 3 if setup.dimension == 2 else 5
            vals = [_num(cmd, k + 1 + i, "vel") for i in range(n)]
            vel = [max(abs(vals[0]), abs(vals[1])), 0.0, vals[-1]] if n == 5 else [max(abs(vals[0]), abs(vals[1])), vals[2], 0.0]
            k += 1 + n
        elif key == "region":
            region, k = w[k + 1], k + 2
        else:
            k += 1
    rho = 0.5 * (dens[0] + dens[1])
    if any(not (d > 0) for d, _ in diams) or not rho > 0:
        raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: diameters and densities must be > 0")
    b.sizes = [(d / 2, p * rho * d ** 3) for d, p in diams]  # number fraction → mass fraction
    b.size_from = f"fix {w[1]} pour ({cmd.where()})"
    b.radius = b.radius or diams[0][0] / 2
    b.density = rho
    setup.insertions.append((region, vel, [t], cmd.where()))


def _uniform(lo: float, hi: float) -> list[tuple[float, float]]:
    """A uniform number distribution of diameters on [lo, hi]: its ends (weight 0: the extremes probed) and the
    midpoints of SIZE_STEPS equal parts (the midpoint rule for the mass-weighted mean, error ~ 1/SIZE_STEPS²)."""
    mids = [(lo + (hi - lo) * (i + 0.5) / SIZE_STEPS, 1.0) for i in range(SIZE_STEPS)]
    return [(lo, 0.0), *mids, (hi, 0.0)]


def _pour_molecule(cmd: Command, setup: Setup, mol: str, offset: int) -> None:
    """fix pour … mol ID: the molecule file's spheres (Types + offset, Diameters, Masses) sized per type; a rigid
    cluster's spheres are probed as single spheres (said in the report)."""
    path = setup.molecules.get(mol)
    if path is None:
        setup.not_audited.append((cmd.where(), cmd.text, f"fix pour mol {mol}: its molecule file is not read"))
        return
    sections: dict = {}
    current = None
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines()[:100_000]:
        text = line.split("#", 1)[0].strip()
        if text in ("Coords", "Types", "Diameters", "Masses", "Charges", "Bonds", "Special Bond Counts"):
            current = sections.setdefault(text, {})
        elif text and current is not None:
            parts = text.split()
            if to_number(parts[0]) is not None and len(parts) >= 2:
                current[int(float(parts[0]))] = parts[1]
    for atom, kind in sections.get("Types", {}).items():
        t = int(float(kind)) + offset
        d, m = (to_number(sections.get(k, {}).get(atom, "")) for k in ("Diameters", "Masses"))
        b = body(setup, t)
        setup.populated.add(t)
        if d and d > 0:
            b.radius = d / 2
        if m and m > 0 and b.density is None:
            b.mass = m
        b.size_from = f"molecule {mol} (its spheres probed as single spheres; the rigid cluster is not)"
    setup.not_audited.append((cmd.where(), cmd.text, f"fix pour of molecule {mol}: rigid clusters of spheres; each "
                                                      "sphere's contacts are probed as a single sphere's"))


def approach_speed(setup: Setup) -> tuple[float, str] | None:
    """The largest relative normal approach speed of two placed bodies (−Δv·Δx/|Δx| > 0), at most 300 bodies."""
    placed = [(a, x, v or [0.0, 0.0, 0.0]) for a, (_, x, v) in setup.atoms.items() if x is not None]
    if not 2 <= len(placed) <= 300:
        return None
    best = None
    for i in range(len(placed)):
        for j in range(i + 1, len(placed)):
            (a, xa, va), (b, xb, vb) = placed[i], placed[j]
            dx = [xb[k] - xa[k] for k in range(3)]
            d = math.sqrt(sum(x * x for x in dx))
            if d == 0:
                continue
            vn = -sum((vb[k] - va[k]) * dx[k] for k in range(3)) / d
            if vn > 0 and (best is None or vn > best[0]):
                best = (vn, f"the relative normal approach speed of atoms {a} and {b}")
    return best


def growth_speed(setup: Setup, script: Script) -> tuple[float, str] | None:
    """Bodies that meet by growing (fix adapt … atom diameter v_NAME, NAME an atom-style formula of a
    property/atom radius or diameter compute): the rate two touching spheres of the largest radius close,
    2·ΔR/(N·dt), ΔR the growth one application gives that radius — evaluated by the reader's own evaluator."""
    radii = [r for b in setup.bodies.values() for r in [b.radius, *(x for x, _ in b.sizes)] if r]
    best = None
    for every, name, where in setup.growth:
        formula = script.atom_formulas.get(name)
        if formula is None or not radii or not every > 0 or not setup.dt:
            continue
        r = max(radii)
        text = formula
        for cid, kind in script.radius_computes.items():
            text = re.sub(rf"\bc_{re.escape(cid)}\b", f"({r!r})" if kind == "radius" else f"({2 * r!r})", text)
        try:
            grown = evaluate(text, script.variables) / 2.0
        except _Unevaluable:
            continue
        dr = grown - r
        if dr > 0 and (best is None or dr > best[0]):
            v = 2.0 * dr / (every * setup.dt)
            best = (dr, (v, f"growing bodies ({where}): every {every:g} steps the diameter of the largest "
                            f"(radius {r:g}) grows by {2 * dr:.4g}, so two touching ones close at 2ΔR/(N·dt) = "
                            f"{v:.4g} on average (the growth comes in jumps)"))
    return best[1] if best else None


def read_common(cmd: Command, setup: Setup, root: Path) -> bool:
    """The commands both engines share that define bodies, their speeds and the step; True when read."""
    w, name = cmd.words, cmd.name
    if name == "units":
        style = w[1] if len(w) > 1 else "(none)"
        if style not in UNITS:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: units {style}: not a unit style "
                              f"({', '.join(UNITS)})")
        setup.units, setup.units_where = style, cmd.where()  # metal and real: converted after the read (to_si)
        setup.units_text = cmd.text
        return True
    if name == "dimension":
        setup.dimension = int(_num(cmd, 1, "dimension"))
        if setup.dimension not in (2, 3):
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: dimension must be 2 or 3")
        return True
    if name == "group" and len(w) >= 4 and w[2] in ("id", "type"):
        _group(cmd, setup)
        return True
    if name == "fix" and len(w) >= 5 and w[3] == "gravity":
        _gravity(cmd, setup)
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
        setup.populated.add(t)
        setup.created.add(t)
        if w[2:3] == ["single"] and len(w) >= 6:
            setup.atoms[len(setup.atoms) + 1] = [t, [_num(cmd, 3 + k, "position") for k in range(3)], None]
        return True
    if name == "set" and len(w) >= 5 and w[1] in ("type", "group", "atom"):
        _set(cmd, setup)
        return True
    if name == "velocity" and len(w) >= 6 and w[2] == "set":
        v = [0.0 if x == "NULL" else _num(cmd, 3 + i, "velocity") for i, x in enumerate(w[3:6])]
        ids = _group_atoms(setup, w[1])
        for a in ids:
            setup.atoms[a][2] = v
        setup.speeds.append((math.sqrt(sum(x * x for x in v)), cmd.where()))
        return True
    if name == "read_data":
        _read_data(cmd, setup, root)
        return True
    if name == "molecule" and len(w) >= 3:
        path = (root / w[2]).resolve()
        if path.is_relative_to(root) and path.is_file():
            setup.molecules[w[1]] = path
        return True
    if name == "fix" and len(w) >= 8 and w[3] == "adapt" and w[5:7] == ["atom", "diameter"] and w[7].startswith("v_"):
        setup.growth.append((_num(cmd, 4, "adapt every N"), w[7][2:], cmd.where()))
        return True
    if name == "fix" and len(w) >= 6 and w[3] == "pour":
        if cmd.problem:
            raise ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {cmd.problem}")
        pour(cmd, setup)
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
        nums = [to_number(x) for x in words if not x.isalpha()]
        if None in nums:
            raise ScriptError(f"{where}: {line[:60]!r}: not a number")
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
            t = int(nums[1])
            b = body(setup, t)
            if not (nums[2] > 0 and nums[3] > 0):
                raise ScriptError(f"{where}: {line[:60]!r}: diameter and density must be > 0")
            b.radius, b.density = nums[2] / 2, nums[3]
            b.sizes.append((nums[2] / 2, nums[3] * nums[2] ** 3))
            b.size_from = f"read_data {cmd.words[1]}"
            setup.populated.add(t)
            if len(setup.atoms) < 100_000:
                setup.atoms[int(nums[0])] = [t, nums[4:7], None]
        elif section == "Velocities" and len(nums) >= 4:
            setup.speeds.append((math.sqrt(sum(x * x for x in nums[1:4])), where))
            if int(nums[0]) in setup.atoms:
                setup.atoms[int(nums[0])][2] = nums[1:4]
