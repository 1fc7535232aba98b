"""Run time against error (``demcheck bench``) and the recommended time step (``demcheck dt``).

For a collision case and each source — the reference's verlet method (the engines' scheme with the seed
law), each engine that can express the model, and the reference's adaptive method over its tolerance —
the errors of restitution, contact time, maximum overlap and peak force against the converged adaptive
answer (rtol 1e-13), with the wall time that bought them:

* time-stepped sources over a grid of steps per elastic contact time (a few to thousands); the order of
  convergence fitted on the asymptotic part; the cheapest time step meeting each target error;
* engines timed two ways: one collision per process (start-up included), and per collision in a batch of
  independent copies run in one process (start-up paid once), so that start-up does not dominate.

Errors are relative (|x − x_ref| / |x_ref|); a source's error is the worst of the four metrics — and, for an
oblique impact with friction, also of tangential restitution and rebound spin, in the suite's units (1 for
a restitution, v_in/R for a spin: a near-zero tangential restitution is not divided by itself). Without
them an oblique case's time step would be chosen on its normal motion alone, blind to the friction law's
own error (Walton's at the Coulomb limit: docs/models.md, "A false plateau"). A metric the scene does not
produce — undefined (NaN or absent) in both the converged answer and the run, as tangential restitution and
rebound spin are for a head-on impact with a friction law — is left out of the error; a metric defined on one
side only is a real disagreement and keeps the error undefined (NaN).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..case import Case
from ..engines import registry
from ..errors import ConfigError, DemcheckError, EngineInterrupted, UnsupportedByEngine
from ..reference.collision import characteristic_time
from ..laws.model import resolve

METRICS = ("restitution", "contact_time", "max_overlap", "peak_force")
OBLIQUE_METRICS = ("tangential_restitution", "rebound_angular_velocity")  # in the suite's units
STEPS_PER_CONTACT = (5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000)
ADAPTIVE_RTOLS = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
TARGETS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)
BATCH = 16
# a native law whose twin has no adaptive solve (a force history): its converged answer is the twin at t_c over
# this many steps, 16 times finer than the finest grid point (DT_STEPS' 10 000). An incremental force history
# makes velocity Verlet first order (measured: Yade's Mindlin twin at 30°, every error halves as the steps double
# from 5 000 to 80 000), so the error of a point n steps per contact is understated by n/CONVERGED_STEPS: 6% at
# 10 000 (at 20 000 steps it was 50%). Cost, measured: 0.2 s at 80 000 steps, 0.8 s at 160 000, once per case.
CONVERGED_STEPS = 160_000


@dataclass
class Point:
    source: str
    steps_per_contact: float | None
    dt: float | None
    rtol: float | None
    wall_time: float  # s per collision (engines: per process)
    batch_time: float | None  # s per collision in a batch (engines)
    errors: dict
    status: str = "ok"
    message: str = ""

    @property
    def error(self) -> float:
        vals = [v for v in self.errors.values() if v is not None and math.isfinite(v)]
        return max(vals) if vals and len(vals) == len(self.errors) else math.nan

    def as_dict(self) -> dict:
        return {"source": self.source, "steps_per_contact": self.steps_per_contact, "dt": self.dt,
                "rtol": self.rtol, "wall_time": self.wall_time, "batch_time": self.batch_time,
                "errors": self.errors, "error": self.error, "status": self.status, "message": self.message}


def metrics_of(case: Case, model) -> tuple[str, ...]:
    """The metrics a case's error is the worst of: the normal four, and the tangential two for an oblique
    (3-D) impact with a friction law."""
    from ..reference.collision import is_one_dimensional

    if is_one_dimensional(case, model) or case.contact.tangential in (None, "none"):
        return METRICS
    return METRICS + OBLIQUE_METRICS


def _defined(x) -> bool:
    return x is not None and math.isfinite(x)


def _errors(m: dict, ref: dict, metrics=METRICS, scales=None) -> dict:
    """The error of each of ``metrics`` of ``m`` against ``ref``. A metric undefined on both sides (the
    scene does not produce it: a head-on impact has no tangential restitution) is left out; one defined on
    one side only is NaN — a disagreement, which makes the point's error NaN."""
    from .verdicts import scale

    out = {}
    for k in metrics:
        a, b = m.get(k), ref.get(k)
        if not _defined(a) and not _defined(b):
            continue
        if not (_defined(a) and _defined(b)):
            out[k] = math.nan
        elif k in OBLIQUE_METRICS:
            out[k] = abs(a - b) / scale(k, b, scales)
        else:
            out[k] = abs(a - b) / abs(b) if b else math.nan
    return out


