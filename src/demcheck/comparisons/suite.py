"""The verification suite run by ``demcheck verify``.

For every case (a file, or each variant of a file's ``[variants]`` table):

* the reference's adaptive method — the seed model's converged answer — checked against the model's closed
  forms where the notes derive them;
* the reference's verlet method at the case's time step (the time step's own error);
* each engine the mapping allows: its deck run for real (or taken from the engine-run cache), its twin at
  the engine's dt, and every metric judged against the converged answer (comparisons/verdicts.py), with the
  distances between the force–time and force–overlap curves.

Reports go to <report>/<run-id>/ and <report>/latest (comparisons/report.py), written atomically. An
interrupted run keeps every finished case and writes a report marked partial.
"""

from __future__ import annotations

import datetime as _dt
import os
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from .. import __version__
from ..io import console as rich_console
from ..case import Case, expand, naming_file
from ..engines import registry
from ..engines.base import case_natives
from ..engines.run import OR_PROCESS
from ..errors import DemcheckError, EngineInterrupted
from ..reference.expected import closed_form_metrics
from ..reference.health import impact_scales
from ..laws.model import resolve
from . import curves, dispatch, sources, verdicts
from .records import CaseResult, SourceResult, Summary
from .result_cache import cached_json, cached_metrics, cached_result

# the suite's engine runs go through each engine's long-lived worker (one per engine per process running cases), a
# failed worker run made again as a process of its own (engines/run.py, OR_PROCESS): the same dumps, without an
# engine start per run
ENGINE_WORKER = OR_PROCESS
SERIES_POINTS = 400


@dataclass
class Options:
    engines: tuple[str, ...] = field(default_factory=lambda: registry.names())
    jobs: int = 1  # 1: in this process; N: a local Dask cluster of N worker processes (comparisons/dispatch.py)
    scheduler: str | None = None  # tcp://HOST:PORT of an existing Dask cluster, whose workers run the cases
    cache: object | None = None  # engines.cache.Cache
    timeout: float = 600.0
    tolerances: verdicts.Tolerances = field(default_factory=verdicts.Tolerances.load)
    expected: list = field(default_factory=verdicts.load_expected)
    baseline: dict | None = None  # a stored earlier run (comparisons/diff.load): every source judged against it too
    named: bool = False  # the engines were named (not default discovery): one a Dask worker lacks fails there


def discover(engines) -> dict:
    from ..engines import discovery

    out = {}
    for e in engines:
        info = discovery.find(e)
        out[e] = {"found": info is not None, "version": info.version if info else None,
                  "executable": info.executable if info else None,
                  "how_to_install": None if info else discovery.how_to_install(e),
                  "why": None if info else discovery.missing(e)}
    return out


