"""Numerical stability (``demcheck stress``): how large a time step each source survives, and where.

For a collision case file, each stress parameter is pushed over its range (stiffness, mass ratio up to a
rigid wall, impact speed, restitution near 0 and near 1, very small and very large radii, grazing
incidence); at each value, and for each source (the reference's verlet method and every engine that can
express the model), the largest stable time step is found by bisection over a grid of steps per elastic
contact time. A run fails when it is unresolved, produces NaN, overlaps beyond half the radius, creates
energy (a law that only stores or dissipates it; reference/health.py), does not separate, or
the engine errors (lost atoms, …). The stability map is dt_max / t_c against each parameter; where an
engine and the reference disagree about the limit by more than one grid step, the point is flagged.

A case with an engine's own setting (``[engine.NAME]``) runs that native law in the engine and in its twin
(``NAME-twin``), on a grid of steps per the native law's own elastic contact time; the engine is flagged against
its twin (the seed model's verlet run is a different law). A parameter that does not move the native run (the
materials' stiffness or restitution, when the setting gives its own) is left out for those two sources, and
the report says so.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..case import Case, _read, from_dict, naming_file
from ..errors import ConfigError, DemcheckError, EngineInterrupted
from ..reference.collision import characteristic_time
from ..reference import health
from ..laws.model import resolve
from .sources import VERLET

# steps per elastic contact time, coarse to fine: the search grid
GRID = (1, 1.5, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 100)


def _scaled(key, factor):
    def apply(raw):
        for m in raw.get("materials", {}).values():
            if key in m:
                m[key] = m[key] * factor
        return raw
    return apply


def _set_materials(key, value):
    def apply(raw):
        for m in raw.get("materials", {}).values():
            m[key] = value
        return raw
    return apply


def _radius(factor):
    def apply(raw):
        for p in raw.get("particles", []):
            p["radius"] = p["radius"] * factor
            if "position" in p and "impact" not in raw:
                p["position"] = [x * factor for x in p["position"]]
        return raw
    return apply


def _impact(key, value):
    def apply(raw):
        if "impact" not in raw:
            raise ConfigError("impact", None, f"stress parameter {key} needs an [impact] table in the case")
        raw["impact"][key] = value
        return raw
    return apply


def _mass_ratio(ratio):
    def apply(raw):
        parts = raw.get("particles", [])
        if len(parts) != 2:
            raise ConfigError("particles", len(parts), "the mass-ratio sweep needs a particle pair")
        mats = raw["materials"]
        base = mats[parts[1]["material"]]
        mats["heavy"] = {**base, "density": base["density"] * ratio}
        parts[1]["material"] = "heavy"
        return raw
    return apply


def parameters(raw: dict) -> dict[str, list[tuple[float, object]]]:
    """The stress parameters that apply to a case: name → [(value, raw transform)]."""
    out = {
        "stiffness (E × factor)": [(f, _scaled("youngs_modulus", f)) for f in (1e-2, 1.0, 1e2)],
        "restitution": [(e, _set_materials("restitution", e)) for e in (0.05, 0.5, 0.99, 1.0)],
        "radius (× factor)": [(f, _radius(f)) for f in (1e-2, 1.0, 1e2)],
    }
    if "impact" in raw:
        out["impact speed (m/s)"] = [(v, _impact("speed", v)) for v in (0.01, 1.0, 100.0)]
        out["incidence angle (°)"] = [(a, _impact("angle", a)) for a in (0.0, 45.0, 85.0, 89.0)]
    if len(raw.get("particles", [])) == 2:
        out["mass ratio"] = [(r, _mass_ratio(r)) for r in (1.0, 10.0, 100.0, 1000.0)]
    return out


@dataclass
class Limit:
    parameter: str
    value: float
    source: str
    steps_per_contact: float | None  # the finest grid point that failed, or None when all were stable
    dt_max_over_tc: float | None
    failure: str = ""
    t_contact: float | None = None  # the elastic contact time the grid is in (a native law's own)


@dataclass
class StressResult:
    case: str
    model: dict
    limits: list[Limit] = field(default_factory=list)
    skipped: dict = field(default_factory=dict)
    natives: dict = field(default_factory=dict)  # engine → its native setting in one line (the case's own)

    def flags(self) -> list[dict]:
        """Where an engine and what it computes disagree about stability by more than one grid step: the
        reference's verlet method for a mapped seed model, the engine's twin for its native setting (a twin
        is the native law itself, never flagged against the seed model's run)."""
        from .sources import ENGINE, VERLET, Source

        out = []
        by = {(l.parameter, l.value, l.source): l for l in self.limits}
        for l in self.limits:
            src = Source.parse(l.source)
            if src.kind != ENGINE:
                continue
            twin = src.twin().label
            against = twin if (l.parameter, l.value, twin) in by else VERLET.label
            r = by.get((l.parameter, l.value, against))
            if r is None:
                continue
            a, b = _grid_index(r.dt_max_over_tc), _grid_index(l.dt_max_over_tc)
            if abs(a - b) > 1:
                out.append({"parameter": l.parameter, "value": l.value, "source": l.source, "against": against,
                            "reference_dt_max_over_tc": r.dt_max_over_tc, "engine_dt_max_over_tc": l.dt_max_over_tc,
                            "engine_failure": l.failure, "reference_failure": r.failure})
        return out

    def summary(self) -> dict:
        return {"case": self.case, "model": self.model, "skipped": self.skipped, "natives": self.natives,
                "limits": [l.__dict__ for l in self.limits], "disagreements": self.flags()}


def _grid_index(x):
    if x is None:
        return -1
    spc = 1.0 / x
    return min(range(len(GRID)), key=lambda i: abs(math.log(GRID[i] / spc)))


def _stable_reference(case: Case, dt: float, t_c: float) -> tuple[bool, str]:
    """Stability, not resolution: a run with few steps inside the contact is inaccurate (``bench`` measures
    that) but stable as long as it stays finite, bounded and does not create energy."""
    try:
        r = VERLET.run(case, dt)
    except DemcheckError as exc:
        return False, str(exc).splitlines()[0]
    if r.status not in ("ok", "unresolved", "unstable"):
        return False, f"{r.status}: {r.message}"
    status, why = health.check(r, case, min_steps=1)
    return status == "ok", why


def _stable_source(case: Case, src, dt: float, native=None, model=None) -> tuple[bool, str]:
    """An engine run's or its twin's stability (``src``, a Source; ``native``: the case's own setting, judged with
    its twin's ``model``): a twin's run that its own checks call neither ok, unresolved nor unstable fails."""
    from .sources import TWIN

    try:
        r = src.run(case, dt, native=native, **({} if src.kind == TWIN else {"timeout": 120.0}))
    except EngineInterrupted:  # Ctrl-C / SIGTERM stops the command, not one run
        raise
    except DemcheckError as exc:
        return False, str(exc).splitlines()[0]
    if src.kind == TWIN and r.status not in ("ok", "unresolved", "unstable"):
        return False, f"{r.status}: {r.message}"
    status, why = health.check(r, case, model, min_steps=1)
    return status == "ok", why


def _native_run(case: Case, engine):
    """(Native, twin model, what the native run sees) of the case's own setting for ``engine`` (an Engine), or
    None: what it sees is its twin's laws and the bodies' initial state, so that a parameter that leaves it
    unchanged is known not to move the native run."""
    from .bench import native_contact, native_seen

    nat = engine.case_native(case)
    if nat is None:
        return None
    model, _ = native_contact(case, nat)
    return nat, model, native_seen(case, model)


def largest_stable(check) -> tuple[float | None, str]:
    """Bisection over GRID (coarse → fine), assuming stability is monotone in dt: the coarsest grid point
    from which every finer one is stable. Returns (steps per contact of the limit, failure of the next
    coarser point) or (None, why) when even the finest point fails."""
    lo, hi = 0, len(GRID) - 1  # GRID[hi] must be stable; find the smallest stable index
    ok, why = check(GRID[hi])
    if not ok:
        return None, why
    failure = ""
    ok0, why0 = check(GRID[0])
    if ok0:
        return GRID[0], ""
    failure = why0
    while hi - lo > 1:
        mid = (lo + hi) // 2
        ok, why = check(GRID[mid])
        if ok:
            hi = mid
        else:
            lo, failure = mid, why
    return GRID[hi], failure


def read_table(path: Path) -> dict:
    """A stress case file's table (its variants dropped: stress pushes parameters of its own), which ``stress_case``
    varies; its Case is api.load's of this table (the one loader). A file that cannot be read is a ConfigError
    naming the file (case.naming_file)."""
    with naming_file(path):
        raw = _read(path)
        raw.pop("variants", None)
        return raw


def check_case(case: Case) -> Case:
    """A case stress can search: a collision (``demcheck stress`` checks every file so as it loads it)."""
    from .sources import collision_only

    return collision_only(case, "stress searches the largest stable step of an impact; a scenario beyond sliding is solved by the adaptive reference alone (`demcheck verify` runs it)")


def limit_task(parameter: str, value, source: str, case: Case, t_c: float, cache=None) -> Limit | str:
    """The largest stable step of ``source`` (reference-verlet, an engine, or NAME-twin: the case's own setting
    for an engine when it has one) at one value of a stress parameter, where the campaign runs it
    (comparisons/dispatch.py). A str: why it did not run (the engine is missing on the Dask worker it went to)."""
    from .dispatch import missing_here
    from .sources import ENGINE, REFERENCE, Source

    src = Source.parse(source)
    if src.kind == REFERENCE:
        spc, why = largest_stable(lambda n: _stable_reference(case, t_c / n, t_c))
        return Limit(parameter, value, source, spc, (1.0 / spc) if spc else None, why, t_c)
    nat = _native_run(case, src.engine)
    native, model = (nat[0], nat[1]) if nat is not None else (None, None)
    t = characteristic_time(model) if nat is not None else t_c
    if src.kind == ENGINE and (lacking := missing_here([src.name])):
        return lacking[src.name]
    spc, why = largest_stable(lambda n: _stable_source(case, src, t / n, native, model))
    return Limit(parameter, value, source, spc, (1.0 / spc) if spc else None, why, t)


def stress_case(raw0: dict, base: Case, engines=None, only: list[str] | None = None,
                progress=None, campaign=None) -> StressResult:
    """Stress one case (``read_table``'s raw table and its Case) over its parameters, each source's search at each
    value a task of ``campaign`` (dispatch.Campaign; default this process); the limits in the order planned."""
    from .dispatch import Campaign
    from .sources import engines_of

    check_case(base)
    res = StressResult(base.name, resolve(base).describe())
    params = parameters(raw0)
    if only:
        params = {k: v for k, v in params.items() if any(o in k for o in only)}
    engines = engines_of(engines)
    tick = progress or (lambda: None)
    plan: list = []  # a Limit known without a run (an invalid value), or the arguments of a limit_task
    for name, values in params.items():
        plan += _plan_parameter(res, name, values, raw0, engines)
    tasks = [(i, args) for i, args in enumerate(plan) if not isinstance(args, Limit)]
    done = {}
    for i, limit in (campaign or Campaign()).completed(limit_task, tasks):
        done[i] = limit
        tick()
    for i, item in enumerate(plan):
        item = done.get(i, item)
        if isinstance(item, str):  # the engine is missing on the worker the search went to
            res.skipped[plan[i][2]] = item
        else:
            res.limits.append(item)
    return res


def _points(res: StressResult, values, raw0: dict, engines) -> list:
    """Each value of a parameter as (value, case, t_c, {engine name: _native_run}), or (value, None, why, {}) for
    a value that makes no valid case; the native settings seen noted in ``res``."""
    from ..engines.mapping import native_summary

    points = []
    for value, transform in values:
        try:
            case = from_dict(transform(copy.deepcopy(raw0)))
            t_c = characteristic_time(resolve(case))
            natives = {e.name: n for e in engines if (n := _native_run(case, e)) is not None}
        except DemcheckError as exc:
            points.append((value, None, f"invalid: {exc}", {}))
            continue
        points.append((value, case, t_c, natives))
        res.natives.update({e: native_summary(n[0]) for e, n in natives.items()})
    return points


def _plan_parameter(res: StressResult, name: str, values, raw0: dict, engines) -> list:
    """The searches of one parameter: per value the reference's verlet method, and each engine that can run it
    (sources.plan) with, for a native setting, its twin. An engine whose native run no value of the parameter
    moves is left out, with its twin, and said so in ``res.skipped``."""
    from ..engines.builds import engine_of
    from .sources import NOT_EXPRESSIBLE, VERLET, Source, plan as which

    points = _points(res, values, raw0, engines)
    still = set()
    for e in engines:
        seen = {n[e.name][2] for _, c, _, n in points if c is not None and e.name in n}
        if len(seen) == 1 and all(c is None or e.name in n for _, c, _, n in points):
            still.add(e.name)
            res.skipped[f"{e.name} and {Source.of(e, twin=True).label} × {name}"] = (
                f"the case's [engine.{engine_of(e.name)}] setting is run, and {name} changes neither it nor the "
                "bodies: its stability is the same at every value")
    out: list = []
    for value, case, t_c, natives in points:
        if case is None:
            out.append(Limit(name, value, VERLET.label, None, None, t_c))
            continue
        out.append((name, value, VERLET.label, case, t_c))
        for p in which(case, [e for e in engines if e.name not in still]):
            if p.source.name in natives:
                out.append((name, value, p.source.twin().label, case, t_c))
            if p.runs:
                out.append((name, value, p.source.label, case, t_c))
            else:
                res.skipped[p.source.name] = ("not expressible: " if p.status == NOT_EXPRESSIBLE else "") + p.why
    return out