def _timed(fn, repeat: int = 3):
    """(best wall time, result) of ``repeat`` calls: the machine is shared and noisy."""
    best, out = math.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def fit_order(points: list[Point], metric: str | None = None) -> float:
    """Slope of log(error) against log(dt) on the asymptotic range (error between 1e-12 and 1e-2, at least
    20 steps per contact): the order of convergence."""
    xs, ys = [], []
    for p in points:
        e = p.error if metric is None else p.errors.get(metric)
        if p.status == "ok" and p.dt and e and math.isfinite(e) and 1e-12 < e < 1e-2 and p.steps_per_contact >= 20:
            xs.append(math.log10(p.dt))
            ys.append(math.log10(e))
    if len(xs) < 3:
        return math.nan
    return float(np.polyfit(xs, ys, 1)[0])


def cheapest(points: list[Point], target: float) -> Point | None:
    """The largest dt of the grid that meets ``target`` — and whose finer steps all do too (so a lucky
    cancellation at one coarse step is not taken for convergence)."""
    pts = sorted((p for p in points if p.dt), key=lambda p: p.dt)
    best = None
    for p in pts:
        if p.status == "ok" and math.isfinite(p.error) and p.error <= target:
            best = p
        else:
            break
    return best


@dataclass
class BenchResult:
    case: str
    model: dict
    t_contact: float
    reference: dict
    points: list[Point] = field(default_factory=list)
    skipped: dict = field(default_factory=dict)
    natives: dict = field(default_factory=dict)  # engine → NativeLaw

    def against(self, src: str) -> str:
        """What a source's errors are measured against."""
        from .sources import ADAPTIVE, Source

        source = Source.parse(src)
        if source.name in self.natives:
            return f"{source.twin().label} converged ({self.natives[source.name].how})"
        return f"{ADAPTIVE.label} converged (the seed model)"

    def sources(self) -> list[str]:
        return list(dict.fromkeys(p.source for p in self.points))

    def summary(self) -> dict:
        from .sources import ADAPTIVE

        out = {"case": self.case, "model": self.model, "t_contact": self.t_contact, "reference": self.reference,
               "points": [p.as_dict() for p in self.points], "skipped": self.skipped, "sources": {},
               "natives": {e: law.as_dict() for e, law in self.natives.items()}}
        for src in self.sources():
            pts = [p for p in self.points if p.source == src]
            names = _used(pts) if pts else list(METRICS)
            s = {"order": fit_order(pts), "order_per_metric": {m: fit_order(pts, m) for m in names},
                 "against": self.against(src), "cheapest": {}}
            for tgt in TARGETS + ((1e-7, 1e-8) if src == ADAPTIVE.label else ()):
                if src == ADAPTIVE.label:
                    ok = [p for p in pts if math.isfinite(p.error) and p.error <= tgt]
                    c = min(ok, key=lambda p: p.wall_time) if ok else None
                else:
                    c = cheapest(pts, tgt)
                s["cheapest"][f"{tgt:g}"] = None if c is None else {
                    "dt": c.dt, "steps_per_contact": c.steps_per_contact, "rtol": c.rtol, "error": c.error,
                    "wall_time": c.wall_time, "batch_time": c.batch_time}
            out["sources"][src] = s
        return out


