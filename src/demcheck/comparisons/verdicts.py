"""Verdicts: does a source agree with the seed model, metric by metric, and if not, why?

The reference's adaptive method is the seed model's converged answer. A time-stepped source at step dt is
compared with it in units of each metric's scale (:func:`scale`), against a tolerance that includes the
time step's own error, measured in the same run (the reference's verlet method, seed law, same dt). For
an engine the difference is split in two (docs/verify.md):

* implementation: the engine against its twin at equal dt (what the engine should compute) — must be
  within ``tolerances.engine.implementation``;
* formula: what is left is the engine's formula (an approximate mapping, documented) or a known engine
  behaviour (``data/expected_differences.toml``, matched by engine version).

Each "differs as expected" carries the engine setting that causes it (``Comparison.setting``): an
expected-differences entry's ``setting``, or, for an approximate mapping, the native keyword each of the
mapping's reasons is about (:func:`mapping_setting`, from ``Mapping.keywords``). The report's traps section
names them. The whole native configuration the mapping chose is recorded per case too (:func:`unavailable`,
``CaseResult.settings``).

Verdicts: agree, differs as expected, differs unexpectedly, not expressible, engine missing, failed.
Only "differs unexpectedly" and "failed" fail a run.
"""

from __future__ import annotations

import fnmatch
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from .. import resources

AGREE = "agree"
EXPECTED = "differs as expected"
UNEXPECTED = "differs unexpectedly"
NOT_EXPRESSIBLE = "not expressible"
MISSING = "engine missing"
FAILED = "failed"
VERDICTS = (AGREE, EXPECTED, UNEXPECTED, NOT_EXPRESSIBLE, MISSING, FAILED)
FAILING = (UNEXPECTED, FAILED)

DATA = resources.data_dir()


@dataclass(frozen=True)
class Tolerances:
    engine_rtol: float = 1e-6
    implementation: float = 1e-9
    verlet_rtol: float = 1e-2
    closed_form: float = 1e-8

    @classmethod
    def load(cls, path: str | Path | None = None) -> "Tolerances":
        d = tomllib.loads(Path(path or DATA / "tolerances.toml").read_text())
        return cls(engine_rtol=d["engine"]["rtol"], implementation=d["engine"]["implementation"],
                   verlet_rtol=d["verlet"]["rtol"], closed_form=d["closed_form"]["rtol"])


@dataclass(frozen=True)
class ExpectedDifference:
    engine: str
    versions: tuple[str, ...]
    reason: str
    normal: str | tuple[str, ...] = "*"  # a model id pattern, or a list of them
    tangential: str | tuple[str, ...] = "*"
    metrics: tuple[str, ...] = ("*",)
    source: str = ""
    setting: str = ""  # the engine's own setting (keyword, class, law) that causes the difference

    def matches(self, engine: str, version: str | None, model: dict, metric: str) -> bool:
        return (fnmatch.fnmatchcase(engine, self.engine)
                and version is not None and any(fnmatch.fnmatchcase(version, v) for v in self.versions)
                and _any_match(model.get("normal", ""), self.normal)
                and _any_match(model.get("tangential", ""), self.tangential)
                and any(fnmatch.fnmatchcase(metric, m) for m in self.metrics))


def _any_match(value: str, patterns) -> bool:
    return any(fnmatch.fnmatchcase(value, p) for p in ((patterns,) if isinstance(patterns, str) else patterns))


def load_expected(path: str | Path | None = None) -> list[ExpectedDifference]:
    from ..errors import ConfigError

    path = Path(path or DATA / "expected_differences.toml")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), "(file)", f"not valid TOML: {exc}") from None
    out = []
    for i, d in enumerate(raw.get("difference", [])):
        where = f"{path.name}: difference.{i}"
        for key in ("engine", "versions", "reason"):
            if key not in d:
                raise ConfigError(f"{where}.{key}", None, "missing")
        if not isinstance(d["versions"], list) or not d["versions"]:
            raise ConfigError(f"{where}.versions", d["versions"], "must be a non-empty list of version patterns")
        unknown = set(d) - {"engine", "versions", "reason", "normal", "tangential", "metrics", "source", "setting"}
        if unknown:
            raise ConfigError(f"{where}.{sorted(unknown)[0]}", d[sorted(unknown)[0]], "unknown key")
        for key in ("normal", "tangential"):
            v = d.get(key, "*")
            if not (isinstance(v, str) or isinstance(v, list) and v and all(isinstance(x, str) for x in v)):
                raise ConfigError(f"{where}.{key}", v, "must be a model id pattern or a non-empty list of them")
        if "setting" in d and not (isinstance(d["setting"], str) and d["setting"].strip()):
            raise ConfigError(f"{where}.setting", d["setting"], "must be a non-empty string: the engine's own "
                                                              "setting (keyword, class or law) that causes the difference")
        out.append(ExpectedDifference(engine=d["engine"], versions=tuple(d["versions"]), reason=d["reason"],
                                      normal=_patterns(d.get("normal", "*")),
                                      tangential=_patterns(d.get("tangential", "*")),
                                      metrics=tuple(d.get("metrics", ["*"])), source=d.get("source", ""),
                                      setting=d.get("setting", "")))
    return out


