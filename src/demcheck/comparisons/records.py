"""The suite's results as typed records: a source's row (:class:`SourceResult`), a case's entry
(:class:`CaseResult`) and a run's summary (:class:`Summary`), built once in the suite (comparisons/suite.py,
packing_suite.py, scenario_rows.py) and read by attribute in the renderers (report/), diff, validate, the API and
the command line.

JSON is the edge: ``to_json()`` writes a record as the dict results.json, a baseline and the API always held (the
same keys, in the same order), ``from_json()`` reads one back — an old results.json too, its missing keys left at
their defaults and keys this release does not know kept as they were (``extra``). The renderers take a record or
such a dict (:meth:`Summary.of`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from . import verdicts

OK, FAILED, UNEXPECTED = "ok", "failed", "unexpected"



def _copy(value, kind):
    """A copy of a container read from a file (``kind`` dict or list; empty for a missing one). A value of another
    shape is kept as it is: the schema does not check these fields and diff never reads them, so an odd one must
    not stop a comparison (a ValueError there was a traceback, exit 1, read as "regressions")."""
    if value is None:
        return kind()
    if kind is list and isinstance(value, (list, tuple)) or kind is dict and isinstance(value, dict):
        return kind(value)
    return value

def _comparison(d) -> verdicts.Comparison:
    """A comparison of a results.json as its record (a key a release before this one did not write: default)."""
    if isinstance(d, verdicts.Comparison):
        return d
    nan = float("nan")
    known = {f.name for f in fields(verdicts.Comparison)}
    values = {"value": nan, "reference": nan, "abs_diff": nan, "rel_diff": nan, "tolerance": nan,
              **{k: v for k, v in d.items() if k in known}}
    values.setdefault("source", "")
    values.setdefault("metric", "")
    values.setdefault("verdict", verdicts.AGREE)
    values["parts"] = _copy(values.get("parts"), dict)
    values["reason"] = values.get("reason") or ""
    values["setting"] = values.get("setting") or ""
    return verdicts.Comparison(**values)


@dataclass
class SourceResult:
    """One source's row of a case: its status and message, and what it ran (method, dt, rtol, version, wall time),
    its metrics, and for an engine its mapping's fidelity and reasons, its twin's and the seed model's verlet
    metrics at its step. ``keys``: the fields the row carries in JSON, in their order (a source that could not run
    carries its status and message alone; a packing's its metrics)."""

    status: str | None
    message: str | None = None
    method: str | None = None
    dt: float | None = None
    rtol: float | None = None
    engine_version: str | None = None
    wall_time: float | None = None
    metrics: dict = field(default_factory=dict)
    cached: bool | None = None
    warnings: list = field(default_factory=list)
    fidelity: str | None = None
    reasons: list = field(default_factory=list)
    twin_metrics: dict | None = None
    seed_verlet_metrics: dict | None = None
    time: float | None = None  # a packing's simulated time
    keys: tuple = ("status", "message")
    extra: dict = field(default_factory=dict)  # keys of a stored row this release does not know

    RUN = ("status", "message", "method", "dt", "rtol", "engine_version", "wall_time", "metrics", "cached",
           "warnings")  # a Result's row (of_run), an engine's mapping after them

    @classmethod
    def of_run(cls, result, **mapped) -> "SourceResult":
        """A Result's row (``mapped``: an engine's fidelity, reasons, twin and seed metrics)."""
        return cls(result.status, result.message, result.method, result.dt, result.rtol, result.engine_version,
                   result.wall_time, result.metrics(), result.meta.get("cached"),
                   result.meta.get("warnings", []), **mapped, keys=cls.RUN + tuple(mapped))

    @classmethod
    def status_only(cls, status: str, message: str) -> "SourceResult":
        """A source that produced no numbers: not expressible, engine missing, failed."""
        return cls(status, message)

    @property
    def ok(self) -> bool:
        return self.status == OK

    def to_json(self) -> dict:
        return {k: (self.extra[k] if k in self.extra else getattr(self, k)) for k in self.keys}

    @classmethod
    def from_json(cls, d: dict) -> "SourceResult":
        known = {f.name for f in fields(cls)} - {"keys", "extra"}
        values = {k: v for k, v in d.items() if k in known}
        values["metrics"] = values.get("metrics") or {}
        values["warnings"], values["reasons"] = _copy(values.get("warnings"), list), _copy(values.get("reasons"), list)
        return cls(**{"status": None, **values}, keys=tuple(d),
                   extra={k: v for k, v in d.items() if k not in known})


@dataclass
class PackingPanel:
    """One source's packing panels' data (report/figures.py draws them): its kinetic energy against time
    (``ke``: (t, E) pairs), its contact-force distribution (``forces``: packing_metrics.force_distribution, with
    its count ``n``) and its solid fraction against height (``profile``; None without a periodic box). A stored
    panel may lack any of them (an older results.json): each is then empty, and a key this release does not know is
    kept (``extra``)."""

    ke: list = field(default_factory=list)
    forces: dict = field(default_factory=dict)
    profile: dict | None = None
    extra: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"ke": self.ke, "forces": self.forces, "profile": self.profile} | self.extra

    @classmethod
    def from_json(cls, d) -> "PackingPanel":
        if isinstance(d, PackingPanel):
            return d
        d = d if isinstance(d, dict) else {}
        return cls(_copy(d.get("ke"), list), _copy(d.get("forces"), dict), d.get("profile"),
                   {k: v for k, v in d.items() if k not in ("ke", "forces", "profile")})


