"""What moved between two verification runs: ``demcheck diff OLD NEW`` and ``verify --baseline``.

A run is read from its results.json (or the report directory holding one, such as ``reports/latest``), or
from a baseline file (``verify --write-baseline``: every source's metrics and verdicts, the engines'
versions, and a tolerance per quantity). Per case, source and metric:

* the value's move, in units of the metric's scale (comparisons/verdicts.scaled, the older value as the
  reference), against the quantity's tolerance: by default ``Tolerances.implementation`` (1e-9: the bar at
  which verify calls an engine different from its own formula; the runs are deterministic, so a rerun of the
  same build moves by 0); a value that appears or disappears (finite in one run only) has moved;
* the verdict's change, ranked as verdicts.worst ranks them (agree < not expressible < engine missing <
  differs as expected < differs unexpectedly < failed): a higher rank is worse;
* a case or source of OLD missing from NEW (in a baseline check, only for the cases that ran).

A regression is a worse verdict, a move beyond the tolerance or a missing source; ``demcheck diff`` exits 1
on any. Reports: markdown, JSON and JUnit (a test case per case × source).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

from ..errors import ConfigError
from ..io import md_text as _t
from ..io import number, plain
from . import schema, verdicts
from .records import Summary

FORMAT = "demcheck-baseline"
FORMAT_VERSION = 1
RANK = {verdicts.AGREE: 0, verdicts.NOT_EXPRESSIBLE: 1, verdicts.MISSING: 2, verdicts.EXPECTED: 3, verdicts.UNEXPECTED: 4, verdicts.FAILED: 5}


def default_tolerance() -> float:
    """The scaled move a value may make between two runs: the implementation bar of data/tolerances.toml."""
    return verdicts.Tolerances.load().implementation


# ----------------------------------------------------------------------------- reading runs


def _numbers(metrics) -> dict:
    """The scalar metrics of a source (numbers and missing values; lists and tables left out)."""
    out = {}
    for k, v in (metrics or {}).items():
        if v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)):
            out[k] = math.nan if v is None else float(v)
    return out


def from_summary(summary: Summary, path: str = "") -> dict:
    """A run (verify's records.Summary, or results.json's content) in the form the comparison reads: per case its
    hash, scales, sources (status, version, metrics) and verdicts per source and metric."""
    summary = Summary.of(summary)
    cases = {}
    for c in summary.cases:
        judged: dict = defaultdict(dict)
        for k in c.comparisons:
            old = judged[k.source].get(k.metric)
            judged[k.source][k.metric] = k.verdict if old is None else verdicts.worst([old, k.verdict])
        sources = {src: {"status": s.status, "version": s.engine_version, "metrics": _numbers(s.metrics)}
                   for src, s in c.sources.items()}
        cases[c.case] = {"hash": c.case_hash, "scales": _scales(c.scales), "sources": sources,
                         "verdicts": {s: dict(v) for s, v in judged.items()}}
    engines = {name: (e.get("version") if e.get("found") else None) for name, e in summary.engines.items()}
    return {"path": path, "run_id": summary.run_id, "started": summary.started, "demcheck": summary.demcheck,
            "partial": bool(summary.partial), "engines": engines, "cases": cases, "tolerances": {}}


def _scales(scales) -> dict:
    """A case's scales, the missing ones (null) left out: a metric without its scale is measured relative to
    OLD's value."""
    return {k: v for k, v in (scales or {}).items() if v is not None}


def load(path, key: str = "OLD") -> dict:
    """A run from a results.json, a report directory holding one, or a baseline file; bad input — not strict
    JSON, or JSON of another shape than comparisons/schema.py's — is a ConfigError naming ``key``, the path
    and what is wrong, before any of it is used."""
    p = Path(path)
    if p.is_dir():
        p = p / "results.json"
        if not p.is_file():
            raise ConfigError(key, str(path), "a directory without results.json (give a report directory, "
                                              "e.g. reports/latest, or a results.json or baseline file)")
    elif not p.is_file():
        raise ConfigError(key, str(path), "no such file or directory")
    try:
        text = p.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(key, str(path), f"cannot be read as JSON ({exc})") from None
    data = schema.parse(text, key, str(path))
    if not isinstance(data, dict):
        raise ConfigError(key, str(path), "is not a demcheck results.json or baseline (not a JSON object)")
    if data.get("format") == FORMAT:
        if data.get("version") != FORMAT_VERSION:
            raise ConfigError(key, str(path), f"baseline format version {data.get('version')!r}: this demcheck "
                                              f"reads version {FORMAT_VERSION}")
        schema.check(data, schema.BASELINE, key, str(path))
        return _from_baseline(data, str(path), key)
    if not isinstance(data.get("cases"), list):
        raise ConfigError(key, str(path), "is not a demcheck results.json or baseline (no list of cases)")
    schema.check(data, schema.RESULTS, key, str(path))
    return from_summary(data, str(path))


