"""``demcheck audit``'s probes beyond sliding: the rolling and twisting resistance, adhesion and heat conduction a
user's deck sets on a type pair or wall (the engine's reader keeps them in ``PairSetting.beyond``), each probed
in a scenario of its own (engines/scenario.py) at the deck's parameters, in the deck's units as the collision
probes run:

* rolling — type C (LAMMPS ``rolling sds``, LIGGGHTS ``epsd3``): a sphere of the type's radius and density at rest
  on a rigid plane tilted past its critical angle (``incline``: incline_critical_angle, closed form atan μr);
  type A (LIGGGHTS ``cdt``): a sphere rolling on a level plane at the characteristic speed (``rolling``:
  rolling_stop_time, rolling_distance, closed forms 7v0/(5μr g), 7v0²/(10μr g));
* twisting — a sphere spinning at v/R about the plane's normal (``twist``: twist_stop_time = Iω0/(μtw m g));
* adhesion — LAMMPS ``jkr``/``dmt``: two like spheres pulled apart (``pull_off``: pull_off_force,
  separation_at_pull_off, the textbook's displacement-controlled break) and, for jkr, an impact at the
  characteristic speed (``adhesive_impact``: restitution, capture_velocity; Thornton & Ning 1998); LIGGGHTS
  ``cohesion sjkr``/``sjkr2``: two like spheres on the pair's elastic Hertz law with −kc·A added, pulled apart
  (``pull_off``: the largest tension in closed form);
* Kratos — a relation on ``DEM_D_Hertz_viscous_Coulomb_JKR``/``_DMT``: the pull-off (and JKR's impact) of two like
  spheres of its E* and PARTICLE_COHESION w (:func:`_kratos_cohesive`); a wall relation's ConstantTorque /
  ViscousTorque rolling friction: the level-wall roll on its Linear_viscous_Coulomb law (:func:`_kratos_rolling`);
* heat — LAMMPS ``heat radius/area``, LIGGGHTS ``fix heat/gran/conduction``: two like spheres held at the head-on
  probe's largest overlap (``conduction``: heat_time_constant, Batchelor & O'Brien 1977 for LIGGGHTS).

Each runs three times: the engine and its twin through Source.run (comparisons/sources.py; a scenario case:
engines/scenario.run, the deck its package writes, and engines/scenario.twin) and the closed form
(reference/scenarios.scenario_metrics, closed=True). A probe whose run fails or gives a metric that is not finite
is a failure, never clean; a sub-model the engine's scenario mapping refuses, or one a probe cannot be built for,
is listed with its reason.
"""

from __future__ import annotations

import dataclasses
import math

from ..case import from_dict
from ..errors import ConfigError, DemcheckError, EngineInterrupted, UnsupportedByEngine
from ..inputs import script as deck_script

TWIN_TOL = 1e-9  # engine against its twin at equal step: the mapping's own tolerance
TRAP_TOL = 0.01  # engine against the closed form: a relative difference above 1% is a trap with its size
TEMPERATURES = (300.0, 400.0)  # the held pair's start (τ does not depend on them)
ROLL_SLIP = 1.05  # the incline needs μs above μr by this factor to roll without slip past the critical angle


def probe_pair(setup, ps, entry: dict, run_engine: bool, speed: float | None, kinds: dict, bodies) -> list:
    """The beyond-sliding probes of one pair or wall: entry["beyond"] (one row a probe or a listed sub-model) and
    the findings they measure. ``kinds``: the engine reader's BEYOND_PROBES (slot → the probe that takes it, one of
    MAKERS); ``bodies()``: ((radius, density) of each side, (m̄, R̄)) of the pair, or ScriptError."""
    if not ps.beyond:
        return []
    if ps.size not in ("", "mass-weighted"):
        entry["notes"].append(f"{', '.join(ps.beyond)}: probed beyond sliding at the mass-weighted size only (each "
                              "scenario is of one sphere size)")
        return []
    rows = entry.setdefault("beyond", [])
    found = []
    for slot, sub in ps.beyond.items():
        for label, raw, why, notes in plans(setup, ps, slot, sub, entry, speed, kinds, bodies):
            row = {"slot": slot, "law": sub["words"], "probe": label, "notes": list(notes)}
            if raw is None:
                row.update(status="not probed", why=why)
            else:
                row["case"] = raw  # the scenario case the probe ran (SI keys, in the deck's units)
                row.update(run_probe(setup, raw, run_engine))
            rows.append(row)
            found += judge(ps, row)
    return found


# ----------------------------------------------------------------------------- the cases