# a case's keys in JSON, in the order each kind of entry always had them (a key whose value is None is left out)
_COLLISION = ("case", "file", "case_hash", "kind", "sources", "comparisons", "curves", "series", "walls", "variant",
              "scenario", "model", "params", "impact", "scales", "settings", "status", "verdict")
_PACKING = ("case", "file", "kind", "case_hash", "sources", "comparisons", "curves", "series", "packing", "model",
            "settings", "status", "verdict", "impact", "scales")
_FAILED = ("case", "file", "case_hash", "status", "verdict", "message", "sources", "curves", "series",
           "comparisons")


@dataclass
class CaseResult:
    """One case's entry: the case (name, file, hash, kind), its model, parameters, impact and scales, every source's
    row (by label) and every comparison, the curves' distances and the plots' series, the engines' native settings
    (one line each), and its status and worst verdict. A case the suite could not run carries the reason
    (``message``); a packing its panels' data (``packing``)."""

    case: str
    file: str | None = None
    case_hash: str | None = None
    kind: str | None = None
    sources: dict = field(default_factory=dict)  # label -> SourceResult
    comparisons: list = field(default_factory=list)  # verdicts.Comparison
    curves: dict = field(default_factory=dict)
    series: list = field(default_factory=list)
    walls: int | None = None
    variant: list | None = None
    scenario: str | None = None
    model: dict | None = None
    params: dict | None = None
    impact: dict | None = None
    scales: dict | None = None
    settings: dict | None = None
    status: str = OK
    verdict: str = verdicts.AGREE
    message: str | None = None
    packing: dict | None = None  # source label -> PackingPanel
    extra: dict = field(default_factory=dict)  # keys of a stored entry this release does not know

    def judged(self) -> "CaseResult":
        """Its verdict (the worst of its comparisons) and status (failed, unexpected or ok) set; itself."""
        self.verdict = verdicts.worst(c.verdict for c in self.comparisons)
        self.status = {verdicts.FAILED: FAILED, verdicts.UNEXPECTED: UNEXPECTED}.get(self.verdict, OK)
        return self

    @property
    def failing(self) -> bool:
        return self.status in (FAILED, UNEXPECTED)

    def note_plan(self, planned) -> bool:
        """An engine source of the case (comparisons/sources.plan) noted: the native configuration its mapping
        chose (``settings``), and, when it cannot run, its row and comparison (verdicts.unavailable). True when it
        runs."""
        setting, comparison = verdicts.unavailable(planned)
        label = planned.source.label
        if setting is not None:
            self.settings = {**(self.settings or {}), label: setting}
        if comparison is None:
            return True
        self.sources[label] = SourceResult.status_only(planned.status, planned.why)
        self.comparisons.append(comparison)
        return False

    def metric(self, source: str, metric: str):
        """A source's metric (None where the source or the metric is not there)."""
        s = self.sources.get(source)
        return None if s is None else s.metrics.get(metric)

    def to_json(self, series: bool = True) -> dict:
        order = _FAILED if self.message is not None else _PACKING if self.kind == "packing" else _COLLISION
        out = {}
        for k in order:
            v = getattr(self, k)
            if k == "sources":
                v = {name: s.to_json() for name, s in v.items()}
            elif k == "comparisons":
                v = [c.as_dict() for c in v]
            elif k == "packing" and v is not None:
                v = {name: PackingPanel.from_json(p).to_json() for name, p in v.items()}
            elif k == "series" and not series:
                continue
            if v is not None:
                out[k] = v
        return out | self.extra

    @classmethod
    def from_json(cls, d: dict) -> "CaseResult":
        if isinstance(d, CaseResult):
            return d
        known = {f.name for f in fields(cls)} - {"extra"}
        values = {k: v for k, v in d.items() if k in known}
        values["sources"] = {name: SourceResult.from_json(s) for name, s in (d.get("sources") or {}).items()}
        values["comparisons"] = [_comparison(c) for c in d.get("comparisons") or []]
        values["curves"] = _copy(d.get("curves"), dict)
        values["series"] = _copy(d.get("series"), list)
        if isinstance(d.get("packing"), dict):
            values["packing"] = {name: PackingPanel.from_json(p) for name, p in d["packing"].items()}
        case = cls(**{"case": "", **values}, extra={k: v for k, v in d.items() if k not in known})
        # an entry without its status or verdict (a hand-built dict) is judged from its comparisons, never
        # read as "ok"/"agree" by default
        return case if "status" in d and "verdict" in d else case.judged()