def _series(contact, source: str) -> dict | None:
    """The contact's force–overlap–time samples for the plots (at most SERIES_POINTS)."""
    if contact is None or contact.empty:
        return None
    c = contact[(contact["delta"] > 0) | (contact["fn"] != 0)]
    if c.empty:
        return None
    step = max(1, len(c) // SERIES_POINTS)
    c = c.iloc[::step]
    t0 = float(c["t"].iloc[0])
    return {"source": source, "t": (c["t"] - t0).tolist(), "delta": c["delta"].tolist(), "fn": c["fn"].tolist()}


def run_case(case: Case, file: Path, opts: Options, found: dict) -> CaseResult:
    entry = CaseResult(case.name, str(file), case.hash, case.kind)
    entry.walls = len(case.walls)  # a wall impact or a pair: the report's panels say which
    entry.variant = variant_labels(case.name, file)
    if case.kind == "packing":
        from .packing_suite import run_packing

        return run_packing(case, opts, found, file)
    if case.run.scenario != "collision":
        return run_scenario(case, entry, opts, found)
    model = resolve(case)
    entry.model = model.describe()
    entry.params = {k: v for k, v in model.params.items() if isinstance(v, (int, float, str, bool))}
    v_in = model.pair.impact_speed
    entry.impact = {"speed": v_in, "restitution_input": model.pair.restitution, **_incidence(case)}
    # energy in units of the bodies' kinetic energy at impact (translation, spin, and the tangential motion
    # a grazing impact carries: the normal part alone vanishes at 90°)
    entry.scales = impact_scales(case, model)
    adaptive, ref = _reference_sources(case, model, entry, opts.tolerances, opts.cache)
    seed_cache: dict = {}
    for planned in sources.plan(case, opts.engines, found):
        if entry.note_plan(planned):
            _engine_source(case, planned, (adaptive, ref), entry, opts, seed_cache)
    entry.series = [s for s in entry.series if s]
    return entry.judged()


def run_scenario(case: Case, entry: CaseResult, opts: Options, found: dict) -> CaseResult:
    """A scenario beyond sliding (run.scenario): the reference's solve against its closed forms
    (reference/expected.scenario_closed_forms), then each engine that expresses the case against its twin and the
    reference (comparisons/scenario_rows.py)."""
    from ..reference.expected import scenario_closed_forms

    model = resolve(case)
    entry.scenario = case.run.scenario
    entry.model = model.describe()
    entry.params = {k: v for k, v in model.params.items() if isinstance(v, (int, float, str, bool))}
    entry.impact = {"speed": model.pair.impact_speed, "restitution_input": model.pair.restitution}
    entry.scales = {}
    if case.run.scenario == "pull_off":  # a separation of 0 (DMT, sjkr) is judged in units of the pull's overlap
        from ..engines.scenario import overlap_scale

        entry.scales["overlap"] = overlap_scale(case)
    comps = entry.comparisons
    adaptive = cached_result(opts.cache, sources.ADAPTIVE.label, case, lambda: sources.ADAPTIVE.run(case))
    entry.sources["reference"] = SourceResult.of_run(adaptive)
    if not adaptive.ok:
        comps.append(verdicts.status_comparison("reference", verdicts.FAILED, f"{adaptive.status}: {adaptive.message}"))
    else:
        got = adaptive.metrics()
        for metric, exact in scenario_closed_forms(case).items():
            comps.append(verdicts.judge_closed_form(metric, got[metric], exact, entry.scales, opts.tolerances))
        from .scenario_rows import engine_rows

        engine_rows(case, entry, opts, found, got)
    return entry.judged()


def _reference_sources(case: Case, model, entry: CaseResult, tol, cache=None) -> tuple:
    """The reference's two methods in ``entry``, with their comparisons: the adaptive one (the seed model's
    converged answer: returned with its metrics) against the closed forms, the verlet one at the case's step
    against it. With ``cache``, the adaptive solve is read from it where it was made before (result_cache.py)."""
    adaptive = cached_result(cache, sources.ADAPTIVE.label, case, lambda: sources.ADAPTIVE.run(case))
    scales, comps = entry.scales, entry.comparisons
    ref = adaptive.metrics()
    entry.sources["reference"] = SourceResult.of_run(adaptive)
    entry.series.append(_series(adaptive.contact, "reference"))
    if not adaptive.ok:
        comps.append(verdicts.status_comparison("reference", verdicts.FAILED, f"{adaptive.status}: {adaptive.message}"))
    for metric, exact in closed_form_metrics(model).items():
        comps.append(verdicts.judge_closed_form(metric, ref[metric], exact, scales, tol))
    label = sources.VERLET.label
    # what the entry keeps of the verlet run (its tables, up to 60 000 rows, are not worth storing)
    started = time.perf_counter()
    part, hit = cached_json(cache, f"{label} against {sources.ADAPTIVE.label}", case,
                            lambda: _verlet_part(case, adaptive))
    verlet = SourceResult.from_json(part["source"])
    if hit:
        verlet.cached, verlet.wall_time = True, time.perf_counter() - started
    entry.sources[label] = verlet
    entry.series.append(part["series"])
    entry.curves[label] = part["curves"]
    spc = case.run.steps_per_contact
    if not verlet.ok:
        # the case's own time step does not give a healthy run (docs/reliability.md): the case fails, whatever
        # the engines do at that step
        comps.append(verdicts.status_comparison(label, verdicts.FAILED, f"{verlet.status}: {verlet.message}"))
    else:
        tol_v = replace(tol, verlet_rtol=case.run.verlet_rtol) if case.run.verlet_rtol else tol
        for metric in ref:
            comps.append(verdicts.judge_verlet(metric, verlet.metrics[metric], ref[metric], spc, scales, tol_v))
    return adaptive, ref


def _verlet_part(case: Case, adaptive) -> dict:
    """The verlet method at the case's step as the entry keeps it: its source row (as JSON: the run cache holds
    it), its plot series, its curves' distances from the adaptive solve."""
    verlet = sources.VERLET.run(case)
    label = sources.VERLET.label
    return {"source": SourceResult.of_run(verlet).to_json(), "series": _series(verlet.contact, label),
            "curves": curves.distances(verlet.contact, adaptive.contact, adaptive.events)}


def _engine_source(case: Case, planned, converged: tuple, entry: CaseResult, opts: Options,
                   seed_cache: dict) -> None:
    """One engine that can run the case (``planned``, sources.plan): its run (from the cache where it was run
    before), its twin and the seed model's verlet run at its dt (read off its states as the engine's run is), and
    each metric judged."""
    src, mp, native = planned.source, planned.mapping, planned.native
    engine, (adaptive, ref), comps = src.label, converged, entry.comparisons
    try:
        # the case's own [engine.NAME] setting at its own step (Source.run's default, engines.collide.setting), as
        # `collide` and `deck` run it: the deck verify runs is the deck `demcheck deck` writes
        res = src.run(case, None, cache=opts.cache, timeout=opts.timeout, worker=ENGINE_WORKER)
    except EngineInterrupted:
        raise  # the case did not finish: it is left out of the (partial) report
    except DemcheckError as exc:
        entry.sources[engine] = SourceResult.status_only("failed", str(exc))
        comps.append(verdicts.status_comparison(engine, verdicts.FAILED, str(exc).splitlines()[0]))
        return
    if not res.ok:  # a run its health checks refuse (unstable, unresolved, failed): its metrics mean nothing
        entry.sources[engine] = SourceResult(res.status, res.message, fidelity=mp.fidelity,
                                             engine_version=res.engine_version,
                                             keys=("status", "message", "fidelity", "engine_version"))
        comps.append(verdicts.status_comparison(engine, verdicts.FAILED, f"{res.status}: {res.message}"))
        return
    me = res.metrics()
    twin = cached_metrics(opts.cache, f"{src.twin().label} {res.dt!r} {native!r}", case,
                          lambda: src.twin().run(case, res.dt, native=native).metrics())
    if res.dt not in seed_cache:
        seed_cache[res.dt] = cached_metrics(
            opts.cache, f"seed verlet {res.dt!r}", case,
            lambda: sources.VERLET.run(case, res.dt, restated=True).metrics())
    seed_v = seed_cache[res.dt]
    entry.sources[engine] = SourceResult.of_run(res, fidelity=mp.fidelity, reasons=list(mp.reasons),
                                                twin_metrics=twin, seed_verlet_metrics=seed_v)
    entry.series.append(_series(res.contact, engine))
    entry.curves[engine] = curves.distances(res.contact, adaptive.contact, adaptive.events)
    for metric in ref:
        comps.append(verdicts.judge_engine(engine, res.engine_version, entry.model, metric, me[metric], ref[metric],
                                           twin[metric], seed_v[metric], mp.fidelity, list(mp.reasons),
                                           entry.scales, opts.tolerances, opts.expected,
                                           setting=verdicts.mapping_setting(mp)))


def variant_labels(name: str, file) -> list[list[str]]:
    """A variant's labels, [[label key, text], …] in the order of its file's ``[variants]`` table (case.expand
    names a variant ``base[key=text,…,GROUP=label]``, a key by its last part, a group by its name); [] for a file
    without variants, or a name that does not read that way. The report's panels keep cases whose other
    labels differ on lines of their own."""
    import tomllib

    try:
        raw = tomllib.loads(Path(file).read_text())
    except (OSError, ValueError):
        return []
    variants, base = raw.get("variants"), raw.get("name")
    if not (isinstance(variants, dict) and variants and isinstance(base, str)):
        return []
    keys = [k if isinstance(v, dict) else k.rsplit(".", 1)[-1] for k, v in variants.items()]
    if not (name.startswith(base + "[") and name.endswith("]")):
        return []
    text, out = name[len(base) + 1:-1], []
    for i, key in enumerate(keys):
        if not text.startswith(key + "="):
            return []
        text = text[len(key) + 1:]
        if i + 1 == len(keys):
            out.append([key, text])
            break
        end = text.find("," + keys[i + 1] + "=")  # the next key's label starts after this one's text
        if end < 0:
            return []
        out.append([key, text[:end]])
        text = text[end + 1:]
    return out


def _incidence(case: Case) -> dict:
    """Incidence angle from the normal (degrees) of the initial relative velocity, and the spin |ω| of
    particle 0 (rad/s) — the axes of the suite's tangential plots."""
    import numpy as np

    from ..case import incidence

    p0 = case.particles[0]
    vn, vt = incidence(case)
    return {"angle": float(np.degrees(np.arctan2(vt, abs(vn)))) if vn else None,
            "spin": float(np.linalg.norm(p0.angular_velocity))}


def collect(paths) -> list[tuple[Path, Case]]:
    """Every case of the files (each variant), read and checked before any is run: an error names the file
    (and the variant, when case.expand says which) at fault, ``cases/x.toml[speed=2]: key = value: rule``."""
    cases = []
    for path in paths:
        with naming_file(path):
            for case in expand(path):
                case_natives(case, registry.all_engines())  # [engine.NAME] settings read before any work
                cases.append((Path(path), case))
    return cases


def run_suite(files: list[Path], report_root: Path, opts: Options | None = None, quiet: bool = False,
              junit: Path | None = None, argv: list[str] | None = None, link: str = "latest") -> Summary:
    from ..engines import run as runner
    from . import report

    opts = opts or Options()
    console = rich_console(stderr=True, quiet=quiet)
    cases = collect(files)  # bad input: one line before any work
    run_id = _dt.datetime.now().strftime("%Y%m%d-%H%M%S") + f"-{os.getpid()}"
    out_dir = report_root / run_id
    found = discover(opts.engines)
    summary = Summary(__version__, run_id, str(out_dir), True, _dt.datetime.now().isoformat(timespec="seconds"),
                      argv if argv is not None else sys.argv, found, opts.tolerances.__dict__, planned=len(cases))
    started = time.perf_counter()
    entries: dict[int, CaseResult] = {}
    interrupted: KeyboardInterrupt | None = None  # SIGINT, or SIGTERM (engines.run.Terminated)
    runner.reset()
    shipped = replace(opts, cache=None, baseline=None)  # what a task needs of the options (its cache is its own)
    if opts.cache is not None:
        from .result_cache import prune

        prune(opts.cache)  # the results of older versions of demcheck (at most one other is kept)
    shared = None
    if opts.jobs > 1 or opts.scheduler:  # the cases that share an engine run (Apart), found while the cluster starts
        from concurrent.futures import ThreadPoolExecutor

        pool = ThreadPoolExecutor(1)
        shared = pool.submit(sharers, [c for _, c in cases], opts.engines, found)
        pool.shutdown(wait=False)
    with dispatch.Campaign(opts.jobs, opts.scheduler, cache=opts.cache, sources=opts.engines) as campaign:
        try:
            with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                          console=console, transient=True) as progress:
                task = progress.add_task("verify", total=len(cases))
                # the packings first: the longest jobs, so that the collisions fill the other workers meanwhile
                order = sorted(range(len(cases)), key=lambda i: cases[i][1].kind != "packing")
                first = {}  # the first case of each file: the one whose force curves the report shows
                for i, (path, _) in enumerate(cases):
                    first.setdefault(path, i)
                tasks = [(i, (cases[i][1], str(cases[i][0]), shipped, found, first[cases[i][0]] == i)) for i in order]
                if shared is not None:  # two cases that share an engine deck never run it at once
                    tasks = Apart(tasks, shared.result(), campaign.running)
                # an interrupt: the engines stopped and none starts; the cases running finish without them (raising
                # EngineInterrupted: left out) or, needing none, finish and are reported (dispatch.Campaign)
                for i, entry in campaign.completed(case_task, tasks):
                    if entry.variant is not None:  # read here, where the case files are
                        entry.variant = variant_labels(entry.case, cases[i][0])
                    entries[i] = entry
                    progress.update(task, advance=1, description=cases[i][1].name[:50])
        except KeyboardInterrupt as exc:
            interrupted = exc
            runner.kill_all()
        except EngineInterrupted as exc:  # in this process (--jobs 1): an engine the interrupt stopped
            interrupted = exc.__cause__ if isinstance(exc.__cause__, KeyboardInterrupt) else KeyboardInterrupt()
            runner.kill_all()
        finally:
            summary.cases = [entries[i] for i in sorted(entries)]
            summary.failed = summary.count_failed()
            summary.wall_time = time.perf_counter() - started
            summary.partial = interrupted is not None or len(summary.cases) < len(cases)
            if opts.cache is not None:
                summary.cache = {"dir": str(opts.cache.dir), "hits": opts.cache.hits, "misses": opts.cache.misses}
            after = _judge_baseline(summary, opts.baseline)  # a fault here still leaves the report written
            report.write_all(summary, out_dir, report_root, junit=junit, link=link)
    _print(console, summary)
    if interrupted is not None:
        raise interrupted
    if after is not None:
        raise DemcheckError(f"{summary.baseline_error} (after the runs; the report of the finished cases is "
                            f"{out_dir})") from after
    return summary