def _from_baseline(data: dict, path: str, key: str) -> dict:
    """A baseline file's run (its shape checked: schema.BASELINE; tolerances finite and >= 0)."""
    tol = {"default": (data.get("tolerances") or {}).get("default"),
           "metrics": dict((data.get("tolerances") or {}).get("metrics") or {})}
    cases = {}
    for name, c in data["cases"].items():
        sources = {}
        for src, s in (c.get("sources") or {}).items():
            sources[src] = {"status": s.get("status"), "version": s.get("version"),
                            "metrics": _numbers(s.get("metrics")), "tolerances": dict(s.get("tolerances") or {})}
        cases[name] = {"hash": c.get("hash"), "scales": _scales(c.get("scales")), "sources": sources,
                       "verdicts": {s: dict(v) for s, v in (c.get("verdicts") or {}).items()}}
    return {"path": path, "run_id": data.get("run_id"), "started": data.get("started"),
            "demcheck": data.get("demcheck"), "partial": bool(data.get("partial")),
            "engines": dict(data.get("engines") or {}), "cases": cases, "tolerances": tol}


def baseline(summary: Summary, tolerance: float | None = None) -> dict:
    """The baseline file of a run (a records.Summary, or results.json's content): every source's metrics and
    verdicts, the engines' versions, and the tolerances (``default`` for every quantity; ``metrics`` per metric
    and ``tolerances`` in a source per quantity may be added by hand to loosen one)."""
    summary = Summary.of(summary)
    run = from_summary(summary)
    return plain({"format": FORMAT, "version": FORMAT_VERSION, "demcheck": run["demcheck"],
                  "run_id": run["run_id"], "started": run["started"], "partial": run["partial"],
                  "command": summary.command, "engines": run["engines"],
                  "tolerances": {"default": default_tolerance() if tolerance is None else tolerance,
                                 "metrics": {}},
                  "cases": run["cases"]})


# ----------------------------------------------------------------------------- comparing


def _scaled(new: float, old: float, metric: str, scales: dict) -> float:
    """|new − old| in the metric's scale (verdicts.scaled, OLD as the reference; relative where the case
    carries no scale for it); 0 when neither exists, NaN when only one does."""
    try:
        return verdicts.scaled(new, old, metric, scales)
    except KeyError:  # a packing's or an old report's case without the scale: relative to OLD
        return verdicts.scaled(new, old, "", {})


def _tolerance(old_run: dict, case: str, source: str, metric: str, default: float) -> float:
    tol = old_run.get("tolerances") or {}
    per = old_run["cases"][case]["sources"].get(source, {}).get("tolerances") or {}
    if metric in per:
        return float(per[metric])
    if metric in (tol.get("metrics") or {}):
        return float(tol["metrics"][metric])
    return float(default if tol.get("default") is None else tol["default"])