@dataclass
class NativeLaw:
    """An engine's own setting of the case (``[engine.NAME]``) and the answer its runs are measured against:
    the twin's converged contact (``converged``, obtained ``how``), with the native law's elastic contact time
    and how far that answer lies from the seed model's (``seed_gap``, per metric, in the bench's units)."""

    engine: str
    native: object  # engines.base.Native
    model: object  # the twin's ResolvedModel
    t_contact: float
    converged: dict
    how: str
    status: str
    message: str
    seed_gap: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        from ..engines.mapping import native_summary

        return {"native": native_summary(self.native), "t_contact": self.t_contact, "converged": self.converged,
                "converged_by": self.how, "status": self.status, "note": self.message,
                "seed_gap": self.seed_gap}


def native_sources(case: Case, engines) -> dict:
    """{source: the Native it runs} for each engine (or build of one) among ``engines`` (Engines or names) whose
    engine the case gives its own setting (``[engine.NAME]``)."""
    from .sources import engines_of

    return {e.name: nat for e in engines_of(engines) if (nat := e.case_native(case)) is not None}


def native_contact(case: Case, native) -> tuple[object, float]:
    """(the twin's ResolvedModel, its elastic contact time) of a native law for the case: the time a native
    law's grid of steps (bench, dt, stress) and its default step (engines.collide.setting) are counted in."""
    from ..engines.mapping import twin_model

    model = twin_model(resolve(case), native)
    return model, characteristic_time(model)


def native_seen(case: Case, model) -> tuple:
    """What a native run sees (``model``: its twin's, ``native_contact``): the twin's laws and the bodies'
    initial state — masses, radii, positions, velocities, spins —, the walls and gravity. Two cases with the same
    are the same native run: a swept or stressed parameter that leaves it unchanged does not move that run."""
    return (model.normal_law, model.tangential_law, tuple(case.mass(i) for i in range(len(case.particles))),
            tuple((p.radius, tuple(p.position), tuple(p.velocity), tuple(p.angular_velocity))
                  for p in case.particles),
            tuple((tuple(w.point), tuple(w.normal)) for w in case.walls), tuple(case.run.gravity))


def native_law(case: Case, engine, native, seed: dict | None = None) -> NativeLaw:
    """The native law of ``engine`` for the case and its converged answer: the twin solved by the adaptive
    method with the engine's kinematic rules, or — a twin with a force history has no adaptive solve — by its
    own scheme at t_c/CONVERGED_STEPS. ``seed``: the seed model's converged metrics, for ``seed_gap``."""
    from ..reference.health import impact_scales
    from .sources import Source

    model, t_c = native_contact(case, native)
    twin = Source.of(engine, twin=True)  # an Engine, or its name
    engine = twin.engine
    conv = twin.run(case, t_c / CONVERGED_STEPS, native=native, converged=True)
    # a twin without an adaptive solve (the engine's own kernel, a force history): its scheme at t_c/CONVERGED_STEPS
    how = (f"verlet at t_c/{CONVERGED_STEPS}: {conv.meta['no_adaptive']} has no adaptive solve"
           if "no_adaptive" in conv.meta else f"adaptive, rtol {conv.rtol:g}")
    m = conv.metrics()
    # the solver's note on a tangential history concerns a contact that slides: none in a head-on impact
    note = conv.message if _defined(m.get("tangential_restitution")) or conv.status != "ok" else ""
    law = NativeLaw(engine.name, native, model, t_c, m, how, conv.status, note)
    if seed is not None:
        law.seed_gap = _errors(law.converged, seed, METRICS + OBLIQUE_METRICS, impact_scales(case, model))
    return law


def _native_errors(law: NativeLaw, metrics: dict, scales) -> dict:
    """A native run's errors against its twin's converged answer: every metric the scene produces (a head-on
    impact's tangential restitution, undefined on both sides, is left out)."""
    return _errors(metrics, law.converged, METRICS + OBLIQUE_METRICS, scales)


@dataclass(frozen=True)
class Basis:
    """What every point of a case's bench is run with and measured against: the case, the converged answer of the
    seed model (``ref``) and the metrics and scales of the errors, its elastic contact time, each engine's native
    law (``natives``, engine → NativeLaw), and the batch size of the engines' batched runs."""

    case: Case
    ref: dict
    metrics: tuple
    scales: dict
    t_contact: float
    natives: dict
    batch: int