def plans(setup, ps, slot: str, sub: dict, entry: dict, speed, kinds: dict, bodies) -> list:
    """[(probe label, the scenario case as a dict or None, why not, notes)] of one sub-model."""
    try:
        sides, effective = bodies()
    except deck_script.ScriptError as exc:
        return [(slot, None, f"no body to probe: {exc}", [])]
    base = {"radius": sides[0][0], "density": sides[0][1], "second": sides[1], "effective": effective}
    maker = MAKERS.get(kinds.get(slot, ""))
    if sub.get("refused"):
        return [(slot, None, sub["refused"], [])]
    if maker is None:
        return [(slot, None, f"{setup.engine}: no probe of its {slot} sub-model in demcheck", [])]
    try:
        return maker(setup, ps, sub, base, entry, speed)
    except (ValueError, ArithmeticError) as exc:
        why = str(exc) if "demcheck has no twin" in str(exc) else f"{type(exc).__name__}: {exc}"
        return [(slot, None, f"the probe cannot be set up: {why}", [])]


def _elastic(setup, ps, base: dict) -> tuple[dict, dict, list]:
    """The sphere-on-a-plane contact of the pair's law: (material, contact keys, notes) — its elastic normal law
    (Hertz with the twin's E*, or LSD with its kn) and a linear tangential spring (a √δ spring taken at the static
    overlap under the sphere's weight), μ the deck's. The normal dashpot is left out (the sphere rests)."""
    from ..engines import registry
    from ..engines.mapping import native_summary
    from ..laws.tangential import SpringTangential, SqrtSpringTangential

    r, rho = base["radius"], base["density"]
    native, notes = ps.native, ["the contact's elastic normal law on a rigid plane (its dashpot left out: the "
                                "sphere rests)"]
    if ps.j is not None and ps.j != ps.i:
        notes.append(f"the sphere is type {ps.i}'s (radius {r:g}, density {rho:g}) under the pair's law")
    if "adhesion" in ps.beyond and _replaces_normal(ps.beyond["adhesion"]):  # its Hertz part, E and ν
        e_mod, _, nu, _ = ps.beyond["adhesion"]["args"]
        native = dataclasses.replace(native, normal="hertz/material", normal_args=(e_mod, nu))
        notes.append(f"the Hertz part of {ps.beyond['adhesion']['law']} (E {e_mod:g}, ν {nu:g}); its adhesion is "
                     "the pull-off probe's")
    if not ps.probe and native is ps.native:
        raise ValueError(f"the sphere rests on the contact's normal law ({native_summary(native)}), of which "
                         "demcheck has no twin")
    nl, tl = registry.get(setup.engine).twin(native, *base["effective"])
    m = rho * 4.0 / 3.0 * math.pi * r ** 3
    g = setup.gravity[0]
    mat = {"density": rho, "restitution": 0.9, "friction": tl.mu_s, "poisson_ratio": 0.3}
    elastic, spring = _elastic_id(nl), tl.slot()
    if elastic == "hertz":
        e_star = nl.k / (4.0 / 3.0 * math.sqrt(base["effective"][1]))
        mat["youngs_modulus"] = e_star * (1.0 - 0.09)
        contact = {"normal": "hertz"}
        delta = (m * g / (4.0 / 3.0 * e_star * math.sqrt(r))) ** (2.0 / 3.0)
    elif elastic == "hooke":
        mat["youngs_modulus"] = 1e9
        contact = {"normal": "lsd", "kn": nl.k}
        delta = m * g / nl.k
    else:
        raise ValueError(f"the normal law {_law_text(nl)} has no sphere-on-plane probe")
    if isinstance(spring, SpringTangential) and tl.mu_s > 0:
        kt = spring.kt * (math.sqrt(r * delta) if isinstance(spring, SqrtSpringTangential) else 1.0)
        if isinstance(spring, SqrtSpringTangential):
            notes.append(f"the √(R̄δ) tangential spring taken at the static overlap: kt = {kt:.6g}")
        contact.update(tangential="spring_sliding", kt=kt)
    return mat, contact, notes


def _record(slot: str, sub: dict, required: bool = True) -> type | None:
    """The record class of the law a deck's sub-model reads back to (its reader names it by the law's id where
    demcheck has the law); where demcheck has none of that name (an engine's own word: cdt, sjkr2), None — or,
    ``required``, a ValueError (the probe is listed with it)."""
    from ..laws.slots import law_class

    law = law_class(slot, sub["law"])
    if law is None and required:
        raise ValueError(f"{slot} {sub['law']}: demcheck has no twin of this law")
    return law


def _replaces_normal(sub: dict) -> bool:
    """An adhesion that is the whole elastic normal law (JKR, DMT: its args E, η, ν, γ)."""
    law = _record("adhesion", sub, required=False)
    return law is not None and law.replaces_normal


def _elastic_id(nl) -> str:
    """The id of a law's elastic record (``hooke``, ``hertz``, ``hls``: NormalLaw.slots), never its exponent."""
    return nl.slots()[0].id


