"""The scenarios beyond sliding in Kratos DEM 10.4.4 (PyPI KratosMultiphysics + KratosDEMApplication): the
adhesive ones through its cohesive discontinuum laws ``DEM_D_Hertz_viscous_Coulomb_JKR`` and ``…_DMT``
(:func:`mapping`), the laws they compute (:func:`twin_laws`: reference/beyond_kratos.py, stepped with the deck's
Velocity_Verlet), the deck (:func:`deck`: engines/kratos/deck.py's project, the relation's law and its
PARTICLE_COHESION; a pull holds both bodies' velocities fixed) and its output read back (:func:`read`).

Measured against Kratos runs (tests/test_scenarios_kratos.py):

* DMT: Kratos' F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄ while δ > 0 is the seed's DMT law: exact;
* JKR: Kratos subtracts √(8πwE*a³) at the Hertz radius a = √(R̄δ) while δ > 0 — not JKR's contact radius, no
  neck below δ = 0, no hysteresis: its largest tension is JKR's (3/2)πwR̄ (F = Ax² − Bx in x = δ^{3/4} has
  the minimum −B²/4A = −(3/2)πwR̄) but at a positive overlap, the contact ends at δ = 0 (not δ_f < 0), and an
  impact loses no energy to adhesion (restitution 1, nothing captured);
* rolling, incline: not written (Kratos' rolling friction models are registered; no deck or twin of them on a wall
  yet), twist: no twisting model, conduction: no heat conduction in this install (each with its reason).
"""

from __future__ import annotations

import functools
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...case import Case
from ...inputs import common
from ...laws.model import resolve
from ...reference import beyond_kratos as _bk
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused

JKR_LAW, DMT_LAW = "DEM_D_Hertz_viscous_Coulomb_JKR", "DEM_D_Hertz_viscous_Coulomb_DMT"
WHY_NOT = {
    "rolling": ("no Kratos deck is written for a sphere rolling on a wall yet: Kratos DEM 10.4.4 registers the "
                "rolling friction models DEMRollingFrictionModelConstantTorque, DEMRollingFrictionModelViscousTorque "
                "and DEMRollingFrictionModelBounded (RollingFrictionOption, the relation's ROLLING_FRICTION, "
                "ROLLING_FRICTION_WITH_WALLS, DEM_ROLLING_FRICTION_MODEL_NAME), but the rolling sphere's twin needs "
                "Kratos' own tangential law on a wall stepped with its rolling torque, which is not written"),
    "twist": ("Kratos DEM 10.4.4 has no twisting torque model: its discontinuum laws give a force, and its only "
              "torque models are the rolling friction models (ConstantTorque, ViscousTorque, Bounded)"),
    "conduction": ("Kratos DEM 10.4.4 (KratosDEMApplication) conducts no heat: heat transfer between particles is "
                   "ThermalDEMApplication's, which is not part of this install (PyPI KratosMultiphysics + "
                   "KratosDEMApplication)"),
}
WHY_NOT["incline"] = WHY_NOT["rolling"].replace("a sphere rolling on a wall", "a sphere on an incline")
JKR_REASON = ("Kratos' DEM_D_Hertz_viscous_Coulomb_JKR subtracts √(8πwE*a³) with the Hertz radius a = √(R̄δ) from "
              "the Hertz force while δ > 0 only: not JKR's contact radius, no neck below δ = 0 and no hysteresis "
              "(its largest tension is JKR's (3/2)πwR̄ = {tension:.4g} N, but at δ = {d_star:.4g} m > 0, and the "
              "contact ends at δ = 0, not at δ_f < 0; an impact loses nothing to adhesion: restitution 1, never "
              "captured)")