def compare(old: dict, new: dict, tolerance: float | None = None, rename: dict | None = None,
            only_common_cases: bool = False) -> dict:
    """Everything that differs between two runs (``load``/``from_summary``), per case, source and metric.
    ``tolerance`` overrides every quantity's tolerance; ``rename`` maps a source of OLD to its name in NEW
    (``lammps@2024=lammps``); ``only_common_cases`` ignores the cases of OLD that NEW did not run (a
    baseline check of a part of the suite)."""
    default = default_tolerance() if tolerance is None else tolerance
    rename = dict(rename or {})
    rows, removed, added, changed_cases = [], [], [], []
    checked = unchanged = 0
    below = 0.0  # the largest move within tolerance
    for case in sorted(set(old["cases"]) | set(new["cases"])):
        o, n = old["cases"].get(case), new["cases"].get(case)
        if n is None:
            if not only_common_cases:
                removed.append({"case": case, "source": "*", "what": "case not in NEW"})
            continue
        if o is None:
            added.append({"case": case, "source": "*", "what": "case not in OLD"})
            continue
        if o["hash"] and n["hash"] and o["hash"] != n["hash"]:
            changed_cases.append(case)
        scales = n["scales"] or o["scales"]
        # a renamed source takes the place of OLD's own source of that name
        targets = set(rename.values())
        o_sources = {rename.get(s, s): (s, v) for s, v in o["sources"].items() if s in rename or s not in targets}
        o_verdicts = {rename.get(s, s): v for s, v in o["verdicts"].items() if s in rename or s not in targets}
        for src in sorted(set(o_sources) | set(n["sources"]) | set(o_verdicts) | set(n["verdicts"])):
            old_name, os_ = o_sources.get(src, (src, None))
            ns = n["sources"].get(src)
            ov, nv = o_verdicts.get(src, {}), n["verdicts"].get(src, {})
            if (os_ is None and not ov) or (ns is None and not nv):
                if ns is None and not nv:
                    removed.append({"case": case, "source": src, "what": "source not in NEW"})
                else:
                    added.append({"case": case, "source": src, "what": "source not in OLD"})
                continue
            om, nm = (os_ or {}).get("metrics", {}), (ns or {}).get("metrics", {})
            for metric in dict.fromkeys([*om, *nm, *ov, *nv]):
                if metric in nm and metric not in om and metric not in ov:
                    # a quantity demcheck did not measure when OLD was written (a newer release): new, not moved
                    added.append({"case": case, "source": src, "what": f"metric {metric} not in OLD"})
                    continue
                a, b = om.get(metric, math.nan), nm.get(metric, math.nan)
                tol = tolerance if tolerance is not None else _tolerance(old, case, old_name, metric, default)
                has_value = metric in om or metric in nm
                moved = _scaled(b, a, metric, scales) if has_value else 0.0
                va, vb = ov.get(metric), nv.get(metric)
                worse = va is not None and vb is not None and RANK[vb] > RANK[va]
                better = va is not None and vb is not None and RANK[vb] < RANK[va]
                beyond = has_value and not (math.isfinite(moved) and moved <= tol)
                checked += 1
                if not (beyond or worse or better or va != vb or moved > 0):
                    unchanged += 1
                    continue
                if not (beyond or worse or better or va != vb):
                    below = max(below, moved)
                rows.append({"case": case, "source": src, "metric": metric, "old": a, "new": b, "moved": moved,
                             "tolerance": tol, "beyond": beyond, "old_verdict": va, "new_verdict": vb,
                             "change": "worse" if worse else "better" if better else "",
                             "old_version": (os_ or {}).get("version"), "new_version": (ns or {}).get("version"),
                             "regression": beyond or worse})
    regressions = [r for r in rows if r["regression"]]
    return {"old": _about(old), "new": _about(new), "engines": _engines(old, new, rename),
            "tolerance": tolerance, "default_tolerance": default, "rename": rename, "checked": checked,
            "unchanged": unchanged, "largest_below_tolerance": below, "rows": rows, "removed": removed,
            "added": added, "changed_cases": changed_cases,
            "counts": {"worse": sum(r["change"] == "worse" for r in rows),
                       "better": sum(r["change"] == "better" for r in rows),
                       "moved": sum(r["beyond"] for r in rows), "removed": len(removed)},
            "regressions": len(regressions) + len(removed)}


def _about(run: dict) -> dict:
    return {k: run.get(k) for k in ("path", "run_id", "started", "demcheck", "partial")}


def _engines(old: dict, new: dict, rename: dict) -> dict:
    targets = set(rename.values())
    o = {rename.get(k, k): v for k, v in old["engines"].items() if k in rename or k not in targets}
    return {k: {"old": o.get(k), "new": new["engines"].get(k)} for k in [*o, *(k for k in new["engines"] if k not in o)]}


# ----------------------------------------------------------------------------- reports


def _v(verdict) -> str:
    return verdict if verdict is not None else "—"