def sharers(cases: list[Case], engines, found: dict) -> dict[int, set[int]]:
    """{case index: the indices of the other cases that share one of its engine runs}: the same engine on the same
    deck's commands (engines/collide.run_identity: the comments that name a case left out) — a case and its copy
    under another name, variants whose difference an engine's mapping cannot express (a truncation rule,
    limit_force). Collisions and scenarios (a packing's deck is its case's own); a deck that cannot be written here
    shares nothing (its case reports why)."""
    from ..engines import collide, scenario

    runs: dict[tuple, set[int]] = {}
    for i, case in enumerate(cases):
        if case.kind == "packing":
            continue
        for planned in sources.plan(case, engines, found):
            if not planned.runs:
                continue
            engine = planned.source.label
            try:
                dk = (collide.setting_deck(case, engine) if case.run.scenario == "collision"
                      else scenario.deck(case, engine))
            except Exception:  # noqa: BLE001 - its case's own task meets the same fault and reports it
                continue
            deck, files = collide.run_identity(dk)
            runs.setdefault((engine, deck, tuple(sorted(files.items()))), set()).add(i)
    out: dict[int, set[int]] = {}
    for shared in runs.values():
        for i in shared if len(shared) > 1 else ():
            out.setdefault(i, set()).update(shared - {i})
    return out


