"""demcheck's Python API: what the command line does, as functions that return Python objects.

``import demcheck`` stays cheap: these functions are looked up here on first use (``demcheck.__getattr__``).

* :func:`load` — a case file, or a dict shaped like one, with overrides → a :class:`~demcheck.case.Case`;
* :func:`collide` — one collision from one source (the reference, an engine, an engine's twin) → a Result with
  ``.metrics()`` and ``.to_frame()``;
* :func:`collide_many` — many reference collisions at once (cases you built) → a pandas DataFrame of their
  metrics and statuses, the 1-D verlet ones solved in one compiled call;
* :func:`sweep` — metrics over a grid of case keys → a pandas DataFrame;
* :func:`verify` — the verification suite over case files → its results dict (what ``results.json`` holds);
* :func:`audit` — a user's own LAMMPS or LIGGGHTS deck, Kratos DEM project or Yade script → the audit as a dict;
* :func:`calibrate` — the native input that realises a target metric in an engine at a time step;
* :func:`pack` — a packing case settled in the reference or an engine → its packing metrics (and its settled
  state written where asked);
* :func:`case_files` — the shipped case files, or one file's text.

Bad input raises :class:`~demcheck.errors.ConfigError` (key, value, rule) before any work; docs/api.md has
examples.
"""

from __future__ import annotations

import copy
import itertools
import math
from pathlib import Path
from typing import Any, Iterable, Mapping

from . import case as _case
from .errors import ConfigError
from .result import Result as _Result

__all__ = ["load", "collide", "collide_many", "sweep", "verify", "audit", "calibrate", "pack", "case_files",
           "packing_universe", "models", "Result", "ConfigError"]

MAX_POINTS = 10_000  # a sweep's grid, as the command line's
MAX_TIMEOUT = 1e6  # s, as the command line's --timeout (the pipes' poll() takes at most ~2.1e6 s)
MAX_JOBS = 256


# ----------------------------------------------------------------------------- every argument checked
# Each public function checks every argument's type and range here, before any work: a wrong one is a ConfigError
# naming the argument, the value and the rule — never a TypeError or ValueError from deep inside.


def _positive(key: str, value, unit: str, hi: float | None = None, optional: bool = True):
    """``value``: a finite number > 0 (and <= ``hi``), or None when ``optional``."""
    if value is None and optional:
        return None
    rule = f"must be a number > 0{f' and <= {hi:g}' if hi is not None else ''} ({unit})"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0 \
            or (hi is not None and value > hi):
        raise ConfigError(key, value, rule)
    return value


def _flag(key: str, value) -> bool:
    if not isinstance(value, bool):
        raise ConfigError(key, value, "must be True or False")
    return value


def _text(key: str, value, rule: str, optional: bool = False):
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise ConfigError(key, value, rule)
    return value


def _path(key: str, value, optional: bool = False):
    """A file system path: text or os.PathLike (None when ``optional``)."""
    import os

    if value is None and optional:
        return None
    if isinstance(value, bytes) or not isinstance(value, (str, os.PathLike)):
        raise ConfigError(key, value if isinstance(value, str) else type(value).__name__,
                          "must be a path (text or pathlib.Path)")
    return value


def _sequence(key: str, value, rule: str) -> list:
    """``value`` as a list: any iterable but text, bytes and a dict; at most MAX_POINTS items."""
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Iterable):
        raise ConfigError(key, _shown(value), rule)
    items = list(itertools.islice(value, MAX_POINTS + 1))
    if len(items) > MAX_POINTS:
        raise ConfigError(key, f"more than {MAX_POINTS} items", rule)
    return items


def _shown(value):
    return value if isinstance(value, (str, int, float, type(None))) else type(value).__name__


class Result(_Result):
    """A source's answer for a case (demcheck.result.Result) with :meth:`to_frame`."""

    __slots__ = ()

    def to_frame(self):
        """The contact's time series as a pandas DataFrame (t, delta, delta_dot, fn, and the tangential
        columns of a 3-D run), one row per output time; a copy."""
        import pandas as pd

        return pd.DataFrame(self.contact).copy()


def _framed(result: _Result) -> Result:
    result.__class__ = Result
    return result


