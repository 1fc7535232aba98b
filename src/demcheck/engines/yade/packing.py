"""Yade packing scripts: the same initial state, laws, floor, gravity, periodic box, dt and steps as the other
engines' packing decks (inputs/packing_decks' layout), as a Python script from one fixed template with only
numbers substituted, checked before every run by :func:`check_script` (the collision guard's rules with this
template's allow-lists).

What the script does, and why:

* **Materials per species.** Yade combines each body's material values into a pair's in series, 1/(1/a + 1/b)
  (ViscElMat kn, cn, ks, cs; FrictMat's effective modulus), and takes the smaller friction angle. Each species
  gets a material carrying twice its like pair's values (exact for like pairs); a pair of two species gets the
  series combination, compared with the case's value (approximate, with the largest difference named, where
  they differ). A floor takes the material that makes each species' wall values the case's: one floor body per
  group of species that share it, masked so that a species touches only its own (Body.mask).
* **The floor.** A ``Wall`` (Ig2_Wall_Sphere_ScGeom, as the collision scripts) where the box is not periodic.
  In Yade's periodic cell a Wall hangs 2023.02a's InsertionSortCollider (its bound is infinite in x and y:
  measured, the run never returns), so a periodic floor is a fixed ``Box`` whose top face is the wall's plane,
  a thousand box widths wide (Ig2_Box_Sphere_ScGeom: the same overlap and normal on its face; its contact point
  is midway into the overlap, arm R − δ/2, where a Wall's is on the plane, R − δ).
* **The periodic cell.** Yade's cell is periodic in x, y and z: x and y are the case's box, z a period twice
  the height of the box and the floor (nothing reaches across it). ``allowBiggerThanPeriod`` lets the floor span
  the cell; ``sortAxis=2`` makes the collider's first search walk z, where the floor's bound is its own (along x
  a box far wider than the cell wraps to an arbitrary arc, and the spheres it misses fall through it).
* **Masses** are the case's (state.mass set, inertia 0.4 m r²), not Yade's from a density.
* **Leap-frog.** Yade's NewtonIntegrator (damping 0) keeps v_{k−½}; the script starts from v_{−½} = v0 − ½dt g,
  so that velocity Verlet's v0 (no contact at t = 0: the layouts start apart) is the full-step velocity at
  step 0, and writes full-step velocities v_k = v_{k−½} + ½dt (F_k/m + g), as the LAMMPS-family engines do.
* **Output.** The translational kinetic energy at the same steps as the other decks' thermo (printed as
  ``step ke atoms`` lines, which engines/packing.run_engine reads from the log), then FINAL_DUMP (every
  particle at step N: x_N, v_N, ω_N and F_N + m g, positions wrapped into the periodic box, float64 %.17g,
  LAMMPS ``dump custom`` layout) and CONTACT_DUMP (every particle pair Yade holds at step N: the two ids,
  penetrationDepth, the normal force vector, the shear force vector and the contact normal), both in the ``dump
  custom`` / ``dump local`` text layout (one parser, engines/dumps.py, for every file in it; ``demcheck pack``'s
  ``universe`` opens FINAL_DUMP as a LAMMPS dump), read by :func:`read` into the packing's record
  (engines.output.PackingOutput).
"""

from __future__ import annotations

import ast
import math
import re
from pathlib import Path

import numpy as np

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common, packing_decks as PD
from ...inputs.common import fmt
from ..base import Engine
from ..mapping import pair_mapping
from .deck import VERSION_NOTE, ascii_comment, guard
from .mapping import MINDLIN, VISCEL

MARKER = "# demcheck: a Yade packing script (Python), generated from a fixed template"
KE = "%d %.17g %d"  # a kinetic energy line: step, ke, atoms (the LAMMPS-family decks' thermo columns)
_KE_LINE = re.compile(r"^(\d+) (\S+) \d+$", re.M)
BOX = {True: "pp pp ff", False: "ff ff ff"}
_BOUNDS = "ITEM: BOX BOUNDS {}\n%.17g %.17g\n%.17g %.17g\n%.17g %.17g\n"
FINAL_HEAD = {p: "ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\n" + _BOUNDS.format(BOX[p]) + "ITEM: ATOMS "
              + " ".join(PD.FINAL_COLUMNS) + "\n" for p in (True, False)}
