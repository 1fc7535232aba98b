"""The scenarios beyond sliding (``[run] scenario``) in an engine, its twin and the seed model at the engine's step.

One :class:`Layout` per case fixes what is run: the step, the number of steps, the sampling, and the bodies'
start. A sphere on a wall starts at its static overlap under its weight (so that an undamped normal spring does
not bounce), a rolling one at ω = n × v/R (rolling without slip, as the scenario is defined); a pull moves body 1
away at a constant speed; an impact starts 2.5 steps before contact (never on a step: a tie at δ = 0 would be
decided by round-off); the held pair of the conduction scenario sits at the case's overlap. The engine runs it
from a deck its package writes (``scenario.py``: ``mapping``, ``twin_laws``, ``deck``, ``read``), the twin steps
the engine's laws with the engine's scheme (reference/beyond.py: ``verlet_pair`` for a pair, ``verlet_wall`` for a
wall, the law along the imposed path for a pull, explicit Euler for the held pair's temperatures), and the seed
model's verlet run steps the case's own laws the same way. Each run's metrics come from one function
(reference/scenarios.stepped_metrics).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..case import Case, rolling_grip  # noqa: F401  (the no-slip bound of type B: case loading refuses past it)
from ..errors import DemcheckError, UnsupportedByEngine
from ..laws.adhesion import adhesive_force
from ..laws.heat import heat_flow
from ..laws.model import resolve
from ..laws.rolling import ViscousRolling
from ..laws.tangential_laws.none import NoTangential
from ..laws.tangential_laws.spring import SpringTangential
from ..reference import beyond as _b
from ..reference.expected import scenario_closed_forms
from ..reference.scenarios import _on_wall, _twisting_law, metric_names, stepped_metrics
from ..result import Result
from . import registry
from .cache import code_fingerprint, get_metrics, put_metrics

WALL = ("rolling", "incline", "twist")
STEPS_PER_PERIOD = 60  # steps per period of the stiffest spring of a sphere on a wall
PULL_STEPS = 25000  # samples along a pull (every step): the break is located to 2.5e-4 of its overlap
IMPACT_STEPS_PER_CONTACT = 2000
CONDUCTION_STEPS_PER_TAU = 20000  # explicit Euler's error on τ is dt/(2τ) = 2.5e-5
HELD_EVERY = 100  # the held pair's samples, steps apart (fewer where an engine's exchange is faster: _held_every)


@dataclass(frozen=True)
class Layout:
    """What a scenario run is: ``dt``, ``steps``, samples ``every`` steps, the bodies' start (``positions``,
    ``velocities``, ``omegas``: one row a body) and, for a pull, body 1's ``pull_speed`` along +x."""

    scenario: str
    dt: float
    steps: int
    every: int
    positions: tuple
    velocities: tuple
    omegas: tuple
    pull_speed: float = 0.0


def mapping(case: Case, engine):
    """The engine's mapping of the case's contact with its scenario's slot (its package's ``scenario.mapping``),
    or "none" with the reason where the engine has no scenario deck."""
    return _engine(engine).scenario_mapping(case)


def _engine(engine):
    return registry.get(engine) if isinstance(engine, str) else engine


# ----------------------------------------------------------------------------- each law's mapping

# the scenarios that run each slot, and the suite's cases of each (cases/suite/beyond-*.toml)
SLOT_CASES = {"rolling": ("rolling", "rolling-linear", "incline", "incline-linear"), "twisting": ("twist",),
              "adhesion": ("pull-off", "adhesive-impact"), "heat": ("conduction",)}


def _rolling_viscous_example(case: Case) -> dict:
    """c_r for a rolling case that runs another rolling law: half the largest Cr the case's sphere rolls under
    without slip (:func:`rolling_grip`), rounded down to one significant digit (1e-8 N·m·s on the suite's glass
    sphere, whose bound is 2.19e-8), so that the example always rolls."""
    from ..errors import ConfigError

    if case.run.scenario != "rolling":
        return {"c_r": 1e-8}  # any Cr > 0: the scenario refuses type B by its own rule, which the listing shows
    bound = rolling_grip(case)[2]
    if not bound > 0.0:
        raise ConfigError("contact.friction", resolve(case).pair.friction,
                          "a viscous rolling torque (type B) rolls the sphere only with friction on the wall")
    half = 0.5 * bound
    unit = 10.0 ** math.floor(math.log10(half))
    return {"c_r": math.floor(half / unit) * unit}


