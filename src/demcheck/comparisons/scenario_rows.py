"""The engine rows of a scenario case beyond sliding (``[run] scenario``) in the suite: per engine that can run it
(comparisons/sources.plan, with the scenario's mapping), its run from the deck its package writes, its twin and
the seed model's verlet run at its step (engines/scenario.py), each metric judged against the reference's solve as
a collision case's are (verdicts.judge_engine: the twin at ≤ the implementation bar, the seed run's distance from
the reference the time step's part). An engine that cannot express the case's law is "not expressible" with
the reason."""

from __future__ import annotations

from ..errors import DemcheckError, EngineInterrupted
from . import sources, verdicts
from .records import CaseResult, SourceResult

# a scenario engine's row: what it ran, its metrics, its mapping and its twin's and seed run's metrics
ROW = ("status", "message", "method", "dt", "engine_version", "wall_time", "metrics", "fidelity", "reasons",
       "twin_metrics", "seed_verlet_metrics")


def engine_rows(case, entry: CaseResult, opts, found: dict, ref: dict) -> None:
    """Every engine of ``opts.engines`` on the scenario case: ``entry`` gains its rows and comparisons; ``ref``: the
    reference's metrics."""
    for planned in sources.plan(case, opts.engines, found):
        if entry.note_plan(planned):
            _engine(case, planned, entry, opts, ref)


def _engine(case, planned, entry: CaseResult, opts, ref: dict) -> None:
    from ..engines import scenario

    src, mp = planned.source, planned.mapping
    label, comps = src.label, entry.comparisons
    try:
        # the twin and the seed run first: where either cannot be made, the row fails without an engine run whose
        # output nothing would read
        twin = scenario.cached_metrics("twin", case, src.engine, opts.cache)
        seed = scenario.cached_metrics("seed", case, src.engine, opts.cache)
        res = src.run(case, timeout=opts.timeout, cache=opts.cache)  # the deck its package writes, cached
    except EngineInterrupted:
        raise
    except DemcheckError as exc:
        entry.sources[label] = SourceResult.status_only("failed", str(exc))
        comps.append(verdicts.status_comparison(label, verdicts.FAILED, str(exc).splitlines()[0]))
        return
    entry.sources[label] = SourceResult(res.status, res.message, res.method, res.dt, engine_version=res.engine_version,
                                        wall_time=res.wall_time, metrics=res.metrics(), fidelity=mp.fidelity,
                                        reasons=list(mp.reasons), twin_metrics=twin, seed_verlet_metrics=seed, keys=ROW)
    if not res.ok:
        comps.append(verdicts.status_comparison(label, verdicts.FAILED, f"{res.status}: {res.message}"))
        return
    got = res.metrics()
    for metric, value in ref.items():
        comps.append(verdicts.judge_engine(label, res.engine_version, entry.model, metric, got[metric], value,
                                           twin[metric], seed[metric], mp.fidelity, list(mp.reasons),
                                           entry.scales, opts.tolerances, opts.expected,
                                           setting=verdicts.mapping_setting(mp)))