def render_markdown(d: dict) -> str:
    o, n = d["old"], d["new"]
    lines = ["# demcheck diff", "",
             f"OLD: {_t(o['path'])} (run {_t(o['run_id'] or '—')}, {_t(o['started'] or '—')}, demcheck {_t(o['demcheck'] or '—')})"
             + (" PARTIAL" if o["partial"] else ""),
             f"NEW: {_t(n['path'])} (run {_t(n['run_id'] or '—')}, {_t(n['started'] or '—')}, demcheck {_t(n['demcheck'] or '—')})"
             + (" PARTIAL" if n["partial"] else ""), ""]
    if d["rename"]:
        lines += ["Sources compared under another name: " + ", ".join(f"OLD {_t(a)} → NEW {_t(b)}" for a, b in
                                                                      d["rename"].items()), ""]
    if d["engines"]:
        lines += ["| engine | OLD version | NEW version |", "|---|---|---|"]
        lines += [f"| {_t(k)} | {_t(v['old']) if v['old'] else 'missing'} | {_t(v['new']) if v['new'] else 'missing'} |"
                  + (" changed" if v["old"] != v["new"] else "") for k, v in d["engines"].items()]
        lines.append("")
    c = d["counts"]
    tol = (f"tolerance {d['tolerance']:g} for every quantity" if d["tolerance"] is not None else
           f"tolerance per quantity, default {d['default_tolerance']:g}")
    lines += [f"**{d['regressions']} regression(s)**: {c['worse']} verdict(s) worse, {c['moved']} value(s) moved "
              f"beyond their tolerance, {c['removed']} case(s) or source(s) gone; {c['better']} verdict(s) "
              f"better. {d['checked']} quantities compared, {d['unchanged']} identical; moves in units of each "
              f"metric's scale ({tol}).", ""]
    if d["changed_cases"]:
        lines += ["Case files changed between the runs (their hash differs): " + ", ".join(map(_t, d["changed_cases"])), ""]
    changed = [r for r in d["rows"] if r["old_verdict"] != r["new_verdict"]]
    if changed:
        lines += ["## Verdicts that changed", "", "| case | source | metric | OLD | NEW | |", "|---|---|---|---|---|---|"]
        lines += [f"| {_t(r['case'])} | {_t(r['source'])} | {_t(r['metric'])} | {_v(r['old_verdict'])} | {_v(r['new_verdict'])} | "
                  f"{'**worse**' if r['change'] == 'worse' else r['change']} |" for r in changed]
        lines.append("")
    moved = [r for r in d["rows"] if r["beyond"]]
    if moved:
        lines += ["## Values that moved beyond their tolerance", "",
                  "| case | source | metric | OLD | NEW | moved (scaled) | tolerance | versions |",
                  "|---|---|---|---|---|---|---|---|"]
        for r in sorted(moved, key=lambda r: -(r["moved"] if math.isfinite(r["moved"]) else math.inf)):
            ver = "" if r["old_version"] == r["new_version"] else f"{_t(_v(r['old_version']))} → {_t(_v(r['new_version']))}"
            lines.append(f"| {_t(r['case'])} | {_t(r['source'])} | {_t(r['metric'])} | {number(r['old'], '.10g')} | "
                         f"{number(r['new'], '.10g')} | {_moved(r['moved'])} | {r['tolerance']:.3g} | {ver} |")
        lines.append("")
    small = [r for r in d["rows"] if not r["beyond"] and r["old_verdict"] == r["new_verdict"]]
    if small:
        lines += [f"{len(small)} other value(s) moved within their tolerance (largest "
                  f"{d['largest_below_tolerance']:.3g}, scaled).", ""]
    for title, items in (("Gone from NEW", d["removed"]), ("New in NEW", d["added"])):
        if items:
            lines += [f"## {title}", ""] + [f"- {_t(i['case'])} · {_t(i['source'])}: {_t(i['what'])}" for i in items] + [""]
    if not d["regressions"] and not d["rows"] and not d["added"]:
        lines += ["Nothing moved: every value and verdict is identical.", ""]
    return "\n".join(lines)


def _moved(x: float) -> str:
    return "appeared or vanished" if not math.isfinite(x) else f"{x:.3g}"


def render_junit(d: dict, name: str = "demcheck-diff") -> str:
    """A test case per case × source: failure when a verdict got worse, a value moved beyond its tolerance
    or the source is gone."""
    suite = ET.Element("testsuite", name=name)
    by: dict = defaultdict(list)
    for r in d["rows"]:
        by[(r["case"], r["source"])].append(r)
    gone = {(i["case"], i["source"]): i for i in d["removed"]}
    keys = sorted(set(by) | set(gone))
    fails = 0
    for case, src in keys:
        tc = ET.SubElement(suite, "testcase", classname=case, name=src)
        bad = [r for r in by.get((case, src), []) if r["regression"]]
        if (case, src) in gone:
            fails += 1
            ET.SubElement(tc, "failure", message=gone[(case, src)]["what"])
        elif bad:
            fails += 1
            ET.SubElement(tc, "failure", message=f"{len(bad)} regression(s)").text = "\n".join(_line(r) for r in bad)
        else:
            ET.SubElement(tc, "system-out").text = "\n".join(_line(r) for r in by[(case, src)])
    suite.set("tests", str(len(keys)))
    suite.set("failures", str(fails))
    suite.set("errors", "0")
    suite.set("skipped", "0")
    root = ET.Element("testsuites")
    root.append(suite)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _line(r: dict) -> str:
    text = (f"{r['metric']}: {number(r['old'], '.10g')} → {number(r['new'], '.10g')} (moved {_moved(r['moved'])} "
            f"scaled, tolerance {r['tolerance']:.3g})")
    if r["old_verdict"] != r["new_verdict"]:
        text += f"; verdict {_v(r['old_verdict'])} → {_v(r['new_verdict'])}"
    return text


