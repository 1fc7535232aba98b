"""The scenarios beyond sliding in LIGGGHTS-PUBLIC 3.8.0: the conduction scenario through ``fix heat/gran/conduction``
(its lens conductance, LensHeat: exact for ``heat = "lens"``, the named variant of Batchelor & O'Brien's
``radius``), the held pair written without an integrator (the bodies stay where the data file puts them); the
rolling sphere on a primitive wall (cdt; epsd3 on the incline); the pull-off of the simplified JKR cohesion
(``cohesion sjkr`` for the lens area, ``sjkr2`` for the band) on the elastic ``hertz/stiffness`` law, body 1 moved
by ``fix move linear`` and body 0 held by one at rest, as LAMMPS's pull. The others are not expressible, each with
its reason: LIGGGHTS has no twisting model, no JKR or DMT normal model and no viscous rolling torque (type B).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ...case import Case
from ...inputs import common
from ...inputs.common import fmt
from .. import family_deck as FD
from ...laws.adhesion import AREA_LENS, SjkrAdhesion
from ...laws.heat import AreaHeat, LensHeat, RadiusHeat
from ...laws.rolling import CAP_SPRING, ConstantTorqueRolling, EpsdRolling, ViscousRolling
from ...laws.model import resolve
from ..base import APPROXIMATE, EXACT, Engine, Mapping, Native, refused
from .deck import VERSION_NOTE, model_setup, property_matrices

WHY_NOT = {
    "twist": "LIGGGHTS-PUBLIC 3.8.0 has no twisting torque model",
    "pull_off": "LIGGGHTS-PUBLIC 3.8.0 has no JKR or DMT normal model (its cohesion sjkr/sjkr2 adds a force "
                "proportional to the contact area to the normal law)",
    "adhesive_impact": "LIGGGHTS-PUBLIC 3.8.0 has no JKR normal model (its cohesion sjkr/sjkr2 adds a force "
                       "proportional to the contact area to the normal law)",
    "rolling": "no LIGGGHTS deck is written for a sphere rolling on a wall yet (its hertz tangential spring is "
               "kt = 8G*√(R̄δ), not the case's constant kt, and the twins of its rolling models step pairs only)",
    "incline": "LIGGGHTS's incline is written for type C (epsd3) only",
}


def mapping(engine: Engine, case: Case) -> Mapping:
    """The case's contact (``engine``'s mapping) with its scenario's slot in LIGGGHTS's words."""
    s = case.run.scenario
    model = resolve(case)
    if s in ("rolling", "incline"):  # the contact itself first: the case's own reason where LIGGGHTS has none
        if isinstance(model.slot("rolling"), ViscousRolling):
            return refused("liggghts", "LIGGGHTS-PUBLIC 3.8.0 has no viscous rolling torque (type B): its rolling "
                                       "models are cdt, epsd, epsd2 and epsd3")
        if not isinstance(model.slot("rolling"), (ConstantTorqueRolling, EpsdRolling)):  # a plug-in law
            return refused("liggghts", f"LIGGGHTS-PUBLIC 3.8.0 has no rolling law like {model.slot('rolling').id!r}: "
                                       "its rolling models are cdt, epsd, epsd2 and epsd3")
        base = engine.map(model, case.contact.params)
        if base.native is None:
            return refused("liggghts", f"the contact of the rolling sphere: {'; '.join(base.reasons)}")
        if s == "rolling":
            return _rolling(model, base)
        if isinstance(model.slot("rolling"), EpsdRolling):
            return _incline(model, base)
    if s == "pull_off" and isinstance(model.slot("adhesion"), SjkrAdhesion):
        return _cohesion(model, engine.map(model, case.contact.params))
    if s in WHY_NOT:
        return refused("liggghts", WHY_NOT[s])
    rec = model.slot("heat")
    if isinstance(rec, AreaHeat):
        return refused("liggghts", "LIGGGHTS fix heat/gran/conduction has no conductance per contact area")
    base = engine.map(model, case.contact.params)
    if base.native is None:
        return base
    r0, r1 = (p.radius for p in case.particles)
    nat = base.native
    twin_rec = LensHeat(rec.k, r0, r1)
    nat.props = {**nat.props}
    nat.comments = [*nat.comments, f"fix heat/gran/conduction, thermalConductivity {rec.k:g} W/(m·K): 2ks√A over "
                                   "the spheres' intersection circle"]
    reasons = []
    if isinstance(rec, RadiusHeat):
        reasons = ["LIGGGHTS fix heat/gran/conduction conducts through the spheres' intersection circle, "
                   "H = 2ks√A (√(2π) × Batchelor & O'Brien's 2ks√(R̄δ) between like spheres at small overlap)"]
    mp = Mapping("liggghts", APPROXIMATE if reasons else EXACT, [*base.reasons, *reasons], nat,
                 {**base.keywords, **{r: "fix heat/gran/conduction" for r in reasons}})
    mp.native.props["slots"] = {"heat": twin_rec}
    return mp


def _cohesion(model, base: Mapping) -> Mapping:
    """sjkr's lens area as ``cohesion sjkr``, its band as ``cohesion sjkr2`` (cohesionEnergyDensity kc), on the
    elastic ``hertz/stiffness`` law: the laws as LIGGGHTS computes them (tests/test_laws_beyond_liggghts.py)."""
    if base.native is None:
        return base
    nat, rec = base.native, model.slot("adhesion")
    if nat.normal != "hertz/stiffness" or nat.props.get("gamman", 0.0) != 0.0:
        return refused("liggghts", "the sjkr pull-off is written for the elastic hertz/stiffness law "
                                   f"(the case maps to {nat.normal}, gamman {nat.props.get('gamman', 0.0):g})")
    name = "sjkr" if rec.area == AREA_LENS else "sjkr2"
    nat.props = {**nat.props, "cohesion": name, "k_c": rec.k_c, "slots": {"adhesion": rec}}
    nat.comments = [*nat.comments, f"cohesion {name}, cohesionEnergyDensity {rec.k_c:g} J/m³: −kc·A added to the "
                                   "normal force while the spheres overlap"]
    return Mapping("liggghts", base.fidelity, list(base.reasons), nat, dict(base.keywords))


def _rolling(model, base: Mapping) -> Mapping:
    """Type A on a wall as ``rolling_friction cdt`` (coefficientRollingFriction μr Rr/R), with the wall's
    hooke/stiffness contact and ``tangential history``."""
    nat, rec = base.native, model.slot("rolling")
    if nat.normal != "hooke/stiffness" or nat.tangential != "history":
        return refused("liggghts", "the rolling scenario is written for hooke/stiffness with tangential history "
                                   f"(the case maps to {nat.normal} / {nat.tangential})")
    r = model.pair.r_eff
    mu = rec.mu_r * rec.r_roll / r
    reasons = [] if rec.full_direction else [
        "cdt takes its direction from the whole relative spin (full_direction): the case's type A takes the "
        "rolling part only — the same torque while the sphere does not spin about the wall's normal"]
    nat.props = {**nat.props, "rolling_friction": mu, "slots": {"rolling": ConstantTorqueRolling(mu, r, True)}}
    nat.comments = [*nat.comments, f"rolling_friction cdt, coefficientRollingFriction {mu:g}"]
    return Mapping("liggghts", APPROXIMATE if reasons else base.fidelity, [*base.reasons, *reasons], nat,
                   {**base.keywords, **{x: "rolling_friction cdt" for x in reasons}})


def _incline(model, base: Mapping) -> Mapping:
    """Type C as ``rolling_friction epsd3``: kr = rollingStiffness·kn·μr²·R² (kn the hooke/stiffness constant),
    the limit on the spring; written without its dashpot (ηr = 0)."""
    nat, rec = base.native, model.slot("rolling")
    if nat.normal != "hooke/stiffness" or nat.tangential != "history":
        return refused("liggghts", "the incline is written for hooke/stiffness with tangential history "
                                   f"(the case maps to {nat.normal} / {nat.tangential})")
    if rec.c_r != 0.0:
        return refused("liggghts", "the incline is written for LIGGGHTS's epsd3 without its dashpot (c_r = 0): "
                                   "its Cr = ηr·2√(Ir kr) on a wall is not checked")
    r = model.pair.r_eff
    mu = rec.mu_r * rec.r_roll / r
    factor = rec.k_r / (nat.props["kn"] * mu * mu * r * r)
    if not factor >= 1.0:
        return refused("liggghts", f"LIGGGHTS requires rollingStiffness ≥ 1 (kr ≥ kn·μr²·R² = "
                                   f"{nat.props['kn'] * mu * mu * r * r:.4g} N·m/rad); the case's kr = {rec.k_r:g}")
    k_r = factor * nat.props["kn"] * mu * mu * r * r
    reasons = [] if rec.cap == CAP_SPRING else [
        "LIGGGHTS's epsd family caps the spring (Ai et al.); the case caps spring + dashpot (no dashpot here)"]
    nat.props = {**nat.props, "rolling_friction": mu, "rolling_model": "epsd3", "rolling_stiffness": factor,
                 "slots": {"rolling": EpsdRolling(mu, r, k_r, 0.0, CAP_SPRING)}}
    nat.comments = [*nat.comments, f"rolling_friction epsd3, coefficientRollingFriction {mu:g}, rollingStiffness "
                                   f"{factor:.10g} (kr = rollingStiffness·kn·μr²·R² = {k_r:.10g} N·m/rad)"]
    return Mapping("liggghts", APPROXIMATE if reasons else base.fidelity, [*base.reasons, *reasons], nat,
                   {**base.keywords, **{x: "rolling_friction epsd3" for x in reasons}})


def twin_laws(engine: Engine, case: Case, nat: Native) -> dict:
    if case.run.scenario == "conduction":
        return {"heat": nat.props["slots"]["heat"]}
    if case.run.scenario == "pull_off":  # hertz/stiffness: kn √R̄ δ^{3/2} (elastic), the cohesion added
        k = nat.props["kn"] * resolve(case).pair.r_eff ** 0.5
        return {"normal": lambda d, rate: k * d ** 1.5, "adhesion": nat.props["slots"]["adhesion"]}
    m = case.mass(0)
    kn, eta = nat.props["kn"], nat.props["gamman"] * m
    damp = nat.props.get("gammat", 0.0) * m if nat.tangential_damping else 0.0
    laws = {"normal": lambda d, rate: kn * d + eta * rate,
            "tangential": (nat.props["kt"], damp, nat.props["friction"]), "arm": 0.5, "truncation": "spring",
            "rolling": nat.props["slots"]["rolling"], "roll_surface_w": True}
    if nat.props.get("rolling_model", "cdt") == "cdt":
        laws["roll_fcrit"] = lambda d, rate: kn * d  # cdt's limit: the elastic part
    else:
        laws["setup_increment"] = True  # the epsd family's set-up step
    return laws


def deck(engine: Engine, case: Case, nat: Native, lay) -> common.Deck:
    if case.run.scenario == "pull_off":
        return _pull_deck(case, nat, lay)
    return _held_deck(case, nat, lay) if case.run.scenario == "conduction" else _wall_deck(case, nat, lay)


DUMP_PULL = ("id", "x", "fx")


def _pull_deck(case: Case, nat: Native, lay) -> common.Deck:
    """The pair at the layout's start, body 0 held by ``fix move`` at rest and body 1 moved along +x at the pull's
    speed (no integrator): x and the force on each body every step."""
    props = {k: v for k, v in nat.props.items() if k not in ("slots", "cohesion", "k_c")}
    plain = replace(nat, props=props)
    matrices = property_matrices(plain, 2, lambda a, b: plain)
    mats = [case.materials[p.material] for p in case.particles]
    model_lines, style, flags = model_setup(plain, matrices, [m.youngs_modulus for m in mats],
                                            [m.poisson_ratio for m in mats])
    kc = fmt(nat.props["k_c"])
    lines = [f"# demcheck scenario {case.run.scenario} ({case.name}); {VERSION_NOTE}",
             *(f"# {c}" for c in nat.comments),
             "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "read_data data.lmp",
             *(f"set atom {i + 1} mass {fmt(case.mass(i))}" for i in range(2)),
             f"neighbor {fmt(max(p.radius for p in case.particles))} bin", "neigh_modify delay 0", *model_lines,
             f"fix m_coh all property/global cohesionEnergyDensity peratomtypepair 2 {kc} {kc} {kc} {kc}",
             f"pair_style gran {style} cohesion {nat.props['cohesion']} {' '.join(flags)}", "pair_coeff * *",
             f"timestep {fmt(lay.dt)}", "group held id 1", "group pulled id 2",
             "fix hold held move linear 0 0 0", f"fix pull pulled move linear {fmt(lay.pull_speed)} 0 0",
             f"dump state all custom 1 {common.DUMP_FILE} {' '.join(DUMP_PULL)}",
             'dump_modify state format "%d %.17g %.17g" sort id', f"run {lay.steps}", ""]
    size = 4 * max(p.radius for p in case.particles) + lay.pull_speed * lay.dt * lay.steps
    box = (np.array(lay.positions).min(axis=0) - size, np.array(lay.positions).max(axis=0) + size)
    held = replace(case, particles=[replace(p, position=tuple(lay.positions[i]), velocity=(0.0, 0.0, 0.0),
                                            angular_velocity=(0.0, 0.0, 0.0)) for i, p in enumerate(case.particles)])
    data = FD.data_file(held, 2, box, f"demcheck: scenario {case.run.scenario} of {case.name}")
    return common.Deck("liggghts", "\n".join(lines), {"data.lmp": data}, dt=lay.dt, check=FD.check_deck)


DUMP_WALL = ("id", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz")


def _wall_deck(case: Case, nat: Native, lay) -> common.Deck:
    """A sphere on a primitive wall (type 2) under gravity, rolling_friction cdt in the pair style and the wall."""
    props = {k: v for k, v in nat.props.items()
             if k not in ("slots", "rolling_friction", "rolling_model", "rolling_stiffness")}
    plain = replace(nat, props=props)
    matrices = property_matrices(plain, 2, lambda a, b: plain)
    model_lines, style, flags = model_setup(plain, matrices, [], [])
    mu, model = nat.props["rolling_friction"], nat.props.get("rolling_model", "cdt")
    style += f" rolling_friction {model}"
    if model == "epsd3":
        model_lines += [f"fix m_rs all property/global rollingStiffness scalar {fmt(nat.props['rolling_stiffness'])}",
                        "fix m_rd all property/global coefficientRollingViscousDamping peratomtypepair 2 0 0 0 0"]
    w = case.walls[0]
    axis = int(np.argmax(np.abs(w.normal)))
    g = np.asarray(case.run.gravity, dtype=float)
    gn = float(np.linalg.norm(g))
    lines = [f"# demcheck scenario {case.run.scenario} ({case.name}); {VERSION_NOTE}",
             *(f"# {c}" for c in nat.comments),
             "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "read_data data.lmp", f"set atom 1 mass {fmt(case.mass(0))}",
             f"neighbor {fmt(case.particles[0].radius)} bin", "neigh_modify delay 0", *model_lines,
             f"fix m_rf all property/global coefficientRollingFriction peratomtypepair 2 {' '.join([fmt(mu)] * 4)}",
             f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *",
             f"fix wall all wall/gran {style} primitive type 2 {'xyz'[axis]}plane {fmt(w.point[axis])} "
             f"{' '.join(flags)}",
             f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(x / gn) for x in g)}",
             "fix integrate all nve/sphere", f"timestep {fmt(lay.dt)}",
             f"dump state all custom {lay.every} {common.DUMP_FILE} {' '.join(DUMP_WALL)}",
             'dump_modify state format "%d' + " %.17g" * (len(DUMP_WALL) - 1) + '" sort id', f"run {lay.steps}", ""]
    pos = np.array(lay.positions[0])
    reach = 4 * case.particles[0].radius + abs(float(np.max(np.abs(lay.velocities[0])))) * lay.dt * lay.steps * 2
    box = (pos - reach, pos + reach)
    p = case.particles[0]
    moved = replace(case, particles=[replace(p, position=tuple(lay.positions[0]), velocity=tuple(lay.velocities[0]),
                                             angular_velocity=tuple(lay.omegas[0]))])
    data = FD.data_file(moved, 2, box, f"demcheck: scenario {case.run.scenario} of {case.name}")
    return common.Deck("liggghts", "\n".join(lines), {"data.lmp": data}, dt=lay.dt, check=FD.check_deck)


def _held_deck(case: Case, nat: Native, lay) -> common.Deck:
    """The held pair: a data file at the layout's positions, the contact's properties, no integrator, the heat fix
    started at body 0's temperature and body 1's set after a ``run 0``."""
    n = len(case.particles)
    props = {k: v for k, v in nat.props.items() if k != "slots"}
    matrices = property_matrices(replace(nat, props=props), n, lambda a, b: replace(nat, props=props))
    mats = [case.materials[p.material] for p in case.particles]
    model_lines, style, flags = model_setup(nat, matrices, [m.youngs_modulus for m in mats],
                                            [m.poisson_ratio for m in mats])
    k = nat.props["slots"]["heat"].k
    t0, t1 = (float(x) for x in case.run.temperatures)
    lines = [f"# demcheck scenario {case.run.scenario} ({case.name}); {VERSION_NOTE}",
             *(f"# {c}" for c in nat.comments),
             "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "read_data data.lmp",
             *(f"set atom {i + 1} mass {fmt(case.mass(i))}" for i in range(n)),
             f"neighbor {fmt(max(p.radius for p in case.particles))} bin", "neigh_modify delay 0", *model_lines,
             f"fix m_k all property/global thermalConductivity peratomtype {' '.join([fmt(k)] * n)}",
             f"fix m_c all property/global thermalCapacity peratomtype {' '.join(fmt(m.specific_heat) for m in mats)}",
             f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *", f"timestep {fmt(lay.dt)}",
             f"fix heat all heat/gran/conduction initial_temperature {fmt(t0)}", "run 0",
             f"set atom 2 property/atom Temp {fmt(t1)}",
             f"dump state all custom {lay.every} {common.DUMP_FILE} id f_Temp",
             'dump_modify state format "%d %.17g" sort id', f"run {lay.steps}", ""]
    box = (np.array(lay.positions).min(axis=0) - 4 * max(p.radius for p in case.particles),
           np.array(lay.positions).max(axis=0) + 4 * max(p.radius for p in case.particles))
    held = replace(case, particles=[replace(p, position=tuple(lay.positions[i]), velocity=(0.0, 0.0, 0.0),
                                            angular_velocity=(0.0, 0.0, 0.0)) for i, p in enumerate(case.particles)])
    data = FD.data_file(held, n, box, f"demcheck: scenario {case.run.scenario} of {case.name}")
    return common.Deck("liggghts", "\n".join(lines), {"data.lmp": data}, dt=lay.dt, check=FD.check_deck)


def read(engine: Engine, case: Case, lay, workdir) -> dict:
    """The held pair's temperatures, sampled from step 0 (the dump after ``run 0`` starts at the run's step 0);
    the rolling sphere's samples."""
    from ..dumps import read_dump

    if case.run.scenario == "pull_off":
        t = read_dump(Path(workdir) / common.DUMP_FILE, columns=DUMP_PULL).sort_values(["step", "id"])
        x, f = t["x"].to_numpy(), t["fx"].to_numpy()
        return {"delta": sum(p.radius for p in case.particles) - (x[1::2] - x[0::2]), "fn": f[1::2]}
    if case.run.scenario != "conduction":
        t = read_dump(Path(workdir) / common.DUMP_FILE, columns=DUMP_WALL).sort_values("step")
        cols = lambda *n: np.column_stack([t[c].to_numpy() for c in n])  # noqa: E731
        return {"t": t["step"].to_numpy() * lay.dt, "x": cols("x", "y", "z"), "v": cols("vx", "vy", "vz"),
                "omega": cols("omegax", "omegay", "omegaz")}

    table = read_dump(Path(workdir) / common.DUMP_FILE, columns=("id", "f_Temp")).sort_values(["step", "id"])
    steps = table["step"].to_numpy()[::2]
    temps = table["f_Temp"].to_numpy()
    return {"t": (steps - steps[0]) * lay.dt, "dT": temps[1::2] - temps[0::2]}
