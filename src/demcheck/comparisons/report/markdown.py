"""report.md: the header, the matrix, the disagreements, the traps, the packings, the cases and a validation's
section, as Markdown."""

from __future__ import annotations

import math
from collections import defaultdict

from ...io import number
from .. import verdicts
from ..records import Summary
from .matrix import MATRIX_METRICS, _SHORT, _cell, _code, _engine_text, _matrix_sources, _md, _model, matrix, traps


# ----------------------------------------------------------------------------- markdown


def render_markdown(summary: Summary) -> str:
    summary = Summary.of(summary)
    lines = [f"# demcheck verification {summary.run_id}", ""]
    for section in (_md_header, _md_matrix, _md_traps, _md_disagreements, _md_packings, _md_cases,
                    validation_markdown):
        lines += section(summary)
    return "\n".join(lines) + "\n"


def _md_header(summary: Summary) -> list[str]:
    lines = []
    if summary.partial:
        lines += [f"**PARTIAL REPORT: the run was interrupted; {len(summary.cases)} of {summary.planned} "
                  "cases finished and are reported below.**", ""]
    lines += [f"demcheck {summary.demcheck} · started {summary.started} · wall time "
              f"{summary.wall_time or 0:.1f} s", "", f"Engines: {_engine_text(summary)}", ""]
    if summary.cache is not None:
        lines += [f"Engine-run cache: {summary.cache['hits']} hits, {summary.cache['misses']} misses "
                  f"({_md(summary.cache['dir'])})", ""]
    counts: dict = defaultdict(int)
    for c in summary.cases:
        for k in c.comparisons:
            counts[k.verdict] += 1
    lines += ["| verdict | comparisons |", "|---|---|"]
    lines += [f"| {v} | {counts[v]} |" for v in verdicts.VERDICTS if counts[v]]
    lines += ["", f"**{summary.failed} case(s) with an unexpected difference or a failure.**", ""]
    if summary.baseline is not None:
        from ..diff import baseline_markdown

        lines += baseline_markdown(summary.baseline)
    return lines


def _md_matrix(summary: Summary) -> list[str]:
    """The agreement matrix: models × sources × metrics, the worst verdict over each model's collision cases."""
    mat = matrix(summary)
    sources = _matrix_sources(summary)
    models = sorted({m for m, _, _ in mat})
    lines = ["## Agreement matrix", "",
             "Worst verdict over the collision cases of each model: ✓ agree, ≈ differs as expected, ✗ differs "
             "unexpectedly, n/e not expressible, missing (engine not installed), FAIL (a run failed), · not "
             "compared. Columns: " + ", ".join(name for _, _, name in MATRIX_METRICS) + ".", ""]
    marks = " · ".join(mark for _, mark, _ in MATRIX_METRICS)
    lines += ["| model | " + " | ".join(f"{_cell(s)}: {marks}" for s in sources) + " |",
              "|---|" + "---|" * len(sources)]
    for m in models:
        cells = []
        for s in sources:
            if (m, s, "*") in mat:
                cells.append(_SHORT[mat[(m, s, "*")]])
                continue
            cells.append(" ".join(_SHORT[mat[(m, s, k)]] if (m, s, k) in mat else "·" for k, _, _ in MATRIX_METRICS))
        lines.append(f"| {_cell(m)} | " + " | ".join(cells) + " |")
    return lines + [""]


def _md_disagreements(summary: Summary) -> list[str]:
    """Every comparison that does not agree, grouped by verdict, source and reason."""
    lines = ["## Disagreements and their reasons", ""]
    reasons: dict = defaultdict(list)
    for c in summary.cases:
        for k in c.comparisons:
            if k.verdict in (verdicts.EXPECTED, verdicts.UNEXPECTED, verdicts.FAILED, verdicts.NOT_EXPRESSIBLE, verdicts.MISSING):
                reasons[(k.verdict, k.source, k.reason)].append((c.case, k.metric, k.rel_diff))
    if not reasons:
        lines.append("None: every source agrees with the seed model on every metric.")
    for (verdict, source, reason), hits in sorted(reasons.items(), key=lambda x: (-len(x[1]), x[0])):
        worst = max((h[2] for h in hits if h[2] is not None and math.isfinite(h[2])), default=None)
        cases = sorted({h[0] for h in hits})
        metrics = sorted({h[1] for h in hits})
        lines += [f"* **{verdict}** — {_md(source)}: {_md(reason)}",
                  f"  {len(hits)} comparison(s) in {len(cases)} case(s); metrics {_md(', '.join(metrics))}"
                  + (f"; largest scaled difference {worst:.3g}" if worst is not None else "")
                  + f". Cases: {_md(', '.join(cases[:6]))}{' …' if len(cases) > 6 else ''}"]
    return lines + [""]