# a law's parameters where a suite case of its slot runs another law of the slot (its own where the case runs it)
# are its record's ``example``; a function of the case where the value must fit it (type B's Cr: the sphere must
# roll without slip)
EXAMPLE_FITS = {ViscousRolling: _rolling_viscous_example}
KEPT_KEYS = ("kt",)  # also the tangential spring's: never taken out with another law's keys
RANK = {"exact": 0, "approximate": 1}


def law_cases(slot: str, law_id: str) -> tuple[list[Case], list[str]]:
    """The suite's cases of ``slot``'s scenarios with its law set to ``law_id`` (the case's own parameters where it
    runs that law, else its record's ``example`` or EXAMPLE_FITS), and the rules that left the others out (a
    scenario that does not run the law: its ConfigError's text)."""
    import tomllib

    from ..case import from_dict
    from ..errors import ConfigError
    from ..laws.base import sub_model
    from ..laws.slots import KEYS
    from ..resources import case_path

    cases, refusals = [], []
    for name in SLOT_CASES[slot]:
        text = case_path(f"suite/beyond-{name}.toml").read_text()
        raw = tomllib.loads(text)
        contact = raw["contact"]
        try:
            if contact.get(slot, "none") != law_id:
                record = sub_model(slot, law_id)
                example = dict(record.example)
                if record in EXAMPLE_FITS:  # of the suite case as it is: its sphere, wall, friction and speed
                    example = EXAMPLE_FITS[record](from_dict(tomllib.loads(text)))
                for key in KEYS.get((slot, contact.get(slot, "none")), ()):
                    if key.name not in KEPT_KEYS:
                        contact.pop(key.name, None)
                contact[slot] = law_id
                contact.update({k: v for k, v in example.items() if k not in contact})
            cases.append(from_dict(raw))
        except ConfigError as exc:
            refusals.append(str(exc))
    return cases, refusals


def law_mappings(slot: str, law_id: str) -> dict:
    """{engine: {fidelity, config, reason, with}}: each registered engine's scenario mapping of the law, the best
    over the suite's cases of its slot (:func:`law_cases`; exact before approximate before none), ``with`` naming
    that case; ``config`` the engine's words for it, ``reason`` the mapping's reasons (the first case's for none)."""
    cases, refusals = law_cases(slot, law_id)
    out = {}
    for name in registry.names():
        best = None
        for case in cases:
            mp = mapping(case, name)
            if best is None or RANK.get(mp.fidelity, 2) < RANK.get(best[0].fidelity, 2):
                best = (mp, case)
        if best is None:
            out[name] = {"fidelity": "none", "config": "", "with": "no scenario",
                         "reason": "no scenario runs it: " + "; ".join(dict.fromkeys(refusals))}
            continue
        mp, case = best
        words = ""
        if mp.native is not None:
            words = "; ".join([_engine(name).summary(mp.native), *mp.native.comments[-1:]])
        out[name] = {"fidelity": mp.fidelity, "config": words, "reason": "; ".join(mp.reasons),
                     "with": f"scenario {case.run.scenario} ({case.name})"}
    return out


# ----------------------------------------------------------------------------- the layout