FINAL_ROW = "%d %d" + " %.17g" * (len(PD.FINAL_COLUMNS) - 2) + "\n"
CONTACT_COLUMNS = ("id1", "id2", "overlap", "fnx", "fny", "fnz", "fsx", "fsy", "fsz", "nx", "ny", "nz")
CONTACT_HEAD = {p: "ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ENTRIES\n%d\n" + _BOUNDS.format(BOX[p]) + "ITEM: ENTRIES "
                + " ".join(CONTACT_COLUMNS) + "\n" for p in (True, False)}
CONTACT_ROW = "%d %d" + " %.17g" * (len(CONTACT_COLUMNS) - 2) + "\n"
STRINGS = frozenset({KE, FINAL_ROW, CONTACT_ROW, *FINAL_HEAD.values(), *CONTACT_HEAD.values(), PD.FINAL_DUMP,
                     PD.CONTACT_DUMP, "w"})
NAMES = frozenset({
    "O", "Vector3", "utils", "FrictMat", "ViscElMat", "ForceResetter", "InsertionSortCollider", "Bo1_Sphere_Aabb",
    "Bo1_Wall_Aabb", "Bo1_Box_Aabb", "InteractionLoop", "Ig2_Sphere_Sphere_ScGeom", "Ig2_Wall_Sphere_ScGeom",
    "Ig2_Box_Sphere_ScGeom", "Ip2_FrictMat_FrictMat_MindlinPhys", "Law2_ScGeom_MindlinPhys_Mindlin",
    "Ip2_ViscElMat_ViscElMat_ViscElPhys", "Law2_ScGeom_ViscElPhys_Basic", "NewtonIntegrator", "open", "range",
    "len", "print",
    # the template's own variables
    "DT", "STEPS", "G", "SAMPLES", "P", "MASK", "N", "LX", "LY", "done", "s", "p", "b", "i", "x", "v", "w", "e",
    "a", "f", "t", "q", "c", "rows", "out"})
KEYWORDS = frozenset({"allowBiggerThanPeriod", "axis", "betan", "cn", "cs", "damping", "density", "fixed",
                      "frictionAngle", "gravity", "kn", "ks", "mask", "material", "poisson", "sense", "sortAxis",
                      "young"})
ATTRIBUTES = frozenset({"periodic", "cell", "setBox", "materials", "bodies", "append", "sphere", "wall", "box",
                        "state", "mass", "inertia", "pos", "vel", "angVel", "engines", "dt", "run", "step", "forces",
                        "f", "t", "dot", "write", "close", "interactions", "isReal", "id1", "id2", "geom", "phys",
                        "penetrationDepth", "normalForce", "shearForce", "normal", "shape", "radius"})
NODES = (ast.Module, ast.Expr, ast.Assign, ast.Call, ast.Name, ast.Load, ast.Store, ast.Attribute, ast.Constant,
         ast.Tuple, ast.List, ast.keyword, ast.For, ast.If, ast.Compare, ast.Lt, ast.Gt, ast.BoolOp, ast.And,
         ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.FloorDiv, ast.Mod, ast.UnaryOp, ast.USub, ast.Subscript,
         ast.ImportFrom, ast.alias, ast.ListComp, ast.comprehension)
REL = 1e-12  # a pair value the series combination gives within this (relative) is the case's, to round-off
MAX_GROUPS = 30  # floor groups have a mask bit each (Yade's masks are ints)
_num = common.float_literal


def check_script(text: str, files: dict | None = None) -> None:
    """The final guard before Yade runs a packing script: the collision guard's rules (parses; only the
    template's names, attributes, keywords, strings, finite numbers and True; no encoding declaration; no files) with
    the packing template's allow-lists. Raises DemcheckError otherwise."""
    guard(text, files, NAMES, ATTRIBUTES, KEYWORDS, STRINGS, NODES, flags=True)


def is_packing_script(text: str) -> bool:
    """Whether a script opens as the packing template does (then :func:`check_script` guards it)."""
    return text.split("\n", 1)[0] == MARKER


# ----------------------------------------------------------------------------- the materials