def _md_traps(summary: Summary) -> list[str]:
    """The traps: for each expected difference met, the engine setting a user's own deck would meet it with."""
    lines = ["## Traps", "",
             "Each expected difference met in this run, by the engine setting that causes it: the setting to look "
             "for in a deck of your own, why it differs from the seed model (the case's numbers shown as …), how "
             "much of this run it touched, and where it is documented.", ""]
    found = traps(summary)
    if not found:
        return lines + ["None met in this run.", ""]
    for t in found:
        settings = ", ".join(_code(s) for s in t["settings"]) or "(the setting was not recorded)"
        cases = _md(", ".join(t["cases"][:6])) + (" …" if len(t["cases"]) > 6 else "")
        lines += [f"* **{_md(t['engine'])}** — {settings} ({t['kind']}): {_md(t['reason'])}",
                  f"  {t['comparisons']} comparison(s) in {len(t['cases'])} case(s); metrics "
                  f"{_md(', '.join(t['metrics']))}. Documented in {_md(t['source']) or '—'}. Cases: {cases}"]
    return lines + [""]


def _md_packings(summary: Summary) -> list[str]:
    packings = [c for c in Summary.of(summary).cases if c.kind == "packing"]
    if not packings:
        return []
    lines = ["## Packings", "", "Bulk values per source (the trajectories are chaotic: compared by these, "
             "within statistical tolerances; column and layer against their static closed form).", "",
             "| case | source | solid fraction | coordination | bed height (m) | mean contact force (N) | "
             "force distribution: KS distance to the reference (critical) | φ_zz; distance to the reference (critical) | "
             "max overlap / d | static closed form |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for c in packings:
        for src, v in c.sources.items():
            m = v.metrics

            def comp(metric, src=src, c=c):
                return next((k for k in c.comparisons if k.source == src and k.metric == metric), None)

            cf, ks, fz = comp("static_overlap"), comp("force_distribution_ks"), comp("fabric_zz")
            lines.append(f"| {_cell(c.case)} | {_cell(src)} | {number(m.get('solid_fraction'), '.4f')} | "
                         f"{number(m.get('coordination_number'), '.3f')} | {number(m.get('bed_height'), '.5g')} | "
                         f"{number(m.get('mean_contact_force'), '.4g')} | "
                         f"{number(ks.value, '.3f') + ' (' + number(ks.tolerance, '.3f') + ') ' + ks.verdict if ks else '—'} | "
                         f"{_fabric_cell(m, fz)} | "
                         f"{number(m.get('max_overlap_ratio'), '.3g')} | "
                         f"{number(cf.value, '.2e') + ' ' + cf.verdict if cf else '—'} |")
    return lines + [""]


def _fabric_cell(metrics: dict, comp: verdicts.Comparison | None) -> str:
    """A source's φ_zz (the contact fabric's vertical component) and, where verify compares it (a poured
    packing's engines), its distance to the reference's against the critical one and the verdict."""
    text = number(metrics.get("fabric_zz"), ".4f")
    if comp:
        text += f"; {number(comp.rel_diff, '.4f')} ({number(comp.tolerance, '.4f')}) {comp.verdict}"
    return text


def _md_cases(summary: Summary) -> list[str]:
    lines = ["## Cases", "", "| case | model | status | sources | worst curve distance (force–time max) |",
             "|---|---|---|---|---|"]
    for c in summary.cases:
        srcs = ", ".join(f"{k}: {v.status if 'status' in v.keys else '—'}" for k, v in c.sources.items())
        worst_curve = max((d.get("force_time_max") or 0.0 for d in c.curves.values()), default=0.0)
        lines.append(f"| {_cell(c.case)} | {_cell(_model(c))} | {_cell(c.status)} | {_cell(srcs)} | "
                     f"{number(worst_curve, '.3g')} |")
    return lines


# ----------------------------------------------------------------------------- validation (demcheck validate)


def validation_markdown(summary: Summary) -> list[str]:
    """The published-benchmark verdicts (comparisons/validate.py): each source against each exact limit and
    each paper's curve, largest deviation, tolerance and what it stands for."""
    val = Summary.of(summary).validation
    if not val:
        return []
    lines = ["", "## Validation against published benchmarks", "",
             "| case file | source | quantity | expected | largest deviation | at | tolerance | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for c in val.checks:
        lines.append(f"| {_cell(c.file)} | {_cell(c.source)} | {_cell(c.quantity)} | "
                     f"{_cell(c.kind)}: {_cell(c.expected)} | {number(c.deviation, '.3g')} | "
                     f"{number(c.at, '.3g')} | {number(c.tolerance, '.3g')} | "
                     f"{_cell(c.verdict)} |")
    lines += ["", "Tolerances:", ""] + sorted({f"* {_md(c.quantity)} ({_md(c.kind)}): {_md(c.why)}"
                                                for c in val.checks})
    return lines