def _overrides(overrides: Iterable[str] | Mapping[str, Any] | None, keyword: Mapping[str, Any],
               key: str = "overrides") -> list:
    """[(dotted key, value)]: ``overrides`` as ``key=value`` texts (--set's form) or a mapping of dotted keys to
    Python values; keywords with ``__`` for the dots (``contact__normal="tti"``). ``key``: the name the errors give
    the overrides (the command line's ``--set``)."""
    out = []
    rule = "must be a list of KEY=VALUE texts or a dict of dotted keys to values"
    if isinstance(overrides, Mapping):
        for k, v in overrides.items():
            out.append((_text(key, k, "a key must be a dotted case key (text), e.g. impact.speed"), v))
    elif overrides is not None:
        if isinstance(overrides, str):
            raise ConfigError(key, overrides, rule + ", not one text")
        for item in _sequence(key, overrides, rule):
            if not isinstance(item, str) or "=" not in item:
                raise ConfigError(key, item, "must be KEY=VALUE with a dotted key, e.g. contact.normal=hertz")
            key, _, text = item.partition("=")
            out.append((key.strip(), _case.parse_value(text.strip())))
    out += [(k.replace("__", "."), v) for k, v in keyword.items()]
    return out


def _raw(source) -> dict:
    """A case's raw table: from a file, a dict (copied), or a Case (its resolved table)."""
    if isinstance(source, _case.Case):
        return copy.deepcopy(source.raw)
    if isinstance(source, Mapping):
        return copy.deepcopy(dict(source))
    if isinstance(source, (str, Path)):
        return _case._read(source)
    raise ConfigError("case", type(source).__name__, "must be a case file's path, a dict shaped like a case file, "
                                                     "or a Case")


def _check_natives(case: _case.Case) -> _case.Case:
    """Every [engine.NAME] table is parsed by its engine now, so that a bad native setting stops before any
    work (a ConfigError naming the key)."""
    if getattr(case, "natives", None):
        from .engines import registry
        from .engines.base import case_natives

        case_natives(case, registry.all_engines())
    return case


def _build(case, pairs: list, base: bool = False) -> _case.Case:
    raw = _raw(case)
    for key, value in pairs:
        _case.set_path(raw, key, value)
    if "variants" in raw and not base:
        raise ConfigError("variants", sorted(raw["variants"]), "a file with [variants] is several cases: "
                                                               "use verify, or load one with its keys overridden")
    return _check_natives(_case.from_dict(raw))


def load(case, overrides: Iterable[str] | Mapping[str, Any] | None = (), *, keys: Mapping[str, str] | None = None,
         base: bool = False, **keyword) -> _case.Case:
    """A validated Case from a case file's path, a dict shaped like one, or a Case, with overrides applied:
    ``key=value`` texts as ``--set`` takes them, a dict of dotted keys to values, or keywords with ``__`` for
    the dots. A Case passed with no override is returned as it is. A file with ``[variants]`` is several cases (a
    ConfigError) unless ``base``: then its base case, without the variants (what the single-case commands run).
    ``keys``: the names the errors give the arguments (``{"overrides": "--set"}``: the command line's; every
    command loads its case here)."""
    if isinstance(case, _case.Case) and not overrides and not keyword:
        return case
    return _build(case, _overrides(overrides, keyword, (keys or {}).get("overrides", "overrides")), _flag("base", base))


def models(model_id: str | None = None, key: str = "model_id") -> list[dict]:
    """The registered contact models (``demcheck models``) as rows: slot, id, seed name, aliases, title, formula,
    source, parameters and each engine's mapping of it (fidelity, with, config, reason). ``model_id``: one id or
    alias (in either slot: ``tti`` names a normal and a tangential model), else ConfigError naming ``key``."""
    from .engines import mapping
    from .laws import normal, tangential

    def rows(registry, slot):
        return [{"slot": slot, "id": m.id, "seed_name": m.seed_name, "aliases": list(m.aliases),
                 "title": m.title, "formula": m.formula, "source": m.source,
                 "params": {p.name: p.meaning for p in m.params}} for m in registry.values()]

    _text(key, model_id, "must be a model's id or alias (text) or None", optional=True)
    table = rows(normal.REGISTRY, "normal") + rows(tangential.REGISTRY, "tangential")
    if model_id is not None:
        found = set()
        for slot, reg in (("normal", normal.REGISTRY), ("tangential", tangential.REGISTRY)):
            try:
                found.add((slot, reg.lookup(model_id).id))
            except KeyError:
                pass
        table = [r for r in table if (r["slot"], r["id"]) in found]
        if not table and not _beyond_rows(model_id):
            import difflib

            from .laws import slots

            known = [*normal.REGISTRY.names(), *tangential.REGISTRY.names(),
                     *(id_ for _, id_ in slots.KEYS)]
            near = difflib.get_close_matches(model_id.strip().lower(), known, n=1)
            raise ConfigError(key, model_id, "is not a registered model" + (f"; did you mean '{near[0]}'?" if near
                                                                            else f"; known: {', '.join(known)}"))
    engines = mapping.by_model()
    for row in table:
        row["engines"] = engines[(row["slot"], row["id"])]
    return table + _beyond_rows(model_id)