def _law_text(nl) -> str:
    """A law's elastic record as a reason names it: F ∝ δ^a for a power-law spring, else its id and title."""
    normal = nl.slots()[0]
    exponent = getattr(normal, "exponent", None)
    return f"F ∝ δ^{exponent:g}" if exponent is not None else f"'{normal.id}' ({normal.title})"


def _on_plane(name: str, mat: dict, radius: float, contact: dict, scenario: str, gravity, velocity=(0, 0, 0),
              spin=(0, 0, 0)) -> dict:
    return {"name": name, "kind": "collision", "materials": {"a": mat},
            "particles": [{"material": "a", "radius": radius, "position": [0.0, 0.0, radius],
                           "velocity": list(velocity), "angular_velocity": list(spin)}],
            "walls": [{"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}], "contact": contact,
            "run": {"scenario": scenario, "gravity": list(gravity)}}


def _gravity_or_none(setup):
    return None if setup.gravity is None or not setup.gravity[0] > 0 else setup.gravity[0]


def _incline(setup, ps, base, mu_r: float, rolling: dict, label: str) -> tuple:
    """The incline of a type C law: tilted so that tan θ sits between μr and the steepest slope the deck's μs
    lets the sphere roll down without slip ((7μs − 5μr)/2), at most 2μr."""
    g = _gravity_or_none(setup)
    if g is None:
        return label, None, "the deck sets no gravity: a sphere on a plane has no load to roll under", []
    mat, contact, notes = _elastic(setup, ps, base)
    mu_s = mat["friction"]
    upper = min(2.0 * mu_r, (7.0 * mu_s - 5.0 * mu_r) / 2.0)
    if "tangential" not in contact or not upper > ROLL_SLIP * mu_r:
        return label, None, (f"μs = {mu_s:g} against μr = {mu_r:g}: a sphere slides before it rolls (rolling without "
                             "slip past the critical angle needs μs > μr), so no incline measures the rolling "
                             "resistance"), notes
    tan = 0.5 * (mu_r + upper)
    theta = math.atan(tan)
    notes.append(f"tilted {math.degrees(theta):.3f}° (tan θ = {tan:.4g}; the critical angle is atan μr)")
    raw = _on_plane(f"audit-{label}", mat, base["radius"], {**contact, **rolling}, "incline",
                    (g * math.sin(theta), 0.0, -g * math.cos(theta)))
    return label, raw, "", notes


def _sds_incline(setup, ps, sub, base, entry, speed) -> list:
    k, gamma, mu = sub["args"]
    r = base["radius"]
    rolling = {"rolling": "epsd", "mu_r": mu, "k_r": k * r * r, "c_r": gamma * r * r, "cap": "total",
               "slack_zero": True}
    return [_incline(setup, ps, base, mu, rolling, f"incline ({ps.label})")]


def _twisting(setup, ps, sub, base, entry, speed) -> list:
    label = f"twist ({ps.label})"
    g = _gravity_or_none(setup)
    if g is None:
        return [(label, None, "the deck sets no gravity: a spinning sphere on a plane has no load", [])]
    if not speed:
        return [(label, None, "no characteristic speed to set the spin by", [])]
    law = _record("twisting", sub)
    mat, contact, notes = _elastic(setup, ps, base)
    if not law.from_contact_radius:  # its own coefficients (LAMMPS twisting sds k γ μ)
        k, gamma, mu = sub["args"]
        contact = {k_: v for k_, v in contact.items() if k_ not in ("tangential", "kt")}
        contact.update(twisting=law.id, k_tw=k, gamma_tw=gamma, mu_tw=mu)
    else:
        if "tangential" not in contact:
            return [(label, None, f"twisting {law.id} is built from the tangential spring and μ: the deck's has none",
                     notes)]
        contact.update(twisting=law.id, mu_t=mat["friction"])
        notes.append("marshall's coefficients from the probe's tangential spring (kt, μs; its dashpot left out)")
    omega = speed / base["radius"]
    notes.append(f"spun at ω0 = v/R = {omega:.6g} (the characteristic speed over the radius)")
    return [(label, _on_plane(f"audit-{label}", mat, base["radius"], contact, "twist", (0.0, 0.0, -g),
                              spin=(0.0, 0.0, omega)), "", notes)]


def _pair_bodies(name: str, mat: dict, radius: float, contact: dict, run: dict, impact: float | None = None) -> dict:
    raw = {"name": name, "kind": "collision", "materials": {"a": mat},
           "particles": [{"material": "a", "radius": radius, "position": [0.0, 0.0, 0.0]},
                         {"material": "a", "radius": radius, "position": [2.0 * radius, 0.0, 0.0]}],
           "contact": contact, "run": run}
    if impact is not None:
        raw["impact"] = {"speed": impact}
    return raw


def _jkr_dmt(setup, ps, sub, base, entry, speed) -> list:
    """``jkr E η ν γ`` / ``dmt E η ν γ``: two like spheres of E, ν, w = 2γ (LAMMPS's surface energy γ), pulled
    apart; jkr also at the characteristic speed."""
    e_mod, eta, nu, gamma = sub["args"]
    if ps.j is None:
        return [(f"pull-off ({ps.label})", None, "the adhesive probes are of two like spheres; a wall's adhesion "
                 "is the same law against a rigid plane, not a scenario of its own", [])]
    mat = {"density": base["density"], "youngs_modulus": e_mod, "poisson_ratio": nu, "restitution": 0.9}
    contact = {"normal": "hertz", "adhesion": sub["law"], "w": 2.0 * gamma}
    notes = [f"w = 2γ = {2 * gamma:g}; E = {e_mod:g}, ν = {nu:g}"
             + (f"; the deck's normal dashpot ({eta:g}) left out (the probes are elastic)" if eta else "")]
    out = [(f"pull-off ({ps.label})", _pair_bodies(f"audit-pull-off-{ps.label}", mat, base["radius"], contact,
                                                    {"scenario": "pull_off"}), "", notes)]
    if "adhesive_impact" in _record("adhesion", sub).scenarios and speed:
        out.append((f"adhesive impact ({ps.label})",
                    _pair_bodies(f"audit-impact-{ps.label}", mat, base["radius"], contact,
                                 {"scenario": "adhesive_impact"}, impact=speed),
                    "", [*notes, f"head-on at the characteristic speed {speed:g}"]))
    return out


def _heat(setup, ps, sub, base, entry, speed) -> list:
    """The held pair: two like spheres at the head-on probe's largest overlap, conducting by the deck's law
    (LAMMPS ``heat radius ks``/``area hs``; LIGGGHTS fix heat/gran/conduction, asked as Batchelor & O'Brien's
    2ks a with ks = 2k0k1/(k0+k1))."""
    from ..laws.heat import LensHeat

    label = f"conduction ({ps.label})"
    if ps.j is None:
        return [(label, None, "the heat probe holds two spheres; a wall's conduction (a wall temperature) is not "
                              "a probe scenario", [])]
    heat = setup.heat
    cps = [heat.get("cp", {}).get(t, heat.get("cp_all")) for t in (ps.i, ps.j)]
    if None in cps:
        return [(label, None, "the deck gives no heat capacity for these types (LAMMPS fix heat/flow; LIGGGHTS "
                              "thermalCapacity)", [])]
    if issubclass(_record("heat", sub), LensHeat):  # LIGGGHTS: the types' conductivities, mixed
        ks = [heat.get("k", {}).get(t, heat.get("k_all")) for t in (ps.i, ps.j)]
        if None in ks:
            return [(label, None, "the deck gives no thermalConductivity for these types", [])]
        k, law = (2.0 * ks[0] * ks[1] / (ks[0] + ks[1]) if ks[0] + ks[1] > 0 else 0.0), "radius"
    else:
        k, law = sub["args"][0], sub["law"]
    if not k > 0:
        return [(label, None, f"conductivity {k:g}: nothing conducts, no time constant to probe", [])]
    overlap, where = _held_overlap(entry, base["radius"])
    rho = base["density"]
    mats = {"a": {"density": rho, "youngs_modulus": 1e9, "poisson_ratio": 0.3, "restitution": 0.9,
                  "specific_heat": cps[0]},
            "b": {"density": base["second"][1], "youngs_modulus": 1e9, "poisson_ratio": 0.3,
                  "restitution": 0.9, "specific_heat": cps[1]}}
    r2 = base["second"][0]
    raw = {"name": f"audit-conduction-{ps.label}", "kind": "collision", "materials": mats,
           "particles": [{"material": "a", "radius": base["radius"], "position": [0.0, 0.0, 0.0]},
                         {"material": "b", "radius": r2, "position": [base["radius"] + r2, 0.0, 0.0]}],
           "contact": {"normal": "hertz", "heat": law, "k": k},
           "run": {"scenario": "conduction", "temperatures": list(TEMPERATURES), "overlap": overlap}}
    return [(label, raw, "", [f"held at overlap {overlap:.4g} ({where}); c_p {cps[0]:g}, {cps[1]:g}",
                              f"conductance law {law}, k = {k:g}"])]


def _held_overlap(entry: dict, radius: float) -> tuple[float, str]:
    for p in entry.get("probes", []):
        m = p.get("engine", p.get("twin", {})) if "error" not in p else {}
        mo = m.get("max_overlap", math.nan)
        if isinstance(mo, float) and math.isfinite(mo) and 0 < mo < radius:
            return mo, "the head-on probe's largest overlap"
    return 0.01 * radius, "1% of the radius: no collision probe gave an overlap"


def _cdt_epsd3(setup, ps, sub, base, entry, speed) -> list:
    mu, stiffness, damping = sub["args"]
    law = sub["law"]
    label = f"{'rolling' if law == 'cdt' else 'incline'} ({ps.label})"
    if mu is None:
        return [(label, None, "rolling_friction needs coefficientRollingFriction (LIGGGHTS stops without it)", [])]
    if law not in ("cdt", "epsd3"):
        return [(label, None, f"rolling_friction {law}: demcheck's LIGGGHTS scenario decks write cdt (rolling) and "
                              "epsd3 (incline) only", [])]
    g = _gravity_or_none(setup)
    if g is None:
        return [(label, None, "the deck sets no gravity: a sphere on a plane has no load to roll under", [])]
    if law == "epsd3":
        return [_incline(setup, ps, base, mu, {"rolling": "epsd", "mu_r": mu, "k_r": _epsd3_kr(setup, ps, base,
                                                                                              mu, stiffness)},
                         label)]
    if not speed:
        return [(label, None, "no characteristic speed to roll at", [])]
    mat, contact, notes = _elastic(setup, ps, base)
    contact.update(rolling="constant_torque", mu_r=mu, full_direction=True)
    notes.append(f"rolling at the characteristic speed {speed:g}, ω = v/R")
    return [(label, _on_plane(f"audit-{label}", mat, base["radius"], contact, "rolling", (0.0, 0.0, -g),
                              velocity=(speed, 0.0, 0.0)), "", notes)]


def _epsd3_kr(setup, ps, base, mu, stiffness) -> float:
    from ..engines import registry

    if stiffness is None:
        raise ValueError("rolling_friction epsd3 needs rollingStiffness")
    nl, _ = registry.get(setup.engine).twin(ps.native, *base["effective"])
    return stiffness * nl.k * mu * mu * base["radius"] ** 2


def _sjkr(setup, ps, sub, base, entry, speed) -> list:
    """LIGGGHTS ``cohesion sjkr``/``sjkr2`` (cohesionEnergyDensity kc): two like spheres of the pair's type on the
    pair's elastic Hertz law (E* read off the engine's twin of the deck's law, its dashpot left out), the cohesion
    −kc·A added (A the lens for sjkr, the band 2πR_xδ for sjkr2), pulled apart (``pull_off``: pull_off_force, the
    largest tension of Hertz + kc·A in closed form; the contact ends at δ = 0)."""
    from ..engines import registry

    (kc,) = sub["args"]
    label = f"pull-off ({ps.label})"
    if kc is None:
        return [(label, None, "cohesion needs cohesionEnergyDensity (LIGGGHTS stops without it)", [])]
    notes = [_sjkr_check(ps, sub["law"], kc, base, entry)]
    if ps.j is None:
        return [(label, None, "the pull-off probe holds two like spheres; a wall's cohesion is the same law against "
                              "a rigid plane, not a scenario of its own", notes)]
    if ps.j != ps.i and tuple(base["second"]) != (base["radius"], base["density"]):
        return [(label, None, f"types {ps.i} and {ps.j} differ in size or density: the sjkr pull-off's closed form "
                              "is of two like spheres", notes)]
    nl, _ = registry.get(setup.engine).twin(ps.native, *base["effective"])
    if _elastic_id(nl) != "hertz":
        return [(label, None, f"the sjkr pull-off's closed form rests on an elastic Hertz law; the pair's normal "
                              f"law is {_law_text(nl)}", notes)]
    e_star = nl.k / (4.0 / 3.0 * math.sqrt(base["effective"][1]))
    nu = 0.3
    mat = {"density": base["density"], "youngs_modulus": 2.0 * (1.0 - nu * nu) * e_star, "poisson_ratio": nu,
           "restitution": 0.9}
    contact = {"normal": "hertz", "adhesion": "sjkr", "k_c": kc, "area": "band" if sub["law"] == "sjkr2" else "lens"}
    notes.append(f"E* = {e_star:.6g} of the pair's Hertz law (its dashpot left out: the pull is quasi-static); "
                 f"kc = {kc:g}, area {contact['area']}")
    return [(label, _pair_bodies(f"audit-pull-off-{ps.label}", mat, base["radius"], contact,
                                 {"scenario": "pull_off"}), "", notes)]


def _sjkr_check(ps, law_id: str, kc: float, base: dict, entry: dict) -> str:
    """The set-up check of a simplified JKR cohesion: its pull −kc·A (A the lens of sjkr, the band 2πR_xδ of
    sjkr2) at the head-on collision probe's largest overlap, against that probe's peak normal force."""
    from ..laws.adhesion import AREA_BAND, AREA_LENS, SjkrAdhesion, adhesive_force

    r0 = base["radius"]
    r1 = base["second"][0] if base["second"] else r0
    delta, where = _held_overlap(entry, min(r0, r1))
    law = SjkrAdhesion(kc, AREA_BAND if law_id == "sjkr2" else AREA_LENS, ps.j is None, r0, r1)
    pull = -adhesive_force(law, delta, 1.0)[0]
    peaks = [p.get("engine", p.get("twin", {})).get("peak_force", math.nan) for p in entry.get("probes", [])
             if "error" not in p]
    peak = peaks[0] if peaks else math.nan
    text = f"set-up check: at overlap {delta:.4g} ({where}) the cohesion pulls {pull:.4g}"
    if math.isfinite(peak) and peak > 0:
        text += (f", {pull / peak:.3g} of the head-on probe's peak normal force {peak:.4g} (its collision runs "
                 "without it)")
    return text


def _kratos_cohesive(setup, ps, sub, base, entry, speed) -> list:
    """Kratos' ``DEM_D_Hertz_viscous_Coulomb_JKR``/``_DMT`` (args: the relation's E*, the first material's ν, its
    PARTICLE_COHESION w): LAMMPS's jkr/dmt probes with two like spheres of that E* (E = 2(1 − ν²)E*) and w."""
    e_star, nu, w = sub["args"]
    e_mod = 2.0 * (1.0 - nu * nu) * e_star
    out = _jkr_dmt(setup, ps, {**sub, "args": (e_mod, 0.0, nu, 0.5 * w)}, base, entry, speed)
    note = (f"w = PARTICLE_COHESION = {w:g}; E* = {e_star:.6g} of the relation (two like spheres of E = {e_mod:.6g}, "
            f"ν = {nu:g}); the relation's DAMPING_GAMMA left out (the probes are elastic)")
    return [(label, raw, why, [note, *notes[1:]] if raw is not None else notes) for label, raw, why, notes in out]


def _kratos_rolling(setup, ps, sub, base, entry, speed) -> list:
    """A Kratos wall relation's rolling friction model (args: ROLLING_FRICTION_WITH_WALLS, STATIC_FRICTION, Kratos'
    Kt/Kn): a sphere of the relation's particle rolling on a level wall at the characteristic speed, on the
    relation's DEM_D_Linear_viscous_Coulomb (Kn of its E* on a wall, Kt = (Kt/Kn)·Kn, μ = STATIC_FRICTION), with
    type A μr = ROLLING_FRICTION_WITH_WALLS (Kratos' torque μ|Fn|(R − δ): Rr = R) or type B Cr = μ W R²."""
    from ..engines import registry

    coef, mu, ratio = sub["args"]
    label = f"rolling ({ps.label})"
    g = _gravity_or_none(setup)
    if g is None:
        return [(label, None, "the project sets no gravity: a sphere on a wall has no load to roll under", [])]
    if not speed:
        return [(label, None, "no characteristic speed to roll at", [])]
    r, rho = base["radius"], base["density"]
    nl, _ = registry.get(setup.engine).twin(ps.native, *base["effective"])  # the relation's law on the wall
    if _elastic_id(nl) != "hooke":
        raise ValueError(f"the rolling probe is of a linear normal law; the relation's is {_law_text(nl)}")
    kn = nl.k
    mat = {"density": rho, "restitution": ps.asked.get("restitution") or 0.9, "friction": mu,
           "youngs_modulus": 1e9, "poisson_ratio": 0.3}
    contact = {"normal": "lsd", "kn": kn, "tangential": "spring_sliding", "kt": ratio * kn}
    weight = rho * 4.0 / 3.0 * math.pi * r ** 3 * g
    if _record("rolling", sub).stops:  # type A (ConstantTorque), else type B (ViscousTorque)
        contact.update(rolling="constant_torque", mu_r=coef, full_direction=True)
        what = f"type A μr = {coef:g} (Rr = R)"
        roll = f"rolling at the characteristic speed {speed:g}, ω = v/R"
    else:
        contact.update(rolling="viscous", c_r=coef * weight * r * r)
        what = f"type B Cr = {coef:g}·W·R² = {coef * weight * r * r:.6g} N·m·s"
        speed, roll = _viscous_roll_speed(speed, coef, mu)
    notes = [f"{ps.native.normal}: Kn = {kn:.6g} N/m of E* {ps.native.normal_args[0]:.6g} on a wall, Kt = "
             f"{ratio:.4g}·Kn (4G*/E* of the two materials), μ = STATIC_FRICTION {mu:g} (Kratos' μ at no slip); "
             f"{what}", roll]
    return [(label, _on_plane(f"audit-{label}", mat, r, contact, "rolling", (0.0, 0.0, -g),
                              velocity=(speed, 0.0, 0.0)), "", notes)]


def _viscous_roll_speed(speed: float, coef: float, mu: float) -> tuple[float, str]:
    """The speed a type B probe rolls at, and its note. Kratos' ViscousTorque Cr = c·W·R² rolls without slip
    while Cr ≤ 1.4 μ m g R²/v0 (case.rolling_grip), i.e. v0 ≤ 1.4 μ/c whatever the sphere: past it the sphere
    slides and the scenario has no closed form, so the probe rolls at half that bound instead of the
    characteristic speed — the deck's rolling law is still exercised, not left unprobed."""
    bound = 1.4 * mu / coef if coef > 0.0 else math.inf
    if speed <= 0.5 * bound:
        return speed, f"rolling at the characteristic speed {speed:g}, ω = v/R"
    slow = 0.5 * bound
    return slow, (f"rolling at {slow:.6g} m/s, ω = v/R: half the no-slip bound 1.4 μ/c = {bound:.6g} m/s of "
                  f"ROLLING_FRICTION_WITH_WALLS c = {coef:g} (at the characteristic speed {speed:g} the sphere "
                  "would slide, and the rolling scenario assumes it rolls)")


# the probe of each kind an engine's reader names in its BEYOND_PROBES (slot → kind)
MAKERS = {"incline_sds": _sds_incline, "twist": _twisting, "pull_off": _jkr_dmt, "held_pair": _heat,
          "rolling_cdt_epsd3": _cdt_epsd3, "pull_off_sjkr": _sjkr, "pull_off_kratos": _kratos_cohesive,
          "rolling_kratos": _kratos_rolling}


# ----------------------------------------------------------------------------- the runs


def run_probe(setup, raw: dict, run_engine: bool) -> dict:
    """The scenario case run in the engine, its twin and the closed form: {status, scenario, fidelity, reasons,
    metrics: {name: {engine, twin, reference}}, engine_vs_twin, engine_vs_reference, twin_vs_reference}."""
    from ..engines import registry
    from ..engines.scenario import mapping as scenario_mapping
    from ..reference.scenarios import scenario_metrics
    from .sources import Source

    try:
        case = from_dict({**raw, "name": _name(raw["name"])})
    except ConfigError as exc:
        return {"status": "not probed", "why": f"the deck's values make no scenario case: {exc}"}
    eng = registry.get(setup.engine)
    out = {"scenario": case.run.scenario}
    mp = scenario_mapping(case, eng)
    out.update(fidelity=mp.fidelity, reasons=list(mp.reasons))
    if mp.native is None:
        return {**out, "status": "not probed", "why": "; ".join(mp.reasons)}
    try:
        ref = scenario_metrics(case, closed=True)
        twin = Source.of(eng, twin=True).run(case)  # a scenario case: engines/scenario.py's twin and run
        res = Source.of(eng).run(case) if run_engine else None
    except EngineInterrupted:
        raise
    except UnsupportedByEngine as exc:
        return {**out, "status": "not probed", "why": str(exc)}
    except (DemcheckError, ValueError, ArithmeticError) as exc:
        return {**out, "status": "failed", "why": f"{type(exc).__name__}: {exc}"}
    sides = {"twin": twin, **({"engine": res} if res is not None else {})}
    out["metrics"] = {k: {"reference": ref[k], **{n: r.metrics().get(k, math.nan) for n, r in sides.items()}}
                      for k in ref}
    bad = [f"{n}: {r.status}: {r.message}" for n, r in sides.items() if not r.ok]
    bad += [f"{n}: {k} is {v[n]}" for k, v in out["metrics"].items() for n in sides
            if not math.isfinite(v[n]) and not (k == "capture_velocity" and not math.isfinite(v["reference"]))]
    if bad:
        return {**out, "status": "failed", "why": "; ".join(bad)[:400]}
    main = "engine" if res is not None else "twin"
    zero = _zero_scale(case)
    out["engine_vs_twin"] = _engine_vs_twin(out, zero) if res is not None else math.nan
    out["engine_vs_reference"] = {k: _ratio(v[main], v["reference"], zero) for k, v in out["metrics"].items()}
    out["twin_vs_reference"] = {k: _ratio(v["twin"], v["reference"], zero) for k, v in out["metrics"].items()}
    out["status"] = "ok"
    out["dt"] = twin.dt
    return out


def _name(text: str) -> str:
    """A case name from a probe's label (a pair label holds × and spaces)."""
    import re

    return re.sub(r"[^A-Za-z0-9_.-]+", "-", text.replace("×", "x")).strip("-")[:200] or "audit-beyond"


def _zero_scale(case) -> float:
    """What a metric whose closed form is 0 is measured against: a pull's overlap scale (DMT breaks at δ = 0; the
    sampled path locates it to 1e-4 of that scale), else 0."""
    if case.run.scenario != "pull_off":
        return 0.0
    from ..engines.scenario import overlap_scale

    return overlap_scale(case)


def _ratio(x: float, ref: float, zero: float = 0.0) -> float:
    """x/ref (1 exact); ref = 0 (DMT's separation at pull-off): 1 when |x| is within 1e-3 of ``zero`` (the
    scenario's scale), else inf."""
    if ref == 0.0:
        return 1.0 if abs(x) <= 1e-3 * zero else math.inf
    if not (math.isfinite(x) and math.isfinite(ref)):
        return 1.0 if x == ref or (math.isnan(x) and math.isnan(ref)) else math.nan
    return x / ref


def _engine_vs_twin(out: dict, zero: float) -> float:
    """The largest relative engine − twin difference; a pull's separation measured against the pull's scale."""
    metrics = dict(out["metrics"])
    return _gap(metrics, "engine", "twin", zero) if metrics else math.nan  # nothing left to compare: no number


def _gap(metrics: dict, a: str, b: str, zero: float = 0.0) -> float:
    worst = 0.0
    for k, v in metrics.items():
        x, y = v[a], v[b]
        if math.isnan(x) and math.isnan(y):
            continue
        if not (math.isfinite(x) and math.isfinite(y)):
            return math.inf
        floor = zero if k == "separation_at_pull_off" and zero > 0 else 1e-300
        worst = max(worst, abs(x - y) / max(abs(y), floor))
    return worst


def judge(ps, row: dict) -> list:
    """The findings of one beyond probe: failed (never clean), the engine off its twin, and each metric more than
    1% off the closed form, with the mapping's reasons naming the cause."""
    status = row.get("status")
    if status == "failed":
        return [deck_script.Finding("trap", "beyond-probe-failed", f"{row['probe']}: the probe of {row['law']} did "
                                    f"not run to a result: {row['why']}", ps.where)]
    if status != "ok":
        return []
    found = []
    if math.isfinite(row["engine_vs_twin"]) and row["engine_vs_twin"] > TWIN_TOL or math.isinf(row["engine_vs_twin"]):
        found.append(deck_script.Finding("trap", "beyond-engine-vs-twin", f"{row['probe']}: the engine differs from "
                                         f"its twin of {row['law']} by {row['engine_vs_twin']:.3g}", ps.where,
                                         {"difference": row["engine_vs_twin"]}))
    off = {k: q for k, q in row["engine_vs_reference"].items() if not (abs(q - 1.0) <= TRAP_TOL)}
    if off:
        which = "engine" if "engine" in next(iter(row["metrics"].values())) else "twin"
        parts = [f"{k} {row['metrics'][k][which]:.4g} against {row['metrics'][k]['reference']:.4g} ({q:.3f}×)"
                 for k, q in off.items()]
        why = "; ".join(row.get("reasons", [])) or "no mapping reason: the engine's formula as the twin computes it"
        found.append(deck_script.Finding("trap", f"beyond-{row['scenario'].replace('_', '-')}",
                                         f"{row['probe']}, {row['law']}: " + ", ".join(parts)
                                         + f" by the closed form — {why}", ps.where,
                                         {"ratios": off, "source": which}))
    return found


def coverage(pairs: list) -> dict:
    """How many beyond-sliding sub-models the deck sets (rows), how many probes ran to a result, failed, or are
    listed with a reason."""
    rows = [r for p in pairs for r in p.get("beyond", [])]
    return {"total": len(rows), "probed": sum(r.get("status") == "ok" for r in rows),
            "failed": sum(r.get("status") == "failed" for r in rows),
            "listed": sum(r.get("status") == "not probed" for r in rows)}


def text_lines(p: dict) -> list[str]:
    """The beyond-sliding probes of one pair entry as report lines."""
    lines = []
    for r in p.get("beyond", []):
        head = f"  beyond: {r.get('probe', r['slot'])} — {r.get('law', '')}"
        if r.get("status") != "ok":
            lines.append(f"{head}: {r.get('status', '').upper()}: {r.get('why', '')}")
            lines += [f"    note: {n}" for n in r.get("notes", [])]
            continue
        ms = ", ".join(f"{k} {_g(v.get('engine', v['twin']))} (twin {_g(v['twin'])}, closed form "
                       f"{_g(v['reference'])}, {_g(r['engine_vs_reference'][k])}×)" for k, v in r["metrics"].items())
        lines.append(f"{head}: {r['fidelity']}; {ms}; engine − twin {_g(r['engine_vs_twin'])}")
        lines += [f"    note: {n}" for n in [*r.get("notes", []), *r.get("notes_run", [])]]
        lines += [f"    reason: {x}" for x in r.get("reasons", [])]
    return lines


def _g(x) -> str:
    return f"{x:.4g}" if isinstance(x, (int, float)) else str(x)