def _patterns(v):
    return v if isinstance(v, str) else tuple(v)


def scale(metric: str, ref: float, case_scales: dict) -> float:
    """The unit a metric's difference is measured in."""
    if metric in ("restitution", "tangential_restitution"):
        return 1.0
    if metric == "energy_dissipated":
        return case_scales["impact_energy"]
    if metric == "rebound_angle":
        return 90.0
    if metric == "rebound_angular_velocity":
        return case_scales["spin"]
    if not ref and metric == "separation_at_pull_off" and "overlap" in case_scales:
        return case_scales["overlap"]  # a contact that ends at δ = 0 (DMT, sjkr): the pull's overlap scale
    return abs(ref) if ref else 1.0


def scaled(a: float, b: float, metric: str, case_scales: dict) -> float:
    """|a − b| in units of the metric's scale; 0 when neither exists (a metric that does not apply), NaN
    when only one does."""
    fa, fb = _finite(a), _finite(b)
    if not (fa or fb):
        return 0.0 if _nan(a) and _nan(b) else math.nan
    if fa != fb:
        return math.nan
    return abs(a - b) / scale(metric, b, case_scales)


def _finite(x) -> bool:
    return x is not None and isinstance(x, (int, float)) and math.isfinite(x)


def _nan(x) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


@dataclass
class Comparison:
    source: str
    metric: str
    value: float
    reference: float
    abs_diff: float
    rel_diff: float  # in units of the metric's scale
    tolerance: float
    verdict: str
    reason: str = ""
    parts: dict = field(default_factory=dict)  # implementation / time step / formula, scaled
    setting: str = ""  # for "differs as expected": the engine setting that causes it, when known

    def as_dict(self) -> dict:
        return {"source": self.source, "metric": self.metric, "value": self.value, "reference": self.reference,
                "abs_diff": self.abs_diff, "rel_diff": self.rel_diff, "tolerance": self.tolerance,
                "verdict": self.verdict, "reason": self.reason, "parts": self.parts, "setting": self.setting}


def judge_engine(engine: str, version: str | None, model: dict, metric: str, value: float, reference: float,
                 twin: float, seed_verlet: float, fidelity: str, reasons: list[str], case_scales: dict,
                 tol: Tolerances, expected: list[ExpectedDifference], status: str = "ok",
                 message: str = "", setting: str = "") -> Comparison:
    """One metric of an engine run against the seed model. A run whose ``status`` is not "ok" (the
    reference's rules, reference/health.py) is FAILED whatever its values; so is a value that is not finite
    where the reference or the twin has one (a broken run is never "agree" or "differs as expected"), and a
    finite engine value whose seed-model runs (converged, or at the engine's step) are not: once the engine is
    checked against its twin, there is nothing to judge it against.
    ``setting``: the native keyword(s) the approximate mapping's reasons are about (:func:`mapping_setting`),
    named on its difference."""
    diff = scaled(value, reference, metric, case_scales)
    impl = scaled(value, twin, metric, case_scales)
    step = scaled(seed_verlet, reference, metric, case_scales)
    formula = scaled(twin, seed_verlet, metric, case_scales)
    tolerance = tol.engine_rtol + 1.01 * (step if _finite(step) else 0.0)
    parts = {"implementation": impl, "time_step": step, "formula": formula}
    absd = abs(value - reference) if _finite(value) and _finite(reference) else math.nan
    c = Comparison(engine, metric, value, reference, absd, diff, tolerance, AGREE, "", parts)
    if status != "ok":
        c.verdict, c.reason = FAILED, f"{status}: {message}"
        return c
    if _nan(value) and _nan(reference) and _nan(twin):
        return c  # a metric that does not apply (a head-on impact's tangential restitution)
    if not _finite(value):
        c.verdict, c.reason = FAILED, f"the engine's value is not finite ({value}) where the seed model has one"
        if not _finite(reference):
            c.reason = f"the engine's value is not finite ({value}) where its twin has one"
        return c
    if not _finite(twin):
        c.verdict = FAILED
        c.reason = f"the twin's value is not finite ({twin}): the engine's {value:.6g} cannot be checked"
        return c
    match = next((e for e in expected if e.matches(engine, version, model, metric)), None)
    if not _finite(impl) or impl > tol.implementation:
        if match is not None:
            c.verdict, c.reason = EXPECTED, f"{match.reason} ({match.source})" if match.source else match.reason
            c.setting = match.setting
        else:
            c.verdict = UNEXPECTED
            c.reason = (f"the engine does not compute its own documented formula: {impl:.3g} from its twin at "
                        f"equal dt (bar {tol.implementation:g})")
        return c
    if not (_finite(reference) and _finite(seed_verlet)):  # engine = twin holds, but nothing to judge it against
        which = "converged run" if not _finite(reference) else "run at the engine's step"
        c.verdict, c.reason = FAILED, f"the seed model's {which} is not finite: the engine's {value:.6g} cannot be judged"
        return c
    if _finite(diff) and diff <= tolerance:
        return c
    if fidelity == "approximate":
        c.verdict, c.reason = EXPECTED, "approximate mapping: " + "; ".join(reasons)
        c.setting = setting
    elif match is not None:
        c.verdict, c.reason = EXPECTED, f"{match.reason} ({match.source})" if match.source else match.reason
        c.setting = match.setting
    else:
        c.verdict = UNEXPECTED
        c.reason = (f"{diff:.3g} from the seed model beyond the time step's own {step:.3g}; the engine meets its "
                    f"twin ({impl:.2g}), so the twin's formula differs ({formula:.3g}) and no documented "
                    "difference explains it")
    return c