def _beyond_rows(model_id: str | None) -> list[dict]:
    """The laws of the slots beyond sliding (laws/slots.py), each engine's mapping as its scenario mapping gives
    it (engines/scenario.law_mappings: exact, approximate or none, with the reasons and the suite case it was
    taken from)."""
    from .engines import scenario
    from .laws import slots
    from .laws.base import sub_model

    rows = []
    for (slot, id_), keys in slots.KEYS.items():
        if model_id is not None and model_id.strip().lower() != id_:
            continue
        formula, source = slots.DOCS[(slot, id_)]
        rows.append({"slot": slot, "id": id_, "seed_name": "—", "aliases": [], "title": sub_model(slot, id_).title,
                     "formula": formula, "source": source, "params": {k.name: k.meaning for k in keys},
                     "engines": scenario.law_mappings(slot, id_)})
    return rows


def sources() -> tuple[str, ...]:
    """The names :func:`collide` takes as ``source``: reference, each registered engine, and its twin."""
    from .comparisons.sources import Source
    from .engines import registry

    engines = registry.all_engines()
    return ("reference", *(Source.of(e).label for e in engines), *(Source.of(e, twin=True).label for e in engines))


def collide(case, source: str = "reference", method: str | None = None, dt: float | None = None,
            overrides: Iterable[str] | Mapping[str, Any] | None = (), timeout: float = 600.0, **keyword) -> Result:
    """One collision from one source → a Result (``.metrics()``, ``.to_frame()``, ``.status``, ``.ok``).

    ``source``: ``"reference"`` (``method`` adaptive — converged — or verlet at ``dt``), an engine's name (its
    deck run for real at ``dt``, default the case's), or ``"NAME-twin"`` (the reference computing that
    engine's formulas with its scheme at ``dt``). A case's ``[engine.NAME]`` native settings are used by that
    engine and its twin, by default at the native law's own step (run.dt, else its twin's elastic contact time
    over run.steps_per_contact). Overrides as :func:`load` takes them."""
    from .comparisons.sources import REFERENCE, Source

    c = load(case, overrides, **keyword)
    _positive("dt", dt, "s")
    _positive("timeout", timeout, "s", MAX_TIMEOUT, optional=False)
    if method not in (None, "adaptive", "verlet"):
        raise ConfigError("method", _shown(method), "must be adaptive or verlet (the reference's), or None")
    known = sources()
    if not isinstance(source, str) or source not in known:
        raise ConfigError("source", _shown(source), f"must be one of {', '.join(known)}")
    src = Source.parse(source, "source")
    if src.kind == REFERENCE:
        return _framed(Source.reference(method).run(c, dt))
    if method is not None:
        raise ConfigError("method", method, "is the reference's (adaptive or verlet); an engine and its twin run "
                                            "velocity Verlet at dt")
    # the case's [engine.NAME] setting at the native law's own step (its twin's contact time / run.steps_per_contact)
    return _framed(src.run(c, dt, timeout=timeout))


def collide_many(cases: Iterable, method: str | None = None, dt: float | None = None):
    """Many reference collisions → a DataFrame, one row per case in order: every metric, ``status`` and
    ``message`` — what :func:`collide` and ``.metrics()`` give for each, without a Result per case. ``cases``:
    anything :func:`load` takes, each (loaded and validated before any is solved). The cases the 1-D verlet
    solver takes (method verlet, and nothing moves the contact off the line of centres) are solved in one
    compiled call, their metrics computed there: a collision then costs about its kernel (docs/performance.md);
    the others one by one. A case whose solve fails keeps its row, with its error as the status."""
    import pandas as pd

    from .reference.batch import collide_many as run

    if method not in (None, "adaptive", "verlet"):
        raise ConfigError("method", _shown(method), "must be adaptive or verlet (the reference's)")
    _positive("dt", dt, "s")
    loaded = [load(c) for c in _sequence("cases", cases, "must be a list of cases (paths, dicts or Cases)")]
    return pd.DataFrame(run(loaded, method, dt))


