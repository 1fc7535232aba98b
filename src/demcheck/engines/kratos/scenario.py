"""The scenarios beyond sliding in Kratos DEM 10.4.4 (PyPI KratosMultiphysics + KratosDEMApplication): the
adhesive ones through its cohesive discontinuum laws ``DEM_D_Hertz_viscous_Coulomb_JKR`` and ``…_DMT``, a sphere
on a wall (rolling; incline with a type A torque) through its rolling friction models
``DEMRollingFrictionModelConstantTorque`` and ``…ViscousTorque`` (:func:`mapping`), the laws they compute
(:func:`twin_laws`: reference/beyond_kratos.py, stepped with the deck's Velocity_Verlet), the deck (:func:`deck`:
engines/kratos/deck.py's project, the relation's law, its PARTICLE_COHESION or its rolling friction model; a pull
holds both bodies' velocities fixed; the header states this mapping's fidelity and reasons) and its output read
back (:func:`read`).

Measured against Kratos runs (tests/test_scenarios_kratos.py):

* DMT: Kratos' F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄ while δ > 0 is the seed's DMT law: exact;
* JKR: Kratos subtracts √(8πwE*a³) at the Hertz radius a = √(R̄δ) while δ > 0 — not JKR's contact radius, no
  neck below δ = 0, no hysteresis: its largest tension is JKR's (3/2)πwR̄ (F = Ax² − Bx in x = δ^{3/4} has
  the minimum −B²/4A = −(3/2)πwR̄) but at a positive overlap, the contact ends at δ = 0 (not δ_f < 0), and an
  impact loses no energy to adhesion (restitution 1, nothing captured);
* rolling (type A): ConstantTorque on a wall is −ROLLING_FRICTION·|Fn|(R − δ)·ω/|ω| from the node's half-step
  spin, added to the contact's moment: with ROLLING_FRICTION = μr Rr/R the case's torque times (1 − δ/R)
  (approximate); the run equals its twin (Kratos' tangential law, its Velocity_Verlet) to ≤ 7e-11 in every sample
  and 1e-15 in the stop time, which is the closed form's ½dt late (the first half step has no torque: HALF_STEP);
* rolling (type B): ViscousTorque on a wall is −ROLLING_FRICTION·|Fn|(R − δ)²·ω: Cr follows |Fn| (approximate,
  ROLLING_FRICTION = Cr/(W R²)); engine = twin likewise;
* type C (epsd): no Kratos 10.4.4 model has a rolling spring (NO_SPRING); DEMRollingFrictionModelBounded is type A
  cut to the torque that stops the spin within a step, not mapped; twist: no twisting model, conduction: no heat
  conduction in this install (each with its reason).
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np

from ...case import Case
from ...errors import DemcheckError
from ...inputs import common
from ...laws.adhesion import DmtAdhesion, JkrAdhesion
from ...laws.damping import NoDamping
from ...laws.model import resolve
from ...laws.normal import HertzNormal
from ...laws.rolling import ConstantTorqueRolling, EpsdRolling, ViscousRolling
from ...laws.tangential_laws.none import NoTangential
from ...reference import beyond_kratos as _bk
from ...reference.scenarios import _on_wall
from ..base import APPROXIMATE, EXACT, Engine, Mapping, Native, refused

JKR_LAW, DMT_LAW = "DEM_D_Hertz_viscous_Coulomb_JKR", "DEM_D_Hertz_viscous_Coulomb_DMT"
# the adhesion records Kratos' cohesive laws express: the law, and its force as reference/beyond_kratos computes it
COHESIVE = {JkrAdhesion: JKR_LAW, DmtAdhesion: DMT_LAW}
COHESIVE_FORCE = {JKR_LAW: _bk.kratos_jkr_force, DMT_LAW: _bk.kratos_dmt_force}
# the rolling records Kratos' rolling friction models express
ROLLING_BY_RECORD = {ConstantTorqueRolling: "DEMRollingFrictionModelConstantTorque",
                     ViscousRolling: "DEMRollingFrictionModelViscousTorque"}
# the same by the law's id: what engines/kratos/audit.py reads a project's model name back to
ROLLING_MODELS = {record.id: name for record, name in ROLLING_BY_RECORD.items()}
WHY_NOT = {
    "twist": ("Kratos DEM 10.4.4 has no twisting torque model: its discontinuum laws give a force, and its only "
              "torque models are the rolling friction models (ConstantTorque, ViscousTorque, Bounded)"),
    "conduction": ("Kratos DEM 10.4.4 (KratosDEMApplication) conducts no heat: heat transfer between particles is "
                   "ThermalDEMApplication's, which is not part of this install (PyPI KratosMultiphysics + "
                   "KratosDEMApplication)"),
}
NO_SPRING = ("Kratos DEM 10.4.4 has no rolling spring (type C, 'epsd'): its rolling friction models are "
             "DEMRollingFrictionModelConstantTorque (type A), DEMRollingFrictionModelViscousTorque (type B) and "
             "DEMRollingFrictionModelBounded (Irazábal's bounded model: type A's torque cut, each step, to the "
             "one that stops the spin within the step; no stiffness kr, no stored moment)")
CONSTANT_REASON = ("Kratos' DEMRollingFrictionModelConstantTorque on a wall is −ROLLING_FRICTION·|Fn|·(R − δ)·ω/|ω|: "
                   "the arm R − δ, not Rr (ROLLING_FRICTION = μr Rr/R: the torque μr Rr|Fn|(1 − δ/R), δ/R = "
                   "{dr:.3g} at the static overlap){direction}")
HALF_STEP = ("the run starts from Kratos' forces of the sphere at rest (demcheck's runner sets v and ω after Kratos' "
             "initialisation, as in its collisions): the first half step has no rolling torque and no tangential "
             "force, so the roll's angular momentum about the contact point is ½dt·M too high and it stops ½dt late "
             "(½dt/t_stop of the stop time, ½dt·v0 of the distance; the twin steps the same start)")
WHOLE_SPIN = (", and its direction is the whole spin's ω/|ω| (the case's full_direction = false takes the rolling "
              "part's: they differ only while the sphere spins about the wall's normal)")
VISCOUS_REASON = ("Kratos' DEMRollingFrictionModelViscousTorque on a wall is −ROLLING_FRICTION·|Fn|·(R − δ)²·ω: "
                  "Cr = ROLLING_FRICTION·|Fn|(R − δ)² follows the normal force (ROLLING_FRICTION = Cr/(W R²), W the "
                  "weight's normal part {weight:.6g} N: the case's Cr at |Fn| = W and δ = 0; (1 − δ/R)² = "
                  "1 − {dr2:.3g} at the static overlap), and it damps the whole spin ω, not its rolling part")
JKR_REASON = ("Kratos' DEM_D_Hertz_viscous_Coulomb_JKR subtracts √(8πwE*a³) with the Hertz radius a = √(R̄δ) from "
              "the Hertz force while δ > 0 only: not JKR's contact radius, no neck below δ = 0 and no hysteresis "
              "(its largest tension is JKR's (3/2)πwR̄ = {tension:.4g} N, but at δ = {d_star:.4g} m > 0, and the "
              "contact ends at δ = 0, not at δ_f < 0; an impact loses nothing to adhesion: restitution 1, never "
              "captured)")


def mapping(engine: Engine, case: Case) -> Mapping:
    """The case's scenario in Kratos' words: the adhesive scenarios through the cohesive laws, a sphere on a wall
    through a rolling friction model (:func:`_rolling`, the contact ``engine``'s mapping), twist and conduction
    none."""
    s = case.run.scenario
    if s in WHY_NOT:
        return refused("kratos", WHY_NOT[s])
    model = resolve(case)
    if s in ("rolling", "incline"):
        return _rolling(engine, case, model)
    rec = model.slot("adhesion")
    if type(rec) not in COHESIVE:
        return refused("kratos", f"Kratos DEM 10.4.4 has no adhesion law like '{rec.id}' (its cohesive laws are "
                                 "DEM_D_*_JKR and DEM_D_*_DMT)")
    if not isinstance(model.contact.damping, NoDamping) or not isinstance(model.contact.tangential, NoTangential):
        return refused("kratos", "the adhesive scenarios are written without a normal dashpot and without a "
                                 "tangential law (DAMPING_GAMMA = 0, no friction)")
    law = COHESIVE[type(rec)]
    nat = Native("kratos", normal=law, normal_args=(rec.e_eff,), damping="gamma", damping_coeff=0.0,
                 tangential="none", limit=True,
                 props={"young_eff": rec.e_eff, "gamma": 0.0, "wall": False, "cohesion": rec.w,
                        "r_eff": rec.r_eff})
    nat.comments = [f"{law}: E* = {rec.e_eff:.10g} Pa, PARTICLE_COHESION w = {rec.w:g} J/m² (the relation's), "
                    "DAMPING_GAMMA = 0, no friction"]
    if law == DMT_LAW:  # the seed's DMT law itself
        return Mapping("kratos", EXACT, [], nat, {})
    tension, d_star = _bk.jkr_hertz_radius_pull_off(rec.r_eff, rec.e_eff, rec.w)
    reason = JKR_REASON.format(tension=tension, d_star=d_star)
    return Mapping("kratos", APPROXIMATE, [reason], nat, {reason: law})


def _rolling(engine: Engine, case: Case, model) -> Mapping:
    """A sphere on a wall: the case's contact mapped as a collision's (engines/kratos/mapping.py, Kratos' own
    tangential law), its rolling resistance as the relation's rolling friction model with RollingFrictionOption."""
    from .mapping import FRICTION

    rec = model.slot("rolling")
    if type(rec) not in ROLLING_BY_RECORD:
        return refused("kratos", NO_SPRING if isinstance(rec, EpsdRolling) else
                       f"no Kratos rolling friction model for '{rec.id}'")
    base = engine.map(model, case.contact.params)
    if base.native is None:
        return refused("kratos", f"the sphere's contact with the wall: {'; '.join(base.reasons)}")
    nat = base.native
    if nat.tangential != FRICTION:
        return refused("kratos", "a sphere rolling on a wall needs the case's tangential spring (Kratos' own "
                                 "tangential law), not tangential 'none'")
    mass, radius, g, theta, _ = _on_wall(case)
    weight = mass * g * math.cos(theta)
    delta = _static_overlap(nat, mass, radius, weight)
    if isinstance(rec, ConstantTorqueRolling):
        mu = rec.mu_r * rec.r_roll / radius
        reason = CONSTANT_REASON.format(dr=delta / radius, direction="" if rec.full_direction else WHOLE_SPIN)
    else:
        mu = rec.c_r / (weight * radius * radius)
        reason = VISCOUS_REASON.format(weight=weight, dr2=1.0 - (1.0 - delta / radius) ** 2)
    name = ROLLING_BY_RECORD[type(rec)]
    nat.props = {**nat.props, "rolling": (name, mu)}
    nat.comments = [*nat.comments, f"RollingFrictionOption = true, {name}, ROLLING_FRICTION = "
                                   f"ROLLING_FRICTION_WITH_WALLS = {mu:.10g}"]
    return Mapping("kratos", APPROXIMATE, [*base.reasons, reason, HALF_STEP], nat,
                   {**base.keywords, reason: name, HALF_STEP: "DEMAnalysisStage.Initialize (v, ω set after it)"})


def _static_overlap(nat: Native, mass: float, radius: float, weight: float) -> float:
    """The overlap at which Kratos' elastic normal force (its spring record, k δ^exponent) carries ``weight``."""
    from .mapping import law_numbers

    spring = law_numbers(nat, mass, radius)["spring"]
    return (weight / spring.k) ** (1.0 / spring.exponent)


def twin_laws(engine: Engine, case: Case, nat: Native) -> dict:
    """Kratos' law (reference/beyond_kratos.py), with its stepping: engines/scenario.step hands the run to
    ``stepper``."""
    if "rolling" in nat.props:
        return _rolling_laws(engine, case, nat)
    p = nat.props
    force = functools.partial(COHESIVE_FORCE[nat.normal], p["r_eff"], nat.normal_args[0], p["cohesion"])
    laws = {"stepper": functools.partial(_step, force)}
    if nat.normal == JKR_LAW:  # start the pull at twice the overlap of Kratos' largest tension (past it)
        laws["pull_scale"] = 2.0 * _bk.jkr_hertz_radius_pull_off(p["r_eff"], nat.normal_args[0], p["cohesion"])[1]
    return laws


def _rolling_laws(engine: Engine, case: Case, nat: Native) -> dict:
    """The sphere on a wall: Kratos' contact (its normal spring and dashpot, its tangential law) and the rolling
    friction model, stepped by reference/beyond_kratos.wall_roll; ``normal`` and ``tangential`` set the layout."""
    from .mapping import law_numbers, tangential_ratio, twin_law_array

    m, r, g, theta, _ = _on_wall(case)
    ln = law_numbers(nat, m, r)
    spring, dashpot = ln["spring"], ln["damping"]  # the normal records: k δ^exponent and η δ^exponent
    c = getattr(dashpot, "eta", 0.0)
    nl, _ = engine.twin(nat, m, r)
    kt = (ln["rho"] or tangential_ratio(nat)) * ln["kn"]  # × √δ for Hertz: at the static overlap
    if isinstance(spring, HertzNormal):
        kt *= math.sqrt(_static_overlap(nat, m, r, m * g * math.cos(theta)))
    return {"stepper": functools.partial(_roll, nl.array(), twin_law_array(nat, m, r), nat.props["rolling"]),
            "normal": lambda d, rate: spring.k * d ** spring.exponent + c * d ** dashpot.exponent * rate,
            "tangential": (kt, 0.0, 0.0)}


def _roll(nl, kp, rolling, case: Case, laws: dict, lay) -> dict:
    w = case.walls[0]
    model = _bk.VISCOUS_TORQUE if rolling[0] == ROLLING_BY_RECORD[ViscousRolling] else _bk.CONSTANT_TORQUE
    return _bk.wall_roll(nl, kp, model, rolling[1], case.particles[0].radius, case.mass(0), lay.positions[0],
                         lay.velocities[0], lay.omegas[0], case.run.gravity, w.point, w.normal, lay.dt, lay.steps,
                         lay.every)


def _step(force, case: Case, laws: dict, lay) -> dict:
    r0, r1 = (c.radius for c in case.particles)
    if case.run.scenario == "pull_off":
        return _bk.pull(force, r0 + r1, lay.positions[1][0], lay.pull_speed, lay.dt, lay.steps)
    return _bk.pair_impact(force, r0, case.mass(0), lay.positions[1][0], lay.velocities[1][0], lay.dt, lay.steps)


def deck(engine: Engine, case: Case, nat: Native, lay) -> common.Deck:
    """The bodies where the layout puts them, the cohesive law on their relation; a pull holds body 1's velocity
    at the pull speed and body 0's at rest (Kratos' fixed velocity degrees of freedom)."""
    from .deck import deck as project

    moved = replace(case, particles=[replace(p, position=tuple(lay.positions[i]), velocity=tuple(lay.velocities[i]),
                                             angular_velocity=tuple(lay.omegas[i]))
                                     for i, p in enumerate(case.particles)])
    fixed = [(1, (0.0, 0.0, 0.0)), (2, (lay.pull_speed, 0.0, 0.0))] if case.run.scenario == "pull_off" else None
    return project(engine, moved, lay.dt, native=nat, steps=lay.steps, fixed=fixed,
                   rolling=nat.props.get("rolling"), mapping=mapping(engine, case))


def read(engine: Engine, case: Case, lay, workdir) -> dict:
    """The runner's state table (every step, engines/kratos/deck.read_states) as reference/scenarios.stepped_metrics
    reads it."""
    from .deck import read_states

    rows = read_states(workdir).sort_values(["step", "id"])
    n = len(case.particles)

    def col(name, body):
        return rows[name].to_numpy()[body::n]

    if case.run.scenario in ("rolling", "incline"):  # every step dumped: the layout's samples are every lay.every-th
        steps = rows["step"].to_numpy()
        if len(steps) != lay.steps + 1 or steps[-1] != lay.steps:
            raise DemcheckError(f"the Kratos state table has {len(steps)} steps, not the layout's {lay.steps + 1}")

        def cols(*names):
            return np.column_stack([col(c, 0)[::lay.every] for c in names])

        return {"t": steps[::lay.every] * lay.dt, "x": cols("x", "y", "z"), "v": cols("vx", "vy", "vz"),
                "omega": cols("omegax", "omegay", "omegaz"), "f": cols("fx", "fy", "fz"),
                "torque": cols("tqx", "tqy", "tqz")}

    if case.run.scenario == "pull_off":
        return {"delta": sum(p.radius for p in case.particles) - (col("x", 1) - col("x", 0)),
                "fn": np.asarray(col("fx", 1), dtype=float)}
    return {"v_rel": float(col("vx", 1)[-1] - col("vx", 0)[-1]), "touching": bool(col("fx", 1)[-1] != 0.0)}