class Apart:
    """A campaign's tasks (``(index, args)``, comparisons/dispatch.py) in their order, except that a case whose engine
    run another case shares (:func:`sharers`) waits while that one is out on the cluster (``running()``: their keys):
    the next one goes first, and the waiting case then reads the run from the cache the other one filled, instead of
    both making it at once. When every task left waits, it stops (StopIteration) and is asked again as a task comes
    back (Campaign.running)."""

    def __init__(self, tasks, shared: dict[int, set[int]], running):
        self.pending = list(tasks)
        self.shared = shared
        self.running = running

    def __iter__(self):
        return self

    def __next__(self):
        if not self.pending:
            raise StopIteration
        busy = self.running()
        for n, (i, _) in enumerate(self.pending):
            if not self.shared.get(i, set()) & busy:
                return self.pending.pop(n)
        raise StopIteration


def _judge_baseline(summary: Summary, baseline: dict | None) -> Exception | None:
    """The finished cases judged against ``baseline`` (diff.apply_baseline); a failure there is returned, noted
    in the summary (``baseline_error``), so that the report of what finished is written before it is raised."""
    if baseline is None:
        return None
    from .diff import apply_baseline

    try:
        apply_baseline(summary, baseline)
    except Exception as exc:  # noqa: BLE001 - raised again once the report is written
        summary.baseline_error = f"the baseline check failed: {type(exc).__name__}: {exc}"
        return exc
    return None


