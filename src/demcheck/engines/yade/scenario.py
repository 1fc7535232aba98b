"""The scenarios beyond sliding in Yade 2023.02a: a sphere on a wall (rolling, incline, twist) with
``CohFrictMat`` + ``Ip2_CohFrictMat_CohFrictMat_CohFrictPhys`` + ``Law2_ScGeom6D_CohFrictPhys_CohesionMoment``
(``useIncrementalForm``, ``always_use_moment_law``) on a fixed box (``Ig2_Box_Sphere_ScGeom6D``: there is no 6-D
wall geometry); :func:`mapping`, :func:`twin_laws` (Yade's leap-frog and law: reference/beyond_yade.py),
:func:`deck` (a fixed template with numbers only, checked by :func:`check_script`) and :func:`read`. The pair
scenarios (pull_off, adhesive_impact, conduction) are handed to :mod:`.pair` (Mindlin's DMT, ThermalEngine).

What the CohFrictPhys computes (CohesiveFrictionalContactLaw.cpp, read; measured against the twin): a linear
normal spring kn = E·R (the box takes the sphere's radius), no normal dashpot; an incremental shear spring
ks = E·R·ν capped at μ|Fn|, no dashpot; an incremental bending moment kr = R²·ks·alphaKr capped at
etaRoll·R·|Fn| (type C, the spring capped, no dashpot); a twisting moment ktw = R²·ks·alphaKtw capped at
etaTwist·R·|Fn| (sds without its dashpot). Yade's other rolling resistance, ViscElMat ``mR`` with ``mRtype`` 1,
is not type A: its source calls ``relAngVel.normalized()`` and drops the result, so the torque is −mR|Fn|·w, a
viscous torque that grows with the spin (docs/findings.md).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np

from ...case import Case
from ...errors import DemcheckError
from ...inputs import common
from ...laws.model import resolve
from ...laws.normal import HertzNormal, HookeNormal
from ...laws.rolling import ConstantTorqueRolling, EpsdRolling, ViscousRolling
from ...laws.tangential_laws.none import NoTangential
from ...laws.tangential_laws.spring import SpringTangential
from ...laws.twisting import MarshallTwisting, SdsTwisting
from ...reference import beyond_yade
from ...reference.scenarios import _on_wall
from ..base import APPROXIMATE, EXACT, Engine, Mapping, Native, refused, worst
from . import pair
from .deck import ascii_comment, guard

FIRST_LINE = "# demcheck: a Yade scenario script (Python), generated from a fixed template"
WALL = ("rolling", "incline", "twist")
TWIST_POISSON = 0.3  # the twist case has no shear spring; Yade's ktw needs ks > 0 (ks = E R ν): any ν, no slip
COLUMNS = ("x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz")
ROW = " ".join(["%.17g"] * len(COLUMNS)) + "\n"
STRINGS = frozenset({ROW, common.DUMP_FILE, "w"})
NAMES = frozenset({"O", "Vector3", "utils", "CohFrictMat", "ForceResetter", "InsertionSortCollider", "Bo1_Sphere_Aabb",
                   "Bo1_Box_Aabb", "InteractionLoop", "Ig2_Box_Sphere_ScGeom6D", "Ip2_CohFrictMat_CohFrictMat_CohFrictPhys",
                   "Law2_ScGeom6D_CohFrictPhys_CohesionMoment", "NewtonIntegrator", "open", "range",
                   "DT", "EVERY", "SAMPLES", "G", "M", "I", "b", "out", "k", "x", "v", "w", "f", "t", "a", "c"})
KEYWORDS = frozenset({"young", "poisson", "frictionAngle", "density", "momentRotationLaw", "etaRoll", "alphaKr",
                      "etaTwist", "alphaKtw", "center", "extents", "fixed", "material", "useIncrementalForm",
                      "always_use_moment_law", "damping", "gravity"})
ATTRIBUTES = frozenset({"materials", "bodies", "append", "sphere", "box", "state", "mass", "inertia", "pos", "vel",
                        "angVel", "engines", "dt", "step", "run", "forces", "f", "t", "write", "close"})
NODES = (__import__("ast").Module,) + tuple(getattr(__import__("ast"), n) for n in (
    "Expr", "Assign", "Call", "Name", "Load", "Store", "Attribute", "Constant", "Tuple", "List", "keyword", "For",
    "BinOp", "Add", "Sub", "Mult", "Div", "Mod", "UnaryOp", "USub", "Subscript", "ImportFrom", "alias"))


def is_scenario_script(text: str) -> bool:
    return text.split("\n", 1)[0] == FIRST_LINE or pair.is_pair_script(text)


def check_script(text: str, files: dict | None = None) -> None:
    """The guard of the scenario template (a pair's: pair.py's): only its names, attributes, keywords, strings and
    numbers."""
    if pair.is_pair_script(text):
        return pair.check_script(text, files)
    if not is_scenario_script(text):
        raise DemcheckError("refusing to run a Yade script: it is not demcheck's scenario template")
    guard(text, files, NAMES, ATTRIBUTES, KEYWORDS, STRINGS, NODES, flags=True)


# ----------------------------------------------------------------------------- the mapping


def mapping(engine: Engine, case: Case) -> Mapping:
    """The case's contact in CohFrictPhys terms (``nat.props``: young, poisson, mu, etaRoll, alphaKr, etaTwist,
    alphaKtw, and the pair's kn, ks, kr, ktw, maxRollPl, maxTwistPl); set here, not by ``engine``'s collision
    mapping (CohFrictPhys is no collision law of its)."""
    s = case.run.scenario
    if s in pair.PAIR:
        return pair.mapping(case)
    model = resolve(case)
    radius = case.particles[0].radius
    made = _contact(case, model, radius)
    if isinstance(made, Mapping):
        return made
    props, fid, reasons = made
    slot = "twisting" if s == "twist" else "rolling"
    law = model.slot(slot)
    made = (_twisting if slot == "twisting" else _rolling)(law, props, radius)
    if isinstance(made, Mapping):
        return made
    fid2, more = made
    nat = Native("yade", normal="CohFrictPhys", tangential="CohesionMoment", props=props)
    nat.comments = [f"CohFrictMat young = {props['young']:.10g}, poisson = {props['poisson']:.10g}: kn = E R = "
                    f"{props['kn']:.10g} N/m, ks = E R nu = {props['ks']:.10g} N/m; kr = {props['kr']:.10g} N m/rad, "
                    f"maxRollPl = {props['max_roll']:.10g} m; ktw = {props['ktw']:.10g} N m/rad, "
                    f"maxTwistPl = {props['max_twist']:.10g} m"]
    reasons = reasons + more
    return Mapping("yade", worst(fid, fid2), reasons, nat,
                   {r: "Law2_ScGeom6D_CohFrictPhys_CohesionMoment" for r in reasons})


def _contact(case, model, radius):
    """(props, fidelity, reasons) of the normal and shear springs, or a refusal."""
    contact = model.contact
    reasons, fid = [], EXACT
    mass, _, g, theta, _ = _on_wall(case)
    weight = mass * g * math.cos(theta)
    normal = contact.normal
    if isinstance(normal, HookeNormal):
        kn = normal.k
    elif isinstance(normal, HertzNormal):
        kn = weight ** (1.0 / 3.0) * normal.k ** (2.0 / 3.0)  # the linear spring with Hertz's overlap under m g
        fid = APPROXIMATE
        reasons.append("CohFrictPhys's normal spring is linear: kn = m g / δ_Hertz(m g), the same static overlap "
                       "under the weight, not the Hertz law")
    else:
        return refused("yade", f"CohFrictPhys has a linear normal spring only, not '{normal.id}'")
    if getattr(contact.damping, "eta", 0.0) > 0.0:
        fid = APPROXIMATE
        reasons.append("CohFrictPhys has no normal dashpot (the sphere rests at its static overlap: the case's "
                       "dashpot only damps the rocking)")
    tl = contact.tangential
    mu = model.pair.friction or 0.0
    if type(tl) is SpringTangential:  # the constant-kt spring (not sqrt_spring, its subclass)
        ks = tl.kt
        if tl.eta > 0.0:
            fid = APPROXIMATE
            reasons.append("CohFrictPhys's shear spring has no dashpot")
    elif isinstance(tl, NoTangential) and case.run.scenario == "twist":
        ks, mu = TWIST_POISSON * kn, 0.0
    else:
        return refused("yade", "a sphere rolling on a wall in Yade needs the case's linear tangential spring "
                               f"(CohFrictPhys ks), not '{tl.id}'")
    young = kn / radius
    props = {"young": young, "poisson": ks / kn, "mu": mu, "kn": kn, "ks": ks, "etaRoll": -1.0, "alphaKr": 0.0,
             "etaTwist": -1.0, "alphaKtw": 0.0, "kr": 0.0, "ktw": 0.0, "max_roll": -1.0, "max_twist": -1.0}
    return props, fid, reasons


def _rolling(law, props, radius):
    r2ks = radius * radius * props["ks"]
    if isinstance(law, EpsdRolling):
        props.update(kr=law.k_r, max_roll=law.mu_r * law.r_roll, etaRoll=law.mu_r * law.r_roll / radius,
                     alphaKr=law.k_r / r2ks)
        if law.c_r > 0.0:
            return APPROXIMATE, ["CohesionMoment's bending moment has no dashpot (type C without its viscous part)"]
        return EXACT, []
    if isinstance(law, ConstantTorqueRolling):
        props.update(kr=r2ks, max_roll=law.mu_r * law.r_roll, etaRoll=law.mu_r * law.r_roll / radius, alphaKr=1.0)
        return APPROXIMATE, ["type A (constant torque) as CohesionMoment's bending spring (kr = R² ks, alphaKr = 1) "
                             "at its limit etaRoll·R·|Fn|: it winds up first and springs back at the stop"]
    if isinstance(law, ViscousRolling):
        return refused("yade", "Yade's only viscous rolling torque (ViscElMat mR, mRtype 1) is −mR|Fn|·w, not −Cr w: "
                               "not mapped")
    return refused("yade", f"Yade has no rolling moment like the rolling law {law.id!r}: not mapped")


def _twisting(law, props, radius):
    if isinstance(law, MarshallTwisting):
        return refused("yade", "Yade's twisting moment has a constant ktw (CohFrictMat alphaKtw): Marshall's "
                               "stiffness from the contact radius is not expressible")
    if not isinstance(law, SdsTwisting):  # a law demcheck gained after this writer (a plug-in law)
        return refused("yade", f"Yade has no twisting moment like the twisting law {law.id!r}: not mapped")
    props.update(ktw=law.k_tw, max_twist=law.mu_tw, etaTwist=law.mu_tw / radius,
                 alphaKtw=law.k_tw / (radius * radius * props["ks"]))
    if law.gamma_tw > 0.0:
        return APPROXIMATE, ["CohesionMoment's twisting moment has no dashpot"]
    return EXACT, []


# ----------------------------------------------------------------------------- the twin


def twin_laws(engine: Engine, case: Case, nat: Native) -> dict:
    """The laws the layout reads (the linear normal spring, the shear spring) and Yade's own stepper."""
    if case.run.scenario in pair.PAIR:
        return pair.twin_laws(case, nat)
    p = nat.props
    kn = p["kn"]
    return {"normal": lambda d, rate: kn * d, "tangential": (p["ks"], 0.0, p["mu"]),
            "stepper": functools.partial(_step, p)}