def sweep(case, vary: Mapping[str, Iterable], source: str = "reference", method: str | None = None,
          dt: float | None = None, overrides: Iterable[str] | Mapping[str, Any] | None = (), *, jobs: int = 1,
          scheduler: str | None = None, progress=None, keys: Mapping[str, str] | None = None, base: bool = False,
          **keyword):
    """Metrics over a grid of case keys → a DataFrame: one row per point (its values, every metric, and its
    status). ``vary`` maps dotted keys to their values (``{"impact.angle": [0, 30, 60]}``); several keys make a
    grid. ``source`` as :func:`collide` takes it: an engine and its twin run the case's ``[engine.NAME]``
    setting — by default at its own step (run.dt, else its twin's elastic contact time over
    run.steps_per_contact) —, which a ``contact.*`` key (the seed model's), varied or overridden, does not
    change, nor a ``materials.*`` key the setting does not read: such a sweep is a ConfigError. Every point is
    validated before any is solved; a point whose solve fails keeps its row with the error as its status. An
    engine's points run in its long-lived worker, which stays (idle) until the interpreter exits or
    ``demcheck.engines.run.shutdown_workers()`` ends it. ``jobs``/``scheduler``: where the points run
    (``demcheck sweep``'s --jobs and --scheduler: comparisons/dispatch.py); ``progress``: called once a point
    (or a batch) is solved; ``keys``: the names the errors give the arguments (the command line's options);
    ``base`` as :func:`load` takes it."""
    from .comparisons.dispatch import Campaign
    from .comparisons.sources import Source
    from .comparisons.sweep import check_source, native_vary_rule, run_sweep

    key = {"source": "source", "method": "method", "dt": "dt", "vary": "vary", "overrides": "overrides",
           **(keys or {})}
    check_source(source, method, (key["source"], key["method"], key["dt"]))  # the command's checks
    _positive(key["dt"], dt, "s")
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= MAX_JOBS:
        raise ConfigError("jobs", _shown(jobs), f"must be a whole number from 1 to {MAX_JOBS}")
    points = _sweep_points(case, vary, _overrides(overrides, keyword, key["overrides"]), key["vary"],
                           _flag("base", base))
    if key["overrides"].startswith("--"):  # the command line's --set: its texts, as typed, in the errors
        points.overrides = list(overrides)
    # a key that cannot move the native law, varied or set: refused before any solve
    native_vary_rule(points, source, _under(key["vary"]), _under(key["overrides"]))
    engine = None if source == "reference" else Source.parse(source).name
    # the command's own loop: an engine's points run in its long-lived worker where it has one, which stays in
    # this process (a campaign's exit would end it: engines/run.py ends it at exit)
    campaign = Campaign(jobs, scheduler, sources=[engine] if engine else [])
    if campaign.in_process:
        return run_sweep(points, method, dt, progress, source=source, campaign=campaign)
    with campaign:
        return run_sweep(points, method, dt, progress, source=source, campaign=campaign)


def _under(key: str) -> str:
    """The prefix of a case key in an error: ``--vary impact.speed`` (an option's), ``vary.impact.speed``."""
    return key + (" " if key.startswith("--") else ".")


def _sweep_points(case, vary, pairs: list, key: str = "vary", base: bool = False):
    """The grid of :func:`sweep` as comparisons.sweep.Points, every point's case built and checked before any is
    solved."""
    from .comparisons.sweep import Points

    if not isinstance(vary, Mapping) or not vary:
        raise ConfigError(key, _shown(vary), "must be a dict of dotted case keys to lists of values")
    axes = []
    for k, values in vary.items():
        k = _text(key, k, "a key must be a dotted case key (text), e.g. impact.speed")
        values = [values] if isinstance(values, str) else _sequence(
            _under(key) + k, values, "must be a list of values, e.g. [0.5, 1.0, 2.0]")
        if not values:
            raise ConfigError(_under(key) + k, values, "must be a non-empty list of values")
        axes.append((k, values))
    total = math.prod(len(v) for _, v in axes)
    if total > MAX_POINTS:
        raise ConfigError(key, {k: len(v) for k, v in axes}, f"makes a grid of {total} points; at most "
                                                              f"{MAX_POINTS}")
    _build(case, pairs, base)  # the base case must be valid on its own
    points = Points(overrides=pairs)
    for combo in itertools.product(*(v for _, v in axes)):
        values = {k: (v.item() if hasattr(v, "item") else v) for (k, _), v in zip(axes, combo)}
        points.append((values, _build(case, [*pairs, *values.items()], base)))
    return points


