"""The scenarios beyond sliding in LAMMPS 22Jul2025 (``pair_style granular`` sub-models): the slot records of a
case mapped to ``rolling sds``, ``twisting sds``/``marshall``, the ``jkr``/``dmt`` normal models and ``heat
radius``/``area`` (:func:`mapping`), the laws those compute (:func:`twin_laws`, as engines/scenario.step takes
them: the records tests/test_laws_beyond_lammps.py checks against the binary), the deck (:func:`deck`) and its
output read back (:func:`read`).

A sphere on a wall is ``fix wall/gran granular`` with the pair's coefficients and ``fix gravity``; a pull moves
body 1 with ``fix move linear`` (body 0 held by a ``fix move`` at rest: the overlap is imposed, as the pull_off
scenario's); the held pair of the conduction scenario is ``fix move`` at rest with ``fix heat/flow``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...case import Case
from ...inputs import common
from ...inputs.common import fmt
from .. import family_deck as FD
from ...laws.adhesion import BREAK_LOAD, DmtAdhesion, JkrAdhesion, SjkrAdhesion
from ...laws.damping import ConstantDamping, NoDamping
from ...laws.heat import AreaHeat, LensHeat, RadiusHeat
from ...laws.model import resolve
from ...laws.rolling import CAP_TOTAL, ConstantTorqueRolling, EpsdRolling, ViscousRolling
from ...laws.tangential_laws.none import NoTangential
from ...laws.twisting import MarshallTwisting, SdsTwisting
from ..base import APPROXIMATE, EXACT, Engine, Mapping, Native, refused, worst
from ..damping import damping

SLOT = {"rolling": "rolling", "incline": "rolling", "twist": "twisting", "pull_off": "adhesion",
        "adhesive_impact": "adhesion", "conduction": "heat"}
HEAT = {RadiusHeat: "radius", AreaHeat: "area"}  # LAMMPS's heat sub-models by the record they compute
NORMAL = {JkrAdhesion: "jkr", DmtAdhesion: "dmt"}  # its adhesive normal sub-models by the record
COLUMNS = ("id", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz", "fx", "fy", "fz")


def mapping(engine: Engine, case: Case) -> Mapping:
    """The case's contact (``engine``'s mapping) and its scenario's slot record in LAMMPS's words (``nat.props``:
    ``words``, the sub-model's pair_coeff keywords; ``slots``, the records LAMMPS computes)."""
    model = resolve(case)
    slot = SLOT[case.run.scenario]
    rec = model.slot(slot)
    if slot == "adhesion":
        return _adhesion(case, model, rec)
    base = engine.map(model, case.contact.params)
    if base.native is None:
        return base
    nat = base.native
    if case.run.scenario in ("rolling", "incline") and nat.tangential != "linear_history":
        return refused("lammps", "a sphere rolling on a wall needs the case's tangential spring (a linear one: "
                                 "LAMMPS linear_history) to roll without slip")
    made = {"rolling": _rolling, "twisting": _twisting, "heat": _heat}[slot](model, rec, nat)
    if isinstance(made, Mapping):
        return made
    words, twin_rec, fid, reasons = made
    nat.props = {**nat.props, "words": words, "slots": {slot: twin_rec}}
    nat.comments = [*nat.comments, f"{words}: the {slot} slot ({rec.id})"]
    return Mapping("lammps", worst(base.fidelity, fid), [*base.reasons, *reasons], nat,
                   {**base.keywords, **{r: words for r in reasons}})


def _rolling(model, rec, nat: Native):
    r = model.pair.r_eff
    if isinstance(rec, ConstantTorqueRolling) and not rec.full_direction:
        k = nat.tangential_args[0]
        mu = rec.mu_r * rec.r_roll / r
        reason = (f"type A (constant torque) as rolling sds with k_roll = kt = {k:.6g} N/m and no damping: the "
                  "spring winds up to its limit μ_roll R̄|Fn| and holds it while the sphere rolls, and springs "
                  "back at the stop")
        return (f"rolling sds {fmt(k)} 0 {fmt(mu)}", EpsdRolling(mu, r, k * r * r, 0.0, CAP_TOTAL, slack_zero=True),
                APPROXIMATE, [reason])
    if isinstance(rec, EpsdRolling):
        k, gamma, mu = rec.k_r / (r * r), rec.c_r / (r * r), rec.mu_r * rec.r_roll / r
        twin_rec = EpsdRolling(mu, r, k * r * r, gamma * r * r, CAP_TOTAL, slack_zero=True)
        exact = rec.c_r == 0.0 or (rec.cap == CAP_TOTAL and rec.slack_zero)
        reasons = [] if exact else ["LAMMPS rolling sds caps spring + dashpot together at μ_roll|Fn| (and gives "
                                    "no torque from an unstretched spring whose dashpot alone passes it); the case "
                                    "caps the spring and drops the dashpot at the limit (Ai et al.)"]
        return (f"rolling sds {fmt(k)} {fmt(gamma)} {fmt(mu)}", twin_rec, EXACT if exact else APPROXIMATE, reasons)
    if isinstance(rec, ConstantTorqueRolling):
        what = "the direction from the whole relative spin (LIGGGHTS cdt)"
    elif isinstance(rec, ViscousRolling):
        what = "a viscous rolling torque (type B)"
    else:  # a law demcheck gained after this writer (a plug-in law): never read as one it knows
        what = f"the rolling law {rec.id!r}"
    return refused("lammps", f"LAMMPS 22Jul2025 has no rolling model with {what}: its only one is rolling sds")


def _twisting(model, rec, nat: Native):
    if isinstance(rec, SdsTwisting):
        return (f"twisting sds {fmt(rec.k_tw)} {fmt(rec.gamma_tw)} {fmt(rec.mu_tw)}",
                SdsTwisting(rec.k_tw, rec.gamma_tw, rec.mu_tw), EXACT, [])
    if not isinstance(rec, MarshallTwisting):  # a law demcheck gained after this writer (a plug-in law)
        return refused("lammps", f"LAMMPS 22Jul2025 has no twisting model like the twisting law {rec.id!r}: its "
                                 "models are twisting sds and marshall")
    if nat.tangential != "linear_history":  # linear_nohistory takes (x_t, μ) only: no spring to build it from
        return refused("lammps", "LAMMPS twisting marshall takes kt, the damping and μ of the tangential model: "
                                 "the case's tangential spring must be the twisting law's (kt, μt, no damping)")
    kt, x_t, mu = nat.tangential_args
    if not (kt == rec.kt and mu == rec.mu_t and x_t == 0.0 and rec.gamma_t == 0.0):
        return refused("lammps", "LAMMPS twisting marshall takes kt, the damping and μ of the tangential model: "
                                 "the case's tangential spring must be the twisting law's (kt, μt, no damping)")
    return "twisting marshall", MarshallTwisting(kt, 0.0, mu), EXACT, []


def _heat(model, rec, nat: Native):
    if isinstance(rec, LensHeat):
        return refused("lammps", "LAMMPS heat radius conducts through a = √(R̄δ), not the spheres' intersection "
                                 "circle (LIGGGHTS's rule)")
    if type(rec) not in HEAT:
        return refused("lammps", f"LAMMPS 22Jul2025 has no heat model like '{rec.id}' (LAMMPS's are heat "
                                 "radius and heat area)")
    return f"heat {HEAT[type(rec)]} {fmt(rec.k)}", rec, EXACT, []


def _adhesion(case: Case, model, rec) -> Mapping:
    """jkr and dmt replace LAMMPS's normal model: ``jkr E 0 ν γ`` with γ = w/2 (LAMMPS's surface energy)."""
    pair = model.pair
    if isinstance(rec, SjkrAdhesion):
        return refused("lammps", "LAMMPS 22Jul2025 has no simplified JKR cohesion (LIGGGHTS sjkr/sjkr2)")
    if type(rec) not in NORMAL:
        return refused("lammps", f"LAMMPS 22Jul2025 has no adhesive normal model like '{rec.id}' (LAMMPS's are jkr "
                                 "and dmt)")
    if len({p.material for p in case.particles}) != 1 or not isinstance(model.contact.damping, NoDamping):
        return refused("lammps", "the adhesive scenarios are written for like bodies without a normal dashpot")
    if not isinstance(model.contact.tangential, NoTangential):
        return refused("lammps", "the adhesive scenarios are written without a tangential law")
    e_mod, nu = pair.youngs_modulus, pair.poisson_ratio
    word = NORMAL[type(rec)]
    nat = Native("lammps", normal=word, normal_args=(e_mod, nu, 0.5 * rec.w), damping="velocity",
                 damping_coeff=0.0, tangential="linear_nohistory", tangential_args=(0.0, 0.0))
    e_star = e_mod / (2.0 * (1.0 - nu * nu))
    words = f"{word} {fmt(e_mod)} 0 {fmt(nu)} {fmt(0.5 * rec.w)}"
    twin_rec = JkrAdhesion(pair.r_eff, e_star, rec.w, BREAK_LOAD) if rec.necks else \
        DmtAdhesion(pair.r_eff, e_star, rec.w)
    nat.props = {"words": words, "slots": {"adhesion": twin_rec}}
    nat.comments = [f"{words}: E* = E/(2(1−ν²)) = {e_star:.10g} Pa, w = 2γ = {rec.w:g} J/m²"]
    reasons = []
    if rec.necks and rec.break_at != BREAK_LOAD:
        reasons = ["LAMMPS jkr ends the contact at the load-controlled pull-off δ_c = −a_c²/(3R̄) "
                   "(F = −(3/2)πwR̄), not at the displacement-controlled δ_f = −3a_f²/R̄ the case asks for"]
    return Mapping("lammps", APPROXIMATE if reasons else EXACT, reasons, nat, {r: words for r in reasons})


def twin_laws(engine: Engine, case: Case, nat: Native) -> dict:
    """The laws ``nat`` computes, as engines/scenario.step takes them."""
    slots = nat.props.get("slots", {})
    if nat.normal in ("jkr", "dmt"):
        return {"adhesion": slots["adhesion"]}
    model = resolve(case)
    m, r = model.pair.m_eff, model.pair.r_eff
    nl, _ = engine.twin(nat, m, r)
    spring = nl.slots()[0]  # the elastic record: k δ^exponent
    dashpot = damping(nat.damping, nat.damping_coeff, spring, m, r)  # the damping record: η δ^exponent
    c, b = dashpot.eta, dashpot.exponent

    def normal(d, rate):
        return spring.k * d ** spring.exponent + c * d ** b * rate

    laws = {"normal": normal, **slots}
    if nat.tangential == "linear_history":
        kt, x_t, mu = nat.tangential_args
        if x_t and not isinstance(dashpot, (NoDamping, ConstantDamping)):
            from ...errors import UnsupportedByEngine
            raise UnsupportedByEngine(f"the wall twin steps a constant tangential dashpot, not x_t × damping "
                                      f"{nat.damping} (δ^{b:g})")
        laws["tangential"] = (kt, x_t * c, mu)
    return laws


# ----------------------------------------------------------------------------- the deck


def deck(engine: Engine, case: Case, nat: Native, lay) -> common.Deck:
    """The scenario's deck: the bodies as the layout places them, the contact in ``pair_coeff`` (and the wall's
    ``fix wall/gran granular``), dumped every ``lay.every`` steps."""
    s, heat = case.run.scenario, case.run.scenario == "conduction"
    n = len(case.particles)
    lo, hi = _box(case, lay)
    lines = [f"# demcheck scenario {s} ({case.name}); LAMMPS 22 Jul 2025, pair_style granular",
             *(f"# {c}" for c in nat.comments),
             "units si", "atom_style sphere", "atom_modify map array", "boundary f f f", "newton off",
             "comm_modify vel yes",
             f"region box block {fmt(lo[0])} {fmt(hi[0])} {fmt(lo[1])} {fmt(hi[1])} {fmt(lo[2])} {fmt(hi[2])} "
             "units box", f"create_box {n} box"]
    if heat:
        lines.append("fix prop all property/atom temperature heatflow ghost yes")
    for i, p in enumerate(case.particles):
        lines += [f"create_atoms {i + 1} single {' '.join(fmt(x) for x in lay.positions[i])} units box",
                  f"set atom {i + 1} diameter {fmt(2 * p.radius)}", f"set atom {i + 1} mass {fmt(case.mass(i))}",
                  f"set atom {i + 1} vx {fmt(lay.velocities[i][0])} vy {fmt(lay.velocities[i][1])} "
                  f"vz {fmt(lay.velocities[i][2])}",
                  f"set atom {i + 1} omega {' '.join(fmt(x) for x in lay.omegas[i])}"]
        if heat:
            lines.append(f"set atom {i + 1} temperature {fmt(case.run.temperatures[i])}")
    coeff = _coeff(nat)
    lines += [f"neighbor {fmt(max(p.radius for p in case.particles))} bin", "neigh_modify delay 0 every 1 check yes",
              "pair_style granular", f"pair_coeff * * {coeff}"]
    lines += _motion(case, nat, lay, coeff)
    lines += [f"timestep {fmt(lay.dt)}",
              f"dump state all custom {lay.every} {common.DUMP_FILE} {' '.join(COLUMNS)}"
              + (" c_th" if heat else ""),
              "dump_modify state format float %.17g sort id", f"thermo {max(lay.steps // 10, 1)}",
              f"run {lay.steps}", ""]
    return common.Deck("lammps", "\n".join(lines), {}, dt=lay.dt, check=FD.check_deck)


def _coeff(nat: Native) -> str:
    if nat.normal in ("jkr", "dmt"):
        return f"{nat.props['words']} damping velocity tangential linear_nohistory 0 0"
    from .deck import coeff_args

    return f"{coeff_args(nat)} {nat.props['words']}"


def _motion(case: Case, nat: Native, lay, coeff: str) -> list[str]:
    s = case.run.scenario
    if s in ("rolling", "incline", "twist"):
        w = case.walls[0]
        axis = int(np.argmax(np.abs(w.normal)))
        where = f"{fmt(w.point[axis])} NULL" if w.normal[axis] > 0 else f"NULL {fmt(w.point[axis])}"
        g = np.asarray(case.run.gravity, dtype=float)
        gn = float(np.linalg.norm(g))
        return [f"fix wall all wall/gran granular {coeff} {'xyz'[axis]}plane {where}",
                f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(x / gn) for x in g)}",
                "fix integrate all nve/sphere"]
    if s == "adhesive_impact":
        return ["fix integrate all nve/sphere"]
    if s == "pull_off":
        return ["group held id 1", "group pulled id 2", "fix hold held move linear 0 0 0",
                f"fix pull pulled move linear {fmt(lay.pull_speed)} 0 0"]
    cps = [case.materials[p.material].specific_heat for p in case.particles]
    return ["fix hold all move linear 0 0 0", f"fix heat all heat/flow type {' '.join(fmt(c) for c in cps)}",
            "compute th all property/atom temperature"]