def case_task(case: Case, file: str, opts: Options, found: dict, panels: bool = False, cache=None) -> CaseResult:
    """One case's entry, where the campaign runs it (comparisons/dispatch.py) with ``cache`` as its run cache. On a
    Dask worker, an engine the client found (``found``) and the worker lacks is "engine missing", the worker named.
    On this machine's local cluster (``--jobs N``) the task also draws the case's report panels into the plot cache
    (``panels``: the first case of its file, whose force curves the report shows; a packing's always), so that the
    report, written after the last case, finds them there instead of drawing them one after another."""
    lacking = dispatch.missing_here(e for e in opts.engines if found[e]["found"])
    # an engine the user named is never skipped: its source fails here (sources.plan), the worker named
    found = {**found, **{e: {**found[e], "found": False, "why": why, "required": opts.named}
                         for e, why in lacking.items()}}
    entry = _safe_case(case, Path(file), replace(opts, cache=cache), found)
    if opts.jobs > 1 and not opts.scheduler and cache is not None:
        from .report.figures import draw_ahead

        draw_ahead(entry, Path(cache.dir) / "plots", panels)
    return entry


def _safe_case(case, path, opts, found) -> CaseResult:
    try:
        return run_case(case, path, opts, found)
    except EngineInterrupted:
        raise
    except DemcheckError as exc:
        failed = CaseResult(case.name, str(path), case.hash, message=str(exc),
                            comparisons=[verdicts.status_comparison("reference", verdicts.FAILED, str(exc))])
        return failed.judged()


