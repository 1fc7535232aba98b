"""What every engine's deck writer shares: the scene (types, box, wall, run length), the numbers' and comments'
text, the deck and its files (the input languages and their guards are the engines': engines/family_deck.py for
LAMMPS and LIGGGHTS)."""

from __future__ import annotations

import math
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


# ----------------------------------------------------------------------------- free text and the deck
#
# Free text (a case's name, a mapping's reasons and comments) reaches a deck only through comment(), whose line
# is a comment in every engine's language: in the LAMMPS family's, a line whose last printable character is "&"
# continues onto the next and triple quotes span lines, so neither is written. Each engine's own guard
# (Deck.check: engines/family_deck.py for the LAMMPS family) is run on every deck and data file demcheck writes.


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


@dataclass
class Deck:
    """An input deck and the files it reads (written beside it)."""

    engine: str
    text: str
    files: dict
    dt: float | None = None  # the time step the deck runs at (s): carried as a number, never parsed back
    # the engine's guard, check(text, files), which raises on a line demcheck does not write: each engine's own (the
    # LAMMPS family's engines/family_deck.check_deck, Yade's and Kratos' their scripts'); there is no default
    check: object = field(kw_only=True, repr=False, compare=False)

    def __post_init__(self):
        if not callable(self.check):
            raise DemcheckError(f"a {self.engine} deck needs its engine's guard (check=), got {self.check!r}")
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