def layout(case: Case, laws: dict) -> Layout:
    """The run of ``case`` for the laws ``laws`` (an engine's twin laws: normal, tangential, …)."""
    s = case.run.scenario
    if s in WALL:
        return _wall_layout(case, laws)
    model = resolve(case)
    r0, r1 = (p.radius for p in case.particles)
    if s == "pull_off":
        scale = laws.get("pull_scale") or overlap_scale(case)  # an engine's law may pull from further in
        dt = 1e-6
        speed = 2.5 * scale / (PULL_STEPS * dt)
        # from δ = scale + half a step: no sample lands on δ = 0, where DMT and sjkr let go and round-off would
        # decide which sample is the last in contact
        return Layout(s, dt, PULL_STEPS, 1, ((0.0, 0.0, 0.0), (r0 + r1 - scale - 0.5 * speed * dt, 0.0, 0.0)),
                      ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)), ((0.0, 0.0, 0.0),) * 2, speed)
    if s == "adhesive_impact":
        law, pair = model.slot("adhesion"), model.pair
        t_c = 2.87 * _b._contact_time_scale(law, pair.m_eff, pair.impact_speed)
        dt = t_c / IMPACT_STEPS_PER_CONTACT
        v = pair.impact_speed
        return Layout(s, dt, 6 * IMPACT_STEPS_PER_CONTACT, 100,
                      ((0.0, 0.0, 0.0), (r0 + r1 + 2.5 * v * dt, 0.0, 0.0)), ((0.0, 0.0, 0.0), (-v, 0.0, 0.0)),
                      ((0.0, 0.0, 0.0),) * 2)
    from ..laws.heat import conductance

    c0, c1 = _capacities(case)
    tau = _b.heat_time_constant_closed(conductance(model.slot("heat"), case.run.overlap), c0, c1)
    dt = tau / CONDUCTION_STEPS_PER_TAU
    return Layout(s, dt, int(1.2 * CONDUCTION_STEPS_PER_TAU), _held_every(dt * laws.get("heat_rate", 0.0)),
                  ((0.0, 0.0, 0.0), (r0 + r1 - case.run.overlap, 0.0, 0.0)), ((0.0, 0.0, 0.0),) * 2,
                  ((0.0, 0.0, 0.0),) * 2)


def _held_every(x: float) -> int:
    """The held pair's sampling, steps apart: HELD_EVERY, or fewer where an engine's explicit Euler exchange is
    faster than the case's law — its laws' ``heat_rate`` H(1/C0 + 1/C1), x = dt·H(1/C0 + 1/C1) the fall of T1 − T0
    a step (Yade's ThermalEngine: its H ignores the contact's size). The e-fold time is read between two samples
    (ln(T1 − T0) linear), so the fall between samples, (1 − x)^every, must stay ≥ 1/e: past it the next sample is
    all but round-off (T1 − T0 is a difference of two temperatures: at x = 0.32, 100 steps apart, (1 − x)^100 of
    100 K is 3e-15 K, below their 5.7e-14 K spacing at 350 K; the time constant came out 10 % off forward Euler's).
    x ≥ 1 is no decay at all (the mapping refuses it: engines/yade/pair.py)."""
    if not x > 0.0:
        return HELD_EVERY
    if x >= 1.0:
        return 1
    return int(max(1, min(HELD_EVERY, math.floor(-1.0 / math.log1p(-x)))))


def overlap_scale(case: Case) -> float:
    """The overlap scale of a pull_off case (where its pull starts): JKR's |δ_f|, DMT's Hertz overlap under its
    pull-off force, sjkr's 4 × the Hertz overlap under its largest tension."""
    model = resolve(case)
    law = model.slot("adhesion")
    return _adhesion_scale(law) if law.replaces_normal else _cohesion_scale(case, model)


def _cohesion_scale(case: Case, model) -> float:
    """The overlap scale of an sjkr pull: 4 × the Hertz overlap under the closed form's largest tension (≈ 2.5 × the
    overlap where it acts), so that the pull starts past it."""
    return 4.0 * (scenario_closed_forms(case)["pull_off_force"] / model.normal_law.k) ** (2.0 / 3.0)


def _adhesion_scale(law) -> float:
    """The overlap scale of a pull: JKR's |δ_f| (a law that necks), DMT's Hertz overlap under its pull-off force."""
    if law.necks:
        return abs(law.separation_at_pull_off("displacement"))
    return (law.pull_off_force("load") / (4.0 / 3.0 * law.e_eff * math.sqrt(law.r_eff))) ** (2.0 / 3.0)


def _capacities(case: Case) -> tuple[float, float]:
    return tuple(case.mass(i) * case.materials[p.material].specific_heat for i, p in enumerate(case.particles))


