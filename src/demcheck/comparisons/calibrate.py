"""``demcheck calibrate CASE --engine E --target restitution=0.6``: the native input that realises a target.

An engine's input is not always what it realises: LAMMPS's ``damping tsuji`` turns an input e = 0.6 into about
0.70, LIGGGHTS's ``limitForce on`` raises e above coefficientRestitution, a time step adds its own error. For
each target metric the engine's package names the input that sets it (:meth:`Engine.knob`); the input is found
by bracketed root finding (Brent's method) on the engine's twin — the reference computing the engine's own
formulas with its scheme — at the run's dt, and confirmed by one run of the engine itself. The result names the
native line to paste (:meth:`Engine.native_lines`).

The configuration calibrated is the case's ``[engine.NAME]`` setting when it has one, else the engine's mapping
of the case's seed model. Several targets are met one after the other (restitution first), each with the
inputs found before it.
"""

from __future__ import annotations

import math

from ..case import Case, run_length
from ..errors import ConfigError, DemcheckError
from ..engines import registry
from ..engines.collide import setting
from ..engines.mapping import contact_mapping, native_summary
from .sources import Source, collision_only

TARGETS = {"restitution": (0.0, 1.0), "tangential_restitution": (-1.0, 1.0)}
ROOT_TOL = 1e-6  # |realised − target| the root is found to, in the metric's own (dimensionless) units
MAX_DOUBLINGS = 60
# the names the errors give the arguments: the API's (a command line passes its options: --target, --engine, --dt)
KEYS = {"targets": "targets", "engine": "engine", "dt": "dt"}


def _under(key: str, metric: str) -> str:
    """One target's key in an error: ``--target restitution`` (the option's), ``targets.restitution``."""
    return key + (" " if key.startswith("--") else ".") + metric