def verify(paths, engines: Iterable[str] | str | None = None, report: str | Path | None = None, jobs: int = 1,
           cache: bool = True, timeout: float = 600.0, *, refresh: bool = False, scheduler: str | None = None,
           baseline: str | Path | None = None, precision: str | None = None, junit: str | Path | None = None,
           quiet: bool = True, argv: list[str] | None = None, keys: Mapping[str, str] | None = None) -> dict:
    """The verification suite over case files (paths of files or directories; a directory without its optin/ and
    benchmarks/ folders: resources.case_files) → its results dict (the ``results.json`` of a report: ``cases``,
    each with its ``sources``, ``comparisons`` and ``status``, and ``failed``, the count of failing cases).
    ``demcheck verify`` is this function: the same files, engines, builds and expected differences give the same
    results.

    ``engines``: names or builds (``"lammps,lammps@2024=/opt/lmp-2024/lmp"``, or a list of them: a build's
    expected differences follow its version), None for every registered one (one not found is reported
    missing), or ``()`` / ``"none"`` for the reference alone; an engine named must be found. ``report``: a
    directory for the report (``<report>/<run-id>/``), or None to write none. ``cache``: read and write the
    engine-run cache (``refresh``: run every deck again, the fresh runs replacing the cached ones). ``scheduler``:
    a Dask cluster's address (``jobs`` then left at 1); ``baseline``: a stored earlier run every source is judged
    against too; ``precision``: each listed engine that has one run as its build in this precision (Yade:
    float128, mpfr150); ``junit``: also write JUnit XML here. ``keys``: the names the errors give the arguments
    (the command line's options)."""
    from .comparisons.suite import Options, run_suite

    key = {"paths": "paths", "engines": "engines", "baseline": "baseline", "precision": "precision",
           **(keys or {})}
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= MAX_JOBS:
        raise ConfigError("jobs", _shown(jobs), f"must be a whole number from 1 to {MAX_JOBS}")
    _positive("timeout", timeout, "s", MAX_TIMEOUT, optional=False)
    _flag("cache", cache)
    _flag("refresh", refresh)
    _report_dir(_path("report", report, optional=True))
    names, named = _engines(engines, precision, key)
    opts = Options(engines=names, jobs=jobs, scheduler=scheduler, timeout=timeout, expected=_expected(names),
                   named=named)
    if cache:
        from .engines.cache import Cache, default_dir

        _writable_cache(default_dir())
        opts.cache = Cache(refresh=refresh)
    files = _case_files(paths, key["paths"])
    if baseline is not None:
        from .comparisons import diff

        opts.baseline = diff.load(_path(key["baseline"], baseline), key["baseline"])  # before any work
    argv = argv if argv is not None else ["demcheck.verify"]
    junit = Path(_path("junit", junit)) if junit is not None else None
    if report is not None:
        return run_suite(files, Path(report), opts, quiet=quiet, junit=junit, argv=argv).to_json()
    import shutil
    import tempfile

    tmp = Path(tempfile.mkdtemp(prefix="demcheck-verify-"))
    try:
        out = run_suite(files, tmp, opts, quiet=quiet, junit=junit, argv=argv)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    out.report = None
    return out.to_json()  # the API's results are the dict results.json holds (with each case's plot series)


def _engines(engines, precision, key) -> tuple[tuple[str, ...], bool]:
    """The engines and builds of ``engines`` (verify's argument) as the command line reads its --engines: a build
    registered under its label, an engine named required to be found (engines.discovery.resolve); and whether they
    were named (not the default list: an engine a Dask worker lacks then fails its case)."""
    from .engines import builds, discovery, registry

    if engines is None:
        text, required = ",".join(n for n in registry.names() if "@" not in n), False
    else:
        if isinstance(engines, str):
            items = [engines]
        else:
            items = _sequence(key["engines"], engines, "must be engine names or builds (a list, or one text "
                                                       "'lammps,yade'), 'none' or None")
        for e in items:
            if not isinstance(e, str):
                raise ConfigError(key["engines"], _shown(e), "must be engine names or builds (text), 'none' or None")
        text, required = ",".join(items) or "none", None
    if precision is not None:
        if not isinstance(precision, str):
            raise ConfigError(key["precision"], _shown(precision), "must be float128 or mpfr150")
        text = builds.with_precision(text, precision, key["precision"])  # yade → yade@float128=…
    named = required if required is not None else discovery.named(key["engines"])
    return tuple(discovery.resolve(text, key["engines"], required)), named


