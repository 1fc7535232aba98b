"""What both deck writers share: the scene (types, box, wall, run length) and the dump."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..case import Case, run_length
from ..errors import DemcheckError, UnsupportedByEngine
from ..laws.model import ResolvedModel, resolve

DUMP_FILE = "dump.txt"  # a collision deck's output of the bodies' states (each engine writes it in its own way)


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


def float_literal(x: float) -> str:
    """A number for a deck that is a Python script or JSON (Yade, Kratos), where an integer and a float differ:
    repr of the double (``2500.0``, ``0.00318``), which reads back as the same double; a non-finite number is
    refused (it is no literal)."""
    x = float(x)
    if not math.isfinite(x):
        raise DemcheckError(f"refusing to write the number {x!r} into an engine's script")
    return repr(x)


def fmt(x: float) -> str:
    """A number as a person writes it in a deck: the shortest text that reads back as the same double (repr:
    ``0.24``, not ``0.23999999999999999``), integers without a decimal point."""
    x = float(x)
    if x.is_integer() and abs(x) < 1e16:
        return str(int(x))
    return repr(x)


def scene(case: Case, dt: float | None = None, length: float = 1.0) -> Scene:
    """The two-body scene of a collision case: dt (the case's, or auto), the number of steps (free flight to
    contact plus ``length`` × 6 elastic contact times), a box that holds both bodies for the whole run."""
    if case.kind != "collision":
        raise UnsupportedByEngine(f"case '{case.name}' is a {case.kind}; decks are written for collisions here")
    model = resolve(case)
    dt, t_end, steps = run_length(case, dt, length, model)
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


def header(engine: str, sc: Scene, mp, version_note: str, hand_command: str) -> list[str]:
    """A collision deck's opening comments: what it is, the case, the model, the mapping (an
    engines.base.Mapping) and its reasons, the step, and how to run it by hand (``hand_command <deck>``)."""
    case = sc.case
    lines = [comment(f"demcheck deck for {engine} ({version_note})"),
             comment(f"case: {case.name} (hash {case.hash})"),
             comment(f"model: normal = {case.contact.normal}, tangential = {case.contact.tangential}, "
                     f"limit_force = {str(case.contact.limit_force).lower()}"),
             comment(f"mapping fidelity: {mp.fidelity}")]
    lines += notes(mp.reasons)
    lines.append(comment(f"dt = {fmt(sc.dt)} s, {sc.steps} steps; dump: {DUMP_FILE} (every step, %.17g)"))
    lines.append(comment(f"run by hand: {hand_command} <this file>"))
    return lines


# ----------------------------------------------------------------------------- free text and the final guard
#
# Both engines read a deck line by line (split at "\n" only): a line that starts with "#" is a comment, but a
# line whose last printable character is "&" continues onto the next (a comment too), and LAMMPS's triple
# quotes span lines. Free text (a case's name, a mapping's reasons and comments) reaches a deck only through
# comment(); check_deck() is run on every deck and data file demcheck writes.


def comment(text: str) -> str:
    """``text`` as one comment line: characters that are not printable (line breaks of any kind, control and
    format characters) escaped, every double quote escaped, and no "&" at the end."""
    out = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)
    out = out.replace('"', '\\"')  # no run of quotes can open a triple-quoted string
    if out.rstrip().endswith("&"):
        out = out.rstrip()[:-1] + "\\x26"
    return f"# {out}"


def notes(texts) -> list[str]:
    """Indented comment lines (a mapping's reasons, a native configuration's comments)."""
    return [comment(f"  {t}") for t in texts]


# every command demcheck writes, and of those that take a style the word's position and the styles it writes
COMMANDS = frozenset({
    "units", "atom_style", "atom_modify", "boundary", "newton", "comm_modify", "communicate", "processors", "region",
    "create_box", "create_atoms", "set", "read_data", "neighbor", "neigh_modify", "pair_style", "pair_coeff", "fix",
    "compute", "timestep", "dump", "dump_modify", "undump", "write_dump", "thermo_style", "thermo_modify", "thermo",
    "run", "hard_particles", "soft_particles", "group"})
STYLES = {"fix": (3, frozenset({"property/global", "wall/gran", "gravity", "nve/sphere", "move", "heat/flow",
                                "heat/gran/conduction",
                                "property/atom"})),
          "compute": (3, frozenset({"pair/local", "property/local", "pair/gran/local", "property/atom"})),
          "group": (2, frozenset({"id"})),
          "dump": (3, frozenset({"custom", "local"})), "pair_style": (1, frozenset({"granular", "gran"})),
          "atom_style": (1, frozenset({"sphere", "granular"})), "region": (2, frozenset({"block"})),
          "thermo_style": (1, frozenset({"custom"})), "write_dump": (2, frozenset({"custom"}))}
# the file a command reads or writes: a plain name in the work directory (no path, no option-looking word)
FILE_ARGUMENT = {"dump": 5, "write_dump": 3, "read_data": 1}
SAFE_FILE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")
DATA_WORDS = frozenset({"atoms", "atom", "types", "xlo", "xhi", "ylo", "yhi", "zlo", "zhi", "Atoms", "Velocities"})


def _refuse(what: str, n: int, line: str, why: str):
    raise DemcheckError(f"refusing to write {what}: line {n} {why}: {line[:80]!r}")


def _check_text(text: str, what: str) -> list[str]:
    lines = text.split("\n")
    for n, line in enumerate(lines, 1):
        if not line.isprintable():
            _refuse(what, n, line, "has a character that is not printable")
        if line.rstrip().endswith("&"):
            _refuse(what, n, line, "would continue onto the next line")
        if '"""' in line:
            _refuse(what, n, line, "has triple quotes")
    return lines