def _print(console: Console, summary: Summary) -> None:
    from rich.markup import escape
    from rich.table import Table

    summary = Summary.of(summary)  # a run's record, or results.json's dict (as the report's renderers take)
    counts: dict[str, int] = {}
    for c in summary.cases:
        for k in c.comparisons:
            counts[k.verdict] = counts.get(k.verdict, 0) + 1
    for c in summary.cases:
        if not c.failing:
            continue
        for k in c.comparisons:
            if k.verdict in verdicts.FAILING:
                said = escape(f"{c.case} {k.source} {k.metric}: {k.reason}")
                console.print(f"[red]{k.verdict}[/] {said}")
    t = Table(title=f"demcheck verify: {len(summary.cases)} of {summary.planned} cases"
              + (" (PARTIAL)" if summary.partial else ""))
    t.add_column("verdict")
    t.add_column("comparisons", justify="right")
    for v in verdicts.VERDICTS:
        if counts.get(v):
            t.add_row(v, str(counts[v]))
    console.print(t)
    engines = ", ".join(f"{k} {v['version']}" if v["found"] else f"{k} missing" for k, v in summary.engines.items())
    console.print(escape(f"engines: {engines or 'none (reference only)'}"))  # a version or reason is text, not markup
    console.print(f"{summary.failed} case(s) failing; wall time {summary.wall_time:.1f} s; "
                  f"report: {summary.report}/report.md (and report.html, results.json, junit.xml)")