def mapping(case: Case) -> Mapping:
    """The case's scenario in Kratos' words: the adhesive scenarios through the cohesive laws, the others none."""
    s = case.run.scenario
    if s in WHY_NOT:
        return refused("kratos", WHY_NOT[s])
    model = resolve(case)
    rec = model.slot("adhesion")
    if rec.id not in ("jkr", "dmt"):
        return refused("kratos", f"Kratos DEM 10.4.4 has no adhesion law like '{rec.id}' (its cohesive laws are "
                                 "DEM_D_*_JKR and DEM_D_*_DMT)")
    if model.contact.damping.id != "none" or model.contact.tangential.id != "none":
        return refused("kratos", "the adhesive scenarios are written without a normal dashpot and without a "
                                 "tangential law (DAMPING_GAMMA = 0, no friction)")
    law = JKR_LAW if rec.id == "jkr" else DMT_LAW
    nat = Native("kratos", normal=law, normal_args=(rec.e_eff,), damping="gamma", damping_coeff=0.0,
                 tangential="none", limit=True,
                 props={"young_eff": rec.e_eff, "gamma": 0.0, "wall": False, "cohesion": rec.w,
                        "r_eff": rec.r_eff, "kind": rec.id})
    nat.comments = [f"{law}: E* = {rec.e_eff:.10g} Pa, PARTICLE_COHESION w = {rec.w:g} J/m² (the relation's), "
                    "DAMPING_GAMMA = 0, no friction"]
    if rec.id == "dmt":
        return Mapping("kratos", EXACT, [], nat, {})
    tension, d_star = _bk.jkr_hertz_radius_pull_off(rec.r_eff, rec.e_eff, rec.w)
    reason = JKR_REASON.format(tension=tension, d_star=d_star)
    return Mapping("kratos", APPROXIMATE, [reason], nat, {reason: law})


def twin_laws(case: Case, nat: Native) -> dict:
    """Kratos' law (reference/beyond_kratos.py), with its stepping: engines/scenario.step hands the run to
    ``stepper``."""
    p = nat.props
    force = functools.partial(_bk.kratos_adhesive_force, p["kind"], p["r_eff"], nat.normal_args[0], p["cohesion"])
    laws = {"stepper": functools.partial(_step, force)}
    if p["kind"] == "jkr":  # start the pull at twice the overlap of Kratos' largest tension (past it)
        laws["pull_scale"] = 2.0 * _bk.jkr_hertz_radius_pull_off(p["r_eff"], nat.normal_args[0], p["cohesion"])[1]
    return laws


def _step(force, case: Case, laws: dict, lay) -> dict:
    r0, r1 = (c.radius for c in case.particles)
    if case.run.scenario == "pull_off":
        return _bk.pull(force, r0 + r1, lay.positions[1][0], lay.pull_speed, lay.dt, lay.steps)
    return _bk.pair_impact(force, r0, case.mass(0), lay.positions[1][0], lay.velocities[1][0], lay.dt, lay.steps)


def deck(case: Case, nat: Native, lay) -> common.Deck:
    """The bodies where the layout puts them, the cohesive law on their relation; a pull holds body 1's velocity
    at the pull speed and body 0's at rest (Kratos' fixed velocity degrees of freedom)."""
    from .deck import deck as project

    moved = replace(case, particles=[replace(p, position=tuple(lay.positions[i]), velocity=tuple(lay.velocities[i]),
                                             angular_velocity=tuple(lay.omegas[i]))
                                     for i, p in enumerate(case.particles)])
    fixed = [(1, (0.0, 0.0, 0.0)), (2, (lay.pull_speed, 0.0, 0.0))] if case.run.scenario == "pull_off" else None
    return project(moved, lay.dt, native=nat, steps=lay.steps, fixed=fixed)


COLUMNS = ("id", "type", "radius", "mass", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
           "fx", "fy", "fz", "tqx", "tqy", "tqz")


def read(case: Case, lay, workdir) -> dict:
    """The runner's dump (every step) as reference/scenarios.stepped_metrics reads it."""
    from ..dumps import read_dump

    rows = read_dump(Path(workdir) / common.DUMP_FILE, columns=COLUMNS).sort_values(["step", "id"])

    def col(name, body):
        return rows[name].to_numpy()[body::2]

    if case.run.scenario == "pull_off":
        return {"delta": sum(p.radius for p in case.particles) - (col("x", 1) - col("x", 0)),
                "fn": np.asarray(col("fx", 1), dtype=float)}
    return {"v_rel": float(col("vx", 1)[-1] - col("vx", 0)[-1]), "touching": bool(col("fx", 1)[-1] != 0.0)}