def check_case(case: Case) -> Case:
    """A case bench can time: a collision (``demcheck bench`` checks every file so as it loads it)."""
    from .sources import collision_only

    return collision_only(case, "bench times the steps of an impact; a scenario beyond sliding is solved by the adaptive reference alone (`demcheck verify` runs it)")


def bench_case(case: Case, engines=None, steps=STEPS_PER_CONTACT, rtols=ADAPTIVE_RTOLS,
               batch: int = BATCH, cache=None, progress=None, campaign=None) -> BenchResult:
    """The work–precision of each source for one collision case (module docstring). ``engines``: the engines
    and builds to time (default every registered one); an engine the case gives its own setting runs it, as
    its twin does, both against the twin's converged answer. Each point is a task of ``campaign``
    (dispatch.Campaign; default this process), the points in the order planned."""
    from ..reference.health import impact_scales
    from . import sources
    from .dispatch import Campaign

    check_case(case)
    model = resolve(case)
    t_c = characteristic_time(model)
    ref = sources.ADAPTIVE.run(case).metrics()
    res = BenchResult(case.name, model.describe(), t_c, ref)
    planned = sources.plan(case, engines)
    res.natives = {p.source.name: native_law(case, p.source.engine, p.native, ref) for p in planned
                   if p.native is not None}
    basis = Basis(case, ref, metrics_of(case, model), impact_scales(case, model), t_c, res.natives, batch)
    plan = [(sources.ADAPTIVE.label, rtol) for rtol in rtols] + [(sources.VERLET.label, spc) for spc in steps]
    # the native law in the reference
    plan += [(p.source.twin().label, spc) for p in planned if p.native is not None for spc in steps]
    for p in planned:
        if p.runs:
            plan += [(p.source.label, spc) for spc in steps]
        else:
            res.skipped[p.source.label] = ("not expressible: " if p.status == sources.NOT_EXPRESSIBLE else "") + p.why
    tick = progress or (lambda: None)
    done = {}
    for i, point in (campaign or Campaign()).completed(point_task, [(i, (basis, *p)) for i, p in enumerate(plan)]):
        done[i] = point
        tick()
    for i in sorted(done):
        if isinstance(done[i], str):  # the engine is missing on the worker the point went to
            res.skipped[plan[i][0]] = done[i]
        else:
            res.points.append(done[i])
    return res


def point_task(basis: Basis, source: str, step: float, cache=None) -> Point | str:
    """One point of a bench, where the campaign runs it (comparisons/dispatch.py): ``step`` is the adaptive
    method's rtol for reference-adaptive, else steps per elastic contact time (a native law's own for an engine
    with one, and its twin). A str: why it did not run (the engine is missing on the Dask worker it went to)."""
    from .dispatch import missing_here
    from .sources import REFERENCE, TWIN, Source

    case, ref, metrics, scales = basis.case, basis.ref, basis.metrics, basis.scales
    src = Source.parse(source)
    if src.kind == REFERENCE:
        rtol, spc = (step, None) if src.method == "adaptive" else (None, step)
        dt = None if spc is None else basis.t_contact / spc
        wall, r = _timed(lambda: src.run(case, dt, rtol=rtol))
        return Point(source, spc, dt, rtol, wall, None, _errors(r.metrics(), ref, metrics, scales), r.status,
                     r.message)
    law = basis.natives.get(src.name)
    if src.kind == TWIN:
        return _twin_point(case, src, law, step, repeat=3)
    lacking = missing_here([src.name])
    if lacking:
        return lacking[src.name]
    return _engine_point(basis, src, law, step)