def combine(a: float, b: float) -> float:
    """Yade's combination of two materials' ViscElMat values (Ip2_ViscElMat_ViscElMat_ViscElPhys): in series,
    a zero value leaving the other's: 1/((1/a if a else 0) + (1/b if b else 0)), 0 when both are 0."""
    s = (1.0 / a if a else 0.0) + (1.0 / b if b else 0.0)
    return 1.0 / s if s else 0.0


def _wall_value(x: float, target: float, what: str) -> float:
    """The wall material's value w with combine(x, w) = target, for a species whose material carries x."""
    if target == 0.0:
        if x == 0.0:
            return 0.0
        raise UnsupportedByEngine(f"Yade cannot express this packing: the wall's {what} is 0 where the particle's "
                                  f"material carries {x:.6g} (Yade leaves the nonzero value of a pair)")
    if x == 0.0:
        return target
    if target >= x:
        raise UnsupportedByEngine(f"Yade cannot express this packing: its wall {what} {target:.10g} is not below the "
                                  f"particle material's {x:.10g} (twice the like pair's), and Yade combines the two "
                                  "in series (1/(1/a + 1/b)), which stays below either")
    return 1.0 / (1.0 / target - 1.0 / x)


class _Laws:
    """Per species a material (keyword arguments), per floor group one, each species' group, the material
    class, the Ip2 and Law2 calls, and the fidelity reasons of the combination."""

    def __init__(self):
        self.species: list[dict] = []
        self.groups: list[dict] = []
        self.group_of: list[int] = []
        self.reasons: list[str] = []
        self.cls = ""
        self.phys = ""
        self.law = ""


def _group(laws: _Laws, wall: dict) -> None:
    """Put a species in the floor group whose material is ``wall`` (a new group when none is)."""
    for g, w in enumerate(laws.groups):
        if w == wall:
            laws.group_of.append(g)
            return
    laws.groups.append(wall)
    laws.group_of.append(len(laws.groups) - 1)


def _cross(laws: _Laws, what: str, got: float, want: float, a: int, b: int) -> None:
    """A pair of two species: Yade's series combination against the case's value."""
    if got == want or (want != 0.0 and abs(got - want) <= REL * abs(want)):
        return
    if want == 0.0 or got == 0.0:
        raise UnsupportedByEngine(f"Yade cannot express this packing: species {a + 1} with {b + 1} has {what} = "
                                  f"{want:.6g}, and Yade's combination of the species' materials gives {got:.6g}")
    laws.reasons.append(f"Yade combines the species' materials in series: species {a + 1} with {b + 1} gets {what} = "
                        f"{got:.10g}, the case's is {want:.10g} ({(got / want - 1.0) * 100:+.3g} %)")


def _viscel(pairs, walls, ns) -> _Laws:
    laws = _Laws()
    laws.cls, laws.phys, laws.law = "ViscElMat", "Ip2_ViscElMat_ViscElMat_ViscElPhys()", "Law2_ScGeom_ViscElPhys_Basic()"
    keys = ("kn", "cn", "ks", "cs")
    for a in range(ns):
        p = pairs[(a, a)].native.props
        laws.species.append({**{k: 2.0 * p[k] for k in keys}, "frictionAngle": math.atan(p.get("mu", 0.0))})
    for (a, b), mp in pairs.items():
        if a == b:
            continue
        p = mp.native.props
        for k in keys:
            _cross(laws, k, combine(laws.species[a][k], laws.species[b][k]), p[k], a, b)
        _cross(laws, "μ", math.tan(min(laws.species[a]["frictionAngle"], laws.species[b]["frictionAngle"])),
               p.get("mu", 0.0), a, b)
    for a, mp in enumerate(walls):
        p, mat = mp.native.props, laws.species[a]
        wall = {k: _wall_value(mat[k], p[k], k) for k in keys}
        wall["frictionAngle"] = _wall_friction(mat["frictionAngle"], p.get("mu", 0.0))
        _group(laws, wall)
    return laws


