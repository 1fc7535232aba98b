"""The LAMMPS input language as LAMMPS and LIGGGHTS both read it (their decks' guard), and the data file both read:
a deck is code the engine executes, so :func:`check_deck` lets through only the lines demcheck writes (every deck and
data file of the family's writers passes it, as ``Deck(check=check_deck)``, and engines/run.py runs it again before a
run). A line is split at "\n" only: a line that starts with "#" is a comment, but a line whose last printable
character is "&" continues onto the next (a comment too), and triple quotes span lines."""

from __future__ import annotations

import re

import numpy as np

from ..case import Case
from ..errors import DemcheckError
from ..inputs.common import Scene, comment, fmt

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