def _engine_point(basis: Basis, src, law, step: float) -> Point:
    """An engine's point: one collision per process, and a batch of copies in one."""
    case, metrics, scales = basis.case, basis.metrics, basis.scales
    dt = (law.t_contact if law else basis.t_contact) / step
    native = law.native if law else None
    try:
        one = src.run(case, dt, cache=None, native=native)
        try:
            many = src.run(case, dt, cache=None, copies=basis.batch, native=native)
        except UnsupportedByEngine:  # an engine whose decks hold one collision: no batched time
            many = None
    except EngineInterrupted:  # Ctrl-C / SIGTERM stops the command, not one run
        raise
    except DemcheckError as exc:
        return Point(src.label, step, dt, None, math.nan, math.nan, {k: math.nan for k in metrics}, "failed",
                     str(exc).splitlines()[0])
    # an engine result carries the reference's own checks (reference/health.py)
    errors = _native_errors(law, one.metrics(), scales) if law else _errors(one.metrics(), basis.ref, metrics, scales)
    return Point(src.label, step, dt, None, one.meta["engine_wall_time"],
                 many.meta["engine_wall_time"] / basis.batch if many is not None else math.nan,
                 errors, one.status, one.message if not one.ok else "")


# ----------------------------------------------------------------------------- demcheck dt


def rayleigh_time(case: Case) -> float:
    """Rayleigh wave time πR√(ρ/G)/(0.1631ν + 0.8766) of the smallest particle (the usual DEM time-step bound)."""
    out = math.inf
    for p in case.particles:
        m = case.materials[p.material]
        out = min(out, math.pi * p.radius * math.sqrt(m.density / m.shear_modulus) / (0.1631 * m.poisson_ratio + 0.8766))
    return out


def hertz_time(case: Case) -> float:
    """The exact elastic Hertz contact time at the case's impact speed (2.868266 (m̄²/(R̄Ē²v))^{1/5})."""
    from ..laws.analytic import HERTZ_DURATION_CONSTANT

    model = resolve(case)
    p = model.pair
    return HERTZ_DURATION_CONSTANT * (p.m_eff**2 / (p.r_eff * p.e_eff**2 * p.impact_speed)) ** 0.2


def _used(points: list[Point]) -> list[str]:
    """The metrics the points' errors are made of, in the order of METRICS + OBLIQUE_METRICS (a metric
    undefined on both sides is in none of them)."""
    seen = {k for p in points for k in p.errors}
    return [k for k in METRICS + OBLIQUE_METRICS if k in seen] + sorted(seen - set(METRICS + OBLIQUE_METRICS))


DT_STEPS = (10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000)  # the grid ``demcheck dt`` measures


def _choose(pts: list[Point], target: float) -> dict:
    """The cheapest step of ``pts`` meeting ``target``: dt, steps per contact, the error to expect and the metric
    that limits it — or dt None and the message saying how far the finest step still is."""
    c = cheapest(pts, target)
    if c is not None:
        return {"dt": c.dt, "steps_per_contact": c.steps_per_contact, "expected_error": c.error,
                "limited_by": max(c.errors, key=lambda k: c.errors[k])}
    finest = min((p for p in pts if p.status == "ok"), key=lambda p: p.dt, default=None)
    why = ""
    if finest is not None:
        worst = sorted(((v, k) for k, v in finest.errors.items() if math.isfinite(v)), reverse=True)
        parts = [f"{v:.2g} in {k}" for v, k in worst if v > target]
        parts += [f"undefined in {k} (one side only)" for k, v in finest.errors.items() if not math.isfinite(v)]
        why = ": at t_c/{:g} the error is still {}".format(finest.steps_per_contact, ", ".join(parts) or "—")
    finest_steps = max((p.steps_per_contact for p in pts), default=math.nan)
    return {"dt": None, "message": f"no time step of the grid (down to t_c/{finest_steps:g}) meets {target:g}{why}"}