def judge_verlet(metric: str, value: float, reference: float, steps_per_contact: float, case_scales: dict,
                 tol: Tolerances) -> Comparison:
    """The reference's verlet method at the case's dt against its converged answer: the time step's error."""
    diff = scaled(value, reference, metric, case_scales)
    absd = abs(value - reference) if _finite(value) and _finite(reference) else math.nan
    c = Comparison("reference-verlet", metric, value, reference, absd, diff, tol.verlet_rtol, AGREE)
    if _nan(value) and _nan(reference):
        return c
    if not (_finite(diff) and diff <= tol.verlet_rtol):
        c.verdict = EXPECTED
        c.reason = (f"time-step error of the velocity-Verlet scheme at {steps_per_contact:.0f} steps per contact "
                    "(docs/models.md, convergence orders)")
    return c


def judge_closed_form(metric: str, value: float, exact: float, case_scales: dict, tol: Tolerances) -> Comparison:
    diff = scaled(value, exact, metric, case_scales)
    c = Comparison("closed-form", metric, value, exact, abs(value - exact), diff, tol.closed_form, AGREE)
    if not (_finite(diff) and diff <= tol.closed_form):
        c.verdict, c.reason = UNEXPECTED, "the adaptive method misses the model's closed form"
    return c


def status_comparison(source: str, verdict: str, reason: str) -> Comparison:
    """A source that produced no numbers (not expressible, engine missing, failed)."""
    nan = math.nan
    return Comparison(source, "*", nan, nan, nan, nan, nan, verdict, reason)


def worst(verdicts) -> str:
    order = {AGREE: 0, NOT_EXPRESSIBLE: 1, MISSING: 2, EXPECTED: 3, UNEXPECTED: 4, FAILED: 5}
    vs = list(verdicts)
    return max(vs, key=order.__getitem__) if vs else AGREE


def unavailable(planned) -> tuple[str | None, Comparison | None]:
    """What a case records of an engine source (``planned``, comparisons/sources.plan), edited nowhere: for one that
    can express the case, the native configuration its mapping chose, in one line of the engine's own words (the
    case's ``settings``: the setting the report's traps section names for an approximate mapping), else None; and
    for one that cannot run it (the model is not expressible, or it is not installed) its status comparison
    (NOT_EXPRESSIBLE, MISSING or FAILED), else None. records.CaseResult.note_plan notes both."""
    mp = planned.mapping
    setting = native_setting(mp.native) if mp.native is not None else None
    if planned.runs:
        return setting, None
    return setting, status_comparison(planned.source.label, planned.status, planned.why)


def mapping_setting(mp) -> str:
    """The native setting an approximate mapping's difference is about: the keyword of each of its reasons
    (``Mapping.keywords``, the engine's own words), once each, joined by "; "; the whole native configuration
    for a reason that names none. Empty for a mapping without reasons."""
    keywords = getattr(mp, "keywords", None) or {}
    out = []
    for r in mp.reasons:
        k = keywords.get(r) or (native_setting(mp.native) if mp.native is not None else "")
        if k and k not in out:
            out.append(k)
    return "; ".join(out)


def native_setting(native) -> str:
    """A native configuration in one line of its engine's own words (the engine's ``summary``)."""
    from ..engines.mapping import native_summary

    return native_summary(native)