def _wall_layout(case: Case, laws: dict) -> Layout:
    mass, radius, g, theta, n = _on_wall(case)
    normal = laws["normal"]
    weight = mass * g * math.cos(theta)
    delta = brentq(lambda d: normal(d, 0.0) - weight, 0.0, 0.5 * radius, xtol=1e-300, rtol=4 * np.finfo(float).eps)
    k = (normal(1.001 * delta, 0.0) - normal(0.999 * delta, 0.0)) / (0.002 * delta)
    if laws.get("tangential") is not None:
        k = max(k, 3.5 * laws["tangential"][0])  # the slip spring on m·(2/7)
    dt = 2.0 * math.pi * math.sqrt(mass / k) / STEPS_PER_PERIOD
    t_end = _wall_duration(case, mass, radius, g, theta)
    steps = int(math.ceil(t_end / dt))
    p = case.particles[0]
    x0 = np.asarray(case.walls[0].point, dtype=float) + (radius - delta) * n
    omega = tuple(p.angular_velocity)
    if case.run.scenario == "rolling":  # rolling without slip from the start, as the scenario is defined
        omega = tuple(np.cross(n, np.asarray(p.velocity, dtype=float)) / radius)
    return Layout(case.run.scenario, dt, steps, max(1, steps // 4000), (tuple(x0),), (tuple(p.velocity),), (omega,))


def _wall_duration(case: Case, mass: float, radius: float, g: float, theta: float) -> float:
    """1.25 × the closed form's stop (rolling, twist; 1.5 × the time constant of a viscous rolling torque, which
    never stops); the time to roll R/4 down the incline."""
    model = resolve(case)
    if case.run.scenario == "rolling":
        law, p, n = model.slot("rolling"), case.particles[0], np.asarray(case.walls[0].normal, dtype=float)
        v = np.asarray(p.velocity, dtype=float)
        if law.decays:  # type B never stops: 1.5 × its time constant (the e-fold time is measured)
            return 1.5 * _b.rolling_viscous_closed(law.c_r, mass, radius, 1.0)[0]
        return 1.25 * _b.rolling_stop_closed(law.mu_r, law.r_roll, radius, float(np.linalg.norm(v - (v @ n) * n)),
                                            g)[0]
    if case.run.scenario == "twist":
        law = _twisting_law(case, model.slot("twisting"))
        omega = abs(float(np.asarray(case.particles[0].angular_velocity) @ np.asarray(case.walls[0].normal)))
        return 1.25 * _b.twist_stop_closed(mass, radius, omega, law.mu_tw, mass * g * math.cos(theta))
    law = model.slot("rolling")
    acc = _b.incline_closed(law.mu_r, law.r_roll, radius, theta, g)[1]
    return math.sqrt(0.5 * radius / acc) if acc > 0 else 0.5


# ----------------------------------------------------------------------------- stepping the laws


def step(case: Case, laws: dict, lay: Layout) -> dict:
    """The scenario stepped with ``laws`` (normal, fcrit, tangential, rolling, twisting, adhesion, heat) at the
    layout's step: the run reference/scenarios.stepped_metrics reads."""
    s = case.run.scenario
    if "stepper" in laws:  # an engine whose scheme is not fix nve/sphere's (Yade's leap-frog, Kratos' own laws)
        return laws["stepper"](case, laws, lay)
    if s in WALL:
        mass, radius = case.mass(0), case.particles[0].radius
        w = case.walls[0]
        return _b.verlet_wall(radius, mass, lay.positions[0], lay.velocities[0], lay.omegas[0], case.run.gravity,
                              w.point, w.normal, lay.dt, lay.steps, lay.every, normal=laws["normal"],
                              fcrit=laws.get("fcrit"), tangential=laws.get("tangential"),
                              rolling=laws.get("rolling"), twisting=laws.get("twisting"),
                              **{k: laws[k] for k in ("roll_fcrit", "arm", "truncation", "setup_increment", "roll_surface_w")
                                 if k in laws})
    if s == "pull_off":
        return _pull(case, laws["adhesion"], lay, laws.get("normal"))
    if s == "adhesive_impact":
        p = case.particles[0]
        x1, v1 = lay.positions[1][0], lay.velocities[1][0]
        out = _b.verlet_pair(p.radius, case.materials[p.material].density, x1, v1, [0.0] * 3, [0.0] * 3, lay.dt,
                             lay.steps, adhesion=laws["adhesion"])
        return {"v_rel": float(out["v"][-1, 1, 0] - out["v"][-1, 0, 0]), "touching": bool(out["f"][-1, 1, 0] != 0.0)}
    return _held(case, laws["heat"], lay)


def _pull(case: Case, law, lay: Layout, normal=None) -> dict:
    """Body 1 moved at the layout's speed (``fix move``: x = x0 + u·k·dt), body 0 held: the law along the path (a
    cohesion that does not replace the normal law added to ``normal(δ, δ̇)`` while the bodies overlap)."""
    r0, r1 = (p.radius for p in case.particles)
    x0, u = lay.positions[1][0], lay.pull_speed
    deltas, forces, touch = [], [], 0.0
    for k in range(lay.steps + 1):
        delta = (r0 + r1) - (x0 + u * (k * lay.dt))
        f, touch = adhesive_force(law, delta, touch)
        if not law.replaces_normal and delta > 0.0:
            f += normal(delta, -u)
        deltas.append(delta)
        forces.append(f if touch else 0.0)
    return {"delta": np.array(deltas), "fn": np.array(forces)}


def _held(case: Case, law, lay: Layout) -> dict:
    """The held pair's temperatures by explicit Euler after each step (``fix heat/flow``), sampled every
    ``lay.every`` steps from step 0."""
    r0, r1 = (p.radius for p in case.particles)
    delta = (r0 + r1) - lay.positions[1][0]
    c0, c1 = _capacities(case)
    t0, t1 = (float(x) for x in case.run.temperatures)
    diffs = [t1 - t0]
    for k in range(1, lay.steps + 1):
        q = heat_flow(law, delta, t0, t1)
        t0, t1 = t0 + lay.dt * q / c0, t1 - lay.dt * q / c1
        if k % lay.every == 0:
            diffs.append(t1 - t0)
    return {"t": np.arange(len(diffs)) * lay.every * lay.dt, "dT": np.array(diffs)}


def seed_laws(case: Case) -> dict:
    """The case's own laws, in the form :func:`step` takes: the seed model at the engine's step."""
    model = resolve(case)
    nl, tl = model.normal_law, model.contact.tangential

    def normal(d, rate):
        return nl.k * d ** nl.a + nl.eta * d ** nl.b * rate

    tangential = None
    if type(tl) is SpringTangential:  # the constant-kt spring (not sqrt_spring, its subclass)
        tangential = (tl.kt, tl.eta, model.pair.friction)
    elif not isinstance(tl, NoTangential):
        raise UnsupportedByEngine(f"the scenario's seed run steps a tangential spring or none, not '{tl.id}'")
    laws = {"normal": normal, "tangential": tangential}
    laws.update({s: model.slot(s) for s in ("rolling", "twisting", "adhesion", "heat")})
    return laws


# ----------------------------------------------------------------------------- results


def _result(case: Case, source: str, method: str, metrics: dict, lay: Layout, started: float, **extra) -> Result:
    bad = [k for k, v in metrics.items() if not math.isfinite(v)]
    status, message = "ok", extra.pop("message", "")
    if bad and not (case.run.scenario == "adhesive_impact" and bad == ["capture_velocity"]):
        status, message = "failed", f"the {case.run.scenario} run gave no {', '.join(bad)} (not finite)"
        cause = _why_not_finite(case, lay)
        message += f": {cause}" if cause else ""
    meta = {"scenario": case.run.scenario, "scenario_metrics": metrics, **extra.pop("meta", {})}
    return Result(source=source, method=method, case_name=case.name, case_hash=case.hash,
                  model=resolve(case).describe(), params=extra.pop("params", {}), contact=None, dt=lay.dt,
                  wall_time=time.perf_counter() - started, status=status, message=message, meta=meta, **extra)


def _why_not_finite(case: Case, lay: Layout) -> str:
    """The cause of a metric that is not finite, where demcheck knows it: a viscous rolling torque (type B) whose
    speed did not fall to v0/e within the run (1.5 T). (A Cr past the no-slip bound, where the sphere slides, is
    refused when the case loads: case.rolling_grip.)"""
    if case.run.scenario != "rolling" or not resolve(case).slot("rolling").decays:
        return ""
    return f"the speed did not fall to v0/e within the run ({lay.steps * lay.dt:.3g} s)"


def _metrics(case: Case, run: dict) -> dict:
    out = stepped_metrics(case, run)
    return {k: float(out[k]) for k in metric_names(case)}


def twin(case: Case, engine) -> Result:
    """The engine's twin: the engine's laws stepped by demcheck with the engine's scheme, at the engine's layout."""
    eng, started = _engine(engine), time.perf_counter()
    mp = mapping(case, eng)
    laws = eng.scenario_twin_laws(case, mp.require())
    lay = layout(case, laws)
    return _result(case, eng.name + "-twin", "verlet", _metrics(case, step(case, laws, lay)), lay, started)


def seed(case: Case, engine) -> Result:
    """The case's own laws stepped with the engine's scheme at the engine's layout (the time step's part)."""
    eng, started = _engine(engine), time.perf_counter()
    lay = layout(case, eng.scenario_twin_laws(case, mapping(case, eng).require()))
    return _result(case, "reference-verlet", "verlet", _metrics(case, step(case, seed_laws(case), lay)), lay, started)


def cached_metrics(which: str, case: Case, engine, cache=None) -> dict:
    """The metrics of the engine's ``twin`` or of the ``seed`` run (``which``), from ``cache``
    (engines.cache.Cache) when an entry is there: keyed by which run it is, the engine, the case's hash and the
    fingerprint of demcheck's own source and of numpy's, numba's and scipy's versions (:func:`code_fingerprint`), so a changed law, scheme,
    mapping or layout never serves an old result. A metric that is not finite is stored as such (its flag
    column), never as a number."""
    import json

    from .cache import key

    run_it = twin if which == "twin" else seed
    if cache is None:
        return run_it(case, engine).metrics()
    name = _engine(engine).name
    names = metric_names(case)
    k = key(f"scenario-{which}", code_fingerprint(), json.dumps({"case": case.hash, "engine": name}), {})
    hit = get_metrics(cache, k, names)
    if hit is not None:
        return hit[0]
    metrics = run_it(case, engine).metrics()
    put_metrics(cache, k, metrics, {})
    return metrics


def deck(case: Case, engine):
    """The deck (inputs.common.Deck) the engine runs for the scenario case (``demcheck deck``; :func:`run` runs
    this one): UnsupportedByEngine with the mapping's reason where the engine cannot express the case."""
    return _planned_deck(case, _engine(engine))[3]


def _planned_deck(case: Case, eng):
    """(mapping, native, layout, deck) of the engine's run of the scenario case."""
    mp = mapping(case, eng)
    nat = mp.require()
    lay = layout(case, eng.scenario_twin_laws(case, nat))
    return mp, nat, lay, eng.scenario_deck(case, nat, lay)


def run(case: Case, engine, timeout: float | None = None, cache=None) -> Result:
    """The engine's run of the scenario from the deck its package writes, read into the scenario's metrics;
    with ``cache`` (engines.cache.Cache) a run that ended ok is kept as what the engine's reader made of its output
    (:func:`_run_table`), keyed as an engine run is (the engine, its version and build, the deck's commands and its
    files': engines/collide.run_identity) and by the reader's code (:func:`_reader_digest`): a warm verify does not run
    the deck again, nor does one after a change to demcheck's code that leaves the deck and its reader as they were
    (the metrics are computed from the kept output each time)."""
    eng, started = _engine(engine), time.perf_counter()
    mp, nat, lay, dk = _planned_deck(case, eng)
    k = None
    if cache is not None:
        from . import discovery
        from .cache import key
        from .collide import run_identity

        version = discovery.require(eng.name).version
        deck_part, files = run_identity(dk)  # its commands: a case's name or notes never make a run of their own
        k = key(eng.name, version, f"scenario run\0reader {_reader_digest(eng)}\0{deck_part}", files)
        hit = _cached_run(cache, k)
        if hit is not None:
            data, meta = hit
            res = _result(case, eng.name, "engine", _metrics(case, data), lay, started,
                          engine_version=meta["engine_version"], params={"mapping": mp.fidelity,
                                                                         "native": eng.summary(nat)},
                          message="; ".join(mp.reasons),
                          meta={"workdir": "", "deck": dk.text, "fidelity": mp.fidelity, "reasons": list(mp.reasons),
                                "warnings": meta["warnings"], "cached": True})
            if res.ok:
                return res
    res, data = _run_deck(case, eng, mp, nat, lay, dk, timeout, started)
    if k is not None and res.ok:
        _put_run(cache, k, data, {"engine_version": res.engine_version, "warnings": list(res.meta["warnings"])})
    return res


def _reader_digest(eng) -> str:
    """A digest of the code that turns the engine's output into the kept data: the engine package's scenario reader
    (its ``scenario`` part), the LAMMPS family's and the dump readers, and this module (its table layout). A fix to
    any of them reads the runs again (the deck and the engine's version alone would serve the old reading); a change
    elsewhere in demcheck leaves the kept runs valid."""
    import hashlib
    import inspect
    import sys

    from . import dumps, family_read

    reader = eng._part("scenario")
    h = hashlib.sha256()
    for module in (reader, dumps, family_read, sys.modules[__name__]):
        h.update(inspect.getsource(module).encode())
    return h.hexdigest()[:16]


def _run_table(data: dict):
    """(table, layout) of a scenario run's output as the engine's reader made it (``read_scenario``: arrays of one
    length, rows × columns or one column, and numbers or flags), for the run cache: each array's columns in the
    table (an empty one for a run of numbers only), the numbers and flags and each entry's shape in ``layout``; None
    where the arrays' lengths differ."""
    import pandas as pd

    columns, layout = {}, {}
    for name, value in data.items():
        a = np.asarray(value)
        if a.ndim == 0:
            layout[name] = ["flag", bool(a)] if a.dtype == bool else ["number", float(a)]
            continue
        a = a.astype(float).reshape(len(a), -1)
        layout[name] = ["array", a.shape[1] if np.ndim(value) == 2 else 0]
        for j in range(a.shape[1]):
            columns[f"{name}.{j}"] = a[:, j]
    if len({len(c) for c in columns.values()}) > 1:
        return None
    return pd.DataFrame(columns), layout


def _from_table(table, layout: dict) -> dict:
    """The run's output from :func:`_run_table`'s (table, layout)."""
    out = {}
    for name, (entry, value) in layout.items():
        if entry == "flag":
            out[name] = bool(value)
        elif entry == "number":
            out[name] = float(value)
        else:
            a = np.column_stack([table[f"{name}.{j}"].to_numpy() for j in range(max(1, value))])
            out[name] = a if value else a[:, 0]
    return out


def _layout_ok(v) -> bool:
    """A cached scenario run's layout: {name: [flag, bool] | [number, float] | [array, columns]}."""
    return isinstance(v, dict) and all(
        isinstance(x, list) and len(x) == 2 and (
            (x[0] == "flag" and isinstance(x[1], bool)) or (x[0] == "number" and isinstance(x[1], float))
            or (x[0] == "array" and isinstance(x[1], int) and not isinstance(x[1], bool) and x[1] >= 0))
        for x in v.values())


def _cached_run(cache, k: str):
    """(the run's output, meta) of a scenario run kept in ``cache``, or None (no entry, or one that does not
    validate: a miss, engines/cache.py)."""
    from .cache import text, texts

    def columns(table, meta) -> str | None:
        want = {f"{n}.{j}" for n, (entry, c) in meta["layout"].items() if entry == "array" for j in range(max(1, c))}
        missing = sorted(want - set(table.columns))
        return f"missing column(s) {', '.join(missing)}" if missing else None

    hit = cache.get(k, meta_keys={"engine_version": text, "warnings": texts, "layout": _layout_ok}, check=columns)
    if hit is None:
        return None
    table, meta = hit
    return _from_table(table, meta["layout"]), meta


def _put_run(cache, k: str, data: dict, meta: dict) -> None:
    kept = _run_table(data)
    if kept is not None:
        cache.put(k, kept[0], {**meta, "layout": kept[1]})


def _run_deck(case: Case, eng, mp, nat, lay, dk, timeout, started) -> tuple[Result, dict]:
    """(the Result, the output as the engine's reader made it) of the deck's run."""
    from . import run as runner

    out = runner.run(eng.name, dk.text, files=dk.files, timeout=timeout or runner.DEFAULT_TIMEOUT)
    try:
        data = eng.read_scenario(case, lay, out.workdir)
    except DemcheckError as exc:
        raise DemcheckError(f"{eng.name}: {exc}; work directory kept: {out.workdir}") from None
    res = _result(case, eng.name, "engine", _metrics(case, data), lay, started, engine_version=out.version,
                  params={"mapping": mp.fidelity, "native": eng.summary(nat)}, message="; ".join(mp.reasons),
                  meta={"workdir": str(out.workdir), "deck": dk.text, "fidelity": mp.fidelity,
                        "reasons": list(mp.reasons), "warnings": out.warnings})
    if res.ok:
        import shutil

        shutil.rmtree(out.workdir, ignore_errors=True)
        res.meta["workdir"] = ""
    else:
        res.message += f"; work directory kept: {out.workdir}"
    return res, data