def _samples(lay) -> int:
    return lay.steps // lay.every + 1


def _step(p: dict, case: Case, laws: dict, lay) -> dict:
    w = case.walls[0]
    return beyond_yade.wall(case.particles[0].radius, case.mass(0), lay.positions[0], lay.velocities[0],
                            lay.omegas[0], case.run.gravity, w.point, w.normal, lay.dt, _samples(lay), lay.every,
                            kn=p["kn"], ks=p["ks"], mu=p["mu"], kr=p["kr"], max_roll=p["max_roll"], ktw=p["ktw"],
                            max_twist=p["max_twist"])


# ----------------------------------------------------------------------------- the deck


_num = common.float_literal


def _vec(xs) -> str:
    return f"Vector3({', '.join(_num(x) for x in xs)})"


def deck(engine: Engine, case: Case, nat: Native, lay) -> common.Deck:
    """The scenario's script: the sphere at the layout's start (v_{−½} = the layout's velocity), a fixed box
    whose top face is the wall, sampled every ``lay.every`` steps (x_k, the full-step velocities)."""
    if case.run.scenario in pair.PAIR:
        return pair.deck(case, nat, lay)
    p, part, wall = nat.props, case.particles[0], case.walls[0]
    if getattr(wall, "material", None) or int(np.count_nonzero(wall.normal)) != 1:
        raise DemcheckError("the Yade scenario script is written for a rigid axis-aligned wall")
    radius, mass = part.radius, case.mass(0)
    n = np.asarray(wall.normal, dtype=float)
    half = 50.0 * radius
    center = np.asarray(wall.point, dtype=float) - half * n
    extents = [1000.0 * radius if c == 0.0 else half for c in n]
    inertia = 0.4 * mass * radius * radius
    mat = (f"CohFrictMat(young={_num(p['young'])}, poisson={_num(p['poisson'])}, "
           f"frictionAngle={_num(math.atan(p['mu']))}, density=1.0, momentRotationLaw=True, "
           f"etaRoll={_num(p['etaRoll'])}, alphaKr={_num(p['alphaKr'])}, etaTwist={_num(p['etaTwist'])}, "
           f"alphaKtw={_num(p['alphaKtw'])})")
    lines = [FIRST_LINE, f"# scenario {case.run.scenario}; Yade 2023.02a, yade -x -n",
             *(ascii_comment("# " + c) for c in nat.comments),
             "from yade import utils", f"DT = {_num(lay.dt)}", f"EVERY = {int(lay.every)}",
             f"SAMPLES = {_samples(lay)}", f"G = {_vec(case.run.gravity)}", f"M = {_num(mass)}",
             f"I = {_num(inertia)}", f"O.materials.append({mat})",
             f"O.bodies.append(utils.box(center={_vec(center)}, extents={_vec(extents)}, fixed=True, material=0))",
             f"b = O.bodies.append(utils.sphere({_vec(lay.positions[0])}, {_num(radius)}, material=0))",
             "O.bodies[b].state.mass = M", "O.bodies[b].state.inertia = Vector3(I, I, I)",
             f"O.bodies[b].state.vel = {_vec(lay.velocities[0])}",
             f"O.bodies[b].state.angVel = {_vec(lay.omegas[0])}",
             "O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),",
             "              InteractionLoop([Ig2_Box_Sphere_ScGeom6D()], [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys()],",
             "                              [Law2_ScGeom6D_CohFrictPhys_CohesionMoment(useIncrementalForm=True, "
             "always_use_moment_law=True)]),",
             "              NewtonIntegrator(damping=0.0, gravity=G)]",
             "O.dt = DT", f"out = open({common.DUMP_FILE!r}, 'w')",
             "for k in range(SAMPLES):",
             "    x = Vector3(O.bodies[b].state.pos)",
             "    v = Vector3(O.bodies[b].state.vel)",
             "    w = Vector3(O.bodies[b].state.angVel)",
             "    O.step()",
             "    f = O.forces.f(b) + G * M",
             "    t = O.forces.t(b)",
             "    a = v + f * (0.5 * DT / M)",
             "    c = w + t * (0.5 * DT / I)",
             f"    out.write({ROW!r} % (x[0], x[1], x[2], a[0], a[1], a[2], c[0], c[1], c[2]))",
             "    for k in range(EVERY - 1):",
             "        O.step()",
             "out.close()", ""]
    return common.Deck("yade", "\n".join(lines), {}, dt=lay.dt, check=check_script)


def read(engine: Engine, case: Case, lay, workdir) -> dict:
    """The samples as reference/scenarios.stepped_metrics reads them."""
    if case.run.scenario in pair.PAIR:
        return pair.read(case, lay, workdir)
    path = Path(workdir) / common.DUMP_FILE
    try:
        rows = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError) as exc:
        raise DemcheckError(f"the Yade scenario output {path} cannot be read: {exc}") from None
    if rows.shape != (_samples(lay), len(COLUMNS)):
        raise DemcheckError(f"the Yade scenario output has {rows.shape[0]} rows of {rows.shape[1]}, "
                            f"not {_samples(lay)} of {len(COLUMNS)}")
    return {"t": np.arange(len(rows)) * lay.every * lay.dt, "x": rows[:, 0:3], "v": rows[:, 3:6],
            "omega": rows[:, 6:9]}
