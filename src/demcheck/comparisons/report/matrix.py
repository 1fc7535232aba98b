"""The matrix of a run (case × engine × metric) and its traps: what every renderer of a report reads."""

from __future__ import annotations

import re
from collections import defaultdict

from ...io import md_text, number
from .. import verdicts
from ..records import CaseResult, Summary
from ..styles import engine_sources


# ----------------------------------------------------------------------------- helpers


def _model(c: CaseResult) -> str:
    """The case's model in one line (a case's entry as a record, or as results.json holds it)."""
    c = CaseResult.from_json(c)
    m = c.model or {}
    if not m:
        return "—"
    text = f"{m['normal']} / {m['tangential']}"
    text += "".join(f" + {slot} {m[slot]}" for slot in ("rolling", "twisting", "adhesion", "heat") if slot in m)
    if c.scenario:
        text += f" ({c.scenario})"
    return text + (" (limit_force)" if m.get("limit_force") else "")


def _engine_text(summary: Summary) -> str:
    parts = []
    for name, e in summary.engines.items():
        parts.append(f"{_md(name)} {_md(e['version'])}" if e["found"] else
                     f"{_md(name)}: missing ({_md(e['how_to_install'])})")
    return "; ".join(parts) if parts else "none selected (reference only)"


_md = md_text


def _cell(text) -> str:
    """Text for a markdown table cell (:func:`_md`: a ``|`` would end the cell, a line break the row)."""
    return _md(text)


def matrix(summary: Summary) -> dict:
    """(model, source, metric) → worst verdict over the collision cases (the packings have their own table)."""
    out: dict = defaultdict(list)
    for c in Summary.of(summary).cases:
        if c.kind == "packing":
            continue
        for k in c.comparisons:
            out[(_model(c), k.source, k.metric)].append(k.verdict)
    return {key: verdicts.worst(vs) for key, vs in out.items()}


_SHORT = {verdicts.AGREE: "✓", verdicts.EXPECTED: "≈", verdicts.UNEXPECTED: "✗", verdicts.NOT_EXPRESSIBLE: "n/e", verdicts.MISSING: "missing",
          verdicts.FAILED: "FAIL"}
_LEGEND = {verdicts.MISSING: "missing: engine not installed", verdicts.FAILED: "FAIL: a run failed"}
# the matrix's columns: (metric, its mark in the header, its name for people)
MATRIX_METRICS = (("restitution", "e", "restitution"), ("contact_time", "t", "contact time"),
                  ("max_overlap", "δ", "max overlap"), ("peak_force", "F", "peak force"),
                  ("energy_dissipated", "E", "energy dissipated"),
                  ("tangential_restitution", "et", "tangential restitution"),
                  ("rebound_angular_velocity", "ω", "rebound spin"))
REFERENCE_SOURCES = ("closed-form", "reference-verlet")


def _matrix_sources(summary: Summary) -> list[str]:
    return [*REFERENCE_SOURCES, *[s for s in engine_sources() if s in summary.engines]]


APPROXIMATE = "approximate mapping: "
MAPPING_DOC = "docs/models.md (the mapping table: each engine's configuration and why it is approximate)"


def _generic(text: str) -> str:
    """A setting or reason with the case's numbers left out (``gammat = 5.038e+08`` → ``gammat = …``,
    ``E*=7.1e+10`` → ``E*=…``): the same trap whatever the case's values, so that it is named once."""
    # a number after "=" and not part of a word ("Kt = 8G*" stays); "= 0" stays (not the case's)
    return re.sub(r"(=\s*)(?!0(?![\w.]))[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(?![\w.])", r"\1…", text)


def traps(summary: Summary) -> list[dict]:
    """Every expected difference of an engine met in the run, grouped by (engine, setting, reason with its
    numbers left out), the setting being what causes it: an entry of data/expected_differences.toml (its
    ``setting`` and ``source``), or an approximate mapping (the native keyword each of its reasons is about,
    ``Comparison.setting`` from ``Mapping.keywords``; documented in the mapping table). Most comparisons
    first."""
    # the shipped entries by the reason a comparison carries (judge_engine's words): their source, and the
    # setting of a comparison from a results.json written before comparisons carried it
    documented = {f"{e.reason} ({e.source})" if e.source else e.reason: e for e in verdicts.load_expected()}
    groups: dict = {}
    for c in Summary.of(summary).cases:
        for k in c.comparisons:
            if k.verdict != verdicts.EXPECTED or k.source in (*REFERENCE_SOURCES, "reference"):
                continue
            reason = k.reason
            entry = documented.get(reason)
            approximate = reason.startswith(APPROXIMATE)
            if not (approximate or entry is not None or k.setting):
                continue  # not an engine setting's doing (a poured packing outside its physical range)
            if approximate:
                # the keywords, "; "-joined; a results.json from before comparisons carried them: the whole
                # native configuration the case recorded
                setting = k.setting or _generic((c.settings or {}).get(k.source, ""))
                settings = [x for x in setting.split("; ") if x]
                text, kind, source = reason[len(APPROXIMATE):], "approximate mapping", MAPPING_DOC
            else:
                setting = k.setting or (entry.setting if entry else "")
                settings = [setting] if setting else []
                text, kind = (entry.reason if entry else reason), "expected difference"
                source = entry.source if entry else ""
            text = _generic(text)
            g = groups.setdefault((k.source, setting, text, kind), {
                "engine": k.source, "settings": settings, "reason": text, "kind": kind, "source": source,
                "cases": set(), "metrics": set(), "comparisons": 0})
            g["cases"].add(c.case)
            g["metrics"].add(k.metric)
            g["comparisons"] += 1
    out = [{**g, "cases": sorted(g["cases"]), "metrics": sorted(g["metrics"])} for g in groups.values()]
    return sorted(out, key=lambda g: (-g["comparisons"], g["engine"], g["settings"], g["reason"]))


def _code(text: str) -> str:
    """Inline code in markdown, whatever backticks the text holds."""
    return f"`` {text} ``" if "`" in text else f"`{text}`"