def check_deck(text: str, files: dict | None = None) -> None:
    """The final guard on a deck (and its data files): every line is a comment, blank, or one of the commands
    demcheck writes (``run N`` a plain step count, no variable substitution, no comment after a command, files
    by plain names in the work directory); anything else raises."""
    for n, line in enumerate(_check_text(text, "a deck"), 1):
        words = line.split()
        if not words or words[0].startswith("#"):  # a comment is a whole line: "#" inside quotes is not one
            continue
        command = words[0]
        if command not in COMMANDS:
            _refuse("a deck", n, line, "is not a command demcheck writes")
        if "#" in line:
            _refuse("a deck", n, line, "has a comment after a command (demcheck writes comments as lines)")
        if "$" in line:
            _refuse("a deck", n, line, "substitutes a variable")
        at = FILE_ARGUMENT.get(command)
        if at is not None and (len(words) <= at or not SAFE_FILE.fullmatch(words[at])):
            _refuse("a deck", n, line, "names a file that is not a plain name in the work directory")
        at, styles = STYLES.get(command, (0, None))
        if styles is not None and (len(words) <= at or words[at] not in styles):
            _refuse("a deck", n, line, f"is not a {command} style demcheck writes")
        if command == "run" and (len(words) != 2 or not words[1].isdigit()):
            _refuse("a deck", n, line, "is not a plain run N")
    for name, data in (files or {}).items():
        check_data(data, name)


def check_data(text: str, name: str = "data file") -> None:
    """A data file: a one-line title (a comment), then header lines (whole-line comments among them, which
    read_data skips), section names and numbers only."""
    header = True
    for n, line in enumerate(_check_text(text, name), 1):
        if n == 1:
            if not line.startswith("#"):
                _refuse(name, n, line, "is not a comment title")
            continue
        if header and line.startswith("#"):
            continue
        if line.strip() in ("Atoms", "Velocities"):
            header = False
        for word in line.split():
            if word not in DATA_WORDS:
                try:
                    float(word)
                except ValueError:
                    _refuse(name, n, line, "is not a number, a header or a section name")


@dataclass
class Deck:
    """An input deck and the files it reads (written beside it)."""

    engine: str
    text: str
    files: dict
    dt: float | None = None  # the time step the deck runs at (s): carried as a number, never parsed back
    check: object = field(default=None, repr=False, compare=False)  # the engine's guard (default: check_deck)

    def __post_init__(self):
        self.check = self.check or check_deck
        self.check(self.text, self.files)

    def write(self, path) -> list:
        from pathlib import Path

        from ..io import write_text

        self.check(self.text, self.files)
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
    lines = [comment(title), "", f"{n * copies} atoms", f"{ntypes} atom types", "",
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