def _wall_friction(phi: float, mu: float) -> float:
    """The wall material's friction angle giving tan(min(φ_particle, φ_wall)) = μ on the wall."""
    phi_w = math.atan(mu)
    if phi_w > phi:
        raise UnsupportedByEngine(f"Yade cannot express this packing: its wall friction μ = {mu:.6g} is above the "
                                  f"particles' own ({math.tan(phi):.6g}), and Yade takes the smaller friction angle")
    return phi_w


def _mindlin(pairs, walls, ns, rad) -> _Laws:
    """FrictMat per species with Poisson's ratio 0 (the shear stiffness is unused: no tangential law is mapped
    with Mindlin), Young's modulus E so that kno = (4/3)E*√R̄ with E* = E_a E_b/(E_a + E_b) and Yade's R̄:
    R_a R_b/(R_a + R_b) for a pair, R/2 on a wall (Ig2_Wall_Sphere_ScGeom and Ig2_Box_Sphere_ScGeom give the
    wall the sphere's radius)."""
    laws = _Laws()
    laws.cls, laws.law = "FrictMat", "Law2_ScGeom_MindlinPhys_Mindlin()"
    betas = {round(mp.native.props["betan"], 12) for mp in [*pairs.values(), *walls]}
    exact = {mp.native.props["betan"] for mp in [*pairs.values(), *walls]}
    if len(betas) > 1:
        raise UnsupportedByEngine("Yade cannot express this packing: Ip2_FrictMat_FrictMat_MindlinPhys takes one "
                                  f"betan for every pair, and the case's pairs need {sorted(exact)}")
    betan = max(exact)
    laws.phys = (f"Ip2_FrictMat_FrictMat_MindlinPhys(betan={_num(betan)})" if betan > 0.0
                 else "Ip2_FrictMat_FrictMat_MindlinPhys()")

    def modulus(kno, r):  # the E* that gives kno at Yade's radius r
        return kno / (4.0 / 3.0 * math.sqrt(r))

    for a in range(ns):
        p = pairs[(a, a)].native.props
        laws.species.append({"young": 2.0 * modulus(p["kno"], rad[a] / 2.0), "poisson": 0.0,
                             "frictionAngle": math.atan(p.get("mu", 0.0))})
    for (a, b), mp in pairs.items():
        if a != b:
            r = rad[a] * rad[b] / (rad[a] + rad[b])
            got = 4.0 / 3.0 * combine(laws.species[a]["young"], laws.species[b]["young"]) * math.sqrt(r)
            _cross(laws, "kno", got, mp.native.props["kno"], a, b)
    for a, mp in enumerate(walls):
        p, mat = mp.native.props, laws.species[a]
        try:
            young = _wall_value(mat["young"], modulus(p["kno"], rad[a] / 2.0), "modulus")
        except UnsupportedByEngine:
            raise UnsupportedByEngine(
                f"Yade cannot express this packing: Yade's Mindlin gives a wall the sphere's radius (R̄ = R/2) and "
                f"combines the moduli in series, so the wall's kno is below twice the like pair's "
                f"({2 * pairs[(a, a)].native.props['kno']:.6g}); the case's is {p['kno']:.6g} N/m^1.5") from None
        _group(laws, {"young": young, "poisson": 0.0, "frictionAngle": _wall_friction(mat["frictionAngle"],
                                                                                      p.get("mu", 0.0))})
    return laws


def _material(laws: _Laws, values: dict) -> str:
    if laws.cls == "ViscElMat":
        args = ", ".join(f"{k}={_num(values[k])}" for k in ("kn", "cn", "ks", "cs", "frictionAngle"))
    else:
        args = ", ".join(f"{k}={_num(values[k])}" for k in ("young", "poisson", "frictionAngle"))
    return f"O.materials.append({laws.cls}({args}, density=1.0))"


# ----------------------------------------------------------------------------- the script


def _mappings(engine: Engine, case: Case, lay: PD.Layout):
    rep, ns = lay.rep, len(lay.table)
    pairs = {}
    for a in range(ns):
        for b in range(a, ns):
            mp = pair_mapping(case, engine, rep[a], rep[b])
            if mp.native is None:
                raise UnsupportedByEngine(f"yade cannot express this model: {'; '.join(mp.reasons)}")
            pairs[(a, b)] = mp
    walls = []
    if case.walls:
        walls = [pair_mapping(case, engine, r, None) for r in rep]
        for mp in walls:
            mp.require()
    kinds = {(mp.native.normal, mp.native.tangential) for mp in [*pairs.values(), *walls]}
    if len(kinds) > 1:
        raise UnsupportedByEngine(f"Yade runs one law for every pair; this packing maps its pairs to {sorted(kinds)}")
    return pairs, walls