def _box(case: Case, lay):
    pos = np.array(lay.positions, dtype=float)
    size = 4.0 * max(p.radius for p in case.particles)
    lo, hi = pos.min(axis=0) - size, pos.max(axis=0) + size
    if case.run.scenario in ("rolling", "incline", "adhesive_impact"):  # a rebound's travel too (a soft, slow contact)
        v = np.abs(np.array(lay.velocities[-1]))
        reach = float(v.max()) * lay.dt * lay.steps + 20.0 * size
        lo, hi = lo - reach, hi + reach
    return lo, hi


# ----------------------------------------------------------------------------- the output


def read(engine: Engine, case: Case, lay, workdir) -> dict:
    """The dump as the run reference/scenarios.stepped_metrics reads."""
    from ..dumps import read_dump

    table = read_dump(Path(workdir) / common.DUMP_FILE, columns=COLUMNS)
    n = len(case.particles)
    rows = table.sort_values(["step", "id"])
    steps = rows["step"].to_numpy()[::n]

    def col(name, body=0):
        return rows[name].to_numpy()[body::n]

    s = case.run.scenario
    if s in ("rolling", "incline", "twist"):
        stack = lambda a, b, c: np.column_stack([col(a), col(b), col(c)])  # noqa: E731
        return {"t": steps * lay.dt, "x": stack("x", "y", "z"), "v": stack("vx", "vy", "vz"),
                "omega": stack("omegax", "omegay", "omegaz")}
    if s == "pull_off":
        return {"delta": sum(p.radius for p in case.particles) - (col("x", 1) - col("x", 0)), "fn": col("fx", 1)}
    if s == "adhesive_impact":
        return {"v_rel": float(col("vx", 1)[-1] - col("vx", 0)[-1]), "touching": bool(col("fx", 1)[-1] != 0.0)}
    return {"t": steps * lay.dt, "dT": col("c_th", 1) - col("c_th", 0)}