def check_targets(targets: dict, key: str = KEYS["targets"]) -> dict:
    """``targets`` (metric → value) checked; else a ConfigError naming ``key`` (the API's ``targets``, the
    command line's ``--target``)."""
    out = {}
    for k, v in targets.items():
        if k not in TARGETS:
            raise ConfigError(key, k, f"must be one of {', '.join(TARGETS)}")
        lo, hi = TARGETS[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (lo < v <= hi):
            raise ConfigError(_under(key, k), v, f"must be a number in ({lo:g}, {hi:g}]")
        out[k] = float(v)
    if not out:
        raise ConfigError(key, None, "give at least one " + ("METRIC=VALUE" if key.startswith("--") else "metric")
                          + " (restitution, tangential_restitution)")
    return out


def calibrate(case: Case, engine: str, targets: dict, dt: float | None = None, confirm: bool = True,
              campaign=None, keys: dict | None = None) -> dict:
    """The calibration as a dict: per target the input found (name, from, to), the twin's realised value, and
    the engine's on confirmation; the native configuration and the lines to paste. The root finding runs here (each
    twin run needs the one before); the confirming engine run is a task of ``campaign`` (dispatch.Campaign; default
    this process). ``keys``: the names the errors give the arguments (KEYS; the command line's options)."""
    keys = {**KEYS, **(keys or {})}
    targets = check_targets(targets, keys["targets"])
    if engine not in registry.names():
        raise ConfigError(keys["engine"], engine, f"must be one of {', '.join(registry.names())}")
    eng = registry.get(engine)
    collision_only(case, "a target metric (restitution) is an impact's")
    if dt is not None and not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise ConfigError(keys["dt"], dt, "must be a number > 0 (s)")
    # the step `demcheck collide --engine` runs the case at (a native setting at its own step): the input found
    # realises the target in the run of the line pasted back into the case
    native, step = setting(case, engine, dt)
    step = step or run_length(case)[0]
    native = native or contact_mapping(case, engine).require()
    if "tangential_restitution" in targets and not _oblique(case):
        raise ConfigError(_under(keys["targets"], "tangential_restitution"), targets["tangential_restitution"],
                          "needs an oblique impact (impact.angle > 0): a head-on one has no tangential motion")
    twin = Source.of(eng, twin=True)
    for metric in targets:  # every input named before any run
        if eng.knob(native, metric) is None:
            raise ConfigError(keys["targets"], metric, f"{eng.title}'s {native_summary(native)} has no input that "
                                                       "sets it")
    out = {"case": case.name, "engine": engine, "dt": step, "from": native_summary(native), "inputs": {}}
    for metric in sorted(targets, key=list(TARGETS).index):
        native, out["inputs"][metric] = _find(case, eng.knob(native, metric), twin, step, metric, targets[metric],
                                              keys["targets"])
    out["native"] = native_summary(native)
    out["lines"] = eng.native_lines(native)
    out["confirmed"] = None
    eng.check_native(native, keys["targets"])  # an input the engine would refuse: stopped before its run
    if confirm:
        _confirm(out, case, engine, step, native, campaign)
    return out


def _find(case: Case, knob, twin: Source, step: float, metric: str, target: float, key: str) -> tuple:
    """(the native configuration with ``knob`` set, its entry in the result): the input that realises ``target``
    in ``twin`` at ``step``, by Brent's method over the knob's range (doubled up to MAX_DOUBLINGS times when it
    has no upper end); a target out of the range's reach is a ConfigError naming ``key``."""
    from scipy.optimize import brentq

    calls = []

    def gap(x):
        v = twin.run(case, step, native=knob.set(x)).metrics()[metric]
        calls.append((x, v))
        if not math.isfinite(v):
            raise DemcheckError(f"the twin's {metric} is not finite at {knob.name} = {x:g}")
        return v - target

    lo, hi = knob.lo, knob.hi
    f_lo = gap(lo)
    if hi is None:
        hi = max(knob.start, 1e-300)
        for _ in range(MAX_DOUBLINGS):
            if (gap(hi) > 0) != (f_lo > 0):
                break
            hi *= 2.0
    f_hi = gap(hi)
    if (f_lo > 0) == (f_hi > 0):
        a, b = calls[0][1], calls[-1][1]
        raise ConfigError(_under(key, metric), target, f"out of reach: {knob.name} in [{lo:g}, {hi:g}] realises "
                                                       f"{min(a, b):.6g} to {max(a, b):.6g} at dt = {step:g} s")
    x = brentq(gap, lo, hi, xtol=1e-14, rtol=1e-12, maxiter=200)
    realised = gap(x) + target
    if abs(realised - target) > ROOT_TOL:
        raise DemcheckError(f"{metric}: Brent's method stopped at {knob.name} = {x:.10g} with {realised:.10g}, "
                            f"not within {ROOT_TOL:g} of {target:g} (the metric jumps there)")
    return knob.set(x), {"input": knob.name, "from": knob.start, "to": x, "target": target, "twin": realised,
                         "twin_runs": len(calls)}


def _confirm(out: dict, case: Case, engine: str, step: float, native, campaign) -> None:
    """The confirming engine run's values in ``out`` (``confirmed``); a run that fails keeps what the twin found,
    with the failure (``confirm_error``)."""
    from .dispatch import Campaign

    [(_, res)] = (campaign or Campaign()).completed(confirm_task, [(0, (case, engine, step, native))])
    if not res.ok:
        out["confirmed"] = False
        out["confirm_error"] = f"the confirming {engine} run is {res.status}: {res.message}"
        return
    m = res.metrics()
    for metric, entry in out["inputs"].items():
        entry["engine"] = m[metric]
    out["engine_version"] = res.engine_version
    out["confirmed"] = all(abs(e["engine"] - e["target"]) <= ROOT_TOL for e in out["inputs"].values())


def confirm_task(case: Case, engine: str, dt: float, native, cache=None):
    """The engine run of the calibrated ``native`` configuration, where the campaign runs it
    (comparisons/dispatch.py); on a Dask worker without the engine, EngineNotFound naming the worker."""
    from ..errors import EngineNotFound
    from .dispatch import missing_here

    lacking = missing_here([engine])
    if lacking:
        raise EngineNotFound(lacking[engine])
    return Source.of(engine).run(case, dt, native=native)


def _oblique(case: Case) -> bool:
    import numpy as np

    p = case.particles
    v = np.asarray(p[0].velocity, float) - (np.asarray(p[1].velocity, float) if len(p) > 1 else 0.0)
    n = (-np.asarray(case.walls[0].normal, float) if case.walls else
         np.asarray(p[1].position, float) - np.asarray(p[0].position, float))
    n = n / np.linalg.norm(n)
    return bool(np.linalg.norm(v - (v @ n) * n) > 1e-12 * max(np.linalg.norm(v), 1e-300)
                or any(np.any(np.asarray(q.angular_velocity) != 0) for q in p))


def text_report(r: dict) -> str:
    lines = [f"calibrate {r['case']} in {r['engine']} at dt = {r['dt']:g} s (from {r['from']})"]
    for metric, e in r["inputs"].items():
        line = (f"  {metric} {e['target']:g}: {e['input']} {e['from']:.10g} → {e['to']:.10g} "
                f"(twin {e['twin']:.10g}")
        if "engine" in e:
            line += f", {r['engine']} {e['engine']:.10g}"
        lines.append(line + ")")
    lines.append("paste:")
    lines += [f"  {x}" for x in r["lines"]]
    if r.get("confirm_error"):
        lines.append(f"NOT CONFIRMED: {r['confirm_error']}")
    elif r["confirmed"] is False:
        lines.append(f"NOT CONFIRMED: the engine run misses a target by more than {ROOT_TOL:g}")
    return "\n".join(lines)
