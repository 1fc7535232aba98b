"""The suite's rows of one engine on a scenario case (comparisons/scenario_rows.engine_rows), for the engines'
scenario tests: (entry, comparisons) as the suite builds them, judged against the reference's solve."""

from __future__ import annotations


def engine_scenario_rows(case, engine: str):
    from demcheck.comparisons.records import CaseResult
    from demcheck.comparisons.scenario_rows import engine_rows
    from demcheck.comparisons.sources import ADAPTIVE
    from demcheck.comparisons.suite import Options, discover
    from demcheck.laws.model import resolve

    opts = Options(engines=(engine,))
    entry = CaseResult(case.name, model=resolve(case).describe(), scales={})
    engine_rows(case, entry, opts, discover(opts.engines), ADAPTIVE.run(case).metrics())
    return entry.to_json(), entry.comparisons