def _floors(case: Case, lay: PD.Layout, laws: _Laws, friction: bool) -> tuple[list[str], list[str]]:
    """The floor bodies (one per wall and group) with the comments that say what they are, and the fidelity
    reason of a Box floor (its arm) where the contacts have friction."""
    periodic = bool(lay.periodic[0])
    masked = len(laws.groups) > 1
    lines, notes = [], []
    for k, w in enumerate(case.walls):
        ax, side = common.wall_axis(w, k)
        if periodic and ax != 2:
            raise UnsupportedByEngine(f"walls.{k}: a wall normal to a periodic axis ({'xyz'[ax]}) is not written for "
                                      "Yade's periodic cell")
        sense = 1 if side == "lo" else -1
        lines.append(common.comment(PD.wall_comment(w, k)
                                    + (", a fixed Box whose face is the plane (a Wall hangs Yade's periodic collider)"
                                       if periodic else ", a Wall")))
        for g in range(len(laws.groups)):
            mask = f", mask={2 << g}" if masked else ""
            mat = len(laws.species) + g
            if not periodic:
                lines.append(f"O.bodies.append(utils.wall({_num(w.point[ax])}, axis={ax}, sense={sense}, "
                             f"material={mat}{mask}))")
                continue
            half = _half_thickness(lay)
            wide = _wide(lay)
            centre = [0.5 * float(lay.hi[0]), 0.5 * float(lay.hi[1]), float(w.point[2]) - sense * half]
            lines += [f"b = O.bodies.append(utils.box({_vec(centre)}, {_vec([wide, wide, half])}, fixed=True, "
                      f"material={mat}{mask}))", "O.bodies[b].state.mass = 0.0"]
    if periodic and case.walls and friction:  # without friction the arm carries no force
        notes.append("the floor is a fixed Box (Ig2_Box_Sphere_ScGeom): its slip and torque arm is R − δ/2 (the "
                     "contact point midway into the overlap), a Wall's R − δ")
    return lines, notes


def _half_thickness(lay: PD.Layout) -> float:
    """A floor box's half thickness: the power of two at or above the largest radius (the overlap's rounding,
    z + h, then stays within an ulp of 2h)."""
    return 2.0 ** math.ceil(math.log2(float(lay.rad.max())))


def _wide(lay: PD.Layout) -> float:
    """A periodic floor's half width: a power of two above a thousand box widths (positions in Yade's cell are
    not wrapped: a particle can drift that far across the boundary before it leaves the floor)."""
    return 2.0 ** math.ceil(math.log2(1000.0 * float(max(lay.hi[0], lay.hi[1]))))


def _vec(xs) -> str:
    return f"Vector3({', '.join(_num(x) for x in xs)})"