def recommend(case: Case, target: float = 1e-3, engines=None) -> dict:
    """A time step for the case's model meeting ``target`` (worst relative error of restitution, contact
    time, maximum overlap and peak force; for an oblique impact with friction also of tangential restitution
    and rebound spin in the suite's units), from the measured work-precision data of the reference's verlet
    method (the engines' scheme, which exact engine mappings reproduce to round-off).

    For each engine among ``engines`` (default every registered one) the case gives its own setting
    (``[engine.NAME]``), ``natives[NAME]`` is the same for that native law: its twin's error against the twin's
    converged answer (the engine computes what its twin does, to round-off)."""
    from .sources import VERLET, Source

    b = bench_case(case, engines=(), rtols=(), steps=DT_STEPS)
    pts = [p for p in b.points if p.source == VERLET.label]
    t_r, t_h = rayleigh_time(case), hertz_time(case)
    out = {"case": case.name, "model": b.model, "target": target, "t_contact": b.t_contact,
           "rayleigh_time": t_r, "hertz_time": t_h, "order": fit_order(pts),
           "metrics": _used(b.points),
           "rules_of_thumb": {"0.2 t_Rayleigh": 0.2 * t_r, "t_Hertz / 50": t_h / 50},
           "table": [{"steps_per_contact": p.steps_per_contact, "dt": p.dt, "error": p.error,
                      "status": p.status} for p in pts]}
    out.update(_choose(pts, target))
    if out["dt"] is not None:
        out.update(dt_over_rayleigh=out["dt"] / t_r, dt_over_hertz=out["dt"] / t_h)
    out["natives"] = {}
    natives = native_sources(case, engines)
    for engine, nat in natives.items():
        law = native_law(case, engine, nat, b.reference)
        twin = _twin_points(case, engine, law, DT_STEPS)
        entry = {**law.as_dict(), "target": target, "order": fit_order(twin), "metrics": _used(twin),
                 "against": f"{Source.of(engine, twin=True).label} converged ({law.how})",
                 "table": [{"steps_per_contact": p.steps_per_contact, "dt": p.dt, "error": p.error,
                            "status": p.status} for p in twin]}
        entry.update(_choose(twin, target))
        out["natives"][engine] = entry
    return out


def _twin_points(case: Case, engine, law: NativeLaw, steps, repeat: int = 1) -> list[Point]:
    """The native law's twin over a grid of steps per its elastic contact time (``_twin_point``)."""
    from .sources import Source

    twin = Source.of(engine, twin=True)
    return [_twin_point(case, twin, law, spc, repeat) for spc in steps]


def _twin_point(case: Case, twin, law: NativeLaw, spc: float, repeat: int = 1) -> Point:
    """The native law's twin (``twin``, a Source) at ``spc`` steps per its elastic contact time, its error against
    the twin's converged answer (best wall time of ``repeat`` runs). A step the run cannot hold (too many steps) is
    that point's failure."""
    from ..reference.health import impact_scales

    dt = law.t_contact / spc
    try:
        wall, r = _timed(lambda: twin.run(case, dt, native=law.native), repeat)
    except ConfigError as exc:
        return Point(twin.label, spc, dt, None, math.nan, None, {k: math.nan for k in METRICS}, "failed",
                     str(exc).splitlines()[0])
    errors = _native_errors(law, r.metrics(), impact_scales(case, law.model))
    return Point(twin.label, spc, dt, None, wall, None, errors, r.status, r.message)


def speed_goal_text(results: list[dict]) -> str:
    """The issue's speed goal, per case: the adaptive method's time to an error of 1e-8 against the time
    each engine needs for 1e-3 (per process and per batched collision), measured in this run."""
    from .sources import ADAPTIVE

    lines = []
    for b in results:
        src = b["sources"]
        a = (src.get(ADAPTIVE.label) or {}).get("cheapest", {}).get("1e-08")
        if a is None:
            continue
        for e in registry.names():
            c = (src.get(e) or {}).get("cheapest", {}).get("0.001")
            if c is None:
                continue
            ratio_p = c["wall_time"] / a["wall_time"]
            ratio_b = (c["batch_time"] / a["wall_time"]) if c.get("batch_time") else math.nan
            lines.append(f"{b['case']}: adaptive to 1e-8 in {a['wall_time'] * 1e3:.3g} ms; {e} to 1e-3 in "
                         f"{c['wall_time'] * 1e3:.3g} ms per process ({ratio_p:.3g}×), "
                         f"{c['batch_time'] * 1e3:.3g} ms per batched collision ({ratio_b:.3g}×) — goal "
                         f"{'met' if min(ratio_p, ratio_b) > 1 else 'MISSED'}")
    return "\n".join(lines)
