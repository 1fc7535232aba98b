"""``demcheck audit DECK``: does a user's own deck (LAMMPS, LIGGGHTS; a Kratos DEM project, a Yade script) do what it
asks for?

The deck is read, never run as written: by the engine itself where its package can (a LAMMPS deck's set-up evaluated
in LAMMPS in a worker process under an allow-list and a budget, engines/lammps/read.py), else by demcheck's reader
(inputs/script.py); the engine's package reads its contact commands
into one Native per type pair and wall × type (engines/<name>/audit.py). For each, the standard probes — a
head-on impact and oblique ones at 30° and 60° — with the deck's radii, densities and time step at a
characteristic speed run in three places: the engine itself (a deck written by the engine's deck writer from
the user's own Native), its twin (the reference computing the engine's formulas, at the deck's dt and
converged), and the nearest seed model with what the deck asks for. The report lists the realised
restitution, tangential restitution, rebound spin and contact time against the asked values, the steps per
contact with the time-step error and the stability margin, and every trap with its measured size.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np

from ..case import Case, from_dict
from ..errors import ConfigError, DemcheckError
from ..io import number
from ..inputs import script as deck_script
from ..laws.model import resolve
from ..laws.damping import ConstantDamping, NoDamping, QuarterDamping, SqrtDamping
from ..laws.normal import HertzNormal, HookeNormal, HysteresisNormal
from ..laws.tangential import NoTangential, SpringTangential, SqrtSpringTangential, ViscousSlidingTangential
from ..engines import registry
from ..engines.mapping import native_summary, twin_model
from . import audit_beyond
from .sources import ADAPTIVE, Source
from .verdicts import Tolerances, scaled

ANGLES = (0.0, 30.0, 60.0)
# |realised − asked| restitution above which the deck does not get what it asks for (restitutions are
# dimensionless; 0.01 is what a calibration to two digits can tell apart)
ASKED_TOL = 0.01
# an attractive normal force (the dashpot pulling the bodies together at the end of the contact) with no limit
# on it: a note above 1% of the peak force (every damped law without a limit has some: so does the seed's), a
# trap above 10% (a strongly damped contact that ends pulling)
ATTRACTION_NOTE, ATTRACTION_TRAP = 0.01, 0.10
MIN_STEPS_PER_CONTACT = 20  # fewer: the contact is resolved too coarsely whatever the error measured
METRICS = ("restitution", "tangential_restitution", "rebound_angular_velocity", "contact_time", "peak_force")
HEALTH = ("max_overlap",)  # read for the pass-through check, never compared


def readers() -> dict:
    """{engine name: its package's deck reader} for every registered engine whose package has an ``audit``
    module (``read(script, root) → Setup``, ``claims(script)``: the deck uses its own vocabulary)."""
    import importlib.util

    out = {}
    for e in registry.all_engines():
        module = f"{type(e).__module__}.audit"
        if importlib.util.find_spec(module) is not None:
            out[e.name] = importlib.import_module(module)
    return out


def detect(script: deck_script.Script, found: dict) -> str:
    """The deck's engine: the first whose reader claims its vocabulary, else the one that reads by default."""
    for name, reader in found.items():
        if reader.claims(script):
            return name
    return next(name for name, reader in found.items() if getattr(reader, "DEFAULT", False))


def read(path: str | Path, engine: str | None = None):
    """The deck as its engine reads it: where the engine's package can evaluate the set-up in the engine
    (``ENGINE_READ``: a worker process, an allow-list, a budget), the engine's substitution, control flow and
    bodies; else — the engine not installed, or its read stopped (the reason is kept in ``read_by``) — the
    present reader (inputs/script.py)."""
    path = Path(path)
    found = readers()
    own = [n for n, r in found.items() if hasattr(r, "claims_file") and r.claims_file(path)]
    if own and (engine is None or engine in own):  # a Kratos project (.json), a Yade script (.py): its own reader
        return found[engine or own[0]].read_file(path)
    try:
        script, refusal = deck_script.read(path), None
    except deck_script.ScriptError as exc:
        script, refusal = None, exc
    name = engine or (detect(script, found) if script is not None else _sniff(path, found))
    if name not in found:
        raise ConfigError("--engine", name, f"audit reads {', '.join(found)} decks")
    root = path.resolve().parent
    via, answer, why, refused_by_engine = getattr(found[name], "ENGINE_READ", None), None, "", False
    if via is not None and path.is_file():
        if not via.available():
            why = "the engine's Python module is not installed"
        else:
            try:
                answer = via.engine_read(path)
                why, refused_by_engine = answer.stopped, answer.engine_error
            except via.ReadFailed as exc:
                why = str(exc)
            if why:
                answer = _within_budget(answer, via, found[name], root)
    if answer is not None:
        script = via.script_of(answer, root)
    elif script is None:
        if why and refusal is not None and "control flow" in str(refusal):
            raise deck_script.ScriptError(f"{refusal} — the engine's read: {why}")
        raise refusal
    setup = found[name].read(script, root)
    setup.script = script
    setup.regions = script.regions
    setup.box = script.variables.get("__box__", (None, None))[1]
    if answer is not None:
        via.apply(setup, answer, script)
        if answer.stopped:  # the budget of commands ran out: what the engine read so far, the rest listed
            where = answer.stopped.split(": ", 1)[0]
            setup.not_audited.append((where, "", answer.stopped))
    elif via is not None:
        setup.read_by = f"demcheck's reader (inputs/script.py): {why}"
        if refused_by_engine:  # the installed engine stops on a set-up line: the deck as written does not run
            where = why.split(": ", 1)[0]
            setup.findings.append(deck_script.Finding("trap", "engine-refuses", f"the installed engine refuses the "
                                                      f"deck: {why}", where))
    for cmd, why_not in script.unread:
        setup.not_audited.append((cmd.where(), cmd.text, why_not))
    if setup.units in deck_script.INCONSISTENT_UNITS:
        convert = getattr(found[name], "to_si", None)
        if convert is None:
            raise deck_script.ScriptError(
                f"{setup.units_where}: {setup.units_text[:70]!r}: units {setup.units}: not audited — {name} converts "
                "between this style's mass, force and time units with constants of its own, which its reader does "
                "not convert")
        convert(setup)
    return setup


def _within_budget(answer, via, reader, root: Path):
    """An engine's read stopped by its budget of commands (a long loop of runs after the set-up): kept when what
    the engine read up to there defines contacts the reader reads, else None (the present reader takes over)."""
    if answer is None or not getattr(answer, "budget", False):
        return None
    try:
        setup = reader.read(via.script_of(answer, root), root)
    except deck_script.ScriptError:
        return None
    return answer if setup.pairs else None


def _sniff(path: Path, found: dict) -> str:
    """The engine of a deck the present reader refuses: its vocabulary read from the raw words of its lines."""
    try:
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError:
        raise deck_script.ScriptError(f"DECK = {str(path)!r}: no such file") from None
    raw = deck_script.Script([deck_script.Command(line.split("#", 1)[0].split(), path.name, 0, line)
                              for line in text.splitlines()[:deck_script.MAX_LINES]])
    return detect(raw, found)


def characteristic_speed(setup: deck_script.Setup, speed: float | None) -> tuple[float, str]:
    """The impact speed of the probes, and where it comes from: --speed; else the relative normal approach speed
    of the placed bodies that meet; else poured or inserted bodies' insertion velocity plus their fall from the
    top of the insertion region to the floor under the deck's gravity; else the deck's largest speed; else the
    closing rate of growing bodies (fix adapt); else, under gravity, the settling speed (a fall of one diameter,
    the largest)."""
    if speed is not None:
        return speed, "--speed"
    found = deck_script.approach_speed(setup)
    if found is not None:
        return found
    fall = _insertion_speed(setup)
    if fall is not None:
        return fall
    moving = [(v, w) for v, w in setup.speeds if v > 0]
    if moving:
        v, w = max(moving)
        return v, f"the deck's largest speed ({w})"
    grown = deck_script.growth_speed(setup, setup.script) if setup.script is not None else None
    if grown is not None:
        return grown
    radii = [r for b in setup.bodies.values() for r in [b.radius, *(x for x, _ in b.sizes)] if r]
    if setup.gravity is not None and setup.gravity[0] > 0 and radii:
        g, _, where = setup.gravity
        d = 2.0 * max(radii)
        return math.sqrt(2.0 * g * d), (f"the settling speed: a fall of one diameter ({d:g}) under the deck's "
                                        f"gravity {g:g} ({where})")
    raise ConfigError("--speed", None, "the deck gives its bodies no speed (no velocity, Velocities, insertion, "
                                       "gravity or characteristicVelocity): give the characteristic impact speed")


def _insertion_speed(setup) -> tuple[float, str] | None:
    best = None
    for region, vel, _types, where in setup.insertions:
        v0 = math.sqrt(sum(x * x for x in vel))
        speed, why = v0, f"the insertion velocity ({where})"
        if setup.gravity is not None and setup.gravity[0] > 0:
            g, axis, g_where = setup.gravity
            bounds = setup.regions.get(region) if region else None
            if not bounds or not all(map(math.isfinite, bounds[2 * axis:2 * axis + 2])):
                bounds = setup.box
            # a plane wall above the insertion region (a lid) is no floor
            floors = [c for a, c in setup.floors if a == axis and bounds is not None and c <= bounds[2 * axis + 1]]
            lo = min(floors) if floors else (setup.box[2 * axis] if setup.box else None)
            if bounds is None or lo is None or not math.isfinite(lo):
                continue
            height = max(bounds[2 * axis + 1] - lo, 0.0)
            speed = math.sqrt(vel[axis] ** 2 + 2.0 * g * height)
            why = (f"poured or inserted bodies ({where}): insertion velocity {vel[axis]:g} plus the fall of {height:g} "
                   f"from the top of {'region ' + region if region and setup.regions.get(region) else 'the box'} to "
                   f"the floor under gravity {g:g} ({g_where})")
        if speed > 0 and (best is None or speed > best[0]):
            best = (speed, why)
    return best


def _body(setup: deck_script.Setup, t: int, radius: float | None = None):
    """(radius, density of a sphere of its mass) of type ``t`` (``radius``: one of its sizes). A 2-D deck's
    density is per area (LAMMPS's 2-D convention, mass = ρπr²): the probes' spheres get that mass."""
    b = setup.bodies.get(t)
    if b is None or b.radius is None:
        raise deck_script.ScriptError(f"type {t}: the deck gives it no diameter (set type {t} diameter, read_data Atoms, or "
                            "a particle template)")
    r = radius or b.radius
    if b.density is None:
        if b.mass is None:
            raise deck_script.ScriptError(f"type {t}: the deck gives it no density or mass")
        return r, b.mass / (4.0 / 3.0 * math.pi * b.radius ** 3)
    if setup.dimension == 2:
        return r, b.density * 0.75 / r
    return r, b.density


def _sides(setup, ps):
    radii = ps.radii or (None, None)
    first = _body(setup, ps.i, radii[0])
    return first, (None if ps.j is None else _body(setup, ps.j, radii[1]))


def _effective(setup, ps):
    (r1, rho1), second = _sides(setup, ps)
    m1 = rho1 * 4.0 / 3.0 * math.pi * r1 ** 3
    if second is None:
        return m1, r1
    r2, rho2 = second
    m2 = rho2 * 4.0 / 3.0 * math.pi * r2 ** 3
    return m1 * m2 / (m1 + m2), r1 * r2 / (r1 + r2)


def expand_sizes(setup) -> None:
    """A pair or wall whose type comes in several sizes (fix pour, templates, per-atom data) is probed at the
    smallest, the largest and the mass-weighted size of each side: one entry each, said in its label."""
    out = []
    for ps in setup.pairs:
        bi = setup.bodies.get(ps.i)
        bj = setup.bodies.get(ps.j) if ps.j is not None else None
        if not ((bi and bi.sizes) or (bj and bj.sizes)):
            out.append(ps)
            continue
        vi = dict(deck_script.size_variants(bi))
        vj = dict(deck_script.size_variants(bj)) if bj is not None else {}
        sources = sorted({b.size_from for b in (bi, bj) if b is not None and b.sizes})
        for label in ("smallest", "largest", "mass-weighted"):
            q = copy.copy(ps)
            q.notes, q.findings = list(ps.notes), list(ps.findings)
            ri = vi.get(label, vi.get(""))
            rj = vj.get(label, vj.get("")) if bj is not None else None
            q.radii, q.size = (ri, rj), label
            q.label = f"{ps.label} ({label})"
            q.notes.append(f"{label} size of {', '.join(sources)}: radius {ri:g}"
                           + (f" and {rj:g}" if rj is not None else ""))
            out.append(q)
    setup.pairs = out


def seed_of(nl, tl, asked: dict) -> tuple[str, str, dict, list[str]]:
    """The nearest seed model of a twin's laws, with what the deck asks for: (normal, tangential, params,
    reasons why it is only near). The laws are read as their slot records (NormalLaw.slots, TangentialLaw.slot):
    the elastic and damping records pick the normal model, the tangential record the tangential one."""
    normal, damping = nl.slots()
    params: dict = {}
    seed, reasons = _seed_normal(normal, damping, asked, params)
    if nl.limit:
        params["limit_force"] = True
    tangential, why = _seed_tangential(tl.slot(), tl.mu_s, seed, params)
    return seed, tangential, params, reasons + why


def _hertz(nl) -> bool:
    """Whether a law's elastic record is Hertz's spring (its stiffness is (4/3)E*√R̄)."""
    return isinstance(nl.slots()[0], HertzNormal)


def _seed_normal(normal, damping, asked: dict, params: dict) -> tuple[str, list[str]]:
    """The seed normal model of an elastic and a damping record (``params`` filled in), with the reasons why it
    is only near."""
    reasons = []
    eta = getattr(damping, "eta", 0.0)
    if isinstance(normal, HysteresisNormal):
        params["kl"] = normal.kl
        return "hls", reasons
    if isinstance(normal, HookeNormal):
        params["kn"] = normal.k
        if "restitution" in asked:
            params["restitution"] = asked["restitution"]
        else:
            params["eta_n"] = eta
            if not isinstance(damping, (NoDamping, ConstantDamping)):
                reasons.append(f"the engine's dashpot grows as δ^{damping.exponent:g}; LSD's is constant")
        return "lsd", reasons
    if not isinstance(normal, HertzNormal):
        raise ValueError(f"no seed normal model near the engine's '{normal.id}' ({normal.title})")
    if eta == 0.0:
        return "hertz", reasons
    if isinstance(damping, SqrtDamping):
        params["eta_n"] = eta
        return "kk", reasons
    if "restitution" in asked:
        params["restitution"] = asked["restitution"]
    else:
        params["eta_n"] = eta
    if not isinstance(damping, QuarterDamping):
        reasons.append(f"the engine's dashpot grows as δ^{damping.exponent:g}; TTIn's as δ^¼")
    return "tti", reasons


def _seed_tangential(record, mu: float, normal: str, params: dict) -> tuple[str, list[str]]:
    """The seed tangential model of a tangential record with friction ``mu`` beside the seed normal model
    ``normal`` (``params`` filled in: the truncation, Kt and the friction), with the reasons why it is only near."""
    reasons = []
    if isinstance(record, NoTangential) or mu == 0.0:
        return "none", reasons
    if isinstance(record, SqrtSpringTangential):
        tangential = "tti" if normal == "tti" else "ddt"
        if tangential == "tti":  # TTIt takes a truncation rule (the engines' Maw history); DDt has Maw's only
            params["truncation"] = "overlap"
    elif isinstance(record, SpringTangential):
        tangential = "spring_sliding"
        params["kt"] = record.kt
    elif isinstance(record, ViscousSlidingTangential):
        tangential = "sliding"
        reasons.append("the engine's tangential dashpot regularises sliding friction")
    else:
        return "none", ["no seed tangential law near the engine's"]
    params["friction"] = mu
    return tangential, reasons


def probe_case(setup, ps, speed: float, angle: float, nl, tl, seed, dt: float | None = None) -> Case:
    normal, tangential, params, _ = seed
    params = dict(params)  # the seed's own stays whole (a probe case may be built more than once)
    (r1, rho1), second = _sides(setup, ps)
    e_star = nl.k / (4.0 / 3.0 * math.sqrt(_effective(setup, ps)[1])) if _hertz(nl) else 1e9
    nu = 0.3
    if getattr(ps.native, "normal", "") == "hertz/material":
        nu = ps.native.normal_args[1]
    b1 = setup.bodies[ps.i]
    restitution = params.pop("restitution", 0.9)
    friction = params.pop("friction", 0.0)

    def material(rho, body=None, own=False):
        if own and body is not None and body.youngs_modulus is not None:
            e, n = body.youngs_modulus, body.poisson_ratio
        else:  # E such that the seed's E* is the engine's: like materials E/(2(1−ν²)), a rigid wall E/(1−ν²)
            n = nu
            e = (1.0 - nu * nu) * e_star * (1.0 if ps.j is None else 2.0)
        return {"density": rho, "youngs_modulus": e, "poisson_ratio": n, "restitution": restitution,
                "friction": friction}

    own = getattr(readers()[setup.engine], "OWN_MODULI", False)  # its deck writer writes each type's modulus
    mats = {"a": material(rho1, b1, own)}
    parts = [{"material": "a", "radius": r1}]
    raw = {"name": f"audit-{ps.label.replace(' ', '-').replace('×', 'x')}-{angle:g}", "materials": mats,
           "particles": parts, "impact": {"speed": speed, "angle": angle},
           "contact": {"normal": normal, "tangential": tangential, **params}, "run": {"dt": dt or setup.dt}}
    if ps.j is None:
        wall = {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}
        if own and ps.wall:
            mats["w"] = {"density": 1000.0, "youngs_modulus": ps.wall["youngs_modulus"],
                         "poisson_ratio": ps.wall["poisson_ratio"], "restitution": restitution, "friction": friction}
            wall.update(rigid=False, material="w")
        raw["walls"] = [wall]
    else:
        r2, rho2 = second
        mats["b"] = material(rho2, setup.bodies[ps.j], own)
        parts.append({"material": "b", "radius": r2})
    return from_dict(raw)


def _metrics(res) -> dict:
    m = res.metrics()
    return {k: m.get(k, math.nan) for k in METRICS + HEALTH}


def _stability(nl, m_eff: float, max_overlap: float, dt: float) -> float:
    """dt_crit/dt: velocity Verlet is stable for ω dt < 2, ω² = (dF/dδ)/m̄ at the largest overlap."""
    normal = nl.slots()[0]
    if isinstance(normal, HysteresisNormal):
        k = max(normal.kl, normal.ku)
    else:
        k = normal.exponent * normal.k * max(max_overlap, 0.0) ** (normal.exponent - 1.0)
    if not k > 0:
        return math.inf
    return 2.0 / math.sqrt(k / m_eff) / dt


def case_at_step(setup, ps, speed, angle, nl, tl, seed) -> tuple[Case, float, str]:
    """The probe's case and the step it runs at: the deck's, or — when the contact at the deck's step takes more
    steps than an engine probe may (case.MAX_STEPS) — the least power-of-two multiple of it that fits, stated. The
    approach is already the contact alone (the bodies start a thousandth of a radius apart)."""
    from ..case import MAX_STEPS, run_length

    dt = setup.dt
    for k in range(80):
        try:
            case = probe_case(setup, ps, speed, angle, nl, tl, seed, dt)
            run_length(case, dt)
        except ConfigError as exc:
            if exc.key not in ("run.dt", "--dt") or "steps" not in exc.rule:
                raise
            dt *= 2.0
            continue
        if k == 0:
            return case, dt, ""
        return case, dt, (f"probed at dt = {dt:.4g} ({2 ** k}× the deck's {setup.dt:g}): at the deck's step the contact "
                          f"takes more than the {MAX_STEPS:,} steps an engine probe may; the time-step error is "
                          "measured at this coarser step (the deck's own step errs less)")
    raise ConfigError("timestep", setup.dt, "no step resolves the probe's contact within the run's bound")


def health_failure(sides: dict, radius: float) -> str:
    """Why a probe measured nothing, or "": a side that did not finish (its status), a contact that never formed
    (no contact time > 0), a restitution that is not a finite number, an overlap that reaches the smaller radius
    (the bodies pass through each other). Each is a failure with its cause, never a gap of 0."""
    for name, m in sides.items():
        if m.get("status", "ok") not in ("ok",) and name != "engine":  # the engine's own failure is engine-failed
            return f"{name}: {m.get('status')}: {str(m.get('message', ''))[:160]}"
        tc, e, mo = (m.get(k, math.nan) for k in ("contact_time", "restitution", "max_overlap"))
        if not (isinstance(tc, float) and math.isfinite(tc) and tc > 0):
            return f"{name}: the contact never formed (contact time {tc})"
        if not math.isfinite(e):
            return f"{name}: the restitution is {e} (no rebound measured)"
        if isinstance(mo, float) and math.isfinite(mo) and mo >= radius:
            return f"{name}: the largest overlap {mo:.3g} reaches the radius {radius:.3g} (the bodies pass through)"
    return ""


def probe(setup, ps, speed: float, angle: float, run_engine: bool = True, tol: Tolerances | None = None) -> dict:
    """One probe of one type pair: the engine, its twin at the probe's dt and converged, and the seed model."""
    tol = tol or Tolerances.load()
    m_eff, r_eff = _effective(setup, ps)
    eng = registry.get(setup.engine)
    nl, tl = eng.twin(ps.native, m_eff, r_eff)
    seed = seed_of(nl, tl, ps.asked)
    case, dt, dt_note = case_at_step(setup, ps, speed, angle, nl, tl, seed)
    out = {"angle": angle, "speed": speed, "dt": dt, "dt_note": dt_note,
           "seed": {"normal": seed[0], "tangential": seed[1], "reasons": seed[3]}}
    scales = {"impact_energy": 0.5 * m_eff * speed ** 2, "spin": speed / case.particles[0].radius}
    twin = Source.of(eng, twin=True).run(case, dt, native=ps.native)
    out["twin"] = {"status": twin.status, "message": twin.message, **_metrics(twin)}
    try:
        conv = _converged(case, eng, ps.native, dt)
        out["converged"] = {"status": conv.status, **_metrics(conv), "by": conv.meta.get("converged_by", "")}
    except ConfigError as exc:
        conv = None
        out["converged"] = {"status": "not run", "message": str(exc)}
    ref = ADAPTIVE.run(case, model=resolve(case))  # the seed model by the two-body kernel
    out["seed"].update(status=ref.status, **_metrics(ref))
    if run_engine:
        res = Source.of(eng).run(case, dt, native=ps.native)
        out["engine"] = {"status": res.status, "message": res.message, "version": res.engine_version,
                         **_metrics(res)}
        fn = res.contact["fn"].to_numpy() if res.contact is not None and len(res.contact) else np.array([0.0])
        d = res.contact["delta"].to_numpy() if res.contact is not None and len(res.contact) else np.array([0.0])
        inside = d > 0
        out["engine"]["min_force"] = float(fn[inside].min()) if inside.any() else math.nan
        out["engine_vs_twin"] = _worst(out["engine"], out["twin"], METRICS, scales)
    main = out.get("engine", out["twin"])
    out["dt_error"] = math.nan
    if conv is not None and conv.ok and twin.ok:
        out["dt_error"] = _worst(out["twin"], out["converged"], [k for k in METRICS if k != "peak_force"], scales)
        if out["dt_error"] > tol.verlet_rtol:  # is it the step's? the error must shrink with dt
            half = Source.of(eng, twin=True).run(case, dt / 2.0, native=ps.native)
            out["dt_error_half"] = (_worst({**_metrics(half)}, out["converged"],
                                           [k for k in METRICS if k != "peak_force"], scales) if half.ok else math.nan)
    t_c = main["contact_time"]
    out["steps_per_contact"] = t_c / setup.dt if math.isfinite(t_c) else math.nan
    mo = twin.metrics().get("max_overlap", math.nan)
    out["stability_margin"] = _stability(nl, m_eff, mo, setup.dt) if math.isfinite(mo) else math.nan
    out["seed_gap"] = _worst(main, out["seed"], [k for k in METRICS if k != "peak_force"], scales)
    sides = {k: out[k] for k in ("engine", "twin", "converged", "seed") if k in out}
    out["failure"] = health_failure(sides, min(p.radius for p in case.particles))
    return out


OWN_LAW_REFINE = 16  # an engine's own twin kernel has no adaptive form: its converged answer is dt / 16 (error / 256)


def _converged(case, eng, native, dt: float):
    """The probe's converged answer: the twin's law by the adaptive solver with the engine's kinematic rules (its
    slip arm, torque arms and history rotation: what the twin steps at dt, so that the difference is the time
    step's alone), or, where the engine's twin steps a law of its own (Engine.own_twin: Kratos' tangential force,
    Yade's Luding law), that kernel at dt / 16 — the adaptive solver would solve the description of the law, not
    the law. A law whose history the adaptive solver does not keep (a force history, a rescaled history) is solved
    with the seed's rules, and the result says so."""
    if eng.own_twin(native):
        conv = Source.of(eng, twin=True).run(case, dt / OWN_LAW_REFINE, native=native)
        conv.meta["converged_by"] = f"the engine's own law stepped at dt/{OWN_LAW_REFINE}"
        return conv
    model = twin_model(resolve(case), native)
    if not (model.tangential_law.force_history or model.tangential_law.rescale_history):
        conv = Source.of(eng, twin=True).run(case, dt, native=native, converged=True)
        conv.meta["converged_by"] = "the adaptive solver, with the engine's kinematic rules"
        return conv
    conv = ADAPTIVE.run(case, model=model)  # the twin's law, the seed's rules
    conv.meta["converged_by"] = "the adaptive solver, with the seed's kinematic rules (its history is not the law's)"
    return conv


REQUIRED = ("restitution", "contact_time")  # every formed contact has them: NaN on both sides is a failure


def _worst(a: dict, b: dict, keys, scales) -> float:
    """The largest scaled difference over ``keys``: a metric one side produced and the other did not (NaN) is an
    infinite difference, never dropped; a metric neither side produces is skipped — unless every contact has it
    (REQUIRED: then neither side measured a contact, an infinite difference too)."""
    worst = 0.0
    for k in keys:
        x, y = a.get(k, math.nan), b.get(k, math.nan)
        if math.isnan(x) and math.isnan(y):
            if k in REQUIRED:
                return math.inf
            continue
        d = scaled(x, y, k, scales)
        if not math.isfinite(d):
            return math.inf
        worst = max(worst, d)
    return worst


def _fidelity(gap: float, reasons: list) -> str:
    if not math.isfinite(gap):
        return "failed"
    return "exact" if gap <= 1e-6 and not reasons else "approximate"


def audit(path: str | Path, engine: str | None = None, speed: float | None = None, run_engine: bool = True,
          tol: Tolerances | None = None, beyond_engine: bool | None = None) -> dict:
    """The audit of a deck as a plain dict (the CLI prints it, --json dumps it). ``status``: "clean" (every pair
    and wall probed or listed with its reason, no trap), "traps", or "not audited" (no probe ran: never clean).
    ``beyond_engine``: run the beyond-sliding probes in the engine (default: as ``run_engine``)."""
    from ..engines import discovery

    tol = tol or Tolerances.load()
    setup = read(path, engine)
    expand_sizes(setup)
    eng = registry.get(setup.engine)
    failed: dict = {}
    for ps in setup.pairs:  # every body the probes need, and a twin of every probed law, before any run
        if ps.probe:
            try:
                eng.twin(ps.native, *_effective(setup, ps))
            except (ZeroDivisionError, OverflowError) as exc:  # the twin exists: a number under- or overflowed
                ps.probe = False
                failed[id(ps)] = (f"the probe cannot be set up: {type(exc).__name__} ({exc}) — a coefficient or a "
                                  "size under- or overflows in floating point")
            except (ValueError, ArithmeticError) as exc:
                ps.probe = False
                ps.notes.append(f"listed, not probed: demcheck has no twin of this setting ({exc})")
    probed = [ps for ps in setup.pairs if ps.probe or ps.beyond]  # the beyond probes spin, roll and hit at v too
    v, v_from = characteristic_speed(setup, speed) if probed else (None, "no pair or wall is probed")
    # the deck names its engine (--engine or its vocabulary): a named engine is required, never skipped
    beyond_engine = run_engine if beyond_engine is None else beyond_engine
    info = discovery.require(setup.engine, "the deck") if (run_engine or beyond_engine) and probed else None
    pairs, findings = [], list(setup.findings)
    for ps in setup.pairs:
        entry, found = _audit_pair(setup, ps, v, run_engine, tol, failed.get(id(ps)), beyond_engine)
        findings += found
        pairs.append(entry)
    _in_si(pairs, deck_script.SI_OF.get(setup.units), v)
    traps = [f for f in findings if f.kind == "trap"]
    coverage = _coverage(pairs)
    status = "traps" if traps else "clean"
    reason = ""
    if not (coverage["pairs"]["probed"] + coverage["walls"]["probed"]):
        status = "not audited"
        reason = _why_nothing(pairs)
        restarts = [w for w, t, _ in setup.not_audited if t.split()[:1] == ["read_restart"]]
        if not pairs and restarts:
            reason += (f" — its box, types and bodies come from read_restart ({restarts[0]}), a binary file demcheck "
                       "does not read (audit the deck that wrote it)")
    return {"deck": str(path), "engine": setup.engine, "engine_version": info.version if info else None,
            "read_by": setup.read_by, "findings": [_finding(f) for f in setup.findings],
            "units": units_info(setup), "dimension": setup.dimension,
            "dt": setup.dt, "dt_from": setup.dt_where, "speed": v, "speed_from": v_from,
            "bodies": {t: {"radius": b.radius, "density": b.density, "mass": b.mass,
                           "sizes": sorted({r for r, _ in b.sizes}) and
                           [min(r for r, _ in b.sizes), max(r for r, _ in b.sizes)]}
                       for t, b in sorted(setup.bodies.items())},
            "pairs": pairs, "not_audited": [{"where": w, "text": t, "why": y} for w, t, y in setup.not_audited],
            "coverage": coverage, "traps": len(traps), "status": status, "status_reason": reason}


def _audit_pair(setup, ps, v, run_engine, tol, failure: str | None,
                beyond_engine: bool = True) -> tuple[dict, list]:
    from ..errors import EngineInterrupted

    entry = {"pair": ps.label, "wall": ps.j is None, "where": ps.where, "native": native_summary(ps.native),
             "asked": ps.asked, "notes": list(ps.notes), "probes": [], "findings": []}
    found = list(ps.findings)
    if failure:
        found.append(deck_script.Finding("trap", "probe-failed", failure, ps.where))
    if ps.probe:
        angles = ANGLES if ps.asked.get("friction", 0.0) > 0 else ANGLES[:1]
        for angle in angles:
            try:
                entry["probes"].append(probe(setup, ps, v, angle, run_engine, tol))
            except EngineInterrupted:
                raise  # an interrupt stops the audit (exit 130/143): never a trap of the user's deck
            except (ValueError, ArithmeticError) as exc:  # a number the probe cannot compute with
                entry["probes"].append({"angle": angle, "error": str(exc)})
                found.append(deck_script.Finding("trap", "probe-failed", f"the {angle:g}° probe cannot be computed: "
                                                 f"{type(exc).__name__}: {exc}", ps.where))
            except DemcheckError as exc:
                entry["probes"].append({"angle": angle, "error": str(exc)})
                found.append(deck_script.Finding("trap", "probe-failed", f"the {angle:g}° probe did not run: {exc}",
                                                 ps.where))
        _judge(setup, ps, entry, found, tol)
        measure = getattr(readers()[setup.engine], "measure", None)  # an engine reader's own measured traps
        if measure is not None and run_engine and entry["probes"] and "engine" in entry["probes"][0]:
            found += measure(setup, ps, entry, lambda native: _rerun(setup, ps, native, entry["probes"][0]))
    found += audit_beyond.probe_pair(setup, ps, entry, beyond_engine, v,
                                     getattr(readers()[setup.engine], "BEYOND_PROBES", {}),
                                     lambda: (_sides(setup, ps), _effective(setup, ps)))
    entry["probed"] = (any("error" not in p and not p.get("failure") for p in entry["probes"])
                       or any(r.get("status") == "ok" for r in entry.get("beyond", [])))
    entry["findings"] = [_finding(f) for f in found]
    return entry, found


def _in_si(pairs: list, si: tuple | None, speed: float | None) -> None:
    """Each probe's physical quantities also in SI ("si": seconds, m/s, rad/s, newtons) where the deck's units
    have a fixed SI meaning (si, cgs, micro, nano: length, mass and time factors; force = mass·length/time²);
    lj's σ, m and τ are the deck's own: no "si"."""
    if si is None:
        return
    length, mass, time = si
    for entry in pairs:
        for p in entry["probes"]:
            if "error" in p:
                continue
            m = p.get("engine", p["twin"])
            p["si"] = {"speed_m_per_s": p["speed"] * length / time, "dt_s": p["dt"] * time,
                       "contact_time_s": m["contact_time"] * time,
                       "rebound_angular_velocity_rad_per_s": m["rebound_angular_velocity"] / time,
                       "peak_force_N": m["peak_force"] * mass * length / time ** 2,
                       "max_overlap_m": m["max_overlap"] * length}


def _coverage(pairs: list) -> dict:
    out = {}
    for kind, rows in (("pairs", [p for p in pairs if not p["wall"]]), ("walls", [p for p in pairs if p["wall"]])):
        n, k = len(rows), sum(p["probed"] for p in rows)
        out[kind] = {"probed": k, "total": n, "fraction": k / n if n else math.nan}
    beyond = audit_beyond.coverage(pairs)
    if beyond["total"]:
        out["beyond-sliding probes"] = beyond
    return out


def _why_nothing(pairs: list) -> str:
    if not pairs:
        return "the deck defines no type pair or wall the audit reads"
    reasons = sorted({n for p in pairs for n in p["notes"] if "not probed" in n}
                     | {f["text"] for p in pairs for f in p["findings"] if f["code"] in ("probe-failed", "pass-through")})
    return "no pair or wall was probed" + (": " + "; ".join(r[:160] for r in reasons[:4]) if reasons else "")


def units_info(setup) -> dict:
    """The deck's units and, for a style with a fixed SI meaning, its units of length, mass and time in SI."""
    si = deck_script.SI_OF.get(setup.units)
    return {"style": setup.units, "from": setup.units_where,
            "si": None if si is None else {"length": si[0], "mass": si[1], "time": si[2]}}


def _finding(f: deck_script.Finding) -> dict:
    return {"kind": f.kind, "code": f.code, "text": f.text, "where": f.where, "size": f.size}


def _judge(setup, ps, entry: dict, found: list, tol: Tolerances) -> None:
    probes = [p for p in entry["probes"] if "error" not in p]
    if not probes:
        return
    head = probes[0]
    main = head.get("engine", head["twin"])
    gap = max(p["seed_gap"] for p in probes)
    reasons = sorted({r for p in probes for r in p["seed"]["reasons"]})
    entry["seed"] = {"normal": head["seed"]["normal"], "tangential": head["seed"]["tangential"],
                     "fidelity": _fidelity(gap, reasons), "gap": gap, "reasons": reasons}
    broken = [p for p in probes if p.get("failure")]
    for p in broken:  # a probe that measured nothing (passing through, no contact, NaN): never "exact"
        code = "pass-through" if "pass through" in p["failure"] else "probe-failed"
        found.append(deck_script.Finding("trap", code, f"{p['angle']:g}° probe: {p['failure']}", ps.where,
                                         {"angle": p["angle"]}))
    if broken:
        entry["seed"]["fidelity"] = "failed"
        probes = [p for p in probes if not p.get("failure")]
        if not probes:
            return
        head = probes[0]
        main = head.get("engine", head["twin"])
    for p in probes:
        eng = p.get("engine")
        if eng is None:
            continue
        if eng["status"] != "ok":
            found.append(deck_script.Finding("trap", "engine-failed", f"{p['angle']:g}° probe: the engine run is "
                                   f"{eng['status']}: {eng['message']}", ps.where))
        elif not p["engine_vs_twin"] <= 1e-9:
            found.append(deck_script.Finding("trap", "engine-vs-twin", f"{p['angle']:g}° probe: the engine differs from the "
                                   f"formulas the audit read from the deck by {p['engine_vs_twin']:.3g}", ps.where,
                                   {"difference": p["engine_vs_twin"]}))
    e_asked = ps.asked.get("restitution")
    e_real = main["restitution"]
    codes = {f.code for f in found}
    if e_asked is not None and not math.isfinite(e_real):
        found.append(deck_script.Finding("trap", "probe-unreadable", f"the realised restitution is {e_real} (the "
                                         "probe produced no rebound to measure)", ps.where))
    elif e_asked is not None:
        size = {"asked": e_asked, "realised": e_real, "difference": e_real - e_asked}
        for f in found:
            if f.code in ("tsuji", "limit"):
                f.size.update(size)
                f.text += f": e = {e_asked:g} asked, {e_real:.4f} realised"
        if abs(e_real - e_asked) > ASKED_TOL and not codes & {"tsuji", "limit"}:
            found.append(deck_script.Finding("trap", "restitution", f"restitution {e_real:.4f} realised, {e_asked:g} asked",
                                   ps.where, size))
    elif e_asked is None and "restitution" in main:
        entry["notes"].append(f"realised restitution {e_real:.4f} (the deck sets a damping coefficient, not e)")
    if ps.intended is not None:  # the measured size of a mixing or wall-moduli trap: the run it meant
        intended = PairLike(ps, ps.intended)
        sizes = [q for q in (_intended_probe(setup, intended, p) for p in probes) if q is not None]
        for f in found:
            if f.code in ("mixing", "wall-moduli") and not sizes:
                f.text += "; not measured: the probes of the deck's or the meant setting were not healthy"
            elif f.code in ("mixing", "wall-moduli"):
                f.size.update({"probes": sizes})
                worst = max(sizes, key=lambda s: max(abs(v) for v in s["difference"].values()))
                key = max(worst["difference"], key=lambda k: abs(worst["difference"][k]))
                f.text += (f"; measured at {worst['angle']:g}°: {key} {worst['deck'][key]:.4g} in the engine, "
                           f"{worst['intended'][key]:.4g} as meant ({worst['difference'][key] * 100:+.1f}%)")
    _judge_time_step(setup, entry, found, probes, tol)
    if not ps.native.limit and "engine" in head:
        peak, low = head["engine"]["peak_force"], head["engine"]["min_force"]
        if math.isfinite(low) and low < -ATTRACTION_NOTE * peak:
            kind = "trap" if low < -ATTRACTION_TRAP * peak else "note"
            found.append(deck_script.Finding(kind, "attraction", f"the normal force pulls the bodies together "
                                   f"({low:.4g} N, {-low / peak * 100:.1f}% of the peak) and no limit holds it at 0",
                                   ps.where, {"min_force": low, "peak_force": peak}))


def _judge_time_step(setup, entry: dict, found: list, probes: list, tol: Tolerances) -> None:
    """The time-step verdicts on the deck's own dt: unstable, too few steps, or an error that shrinks with dt (a
    gap that stays at dt/2 is a model difference, named so, never a time-step error)."""
    spc = min(p["steps_per_contact"] for p in probes)
    margin = min(p["stability_margin"] for p in probes)
    at_deck = [p for p in probes if not p.get("dt_note")]  # a probe at a coarser step says nothing of the deck's
    dt_err = max((p["dt_error"] for p in at_deck if not math.isnan(p["dt_error"])), default=math.nan)
    shrinks = all(p.get("dt_error_half", 0.0) < 0.75 * p["dt_error"] for p in at_deck
                  if math.isfinite(p["dt_error"]) and p["dt_error"] > tol.verlet_rtol)
    entry["time_step"] = {"dt": setup.dt, "steps_per_contact": spc, "dt_error": dt_err, "stability_margin": margin,
                          "probe_dt": max(p["dt"] for p in probes), "error_shrinks_with_dt": shrinks}
    for note in sorted({p["dt_note"] for p in probes if p.get("dt_note")}):
        entry["notes"].append(note)
    if math.isfinite(dt_err) and dt_err > tol.verlet_rtol and not shrinks and spc >= MIN_STEPS_PER_CONTACT:
        half = max(p.get("dt_error_half", math.nan) for p in at_deck)
        entry["notes"].append(f"model difference, not a time-step error: the stepped twin differs from its converged "
                              f"contact by {dt_err:.3g} at dt and {half:.3g} at dt/2 — the gap does not shrink with "
                              "the step")
        dt_err = math.nan  # not the step's error
    if not (math.isfinite(spc) and math.isfinite(margin)):
        found.append(deck_script.Finding("trap", "probe-unreadable", f"dt = {setup.dt:g} s: the probes give no contact "
                                         "time or overlap to judge the time step by", setup.dt_where))
    elif margin < 1.0:
        found.append(deck_script.Finding("trap", "dt-unstable", f"dt = {setup.dt:g} s is above velocity Verlet's stability "
                               f"limit {margin * setup.dt:.3g} s for this contact", setup.dt_where,
                               {"stability_margin": margin}))
    elif spc < MIN_STEPS_PER_CONTACT or (math.isfinite(dt_err) and dt_err > tol.verlet_rtol):
        found.append(deck_script.Finding("trap", "dt-coarse", f"dt = {setup.dt:g} s: {spc:.1f} steps per contact, "
                               f"time-step error {dt_err:.3g} against the converged contact", setup.dt_where,
                               {"steps_per_contact": spc, "dt_error": dt_err}))


class PairLike:
    """A pair setting with another Native (what the deck meant): probed like the deck's own."""

    def __init__(self, ps, native):
        self.__dict__.update(vars(ps))
        self.native = native


def _intended_probe(setup, intended, p: dict) -> dict | None:
    """The deck's probe against the run it meant — None when either is unhealthy (a failed run, bodies passing
    through, a metric that is not finite): a trap's size is never measured from a broken run."""
    q = probe(setup, intended, p["speed"], p["angle"], run_engine="engine" in p)
    deck = p["engine"] if "engine" in p else p["twin"]
    meant = q["engine"] if "engine" in q else q["twin"]
    if (p.get("failure") or q.get("failure") or deck.get("status", "ok") != "ok" or meant.get("status", "ok") != "ok"
            or not all(math.isfinite(x.get(k, math.nan)) for x in (deck, meant) for k in REQUIRED)):
        return None
    keys = [k for k in METRICS if math.isfinite(deck.get(k, math.nan)) and math.isfinite(meant.get(k, math.nan))
            and meant[k] != 0]
    return {"angle": p["angle"], "deck": {k: deck[k] for k in keys}, "intended": {k: meant[k] for k in keys},
            "difference": {k: deck[k] / meant[k] - 1.0 for k in keys}}


def text_report(r: dict) -> str:
    """The audit as text for people."""
    u = r["units"]
    t_unit, v_unit = UNIT_WORDS.get(u["style"], ("time units", "speed units"))
    lines = [f"audit of {r['deck']} ({r['engine']} {r['engine_version'] or ''}".rstrip() + ")",
             f"  read by {r['read_by']}",
             f"  units {u['style']} ({u['from']}); " + (
                 "the probes run in the deck's units (a consistent system: the same numbers in any), "
                 + ("times and speeds below in them, SI in brackets" if u["si"] and u["style"] != "si" else
                    "SI" if u["si"] else "no SI conversion: lj's σ, m and ε are the deck's own")),
             f"  dt = {r['dt']:g} {t_unit}{_si(r['dt'], u, 'time')} ({r['dt_from']}); characteristic speed "
             + (f"{r['speed']:g} {v_unit}{_si(r['speed'], u, 'speed')} ({r['speed_from']})" if r["speed"] is not None
                else f"— ({r['speed_from']})")]
    for f in r.get("findings", []):  # the deck's own (not one pair's): the engine refusing a line
        lines.append(f"  {f['kind'].upper()} [{f['code']}]: {f['text']}")
    cov = r["coverage"]
    lines.append("  probed: " + ", ".join(f"{c['probed']} of {c['total']} {kind}" for kind, c in cov.items())
                 + (" (2-D deck: density per area, probed as spheres of that mass)" if r["dimension"] == 2 else ""))
    for p in r["pairs"]:
        lines.append(f"\n{p['pair']}: {p['native']}  [{p['where']}]")
        if "seed" in p:
            s = p["seed"]
            lines.append(f"  nearest seed model: normal {s['normal']}, tangential {s['tangential']} — {s['fidelity']}"
                         f" (largest gap {s['gap']:.3g})" + (f"; {'; '.join(s['reasons'])}" if s["reasons"] else ""))
        asked = ", ".join(f"{k} {v:g}" for k, v in p["asked"].items())
        if asked:
            lines.append(f"  asks for: {asked}")
        for q in p["probes"]:
            if "error" in q:
                lines.append(f"  {q['angle']:>3g}°: not run: {q['error']}")
                continue
            m = q.get("engine", q["twin"])
            lines.append(f"  {q['angle']:>3g}°: e {m['restitution']:.4f} (seed {q['seed']['restitution']:.4f}), "
                         f"et {_f(m['tangential_restitution'])}, spin {_f(m['rebound_angular_velocity'])} rad/"
                         f"{t_unit}, tc {m['contact_time']:.4g} {t_unit}{_si(m['contact_time'], u, 'time')}; "
                         f"engine − twin {_f(q.get('engine_vs_twin', math.nan))}")
        if "time_step" in p:
            t = p["time_step"]
            lines.append(f"  time step: {t['steps_per_contact']:.1f} steps per contact, error {_f(t['dt_error'])}, "
                         f"stability margin {t['stability_margin']:.3g}×")
        for n in p["notes"]:
            lines.append(f"  note: {n}")
        lines += audit_beyond.text_lines(p)
        for f in p["findings"]:
            lines.append(f"  {f['kind'].upper()} [{f['code']}]: {f['text']}")
    if r["not_audited"]:
        lines.append("\nnot audited (read, never run):")
        lines += [f"  {n['where']}: {n['text'][:70]} — {n['why']}" for n in r["not_audited"]]
    if r["status"] == "not audited":
        lines.append(f"\nNOT AUDITED: {r['status_reason']} — nothing was probed, so nothing is called clean"
                     + (f" ({r['traps']} trap(s) read from the settings)" if r["traps"] else ""))
    else:
        lines.append(f"\n{r['traps']} trap(s)" if r["traps"] else "\nno trap found")
    return "\n".join(safe_text(line) for line in lines)


UNIT_WORDS = {"si": ("s", "m/s"), "cgs": ("s", "cm/s"), "micro": ("µs", "µm/µs"), "nano": ("ns", "nm/ns"),
              "lj": ("τ", "σ/τ")}


def _si(x, units: dict, kind: str) -> str:
    si = units["si"]
    if si is None or units["style"] == "si" or x is None or not math.isfinite(x):
        return ""
    factor = si["time"] if kind == "time" else si["length"] / si["time"]
    return f" [{x * factor:.4g} {'s' if kind == 'time' else 'm/s'}]"


_CONTROL = {c: f"\\x{c:02x}" for c in [*range(0, 9), *range(11, 32), 127, *range(128, 160)]}


def safe_text(text: str) -> str:
    """A line for a terminal: control characters from a deck (escape sequences that set the title or clear the
    screen) shown as \\xNN, never sent raw; a tab stays."""
    return text.translate(_CONTROL)


def _f(x) -> str:
    return number(x, ".4g")


def reverse(engine: str, line: str, radius: float = 1e-3, density: float = 2500.0, speed: float = 1.0) -> dict:
    """The reverse lookup of one native setting (``demcheck models --engine E "…"``): its nearest seed model
    and implied parameters for a like pair (``radius``, ``density``), its fidelity — the head-on probe, and the
    oblique ones at 30° and 60° with friction, at ``speed``: the twin's converged contact against the seed
    model's, *exact* within 1e-6 (scaled) — and its static traps. No engine runs; ``demcheck audit`` measures
    the traps in the engine. A setting the engine's reader cannot read is a ConfigError naming it."""
    from .bench import native_law

    found = readers()
    reader = found.get(engine)
    if reader is None or not hasattr(reader, "reverse"):
        known = {n: r for n, r in found.items() if hasattr(r, "reverse")}
        raise ConfigError("--engine", engine, "has no reverse lookup; it reads " + "; ".join(
            f"{n}: {getattr(r, 'REVERSE_SYNTAX', 'its setting')}" for n, r in known.items()))
    for key, value in (("--radius", radius), ("--density", density), ("--speed", speed)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ConfigError(key, value, "must be a finite number > 0")
    setup = deck_script.Setup(engine)
    try:
        ps = reader.reverse(line, setup)
    except deck_script.ScriptError as exc:
        raise ConfigError("SETTING", line, str(exc).split(": ", 2)[-1]) from None
    body = setup.bodies.setdefault(ps.i, deck_script.Body(ps.i))
    body.radius, body.density = radius, density
    m = density * 4.0 / 3.0 * math.pi * radius ** 3
    findings = [_finding(f) for f in [*setup.findings, *ps.findings]]
    out = {"engine": engine, "setting": line, "native": native_summary(ps.native), "asked": ps.asked,
           "pair": {"radius": radius, "density": density, "speed": speed}, "findings": findings,
           "notes": list(ps.notes)}
    if not ps.probe:  # a law demcheck has no twin of: listed, with its traps
        return {**out, "seed": None, "fidelity": "none", "gap": math.nan, "implied": {}}
    eng = registry.get(engine)
    try:
        nl, tl = eng.twin(ps.native, m / 2.0, radius / 2.0)
        normal, tangential, params, reasons = seed_of(nl, tl, ps.asked)  # (a plug-in's twin may have no seed)
    except (ValueError, ArithmeticError) as exc:
        raise ConfigError("SETTING", line, f"no twin: {exc}") from None
    implied = {"normal_force": f"{nl.k:.6g} δ^{nl.a:g}", "damping": f"{nl.eta:.6g} δ^{nl.b:g} (N·s/m at δ^b)",
               "limit": nl.limit}
    if _hertz(nl):
        implied["E*"] = nl.k / (4.0 / 3.0 * math.sqrt(radius / 2.0))
    if isinstance(tl.slot(), SpringTangential):
        implied["kt"] = f"{tl.kt:.6g}" + (" √(R̄δ)" if isinstance(tl.slot(), SqrtSpringTangential) else "")
    # fidelity: the twin's converged contact against the seed model's, at the like pair and ``speed``
    try:
        setup.dt = nl.characteristic_time(m / 2.0, speed) / 1000.0  # the probe case's run.dt (no run uses it)
    except (ValueError, ArithmeticError) as exc:
        raise ConfigError("SETTING", line, f"the contact cannot be computed: {exc}") from None
    if not (math.isfinite(setup.dt) and setup.dt > 0):
        raise ConfigError("SETTING", line, f"the contact cannot be computed: its time scale is {setup.dt * 1000:g} s "
                                           "(a coefficient under- or overflows in floating point)")
    gap, probes, failures = 0.0, [], []
    scales = {"impact_energy": 0.25 * m * speed ** 2, "spin": speed / radius}
    for angle in (ANGLES if ps.asked.get("friction", 0.0) > 0 else ANGLES[:1]):
        try:
            case = probe_case(setup, ps, speed, angle, nl, tl, seed_of(nl, tl, ps.asked))
            twin = native_law(case, engine, ps.native)
            seed = ADAPTIVE.run(case, model=resolve(case))
        except (ValueError, ArithmeticError) as exc:
            raise ConfigError("SETTING", line, f"the {angle:g}° probe cannot be computed: {exc}") from None
        g = _worst(_metrics_of(twin.converged), _metrics(seed), [k for k in METRICS if k != "peak_force"], scales)
        failure = health_failure({"converged twin": {"status": twin.status, **_metrics_of(twin.converged)},
                                  "seed model": {"status": seed.status, "message": seed.message, **_metrics(seed)}},
                                 radius)
        probes.append({"angle": angle, "twin": _metrics_of(twin.converged), "twin_by": twin.how,
                       "seed": _metrics(seed), "gap": g, "failure": failure})
        if failure:
            failures.append(f"{angle:g}°: {failure}")
        gap = max(gap, g)
    e_asked, e_real = ps.asked.get("restitution"), probes[0]["twin"]["restitution"]
    for f in findings:  # the traps that miss the asked e, with the head-on probe's converged e
        if f["code"] in ("tsuji", "limit") and e_asked is not None and math.isfinite(e_real) and not probes[0]["failure"]:
            f["size"].update(asked=e_asked, realised=e_real, difference=e_real - e_asked)
            f["text"] += (f": e = {e_asked:g} asked, {e_real:.4f} realised (head-on at {speed:g} m/s, converged; "
                          "the engine's own step adds its time-step error)")
    fidelity = "failed" if failures else _fidelity(gap, reasons)
    return {**out, "seed": {"normal": normal, "tangential": tangential, "params": params, "reasons": reasons},
            "fidelity": fidelity, "gap": math.nan if failures else gap, "failures": failures, "probes": probes,
            "implied": implied}


def _metrics_of(m: dict) -> dict:
    return {k: m.get(k, math.nan) for k in METRICS + HEALTH}


def _rerun(setup, ps, native, p: dict) -> dict:
    """The engine's metrics of probe ``p`` run again with another Native (an engine reader's measured trap)."""
    nl, tl = registry.get(setup.engine).twin(native, *_effective(setup, ps))
    case = probe_case(setup, ps, p["speed"], p["angle"], nl, tl, seed_of(nl, tl, ps.asked), p["dt"])
    res = Source.of(setup.engine).run(case, p["dt"], native=native)
    return {"status": res.status, "message": res.message, **_metrics(res)}