def deck(engine: Engine, case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    lay = PD.layout(case, duration, dt)
    pairs, walls = _mappings(engine, case, lay)
    ns = len(lay.table)
    rad = [s.radius for s in lay.table]
    normal = next(iter(pairs.values())).native.normal
    if normal == VISCEL:
        laws = _viscel(pairs, walls, ns)
    elif normal == MINDLIN:
        laws = _mindlin(pairs, walls, ns, rad)
    else:
        raise UnsupportedByEngine(f"no Yade packing script for {normal}")
    if len(laws.groups) > MAX_GROUPS:
        raise UnsupportedByEngine(f"Yade packing scripts mask each floor group with a bit: {len(laws.groups)} groups "
                                  f"are more than {MAX_GROUPS}")
    periodic = bool(lay.periodic[0])
    friction = next(iter(pairs.values())).native.tangential != "none"
    floor_lines, floor_notes = _floors(case, lay, laws, friction)
    mappings = [*pairs.values(), *walls]
    fidelities = sorted({mp.fidelity for mp in mappings}
                        | ({"approximate"} if laws.reasons or floor_notes else set()))
    reasons = list(dict.fromkeys([*(r for mp in mappings for r in mp.reasons), *laws.reasons, *floor_notes]))
    g = np.asarray(case.run.gravity, float)
    every = max(1, lay.steps // 50)
    samples = [*range(0, lay.steps, every), lay.steps]
    lo, hi = [float(v) for v in lay.lo], [float(v) for v in lay.hi]
    bounds = [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]
    masked = len(laws.groups) > 1

    lines = [*_head(case, lay, ns, fidelities, reasons), "from yade import utils", "",
            common.comment(f"the run: dt (s), steps, gravity (m/s^2), the steps whose translational kinetic energy "
                           f"is printed (every {every} and the last)"),
            f"DT = {_num(lay.dt)}", f"STEPS = {int(lay.steps)}", f"G = {_vec(g)}",
            f"SAMPLES = [{', '.join(str(int(s)) for s in samples)}]"]
    if periodic:
        lines += _periodic_cell(case, lay, lo, hi)
    lines += _materials(laws, lay, pairs, walls, masked)
    lines += _bodies(case, lay, laws, g, masked)
    lines += floor_lines
    lines += _engines_and_samples(laws, periodic)
    lines += _outputs(periodic, bounds)
    # free text (the case's and materials' names, the mapping's words) reaches the script only in comments, each
    # an ASCII line (Yade reads a script in the locale's encoding when it is run by hand)
    text = "\n".join(ascii_comment(x) if x.startswith("#") else x for x in lines)
    return common.Deck("yade", text, {}, dt=lay.dt, check=check_script)


def _head(case: Case, lay, ns: int, fidelities: list, reasons: list) -> list[str]:
    """The script's header: what wrote it, the case, the mapping's fidelity and notes, how to run it."""
    return [MARKER, "# every value below is a number written by demcheck",
            common.comment(f"demcheck packing script for yade ({VERSION_NOTE})"),
            common.comment(f"case: {case.name} (hash {case.hash})"),
            common.comment(f"model: normal = {case.contact.normal}, tangential = {case.contact.tangential}, "
                           f"limit_force = {str(case.contact.limit_force).lower()}; mapping fidelity: "
                           f"{', '.join(fidelities)}"),
            *common.notes(reasons),
            common.comment(f"{len(case.particles)} particles of {ns} species; {lay.steps} steps of dt = {fmt(lay.dt)} s "
                           f"({fmt(lay.duration)} s); final state: {PD.FINAL_DUMP} (every particle), {PD.CONTACT_DUMP} "
                           "(every particle pair in contact)"),
            common.comment("run by hand: yade -x -n <this file> (it writes both files in the working directory and "
                           "prints 'step ke atoms' lines)")]


def _periodic_cell(case: Case, lay, lo: list, hi: list) -> list[str]:
    """Yade's periodic cell, x and y the case's box."""
    # Yade's cell is periodic in z too: twice the height from the lowest floor box to the top of the box
    half = _half_thickness(lay)
    zs = [float(w.point[2]) for w in case.walls]
    lz = 2.0 * (max([hi[2], *(z + 2.0 * half for z in zs)]) - min([lo[2], *(z - 2.0 * half for z in zs)]))
    return [common.comment("Yade's periodic cell (periodic in x, y and z): x and y the case's box, z twice the "
                           "height of the box and the floor, so nothing reaches across it"),
            "O.periodic = True", f"O.cell.setBox({_num(hi[0])}, {_num(hi[1])}, {_num(lz)})",
            f"LX = {_num(hi[0])}", f"LY = {_num(hi[1])}"]


def _materials(laws, lay, pairs: dict, walls: list, masked: bool) -> list[str]:
    """One Yade material per species, then the floors', and the laws of each pair as comments."""
    lines = [common.comment("material k: species k + 1 (it carries twice its like pair's values: Yade combines "
                            "two materials in series); after them the floor's"
                            + (" (one per group of species, each group masked to its own floor)" if masked else ""))]
    for k, s in enumerate(lay.table):
        lines += [common.comment(f"species {s.type}: {s.material}, radius {fmt(s.radius)} m, mass {fmt(s.mass)} kg"),
                  _material(laws, laws.species[k])]
    for g_, w in enumerate(laws.groups):
        who = ", ".join(str(a + 1) for a, gg in enumerate(laws.group_of) if gg == g_)
        lines += [common.comment(f"the floor of species {who}: the wall's values of the case in series with the "
                                 "species' material"), _material(laws, w)]
    lines += [c for c in PD.law_comments(
        [*((f"species {a + 1} with {b + 1}", mp) for (a, b), mp in pairs.items()),
         *((f"species {a + 1} with the walls", mp) for a, mp in enumerate(walls))])]
    return lines


def _bodies(case: Case, lay, laws, g, masked: bool) -> list[str]:
    """Every particle's row, and the loop that makes Yade bodies of them."""
    lines = [common.comment("every particle: material (its species), radius (m), mass (kg), moment of inertia "
                            "0.4 m r^2 (kg m^2), position (m),"),
             common.comment("velocity v0 - dt/2 g (leap-frog's v at -dt/2, so that v0 is the full-step velocity at "
                            "step 0: no contact at t = 0), angular velocity (rad/s)"),
             "P = ["]
    for k, part in enumerate(case.particles):
        sp = int(lay.species[k])
        m = case.mass(k)
        inertia = 0.4 * m * part.radius * part.radius
        v = [float(part.velocity[i]) - 0.5 * lay.dt * float(g[i]) for i in range(3)]
        row = [_num(part.radius), _num(m), _num(inertia), *(_num(x) for x in part.position), *(_num(x) for x in v),
               *(_num(x) for x in part.angular_velocity)]
        lines.append(f"    ({sp}, {', '.join(row)}),")
    lines.append("]")
    if masked:
        ns = len(lay.table)
        lines += [common.comment("each species' mask: bit 0 (every particle touches every particle) and its floor "
                                 "group's bit"),
                  f"MASK = [{', '.join(str(1 | (2 << laws.group_of[a])) for a in range(ns))}]"]
    lines += ["for p in P:",
              "    b = O.bodies.append(utils.sphere(Vector3(p[4], p[5], p[6]), p[1], material=p[0]"
              + (", mask=MASK[p[0]]))" if masked else "))"),
              "    O.bodies[b].state.mass = p[2]",
              "    O.bodies[b].state.inertia = Vector3(p[3], p[3], p[3])",
              "    O.bodies[b].state.vel = Vector3(p[7], p[8], p[9])",
              "    O.bodies[b].state.angVel = Vector3(p[10], p[11], p[12])",
              "N = len(P)"]
    return lines


def _engines_and_samples(laws, periodic: bool) -> list[str]:
    """The engines, and the loop that prints the kinetic energy at each sample step."""
    bo1, ig2 = ("Bo1_Box_Aabb()", "Ig2_Box_Sphere_ScGeom()") if periodic else ("Bo1_Wall_Aabb()",
                                                                                 "Ig2_Wall_Sphere_ScGeom()")
    return [common.comment("the engines: Yade's leap-frog NewtonIntegrator without its numerical damping (0.2 in "
                           "many examples)"),
            f"O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), {bo1}]"
            + (", allowBiggerThanPeriod=True, sortAxis=2)," if periodic else "),"),
            f"              InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), {ig2}], [{laws.phys}], [{laws.law}]),",
            "              NewtonIntegrator(damping=0.0, gravity=G)]",
            "O.dt = DT",
            common.comment("at each sample step s: the state x_s, v_{s-1/2}, w_{s-1/2}; one step computes F_s; the "
                           "full-step velocity v_s = v_{s-1/2} + dt/2 (F_s/m + g)"),
            "done = 0",
            "for s in SAMPLES:",
            "    if s > done:",
            "        O.run(s - done, True)",
            "    x = [Vector3(O.bodies[i].state.pos) for i in range(N)]",
            "    v = [Vector3(O.bodies[i].state.vel) for i in range(N)]",
            "    w = [Vector3(O.bodies[i].state.angVel) for i in range(N)]",
            "    O.step()",
            "    e = 0.0",
            "    for i in range(N):",
            "        a = v[i] + (O.forces.f(i) / P[i][2] + G) * (0.5 * DT)",
            "        e = e + 0.5 * P[i][2] * a.dot(a)",
            f"    print({KE!r} % (s, e, N))",
            "    done = s + 1"]


def _outputs(periodic: bool, bounds: list) -> list[str]:
    """The final state of every particle and the particle pairs in contact, as dumps."""
    return [common.comment("the final state at step STEPS: every particle (id = body id + 1, type = species; radius "
                           "and mass as Yade holds them), F + m g as the LAMMPS-family engines write a particle's "
                           "force"
                           + ("; x and y wrapped into the box" if periodic else "")),
            f"out = open({PD.FINAL_DUMP!r}, 'w')",
            f"out.write({FINAL_HEAD[periodic]!r} % (STEPS, N, {', '.join(_num(b) for b in bounds)}))",
            "for i in range(N):",
            "    f = O.forces.f(i)",
            "    t = O.forces.t(i)",
            "    a = v[i] + (f / P[i][2] + G) * (0.5 * DT)",
            "    q = w[i] + t * (0.5 * DT / P[i][3])",
            "    f = f + G * P[i][2]",
            "    b = O.bodies[i]",
            (f"    out.write({FINAL_ROW!r} % (i + 1, P[i][0] + 1, b.shape.radius, b.state.mass, "
             + ("x[i][0] - LX * (x[i][0] // LX), x[i][1] - LY * (x[i][1] // LY), " if periodic
                else "x[i][0], x[i][1], ")
             + "x[i][2], a[0], a[1], a[2], q[0], q[1], q[2], f[0], f[1], f[2]))"),
            "out.close()",
            common.comment("every particle pair in contact at step STEPS (the floor's contacts left out): the ids, "
                           "penetrationDepth, the normal force on the second (repulsive along the normal),"),
            common.comment("the stored shear force (ViscElPhys: its elastic part; MindlinPhys: without the "
                           "dashpot) and the normal from the first to the second"),
            "rows = [c for c in O.interactions if c.isReal and c.id1 < N and c.id2 < N]",
            f"out = open({PD.CONTACT_DUMP!r}, 'w')",
            f"out.write({CONTACT_HEAD[periodic]!r} % (STEPS, len(rows), {', '.join(_num(b) for b in bounds)}))",
            "for c in rows:",
            "    f = c.phys.normalForce",
            "    t = c.phys.shearForce",
            "    a = c.geom.normal",
            f"    out.write({CONTACT_ROW!r} % (c.id1 + 1, c.id2 + 1, c.geom.penetrationDepth, f[0], f[1], f[2], "
            "t[0], t[1], t[2], a[0], a[1], a[2]))",
            "out.close()", ""]


def read(engine, workdir, log: str, box=None):
    """A packing script's output as its record (engines.output.PackingOutput): the final state (the last block of
    FINAL_DUMP, sorted by id), the contacts (:func:`contacts`) and the kinetic energy lines of ``log``."""
    from ..output import PackingOutput

    final = _last_block(Path(workdir) / PD.FINAL_DUMP, PD.FINAL_COLUMNS).sort_values("id").reset_index(drop=True)
    ke = [(int(m.group(1)), float(m.group(2))) for m in _KE_LINE.finditer(log)]
    return PackingOutput(final, contacts(Path(workdir) / PD.CONTACT_DUMP), ke, log)


def contacts(path):
    """CONTACT_DUMP (the last block: every pair Yade holds) as engines.output.CONTACT_COLUMNS: Fn = normalForce ·
    normal (repulsive > 0), |Ft| = |shearForce|; the overlap is Yade's penetrationDepth (across a periodic
    boundary too: Yade computes it with the cell shift)."""
    from ..output import touching

    v = _last_block(path, CONTACT_COLUMNS)[list(CONTACT_COLUMNS)].to_numpy(float)
    i, j = v[:, 0].astype(np.int64) - 1, v[:, 1].astype(np.int64) - 1
    fn = np.einsum("ij,ij->i", v[:, 3:6], v[:, 9:12])
    return touching(i, j, v[:, 2], fn, np.linalg.norm(v[:, 6:9], axis=1))


def _last_block(path, columns):
    from ..dumps import read_dump

    table = read_dump(path, columns=columns)
    return table[table["step"] == table["step"].max()] if len(table) else table