def _expected(names) -> list:
    """The expected differences (data/expected_differences.toml), each repeated for every labelled build of its
    engine among ``names``: a build's differences follow its own version."""
    from .comparisons import verdicts
    from .engines import builds

    return builds.expected_for(verdicts.load_expected(), names)


def _writable_cache(where) -> None:
    """The engine-run cache's directory can be made and written (checked before any work)."""
    from .io import check_output

    check_output("DEMCHECK_CACHE", where, directory=True)


def _report_dir(report) -> None:
    """A report directory demcheck can make: not a file, and its ``latest`` a symlink (or absent)."""
    if report is None:
        return
    p = Path(report)
    if p.exists() and not p.is_dir():
        raise ConfigError("report", str(report), f"{p.resolve()} is a file, not a directory")
    latest = p / "latest"
    if latest.exists() and not latest.is_symlink():
        raise ConfigError("report", str(report), f"{latest} is not the symlink demcheck moves to each new run")


def _case_files(paths, key: str = "paths") -> list[Path]:
    """The case files of verify's ``paths`` (resources.case_files: the one case discovery of every command)."""
    from .resources import case_files

    rule = "must be a case file's or directory's path, or a list of them"
    paths = [paths] if isinstance(paths, (str, Path)) else _sequence(key, paths, rule)
    for p in paths:
        _path(key, p)
    return case_files(paths, key)


def audit(path, engine: str | None = None, speed: float | None = None, run_engine: bool = True) -> dict:
    """The audit of a user's own LAMMPS or LIGGGHTS deck, Kratos DEM project or Yade script (``demcheck audit``) as
    a dict: per type pair and
    wall × type the native law, the nearest seed model, the probes (engine, twin, seed model) and the traps
    with their measured sizes; ``status`` is "clean", "traps" or "not audited" (nothing probed: never clean).
    ``run_engine=False``: the twin only."""
    from .comparisons.audit import audit as run

    _path("path", path)
    _text("engine", engine, "must be an engine's name (text) or None", optional=True)
    _positive("speed", speed, "m/s")
    _flag("run_engine", run_engine)
    return run(path, engine=engine, speed=speed, run_engine=run_engine)


def calibrate(case, engine: str, targets: Mapping[str, float], dt: float | None = None,
              confirm: bool = True, overrides: Iterable[str] | Mapping[str, Any] | None = (), *, jobs: int = 1,
              scheduler: str | None = None, keys: Mapping[str, str] | None = None, base: bool = False,
              **keyword) -> dict:
    """The native input of ``engine`` that realises ``targets`` (``{"restitution": 0.6}``; also
    ``tangential_restitution``) for the case's contact at ``dt``: root finding on the engine's twin, confirmed
    by one engine run (``confirm``). Returns a dict with the input, the line to paste, and the realised
    values (twin and engine). ``jobs``/``scheduler``: where the confirming run goes (``demcheck calibrate``'s
    --jobs and --scheduler: comparisons/dispatch.py); ``keys``: the names the errors give the arguments
    (``engine``, ``targets``, ``dt``, ``overrides``: the command line's options); ``base`` as :func:`load` takes
    it."""
    from .comparisons.calibrate import KEYS, calibrate as run, check_targets
    from .comparisons.dispatch import Campaign

    key = {**KEYS, "overrides": "overrides", **(keys or {})}
    _text(key["engine"], engine, "must be an engine's name (text)")
    if not isinstance(targets, Mapping):
        raise ConfigError(key["targets"], _shown(targets), "must be a dict of metric names to values, e.g. "
                                                           "{'restitution': 0.6}")
    check_targets(dict(targets), key["targets"])
    _positive(key["dt"], dt, "s")
    _flag("confirm", confirm)
    if isinstance(jobs, bool) or not isinstance(jobs, int) or not 1 <= jobs <= MAX_JOBS:
        raise ConfigError("jobs", _shown(jobs), f"must be a whole number from 1 to {MAX_JOBS}")
    c = load(case, overrides, keys=keys, base=base, **keyword)
    with Campaign(jobs, scheduler, sources=[engine]) as campaign:
        return run(c, engine, dict(targets), dt=dt, confirm=confirm, campaign=campaign, keys=key)


