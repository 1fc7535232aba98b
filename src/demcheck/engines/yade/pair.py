"""The pair scenarios beyond sliding in Yade 2023.02a (scenario.py hands them here): ``pull_off`` through Mindlin's
DMT (``Ip2_FrictMat_FrictMat_MindlinPhys(gamma)`` + ``Law2_ScGeom_MindlinPhys_Mindlin(includeAdhesion=True)``)
and ``conduction`` through ``ThermalEngine`` (Debian's build has the THERMAL feature); :func:`mapping`,
:func:`twin_laws` (Yade's own laws and scheme: reference/beyond_yade.py), :func:`deck` (a fixed template with
numbers only, checked by :func:`check_script`) and :func:`read`.

What Yade computes (read in HertzMindlin.cpp and Thermal.cpp of 2023.02a; measured against the twin,
tests/test_scenarios_yade.py):

* DMT: Fn = (4/3)E*√R̄ δ^{3/2} − 4πR̄γ while δ ≥ 0, E* and R̄ as the seed's, γ the Ip2 functor's ``gamma`` (a
  surface energy: w = 2γ gives DMT's 2πwR̄), no force below δ = 0 — the seed's DMT law: exact with γ = w/2;
* no JKR law (no class of the build has one), no force proportional to the contact area (``CohFrictMat``'s
  ``normalCohesion`` is a breakable bond: a tensile strength, not −kc·A on the Hertz law): jkr, sjkr and the
  adhesive impact (JKR's) are not expressible;
* ThermalEngine (with a dead FlowEngine, advection off): H = 2(k0 + k1) r0 r1/(r0 + r1 − δ) by forward Euler at
  the step, C = Cp ρ (4/3)πr³ — a conductance that ignores the contact's size: the case's conductivity as
  ``k``, approximate (its H quantified against the case's law in the mapping's reason). Its first call sets
  every body to ``particleT0`` (the script sets the case's temperatures after it: the pair conducts nothing
  while both are at particleT0).
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from ...case import Case
from ...errors import DemcheckError
from ...inputs import common
from ...laws.adhesion import DmtAdhesion
from ...laws.damping import NoDamping
from ...laws.heat import conductance
from ...laws.model import resolve
from ...laws.tangential import NoTangential
from ...reference import beyond_yade
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused
from .deck import ascii_comment, guard

FIRST_LINE = "# demcheck: a Yade pair scenario script (Python), generated from a fixed template"
PAIR = ("pull_off", "adhesive_impact", "conduction")
BLOCKED = "xyzXYZ"
ROW = "%.17g %.17g\n"
STRINGS = frozenset({ROW, BLOCKED, common.DUMP_FILE, "w"})
NAMES = frozenset({"O", "Vector3", "utils", "FrictMat", "ForceResetter", "InsertionSortCollider", "Bo1_Sphere_Aabb",
                   "InteractionLoop", "Ig2_Sphere_Sphere_ScGeom", "Ip2_FrictMat_FrictMat_MindlinPhys",
                   "Law2_ScGeom_MindlinPhys_Mindlin", "Ip2_FrictMat_FrictMat_FrictPhys",
                   "Law2_ScGeom_FrictPhys_CundallStrack", "FlowEngine", "ThermalEngine", "NewtonIntegrator", "open",
                   "range", "DT", "SAMPLES", "EVERY", "a", "b", "out", "k", "f", "x"})
KEYWORDS = frozenset({"young", "poisson", "frictionAngle", "density", "material", "gamma", "includeAdhesion",
                      "damping", "dead", "advection", "fluidConduction", "thermoMech", "solidThermoMech",
                      "fluidThermoMech", "unboundCavityBodies", "boundarySet", "tsSafetyFactor", "particleK",
                      "particleCp", "particleT0", "particleAlpha", "fluidBeta"})
ATTRIBUTES = frozenset({"materials", "bodies", "append", "sphere", "state", "blockedDOFs", "vel", "pos", "temp",
                        "Cp", "k", "engines", "dt", "step", "forces", "f", "write", "close"})
NODES = (__import__("ast").Module,) + tuple(getattr(__import__("ast"), n) for n in (
    "Expr", "Assign", "Call", "Name", "Load", "Store", "Attribute", "Constant", "Tuple", "List", "keyword", "For",
    "BinOp", "Sub", "Mod", "Subscript", "ImportFrom", "alias"))
NO_JKR = ("Yade 2023.02a has no JKR law (no class of its build computes one; its adhesive elastic law is "
          "Mindlin's DMT: Ip2_FrictMat_FrictMat_MindlinPhys gamma with Law2_ScGeom_MindlinPhys_Mindlin "
          "includeAdhesion)")
NO_SJKR = ("Yade 2023.02a has no cohesion proportional to the contact area: CohFrictMat's normalCohesion is a "
           "breakable bond (a tensile strength on a linear spring), not −kc·A added to the Hertz law")
THERMAL = "ThermalEngine (2(k0 + k1) r0 r1 / d)"


def is_pair_script(text: str) -> bool:
    return text.split("\n", 1)[0] == FIRST_LINE


def check_script(text: str, files: dict | None = None) -> None:
    """The guard of the pair template: only its names, attributes, keywords, strings and numbers."""
    if not is_pair_script(text):
        raise DemcheckError("refusing to run a Yade script: it is not demcheck's pair scenario template")
    guard(text, files, NAMES, ATTRIBUTES, KEYWORDS, STRINGS, NODES, flags=True)


# ----------------------------------------------------------------------------- the mapping


def mapping(case: Case) -> Mapping:
    s = case.run.scenario
    if s == "adhesive_impact":
        return refused("yade", NO_JKR + ": the adhesive impact is JKR's")
    model = resolve(case)
    if s == "conduction":
        return _heat(case, model)
    rec = model.slot("adhesion")
    if not isinstance(rec, DmtAdhesion):  # JKR (an adhesive elastic law too) or a cohesion on the elastic law
        return refused("yade", NO_JKR if rec.replaces_normal else NO_SJKR)
    if not isinstance(model.contact.damping, NoDamping) or not isinstance(model.contact.tangential, NoTangential):
        return refused("yade", "the pull is written without a normal dashpot and without a tangential law (Mindlin "
                               "betan = betas = 0, frictionAngle = 0)")
    gamma = 0.5 * rec.w
    nat = Native("yade", normal="MindlinPhys", tangential="Mindlin DMT", props={"gamma": gamma})
    nat.comments = [f"Ip2_FrictMat_FrictMat_MindlinPhys gamma = w/2 = {gamma:.10g} J/m2 (a surface energy: "
                    f"adhesion 4 pi R gamma = 2 pi w R = {rec.pull_off_force():.10g} N), "
                    "Law2_ScGeom_MindlinPhys_Mindlin includeAdhesion = True, no damping, no friction"]
    return Mapping("yade", EXACT, [], nat, {})


def _heat(case: Case, model) -> Mapping:
    law = model.slot("heat")
    if not law.conductivity:
        return refused("yade", "ThermalEngine takes a conductivity (W/(m K)), not a conductance per area: no "
                               "setting of Yade 2023.02a gives hs pi a^2")
    r0, r1 = (p.radius for p in case.particles)
    delta = case.run.overlap
    h_case = conductance(law, delta)
    h_yade = beyond_yade.thermal_conductance(law.k, law.k, r0, r1, delta)
    reason = (f"ThermalEngine's conductance 2(k0 + k1) r0 r1/(r0 + r1 − δ) ignores the contact's size: with "
              f"k = ks = {law.k:g} W/(m K) it is {h_yade:.4g} W/K at δ = {delta:g} m, where the case's '{law.id}' "
              f"law gives {h_case:.4g} W/K ({h_yade / h_case:.3g}×: the time constant {h_case / h_yade:.3g}× the "
              "case's)")
    unstable = _euler_refusal(case, law, h_yade, h_case)
    if unstable:
        return refused("yade", unstable)
    nat = Native("yade", normal="FrictPhys", tangential=THERMAL, props={"k": law.k})
    nat.comments = [f"ThermalEngine particleK = {law.k:g} W/(m K) (the case's ks), per-body Cp = the materials' "
                    "specific heat, a dead FlowEngine, advection off, tsSafetyFactor = 0 (every step)"]
    return Mapping("yade", APPROXIMATE, [reason], nat, {reason: "ThermalEngine"})


def _capacities(case: Case) -> list[float]:
    return [beyond_yade.thermal_capacity(m.specific_heat, m.density, p.radius)
            for m, p in zip(_materials(case), case.particles)]


def _euler_refusal(case: Case, law, h_yade: float, h_case: float) -> str:
    """Why ThermalEngine cannot run the held pair at the scenario's step, or "": its forward Euler (T += Q·dt/C)
    decays monotonically only while x = dt·H(1/C0 + 1/C1) < 1 (reference/beyond_yade.py ``euler_factor``). The
    layout's step resolves the case's law (dt = τ_case/CONDUCTION_STEPS_PER_TAU), so x is Yade's H over the case's
    divided by that number: a tiny overlap, where the case's conductance (∝ √δ) is tiny and Yade's (which ignores the
    contact's size) is not, passes it. The step stays the case's — the seed's run at the engine's step must span
    1.2 τ_case, and a step for Yade's faster exchange would need H_yade/H_case times as many steps (4.8e8 at
    the bound, each a Python-driven O.step) — so the case is refused, naming the least overlap Yade runs."""
    from .. import scenario

    dt = scenario.layout(case, {}).dt
    caps = _capacities(case)
    x = beyond_yade.euler_factor(h_yade, caps[0], caps[1], dt)
    if x < 1.0:
        return ""
    r0, r1 = (p.radius for p in case.particles)
    per_ratio = x / (h_yade / h_case)  # dt/τ_case: the same at every overlap (the layout's dt ∝ τ_case)

    def excess(log_delta):
        d = math.exp(log_delta)
        return math.log(beyond_yade.thermal_conductance(law.k, law.k, r0, r1, d) / conductance(law, d) * per_ratio)

    top = math.log(0.5 * min(r0, r1))
    least = "no overlap below half the smaller radius passes it"
    if excess(top) < 0.0:  # the least overlap, rounded up to three digits
        d = math.exp(brentq(excess, math.log(case.run.overlap), top))
        unit = 10.0 ** (math.floor(math.log10(d)) - 2)
        least = f"Yade runs this pair from run.overlap = {math.ceil(d / unit) * unit:.3g} m"
    return (f"run.overlap = {case.run.overlap:g}: ThermalEngine's forward Euler at the scenario's step (dt = {dt:.3g} s,"
            f" {per_ratio:.3g} of the case's τ) must shrink T1 − T0 monotonically, dt·H(1/C0 + 1/C1) < 1 (past 1 it "
            f"flips sign every step, past 2 it grows): Yade's H = {h_yade:.4g} W/K is {h_yade / h_case:.3g}× the "
            f"case's {h_case:.4g} W/K, giving {x:.3g}; {least}")


# ----------------------------------------------------------------------------- the twin


def _materials(case: Case):
    return [case.materials[p.material] for p in case.particles]


def twin_laws(case: Case, nat: Native) -> dict:
    laws = {"stepper": functools.partial(_step, nat.props)}
    if case.run.scenario == "conduction":  # the held pair's sampling resolves Yade's exchange (scenario._held_every)
        r0, r1 = (p.radius for p in case.particles)
        h = beyond_yade.thermal_conductance(nat.props["k"], nat.props["k"], r0, r1, case.run.overlap)
        laws["heat_rate"] = beyond_yade.euler_factor(h, *_capacities(case), 1.0)
    return laws


def _step(props: dict, case: Case, laws: dict, lay) -> dict:
    r0, r1 = (p.radius for p in case.particles)
    m0, m1 = _materials(case)
    if case.run.scenario == "pull_off":
        kno, adhesion = beyond_yade.mindlin_constants(m0.youngs_modulus, m0.poisson_ratio, r0, m1.youngs_modulus,
                                                      m1.poisson_ratio, r1, props["gamma"])
        return beyond_yade.pull(kno, adhesion, r0 + r1, lay.positions[1][0], lay.pull_speed, lay.dt, lay.steps)
    h = beyond_yade.thermal_conductance(props["k"], props["k"], r0, r1, r0 + r1 - lay.positions[1][0])
    caps = _capacities(case)
    t0, t1 = (float(t) for t in case.run.temperatures)
    return beyond_yade.held(h, caps[0], caps[1], t0, t1, lay.dt, lay.steps, lay.every)


# ----------------------------------------------------------------------------- the deck


_num = common.float_literal


def _vec(xs) -> str:
    return f"Vector3({', '.join(_num(x) for x in xs)})"


def _samples(lay) -> int:
    return lay.steps // lay.every + 1


def deck(case: Case, nat: Native, lay) -> common.Deck:
    """Both bodies with every degree of freedom blocked where the layout puts them (a pull: body 1's velocity
    held at the pull speed); a pull writes body 1's x and the force on it before each step's move, a held pair
    its two temperatures every ``lay.every`` steps."""
    r0, r1 = (p.radius for p in case.particles)
    lines = [FIRST_LINE, f"# scenario {case.run.scenario}; Yade 2023.02a, yade -x -n",
             *(ascii_comment("# " + c) for c in nat.comments), "from yade import utils",
             f"DT = {_num(lay.dt)}", f"EVERY = {int(lay.every)}", f"SAMPLES = {_samples(lay)}"]
    for m in _materials(case):
        lines.append(f"O.materials.append(FrictMat(young={_num(m.youngs_modulus)}, poisson={_num(m.poisson_ratio)}, "
                     f"frictionAngle=0.0, density={_num(m.density)}))")
    lines += [f"a = O.bodies.append(utils.sphere({_vec(lay.positions[0])}, {_num(r0)}, material=0))",
              f"b = O.bodies.append(utils.sphere({_vec(lay.positions[1])}, {_num(r1)}, material=1))",
              f"O.bodies[a].state.blockedDOFs = {BLOCKED!r}", f"O.bodies[b].state.blockedDOFs = {BLOCKED!r}"]
    body = _pull_lines(nat, lay) if case.run.scenario == "pull_off" else _held_lines(case, nat)
    return common.Deck("yade", "\n".join(lines + body + ["out.close()", ""]), {}, dt=lay.dt, check=check_script)


def _pull_lines(nat: Native, lay) -> list[str]:
    return ["# body 1 moves at the pull speed (its degrees of freedom blocked: pos += vel dt each step)",
            f"O.bodies[b].state.vel = {_vec((lay.pull_speed, 0.0, 0.0))}",
            "O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),",
            "              InteractionLoop([Ig2_Sphere_Sphere_ScGeom()],",
            f"                              [Ip2_FrictMat_FrictMat_MindlinPhys(gamma={_num(nat.props['gamma'])})],",
            "                              [Law2_ScGeom_MindlinPhys_Mindlin(includeAdhesion=True)]),",
            "              NewtonIntegrator(damping=0.0)]",
            "O.dt = DT", f"out = open({common.DUMP_FILE!r}, 'w')",
            "for k in range(SAMPLES):",
            "    x = O.bodies[b].state.pos[0]",
            "    O.step()",
            "    f = O.forces.f(b)",
            f"    out.write({ROW!r} % (x, f[0]))"]


def _held_lines(case: Case, nat: Native) -> list[str]:
    m0, m1 = _materials(case)
    t0, t1 = (float(t) for t in case.run.temperatures)
    k = _num(nat.props["k"])
    return ["O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),",
            "              InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],",
            "                              [Law2_ScGeom_FrictPhys_CundallStrack()]),",
            "              FlowEngine(dead=True),",
            # 0 for False: the guard's constants are numbers (and True)
            "              ThermalEngine(advection=0, fluidConduction=0, thermoMech=0, solidThermoMech=0,",
            "                            fluidThermoMech=0, unboundCavityBodies=0, boundarySet=True,",
            f"                            tsSafetyFactor=0.0, particleK={k}, particleCp={_num(m0.specific_heat)},",
            f"                            particleT0={_num(t0)}, particleAlpha=0.0, fluidBeta=0.0),",
            "              NewtonIntegrator(damping=0.0)]",
            "O.dt = DT",
            "# ThermalEngine's first call sets every body's temperature, k and Cp to particleT0, particleK,",
            "# particleCp (at one temperature nothing flows): the case's are set after it",
            "O.step()",
            f"O.bodies[a].state.temp = {_num(t0)}", f"O.bodies[b].state.temp = {_num(t1)}",
            f"O.bodies[a].state.Cp = {_num(m0.specific_heat)}", f"O.bodies[b].state.Cp = {_num(m1.specific_heat)}",
            f"O.bodies[a].state.k = {k}", f"O.bodies[b].state.k = {k}",
            f"out = open({common.DUMP_FILE!r}, 'w')",
            "for k in range(SAMPLES):",
            f"    out.write({ROW!r} % (O.bodies[a].state.temp, O.bodies[b].state.temp))",
            "    for f in range(EVERY):",
            "        O.step()"]


def read(case: Case, lay, workdir) -> dict:
    """A pull's overlap and force on body 1 at each step; a held pair's T1 − T0 at the samples."""
    path = Path(workdir) / common.DUMP_FILE
    try:
        rows = np.loadtxt(path, ndmin=2)
    except (OSError, ValueError) as exc:
        raise DemcheckError(f"the Yade scenario output {path} cannot be read: {exc}") from None
    want = lay.steps + 1 if case.run.scenario == "pull_off" else _samples(lay)
    if rows.shape != (want, 2):
        raise DemcheckError(f"the Yade scenario output has {rows.shape[0]} rows of {rows.shape[1]}, not {want} of 2")
    if case.run.scenario == "pull_off":
        r_sum = sum(p.radius for p in case.particles)
        return {"delta": r_sum - rows[:, 0], "fn": rows[:, 1]}
    return {"t": np.arange(len(rows)) * lay.every * lay.dt, "dT": rows[:, 1] - rows[:, 0]}