@dataclass
class Check:
    """One verdict of ``demcheck validate`` (comparisons/validate.py): a source against a benchmark's exact limit
    (``kind`` "limit") or a paper's curve ("curve") over one case file's variants — the largest deviation, where
    (``at``, on the benchmark's x axis), the tolerance there, what the tolerance stands for (``why``), the verdict,
    how many variants or paper points it judged; a curve's regime (gross sliding or partial slip), a limit the law
    itself misses (``law``). ``keys``: the fields it carries in JSON, in their order."""

    benchmark: str
    file: str
    source: str
    kind: str
    quantity: str
    expected: str
    deviation: float | None = None
    at: float | None = None
    tolerance: float | None = None
    why: str = ""
    verdict: str = ""
    points: int = 0
    regime: str | None = None
    law: bool = False
    keys: tuple = ()
    extra: dict = field(default_factory=dict)

    LIMIT = ("benchmark", "file", "source", "kind", "quantity", "expected", "deviation", "at", "tolerance", "why",
             "verdict", "points")
    CURVE = ("benchmark", "file", "source", "kind", "quantity", "expected", "regime", "tolerance", "why",
             "deviation", "at", "verdict", "points")

    def __post_init__(self):
        if not self.keys:
            self.keys = (self.LIMIT + (("law",) if self.law else ())) if self.kind == "limit" else self.CURVE

    def to_json(self) -> dict:
        return {k: (self.extra[k] if k in self.extra else getattr(self, k)) for k in self.keys}

    @classmethod
    def from_json(cls, d) -> "Check":
        if isinstance(d, Check):
            return d
        known = {f.name for f in fields(cls)} - {"keys", "extra"}
        values = {"benchmark": "", "file": "", "source": "", "kind": "", "quantity": "", "expected": "",
                  **{k: v for k, v in d.items() if k in known}}
        return cls(**values, keys=tuple(d), extra={k: v for k, v in d.items() if k not in known})


@dataclass
class Validation:
    """What ``demcheck validate`` adds to a run: the benchmarks judged (name, title, case files), every
    :class:`Check`, the plot series (one per case file and quantity: each source's x and y, the paper's points) and
    the checks that fail the run (the reference missing an exact limit that is not the law's own miss)."""

    benchmarks: list = field(default_factory=list)
    checks: list = field(default_factory=list)  # Check
    series: list = field(default_factory=list)
    failed: list = field(default_factory=list)  # Check
    extra: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"benchmarks": self.benchmarks, "checks": [c.to_json() for c in self.checks], "series": self.series,
                "failed": [c.to_json() for c in self.failed]} | self.extra

    @classmethod
    def from_json(cls, d) -> "Validation | None":
        if d is None or isinstance(d, Validation):
            return d
        known = ("benchmarks", "checks", "series", "failed")
        return cls(_copy(d.get("benchmarks"), list), [Check.from_json(c) for c in d.get("checks") or []],
                   _copy(d.get("series"), list), [Check.from_json(c) for c in d.get("failed") or []],
                   {k: v for k, v in d.items() if k not in known})


@dataclass
class Summary:
    """A run: demcheck's version, its id, report folder, start, command line, the engines found (discovery's
    record by name), the tolerances, every finished case (:class:`CaseResult`), how many fail, how many were
    planned, its wall time, whether it is partial; the run cache's hits and misses, a baseline check
    (comparisons/diff.apply_baseline) and a validation (comparisons/validate.py) where there are."""

    demcheck: str | None = None
    run_id: str | None = None
    report: str | None = None
    partial: bool = False
    started: str | None = None
    command: list | None = None
    engines: dict = field(default_factory=dict)
    tolerances: dict | None = None
    cases: list = field(default_factory=list)  # CaseResult
    failed: int = 0
    planned: int | None = None
    wall_time: float | None = None
    cache: dict | None = None
    baseline: dict | None = None
    baseline_error: str | None = None
    validation: Validation | None = None
    extra: dict = field(default_factory=dict)

    OPTIONAL = ("cache", "baseline", "baseline_error", "validation")  # in JSON only where there are

    def count_failed(self) -> int:
        """How many cases fail (an unexpected difference or a failure)."""
        return sum(c.failing for c in self.cases)

    def to_json(self, series: bool = True) -> dict:
        out = {}
        for f in fields(self):
            if f.name == "extra":
                continue
            v = getattr(self, f.name)
            if f.name == "cases":
                v = [c.to_json(series) for c in v]
            elif f.name == "validation" and v is not None:
                v = Validation.from_json(v).to_json()
            if v is not None or f.name not in self.OPTIONAL:
                out[f.name] = v
        return out | self.extra

    @classmethod
    def from_json(cls, d: dict) -> "Summary":
        known = {f.name for f in fields(cls)} - {"extra"}
        values = {k: v for k, v in d.items() if k in known}
        values["cases"] = [CaseResult.from_json(c) for c in d.get("cases") or []]
        values["engines"] = _copy(d.get("engines"), dict)
        if isinstance(d.get("validation"), dict):
            values["validation"] = Validation.from_json(d["validation"])
        return cls(**values, extra={k: v for k, v in d.items() if k not in known})

    @classmethod
    def of(cls, summary) -> "Summary":
        """``summary`` as a record: itself, or a results.json's dict read (:meth:`from_json`)."""
        return summary if isinstance(summary, Summary) else cls.from_json(summary)