def case_files(name: str | None = None, key: str = "name") -> dict:
    """The case files shipped with demcheck (``demcheck cases``; not ``demcheck.cases``, the name of the folder
    that ships them, which an ``import demcheck.cases`` would put in its place): ``{"root", "cases"}``, a row per
    file (name, folder, kind, normal and tangential model, whether the default suite runs it, path); with
    ``name`` (a shipped case's name or a file's path, as every command takes it) that file: ``{"name", "path",
    "text"}``. An unknown name is a ConfigError naming ``key``."""
    from . import resources

    if name is not None:
        path = resources.case_path(_text(key, name, "must be a shipped case's name or a case file's path (text)"),
                                   key)
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError) as exc:
            raise ConfigError(key, name, f"must be a case file (TOML, UTF-8 text): {type(exc).__name__}") from None
        return {"name": path.stem, "path": str(path), "text": text}
    return {"root": str(resources.cases_dir()), "cases": resources.case_rows()}


PACK_FILES = {"csv": ("particles.csv", "contacts.csv"), "vtk": ("particles.vtu", "contacts.vtu")}  # as the
# command line's --csv and --vtk check them (comparisons/packing_output.VTK_FILES)


def pack(case, engine: str = "reference", duration: float | None = None, mpi: int = 1, threads: int = 1,
         timeout: float = 3600.0, overrides: Iterable[str] | Mapping[str, Any] | None = (), *, csv=None, vtk=None,
         xyz=None, wrote=None, keys: Mapping[str, str] | None = None, base: bool = False, **keyword) -> dict:
    """Settle a packing case (``demcheck pack``) in the N-body reference solver (``threads``: numba's, the same
    physics summed in another order) or in an engine (``mpi`` ranks) from the same initial state → its summary:
    case, source, particles, dt, contacts and the packing metrics (comparisons/packing_metrics.py, with the
    contact network's fabric tensor). ``duration``: the simulated time (default the case's packing.duration).
    ``csv``, ``vtk`` (directories) and ``xyz`` (a file) write the settled state there (checked before any work);
    ``wrote(path)`` is called for each file written. ``keys``: the names the errors give the arguments (the
    command line's options); ``base`` as :func:`load` takes it."""
    from .engines import registry
    from .io import check_output

    k = {n: n for n in ("engine", "duration", "mpi", "threads", "timeout", "csv", "vtk", "xyz", "overrides")}
    k.update(keys or {})
    names = [n for n in registry.names() if "@" not in n]
    if engine not in ("reference", *names):
        raise ConfigError(k["engine"], _shown(engine), f"must be reference or an engine ({', '.join(names)})")
    _positive(k["duration"], duration, "s")
    _positive(k["timeout"], timeout, "s", MAX_TIMEOUT, optional=False)
    if isinstance(mpi, bool) or not isinstance(mpi, int) or not 1 <= mpi <= MAX_JOBS:
        raise ConfigError(k["mpi"], _shown(mpi), f"must be a whole number from 1 to {MAX_JOBS} (MPI ranks)")
    for what, where in (("csv", csv), ("vtk", vtk), ("xyz", xyz)):
        if where is not None:
            check_output(k[what], _path(k[what], where), directory=what != "xyz", files=PACK_FILES.get(what, ()))
    c = load(case, overrides, keys={"overrides": k["overrides"]}, base=base, **keyword)
    threads = _pack_checks(c, engine, duration, mpi, threads, k, names)
    from .comparisons import packing_output as po

    out, settled, tables = (_pack_reference(c, duration, threads) if engine == "reference" else
                            _pack_engine(c, engine, duration, mpi, timeout))
    for path in _pack_write(settled, tables, csv, vtk, xyz, po):
        if wrote is not None:
            wrote(path)
    return out