# ----------------------------------------------------------------------------- baselines in verify


def apply_baseline(summary: Summary, base: dict, tolerance: float | None = None) -> dict:
    """Judge a finished verify run (its records.Summary) against a baseline (``load``): every regression becomes
    a "differs unexpectedly" comparison of its source and metric (reason "baseline: …"), so the case fails
    and the report, JUnit and exit code say so; ``summary.baseline`` holds the whole comparison. Only the
    cases that ran are compared."""
    d = compare(base, from_summary(summary, "this run"), tolerance, only_common_cases=True)
    by_case: dict = defaultdict(list)
    for r in d["rows"]:
        if r["regression"]:
            by_case[r["case"]].append(r)
    for i in d["removed"]:
        by_case[i["case"]].append(i)
    for c in summary.cases:
        for r in by_case.get(c.case, []):
            if "metric" not in r:
                comp = verdicts.status_comparison(r["source"], verdicts.UNEXPECTED, f"baseline: {r['source']} {r['what']} "
                                           f"(it ran in the baseline {base['path']})")
            else:
                why = [] if not r["beyond"] else [f"moved {_moved(r['moved'])} from the baseline's "
                                                  f"{number(r['old'], '.10g')} (scaled; tolerance {r['tolerance']:.3g})"]
                if r["change"] == "worse":
                    why.append(f"verdict {_v(r['old_verdict'])} in the baseline, {_v(r['new_verdict'])} now")
                if r["old_version"] != r["new_version"]:
                    why.append(f"version {_v(r['old_version'])} → {_v(r['new_version'])}")
                absd = abs(r["new"] - r["old"]) if math.isfinite(r["new"]) and math.isfinite(r["old"]) else math.nan
                comp = verdicts.Comparison(r["source"], r["metric"], r["new"], r["old"], absd, r["moved"], r["tolerance"],
                                    verdicts.UNEXPECTED, "baseline: " + "; ".join(why))
            c.comparisons.append(comp)
        if c.case in by_case:
            c.judged()
    summary.failed = summary.count_failed()
    summary.baseline = {k: v for k, v in d.items() if k != "new"} | {"path": base["path"]}
    return summary.baseline


def baseline_markdown(b: dict) -> list[str]:
    """report.md's section on the baseline check."""
    c = b["counts"]
    lines = ["## Baseline", "", f"Against {_t(b['path'])} (run {_t(b['old']['run_id'] or '—')}): {b['checked']} quantities "
             f"compared, {b['unchanged']} identical; **{b['regressions']} regression(s)** ({c['worse']} verdict(s) "
             f"worse, {c['moved']} value(s) moved beyond their tolerance, {c['removed']} source(s) gone); "
             f"{c['better']} verdict(s) better.", ""]
    changed = {k: v for k, v in b["engines"].items() if v["old"] != v["new"]}
    if changed:
        lines += ["Engine versions changed: " + "; ".join(f"{_t(k)} {_t(_v(v['old']))} → {_t(_v(v['new']))}"
                                                          for k, v in changed.items()), ""]
    bad = [r for r in b["rows"] if r["regression"]]
    if bad:
        lines += ["| case | source | metric | baseline | now | moved (scaled) | tolerance | verdict |",
                  "|---|---|---|---|---|---|---|---|"]
        lines += [f"| {_t(r['case'])} | {_t(r['source'])} | {_t(r['metric'])} | {number(r['old'], '.10g')} | "
                  f"{number(r['new'], '.10g')} | {_moved(r['moved'])} | {r['tolerance']:.3g} | "
                  f"{_v(r['old_verdict'])} → {_v(r['new_verdict'])} |" for r in bad]
        lines.append("")
    return lines