def _pack_checks(case, engine: str, duration, mpi: int, threads, k: dict, names: list) -> int:
    """pack's checks of the case and the options together, before any work; the threads to use."""
    from .reference import packing

    if case.kind != "packing":
        raise ConfigError("kind", case.kind, "demcheck pack runs packing cases (kind = \"packing\")")
    if mpi > 1 and engine == "reference":
        raise ConfigError(k["mpi"], mpi, f"applies to an engine ({k['engine']} {'|'.join(names)}); the reference "
                          f"runs on threads ({k['threads']})")
    if engine != "reference" and isinstance(threads, int) and not isinstance(threads, bool) and threads > 1:
        raise ConfigError(k["threads"], _shown(threads), f"applies to the reference ({k['engine']} reference); an "
                          f"engine runs on MPI ranks ({k['mpi']})")
    if engine != "reference":
        from .comparisons.packing_suite import engine_blind

        if (why := engine_blind(case)) is not None:
            raise ConfigError(k["engine"], engine, why)
    try:
        threads = packing.check_threads(threads)  # no more than numba may start here
    except ConfigError as exc:
        raise ConfigError(k["threads"], exc.value, exc.rule) from None
    key, value = (k["duration"], duration) if duration else ("packing.duration", case.packing.duration)
    fall = packing.fall_time(case)  # a shorter run reports the starting lattice, not a packing
    if value is not None and value < fall:
        raise ConfigError(key, value, f"must be at least the fall of the lowest body to the floor, √(2h/g) = "
                          f"{fall:.3g} s: a shorter run ends before any body touches it (no packing forms)")
    return threads


def _pack_reference(case, duration, threads: int) -> tuple:
    """(summary, settled state, (particles, contacts) tables) of the reference's packing."""
    import pandas as pd

    from .comparisons import packing_metrics, packing_output
    from .inputs.packing_decks import CONTACT_COLUMNS
    from .reference import packing

    st = packing.simulate(case, duration=duration, threads=threads)
    nc = min(st.n_contacts, len(st.contacts))
    box = case.packing.box if case.packing else None
    m = packing_metrics.compute(st.x, st.rad, box=box, forces=st.contacts[:nc, 3], overlaps=st.contacts[:nc, 2],
                                ke=[e for _, e in st.ke])
    out = {"case": case.name, "source": "reference", "threads": threads, "particles": len(case.particles),
           "time": st.time, "dt": packing.packing_dt(case), "contacts": st.n_contacts, "metrics": m}
    contacts = pd.DataFrame(st.contacts[:nc], columns=list(CONTACT_COLUMNS)).astype({"i": int, "j": int})
    return out, packing_output.from_reference(case, st), (_particle_table(st.x, st.rad), contacts)


def _pack_engine(case, engine: str, duration, mpi: int, timeout: float) -> tuple:
    """(summary, settled state, (particles, contacts) tables) of an engine's packing."""
    from .comparisons import packing_metrics, packing_output
    from .engines.packing import run_engine
    from .reference import packing

    run = run_engine(case, engine, duration=duration, mpi=mpi, timeout=timeout)
    box = case.packing.box if case.packing else None
    x, rad = run.table[["x", "y", "z"]].to_numpy(), run.table["radius"].to_numpy()
    m = packing_metrics.compute(x, rad, box=box, forces=run.contacts["fn"].to_numpy(),
                                overlaps=run.contacts["overlap"].to_numpy(), ke=[e for _, e in run.ke])
    out = {"case": case.name, "source": engine, "engine_version": run.version, "mpi": mpi,
           "particles": len(run.table), "dt": packing.packing_dt(case), "contacts": len(run.contacts), "metrics": m}
    return out, packing_output.from_engine(case, run), (_particle_table(x, rad), run.contacts)


def _particle_table(x, rad):
    import pandas as pd

    return pd.DataFrame({"id": range(len(x)), "x": x[:, 0], "y": x[:, 1], "z": x[:, 2], "radius": rad})


def _pack_write(settled, tables, csv, vtk, xyz, po):
    """Write the settled state where asked (csv, vtk directories; xyz file), yielding each path written."""
    if csv:
        from .io import write_text

        for name, table in zip(PACK_FILES["csv"], tables):
            write_text(Path(csv) / name, table.to_csv(index=False, float_format="%.17g"))
            yield Path(csv) / name
    if vtk:
        yield from po.write_vtk(settled, vtk)
    if xyz:
        yield po.write_xyz(settled, xyz)


def packing_universe(path, dt: float = 1.0):
    """An engine's packing as an MDAnalysis Universe (float32 positions, radii and masses per atom): ``path`` is
    the run directory of a packing deck (``demcheck deck``, run by hand) or a LAMMPS-style dump; ``dt`` the
    packing's time step, for frame times in seconds. Fine for particle tables, profiles and fabric, not for
    overlaps (docs/packing.md)."""
    from .engines.packing import universe

    if not Path(_path("path", path)).exists():
        raise ConfigError("path", str(path), "no such file or directory")
    return universe(path, _positive("dt", dt, "s", optional=False))
