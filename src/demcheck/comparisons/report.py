"""The reports of a verification run: results.json, report.md, junit.xml and report.html.

Every file is written atomically (io.atomic_path); ``<root>/latest`` is switched to the new run only after
its files exist. report.html carries its plots inline (PNG, base64) and a small script that marks the page
``data-plots-ok`` once every plot has decoded, which the browser test reads back.
"""

from __future__ import annotations

import base64
import functools
import html
import io
import logging
import math
import os
import re
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

from ..io import md_text, number, plain, write_json, write_text
from . import verdicts
from .styles import engine_sources

def write_all(summary: dict, out_dir: Path, root: Path, junit: Path | None = None, link: str = "latest") -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    PLOT_CACHE["dir"] = Path(summary["cache"]["dir"]) / "plots" if "cache" in summary else None
    data = {k: v for k, v in summary.items()}
    data["cases"] = [{k: v for k, v in c.items() if k != "series"} for c in summary["cases"]]
    write_json(out_dir / "results.json", plain(data))
    write_text(out_dir / "report.md", render_markdown(summary))
    junit_text = render_junit(summary)
    write_text(out_dir / "junit.xml", junit_text)
    if junit is not None:
        write_text(junit, junit_text)
    try:
        page = render_html(summary)
    except KeyboardInterrupt:  # interrupted while drawing: the page without its plots, then stop
        write_text(out_dir / "report.html", render_html(summary, draw=False))
        link_latest(root, out_dir, link)
        raise
    write_text(out_dir / "report.html", page)
    link_latest(root, out_dir, link)


def link_latest(root: Path, out_dir: Path, name: str = "latest") -> None:
    """Point the symlink ``<root>/<name>`` (``latest`` is verify's; bench, stress and validate keep their own,
    ``latest-bench`` …) at ``out_dir`` (a run directory in ``root``) in one step: a new
    link beside it renamed over it. ``latest`` is demcheck's own link — the command line refuses a real file
    or directory there before any work (cli.check_output) — and should the rename fail all the same, the new
    link is removed, never left behind."""
    tmp = root / f".{name}.{os.getpid()}"
    if tmp.is_symlink() or tmp.exists():
        tmp.unlink()
    tmp.symlink_to(out_dir.name)
    try:
        os.replace(tmp, root / name)
    finally:
        if tmp.is_symlink():
            tmp.unlink()


# ----------------------------------------------------------------------------- helpers


def _model(c: dict) -> str:
    m = c.get("model") or {}
    if not m:
        return "—"
    text = f"{m['normal']} / {m['tangential']}"
    return text + (" (limit_force)" if m.get("limit_force") else "")


def _engine_text(summary: dict) -> str:
    parts = []
    for name, e in summary["engines"].items():
        parts.append(f"{_md(name)} {_md(e['version'])}" if e["found"] else
                     f"{_md(name)}: missing ({_md(e['how_to_install'])})")
    return "; ".join(parts) if parts else "none selected (reference only)"


_md = md_text


def _cell(text) -> str:
    """Text for a markdown table cell (:func:`_md`: a ``|`` would end the cell, a line break the row)."""
    return _md(text)


def matrix(summary: dict) -> dict:
    """(model, source, metric) → worst verdict over the collision cases (the packings have their own table)."""
    out: dict = defaultdict(list)
    for c in summary["cases"]:
        if c.get("kind") == "packing":
            continue
        for k in c.get("comparisons", []):
            out[(_model(c), k["source"], k["metric"])].append(k["verdict"])
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


def _matrix_sources(summary: dict) -> list[str]:
    return [*REFERENCE_SOURCES, *[s for s in engine_sources() if s in summary["engines"]]]


# ----------------------------------------------------------------------------- markdown


def render_markdown(summary: dict) -> str:
    lines = [f"# demcheck verification {summary['run_id']}", ""]
    for section in (_md_header, _md_matrix, _md_traps, _md_disagreements, _md_packings, _md_cases,
                    validation_markdown):
        lines += section(summary)
    return "\n".join(lines) + "\n"


def _md_header(summary: dict) -> list[str]:
    lines = []
    if summary["partial"]:
        lines += [f"**PARTIAL REPORT: the run was interrupted; {len(summary['cases'])} of {summary['planned']} "
                  "cases finished and are reported below.**", ""]
    lines += [f"demcheck {summary['demcheck']} · started {summary['started']} · wall time "
              f"{summary.get('wall_time', 0):.1f} s", "", f"Engines: {_engine_text(summary)}", ""]
    if "cache" in summary:
        lines += [f"Engine-run cache: {summary['cache']['hits']} hits, {summary['cache']['misses']} misses "
                  f"({_md(summary['cache']['dir'])})", ""]
    counts: dict = defaultdict(int)
    for c in summary["cases"]:
        for k in c.get("comparisons", []):
            counts[k["verdict"]] += 1
    lines += ["| verdict | comparisons |", "|---|---|"]
    lines += [f"| {v} | {counts[v]} |" for v in verdicts.VERDICTS if counts[v]]
    lines += ["", f"**{summary['failed']} case(s) with an unexpected difference or a failure.**", ""]
    if "baseline" in summary:
        from .diff import baseline_markdown

        lines += baseline_markdown(summary["baseline"])
    return lines


def _md_matrix(summary: dict) -> list[str]:
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


def _md_disagreements(summary: dict) -> list[str]:
    """Every comparison that does not agree, grouped by verdict, source and reason."""
    lines = ["## Disagreements and their reasons", ""]
    reasons: dict = defaultdict(list)
    for c in summary["cases"]:
        for k in c.get("comparisons", []):
            if k["verdict"] in (verdicts.EXPECTED, verdicts.UNEXPECTED, verdicts.FAILED, verdicts.NOT_EXPRESSIBLE, verdicts.MISSING):
                reasons[(k["verdict"], k["source"], k["reason"])].append((c["case"], k["metric"], k["rel_diff"]))
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


APPROXIMATE = "approximate mapping: "
MAPPING_DOC = "docs/models.md (the mapping table: each engine's configuration and why it is approximate)"


def _generic(text: str) -> str:
    """A setting or reason with the case's numbers left out (``gammat = 5.038e+08`` → ``gammat = …``,
    ``E*=7.1e+10`` → ``E*=…``): the same trap whatever the case's values, so that it is named once."""
    # a number after "=" and not part of a word ("Kt = 8G*" stays); "= 0" stays (not the case's)
    return re.sub(r"(=\s*)(?!0(?![\w.]))[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(?![\w.])", r"\1…", text)


def traps(summary: dict) -> list[dict]:
    """Every expected difference of an engine met in the run, grouped by (engine, setting, reason with its
    numbers left out), the setting being what causes it: an entry of data/expected_differences.toml (its
    ``setting`` and ``source``), or an approximate mapping (the native keyword each of its reasons is about,
    ``Comparison.setting`` from ``Mapping.keywords``; documented in the mapping table). Most comparisons
    first."""
    # the shipped entries by the reason a comparison carries (judge_engine's words): their source, and the
    # setting of a comparison from a results.json written before comparisons carried it
    documented = {f"{e.reason} ({e.source})" if e.source else e.reason: e for e in verdicts.load_expected()}
    groups: dict = {}
    for c in summary["cases"]:
        for k in c.get("comparisons", []):
            if k["verdict"] != verdicts.EXPECTED or k["source"] in (*REFERENCE_SOURCES, "reference"):
                continue
            reason = k["reason"]
            entry = documented.get(reason)
            approximate = reason.startswith(APPROXIMATE)
            if not (approximate or entry is not None or k.get("setting")):
                continue  # not an engine setting's doing (a poured packing outside its physical range)
            if approximate:
                # the keywords, "; "-joined; a results.json from before comparisons carried them: the whole
                # native configuration the case recorded
                setting = k.get("setting") or _generic((c.get("settings") or {}).get(k["source"], ""))
                settings = [x for x in setting.split("; ") if x]
                text, kind, source = reason[len(APPROXIMATE):], "approximate mapping", MAPPING_DOC
            else:
                setting = k.get("setting") or (entry.setting if entry else "")
                settings = [setting] if setting else []
                text, kind = (entry.reason if entry else reason), "expected difference"
                source = entry.source if entry else ""
            text = _generic(text)
            g = groups.setdefault((k["source"], setting, text, kind), {
                "engine": k["source"], "settings": settings, "reason": text, "kind": kind, "source": source,
                "cases": set(), "metrics": set(), "comparisons": 0})
            g["cases"].add(c["case"])
            g["metrics"].add(k["metric"])
            g["comparisons"] += 1
    out = [{**g, "cases": sorted(g["cases"]), "metrics": sorted(g["metrics"])} for g in groups.values()]
    return sorted(out, key=lambda g: (-g["comparisons"], g["engine"], g["settings"], g["reason"]))


def _code(text: str) -> str:
    """Inline code in markdown, whatever backticks the text holds."""
    return f"`` {text} ``" if "`" in text else f"`{text}`"


def _md_traps(summary: dict) -> list[str]:
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


def _md_packings(summary: dict) -> list[str]:
    packings = [c for c in summary["cases"] if c.get("kind") == "packing"]
    if not packings:
        return []
    lines = ["## Packings", "", "Bulk values per source (the trajectories are chaotic: compared by these, "
             "within statistical tolerances; column and layer against their static closed form).", "",
             "| case | source | solid fraction | coordination | bed height (m) | mean contact force (N) | "
             "force distribution: KS distance to the reference (critical) | φ_zz; distance to the reference (critical) | "
             "max overlap / d | static closed form |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for c in packings:
        for src, v in c["sources"].items():
            m = v.get("metrics") or {}

            def comp(metric, src=src, c=c):
                return next((k for k in c["comparisons"] if k["source"] == src and k["metric"] == metric), None)

            cf, ks, fz = comp("static_overlap"), comp("force_distribution_ks"), comp("fabric_zz")
            lines.append(f"| {_cell(c['case'])} | {_cell(src)} | {number(m.get('solid_fraction'), '.4f')} | "
                         f"{number(m.get('coordination_number'), '.3f')} | {number(m.get('bed_height'), '.5g')} | "
                         f"{number(m.get('mean_contact_force'), '.4g')} | "
                         f"{number(ks['value'], '.3f') + ' (' + number(ks['tolerance'], '.3f') + ') ' + ks['verdict'] if ks else '—'} | "
                         f"{_fabric_cell(m, fz)} | "
                         f"{number(m.get('max_overlap_ratio'), '.3g')} | "
                         f"{number(cf['value'], '.2e') + ' ' + cf['verdict'] if cf else '—'} |")
    return lines + [""]


def _fabric_cell(metrics: dict, comp: dict | None) -> str:
    """A source's φ_zz (the contact fabric's vertical component) and, where verify compares it (a poured
    packing's engines), its distance to the reference's against the critical one and the verdict."""
    text = number(metrics.get("fabric_zz"), ".4f")
    if comp:
        text += f"; {number(comp['rel_diff'], '.4f')} ({number(comp['tolerance'], '.4f')}) {comp['verdict']}"
    return text


def _md_cases(summary: dict) -> list[str]:
    lines = ["## Cases", "", "| case | model | status | sources | worst curve distance (force–time max) |",
             "|---|---|---|---|---|"]
    for c in summary["cases"]:
        srcs = ", ".join(f"{k}: {v.get('status', '—')}" for k, v in c.get("sources", {}).items())
        worst_curve = max((d.get("force_time_max") or 0.0 for d in c.get("curves", {}).values()), default=0.0)
        lines.append(f"| {_cell(c['case'])} | {_cell(_model(c))} | {_cell(c['status'])} | {_cell(srcs)} | "
                     f"{number(worst_curve, '.3g')} |")
    return lines


# ----------------------------------------------------------------------------- validation (demcheck validate)


def validation_markdown(summary: dict) -> list[str]:
    """The published-benchmark verdicts (comparisons/validate.py): each source against each exact limit and
    each paper's curve, largest deviation, tolerance and what it stands for."""
    val = summary.get("validation")
    if not val:
        return []
    lines = ["", "## Validation against published benchmarks", "",
             "| case file | source | quantity | expected | largest deviation | at | tolerance | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for c in val["checks"]:
        lines.append(f"| {_cell(c['file'])} | {_cell(c['source'])} | {_cell(c['quantity'])} | "
                     f"{_cell(c['kind'])}: {_cell(c['expected'])} | "
                     f"{number(c['deviation'], '.3g')} | {number(c['at'], '.3g')} | {number(c['tolerance'], '.3g')} | "
                     f"{_cell(c['verdict'])} |")
    lines += ["", "Tolerances:", ""] + sorted({f"* {_md(c['quantity'])} ({_md(c['kind'])}): {_md(c['why'])}"
                                                for c in val["checks"]})
    return lines


def validation_plots(summary: dict) -> list[tuple[str, str]]:
    """One panel per case file and quantity, drawn like the papers' figures: each source a line over the
    benchmark's axis, the paper's points over them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from . import plots

    out = []
    for line in (summary.get("validation") or {}).get("series", []):
        if not line["x_label"]:
            continue
        fig, ax = plt.subplots(figsize=(5.2, 3.6), layout="constrained")
        ys = []
        for src, xy in sorted(line["sources"].items(), key=lambda kv: plots.source_order(kv[0])):
            pts = sorted((x, y) for x, y in zip(xy["x"], xy["y"]) if y is not None)
            if pts:
                plots.source_line(ax, [p[0] for p in pts], [p[1] for p in pts], src)
                ys += [p[1] for p in pts]
        if line["paper"]:
            ax.plot([p[0] for p in line["paper"]], [p[1] for p in line["paper"]], "k*", ms=7, label="paper")
            ys += [p[1] for p in line["paper"]]
        ax.set(xlabel=plots.literal(line["x_label"]), ylabel=plots.literal(line["label"]),
               title=plots.wrap_title(f"{line['file']}: {line['quantity']}", 50))
        ax.title.set_fontsize(9)
        ax.grid(alpha=0.3)
        plots.plain_ticks(ax)
        plots.min_span(ax, ys)
        if ax.get_legend_handles_labels()[0]:
            plots.legend(ax, fontsize=7)
        out.append((f"{line['file']} {line['quantity']}", _png(fig)))
    return out


# ----------------------------------------------------------------------------- junit


def render_junit(summary: dict) -> str:
    """One testcase per case × source (the reference's checks, each engine): failure for an unexpected
    difference or a failed run, skipped for not expressible or a missing engine."""
    suite = ET.Element("testsuite", name="demcheck-verify", timestamp=summary["started"],
                       time=f"{summary.get('wall_time', 0):.3f}")
    n = fails = errors = skips = 0
    for c in summary["cases"]:
        by_source: dict = defaultdict(list)
        for k in c.get("comparisons", []):
            src = "reference" if k["source"] in ("closed-form", "reference-verlet") else k["source"]
            by_source[src].append(k)
        for src, comps in by_source.items():
            n += 1
            tc = ET.SubElement(suite, "testcase", classname=f"{c['case']}", name=f"{_model(c)} · {src}")
            bad = [k for k in comps if k["verdict"] == verdicts.UNEXPECTED]
            failed = [k for k in comps if k["verdict"] == verdicts.FAILED]
            skipped = [k for k in comps if k["verdict"] in (verdicts.NOT_EXPRESSIBLE, verdicts.MISSING)]
            if failed:
                errors += 1
                ET.SubElement(tc, "error", message=failed[0]["reason"][:500]).text = "\n".join(
                    f"{k['source']} {k['metric']}: {k['reason']}" for k in failed)
            elif bad:
                fails += 1
                ET.SubElement(tc, "failure", message=f"{len(bad)} unexpected difference(s)").text = "\n".join(
                    f"{k['metric']}: {number(k['value'])} vs {number(k['reference'])} (scaled {number(k['rel_diff'], '.3g')} > "
                    f"{number(k['tolerance'], '.3g')}): {k['reason']}" for k in bad)
            elif skipped:
                skips += 1
                ET.SubElement(tc, "skipped", message=skipped[0]["reason"][:500])
            expected = [k for k in comps if k["verdict"] == verdicts.EXPECTED]
            if expected:
                ET.SubElement(tc, "system-out").text = "\n".join(
                    f"differs as expected: {k['metric']} ({number(k['rel_diff'], '.3g')}): {k['reason']}" for k in expected)
    suite.set("tests", str(n))
    suite.set("failures", str(fails))
    suite.set("errors", str(errors))
    suite.set("skipped", str(skips))
    root = ET.Element("testsuites")
    root.append(suite)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


# ----------------------------------------------------------------------------- html

# verdict → the class of its matrix and table cells (and their colours below)
VERDICT_CLASS = {verdicts.AGREE: "v-agree", verdicts.EXPECTED: "v-expected", verdicts.UNEXPECTED: "v-unexpected",
                 verdicts.FAILED: "v-failed", verdicts.NOT_EXPRESSIBLE: "v-not-expressible",
                 verdicts.MISSING: "v-missing"}
_STYLE = """
body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:13px}td,th{border:1px solid #ccc;padding:3px 6px;
overflow-wrap:break-word}th{background:#f3f3f3}
.v-agree{background:#c8ecd0}.v-expected{background:#ffe08a}.v-unexpected,.v-failed{background:#f5a3a3;font-weight:bold}
.v-not-expressible,.v-missing{background:#d9d9d9}.v-none{color:#999}
table.matrix td.mark{text-align:center;min-width:1.4em}table.matrix th.src{border-left:2px solid #888}
table.matrix td.first{border-left:2px solid #888}
.legend span{display:inline-block;padding:1px 8px;margin:0 4px 4px 0;border:1px solid #bbb}
.status-ok{color:#1a7f37}.status-unexpected,.status-failed{color:#cf222e;font-weight:bold}
.partial,.plot-error{background:#fff3cd;padding:.5em;border:1px solid #e0c060}img{max-width:100%;border:1px solid #ddd;margin:4px 0}
details{margin:.4em 0}summary{cursor:pointer}code{background:#f3f3f3;padding:0 3px}
"""
_SCRIPT = """
<script>
window.addEventListener('load', function () {
  var imgs = Array.prototype.slice.call(document.querySelectorAll('img.plot'));
  var ok = imgs.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length;
  document.body.setAttribute('data-plots', String(imgs.length));
  document.body.setAttribute('data-plots-ok', String(ok));
});
</script>
"""
# what a plot draws, in every plot-cache key: raise it when a plot changes, so that no stale PNG is reused
PLOT_VERSION = 3
# P(f/⟨f⟩) is drawn for a source with at least this many contact forces: a histogram of a handful (a column
# of five spheres has four) shows the few forces' values, not a distribution
MIN_CONTACTS = 50


def _markdown_html(lines: list[str]) -> str:
    """Markdown rendered by markdown-it (CommonMark and tables). Raw HTML is not let through: case names and
    reasons come from users' case files and engines, so raw HTML in one would be shown as text, never run; and
    every such text is escaped (:func:`_md`) before it reaches markdown, so that none is read as a link or
    emphasis either. A line break is kept (a list item's second line, its counts, starts a line of its own)."""
    return _markdown().render("\n".join(lines))


@functools.lru_cache(maxsize=1)
def _markdown():
    from markdown_it import MarkdownIt

    return MarkdownIt("commonmark", {"html": False, "breaks": True}).enable("table")


def _png(fig) -> str:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


# the plot cache: <engine-run cache>/plots (under $DEMCHECK_CACHE), set by write_all when the run uses the cache
PLOT_CACHE: dict = {"dir": None}
_PNG_START, _PNG_END = b"\x89PNG\r\n\x1a\n", b"IEND\xaeB`\x82"
_DAMAGED_LOGGED: set = set()


def _cached(key_obj, render, valid):
    """A plot's text (a PNG in base64, or a JSON list of them), from the plot cache when the same data was
    drawn before (warm runs). An entry that does not read back ``valid`` (truncated, changed) is a miss: drawn
    again and replaced. A cache that cannot be written only costs the drawing."""
    import hashlib
    import json

    d = PLOT_CACHE["dir"]
    if d is None:
        return render()
    k = hashlib.sha256(json.dumps(plain(key_obj), sort_keys=True, default=str).encode()).hexdigest()
    path = Path(d) / f"{k}.b64"
    try:
        text = path.read_text()
    except FileNotFoundError:
        text = None
    except (OSError, UnicodeDecodeError):
        text = ""
    if text is not None:
        if valid(text):
            return text
        if path not in _DAMAGED_LOGGED:  # once, as the engine-run cache does (logger demcheck.cache)
            _DAMAGED_LOGGED.add(path)
            logging.getLogger("demcheck.cache").warning(
                "demcheck: plot cache: ignoring the damaged entry %s; it is drawn again and replaced", path)
    out = render()
    try:
        write_text(path, out)
    except OSError:
        pass
    return out


def _png_ok(b64) -> bool:
    """A whole PNG in base64: its signature first, its IEND chunk last."""
    try:
        data = base64.b64decode(b64, validate=True)
    except (ValueError, TypeError):
        return False
    return data.startswith(_PNG_START) and data.endswith(_PNG_END)


def _plot_list_ok(text: str) -> bool:
    """A JSON list of [title, PNG in base64] pairs."""
    import json

    try:
        items = json.loads(text)
    except ValueError:
        return False
    return isinstance(items, list) and all(isinstance(x, list) and len(x) == 2 and isinstance(x[0], str)
                                           and _png_ok(x[1]) for x in items)


def _img(b64: str, alt: str) -> str:
    return f'<img class="plot" alt="{html.escape(alt)}" src="data:image/png;base64,{b64}">'


def case_panels(entry: dict) -> str | None:
    """Force–overlap loop and force–time curve of one case, one line per source."""
    series = entry.get("series") or []
    if not series:
        return None
    return _cached({"case": entry["case"], "series": series, "v": PLOT_VERSION},
                   lambda: _png(case_figure(entry["case"], series)), _png_ok)


def case_figure(name, series):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from . import plots

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.4), layout="constrained")
    for s in sorted(series, key=lambda s: plots.source_order(s["source"])):
        for ax, x in ((a1, [d * 1e6 for d in s["delta"]]), (a2, [t * 1e6 for t in s["t"]])):
            plots.source_line(ax, x, s["fn"], s["source"], markers=False)
    a1.set(xlabel="overlap δ (µm)", ylabel="Fn (N)", title="force–overlap")
    a2.set(xlabel="time since contact start (µs)", ylabel="Fn (N)", title="force–time")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.axhline(0, color="0.6", lw=0.5)
        plots.plain_ticks(a)
    plots.legend(a1, fontsize=7)
    fig.suptitle(plots.wrap_title(name, 90), fontsize=9)
    return fig


def _metric_of(entry, source, metric):
    s = entry.get("sources", {}).get(source, {})
    return (s.get("metrics") or {}).get(metric)


def suite_plots(summary: dict) -> list[tuple[str, str]]:
    """Restitution in vs out; restitution against impact speed; tangential restitution and rebound spin
    against incidence angle — each per model and source."""
    import json

    key = [(c["case"], c.get("file"), _model(c), c.get("impact"), c.get("walls"), c.get("variant"),
            {s: (v.get("metrics") or {}) for s, v in c.get("sources", {}).items()}) for c in summary["cases"]]
    text = _cached({"suite": key, "v": PLOT_VERSION}, lambda: json.dumps(_suite_plots(summary)), _plot_list_ok)
    return [tuple(x) for x in json.loads(text)]


def _suite_plots(summary: dict) -> list[tuple[str, str]]:
    return [(title, _png(fig)) for title, fig in suite_figures(summary)]


def _kind(c: dict) -> str:
    """A wall impact or a pair, by the case's number of walls (never its name); "" when the entry does not say
    (a results.json from before entries carried it)."""
    walls = c.get("walls")
    return "" if walls is None else "wall" if walls else "pair"


def _lines(cases: list[dict], x_key: str) -> dict:
    """The cases of each file split into lines along ``x_key``: a file's variant labels (``entry["variant"]``)
    other than those that set x keep cases apart — a file varying the speed and limit_force draws a line per
    limit_force. A label sets x when, within the file, its texts and the x values go one to one (``speed``
    for impact.speed, ``velocity`` for a particle's velocity that sets the incidence angle, a group zipping
    x with other keys). {(file, ((key, text), …)): cases}; the labels are None for a file whose entries carry
    none (a file without variants, a results.json from before entries carried them)."""
    by_file = defaultdict(list)
    for c in cases:
        by_file[c.get("file") or c["case"]].append(c)
    out = {}
    for file, cs in by_file.items():
        keys = [k for k, _ in cs[0].get("variant") or []]
        labelled = bool(keys) and all([k for k, _ in c.get("variant") or []] == keys for c in cs)
        keep = []
        for i in range(len(keys) if labelled else 0):
            pairs = {(c["variant"][i][1], round(float(c["impact"][x_key]), 9)) for c in cs}
            if not len(pairs) == len({t for t, _ in pairs}) == len({x for _, x in pairs}):
                keep.append(i)  # not x's own label: its values are lines of their own
        for c in cs:
            labels = tuple((keys[i], c["variant"][i][1]) for i in keep) if labelled else None
            out.setdefault((file, labels), []).append(c)
    return out


def _label_text(labels) -> str:
    return "".join(f", {k}={v}" for k, v in labels or ())


def speed_panels(cases: list[dict]) -> dict:
    """The panels of "restitution against impact speed": one per case file (its variants over speed) and
    value of its other variant labels (:func:`_lines`), titled by the model, pair or wall, the file and those
    labels — a line never joins the cases of two files, nor two values of another key."""
    groups = defaultdict(list)
    with_speed = [c for c in cases if c["impact"].get("speed") is not None]
    for (file, labels), cs in _lines(with_speed, "speed").items():
        for c in cs:
            groups[(_model(c), _kind(c), file, labels)].append(c)
    return {" ".join(x for x in (model, kind) if x) + f" ({Path(file).stem}{_label_text(labels)})": cs
            for (model, kind, file, labels), cs in groups.items() if len({c["impact"]["speed"] for c in cs}) > 1}


def angle_panels(cases: list[dict]) -> dict:
    """The panels against incidence angle: one per case file and value of its other variant labels
    (:func:`_lines`: the initial spin's among them, titled by them); a file whose entries carry no labels, one
    per initial spin (titled by it)."""
    groups = defaultdict(list)
    with_angle = [c for c in cases if c["impact"].get("angle") is not None]
    for (file, labels), cs in _lines(with_angle, "angle").items():
        for c in cs:
            spin = round(c["impact"].get("spin") or 0.0, 6) if labels is None else None
            groups[(file, labels, spin)].append(c)
    return {f"{_model(cs[0])}{'' if spin is None else f', spin {spin:g}'} ({Path(file).stem}{_label_text(labels)})": cs
            for (file, labels, spin), cs in groups.items() if len(cs) > 1}


def suite_figures(summary: dict) -> list[tuple[str, object]]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from . import plots

    out = []
    sources = ["reference", *engine_sources()]
    collisions = [c for c in summary["cases"] if c.get("kind") != "packing" and c.get("impact")]
    normal = [c for c in collisions if c.get("model") and c["model"]["tangential"] == "none"]
    with_input = [c for c in normal if c["impact"].get("restitution_input") is not None]
    if with_input:
        fig, ax = plt.subplots(figsize=(4.6, 4.2), layout="constrained")
        for src in sources:
            pts = [(c["impact"]["restitution_input"], _metric_of(c, src, "restitution")) for c in with_input]
            pts = [(x, y) for x, y in pts if y is not None and math.isfinite(y)]
            if pts:
                plots.source_line(ax, *zip(*pts), src, line=False)
        ax.plot([0, 1], [0, 1], color="0.5", lw=0.8)
        ax.set(xlabel="input restitution", ylabel="measured restitution", title="restitution: in vs out")
        plots.legend(ax, fontsize=7)
        ax.grid(alpha=0.3)
        plots.plain_ticks(ax)
        out.append(("restitution in vs out", fig))
    panels = speed_panels(normal)
    if panels:
        out.append(("restitution against impact speed",
                    panel_grid(panels, sources, "speed", "restitution", "impact speed (m/s)", "restitution",
                               log_x=True)))
    oblique = [c for c in collisions if c.get("model") and c["model"]["tangential"] != "none"
               and c["impact"].get("angle") is not None]
    panels = angle_panels(oblique)
    for metric, label in (("tangential_restitution", "tangential restitution"),
                          ("rebound_angular_velocity", "rebound spin (rad/s)")):
        if panels:
            out.append((f"{label} against incidence angle",
                        panel_grid(panels, sources, "angle", metric, "incidence angle (°)", label)))
    return out


def panel_grid(panels: dict, sources, x_key: str, metric: str, x_label: str, y_label: str, log_x: bool = False):
    """One panel per group of cases: a metric against an impact parameter, a line per source; one legend for
    the figure, above the panels."""
    import matplotlib.pyplot as plt

    from . import plots

    n = len(panels)
    cols = min(4, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.1 * cols + 0.6, 2.7 * rows + 0.9), squeeze=False,
                             layout="constrained")
    handles = {}
    for ax, (name, cs) in zip(axes.ravel(), sorted(panels.items())):
        cs = sorted(cs, key=lambda c: c["impact"][x_key])
        ys = []
        for src in sources:
            pts = [(c["impact"][x_key], _metric_of(c, src, metric)) for c in cs]
            pts = [p for p in pts if p[1] is not None and math.isfinite(p[1])]
            if pts:
                handles.setdefault(src, plots.source_line(ax, *zip(*pts), src))
                ys += [p[1] for p in pts]
        if log_x:
            ax.set_xscale("log")
        ax.set_title(plots.wrap_title(name), fontsize=8)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
        plots.plain_ticks(ax)
        if ys:
            plots.min_span(ax, ys)
        else:
            plots.note(ax, f"no {metric} from any source")
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    if handles:
        plots.legend(fig, list(handles.values()), list(handles), loc="outside upper center", ncol=len(handles),
                   fontsize=7, frameon=False)
    fig.supxlabel(x_label, fontsize=8)
    fig.supylabel(y_label, fontsize=8)
    return fig


def packing_plots(entry: dict) -> str:
    return _png(packing_figure(entry))


def force_count(forces: dict) -> int | None:
    """How many contact forces a P(f/⟨f⟩) histogram holds: its ``n`` (packing_metrics.force_distribution
    records it); None — unknown — for one without (a results.json from before it was recorded)."""
    n = forces.get("n")
    return None if n is None else int(n)


def packing_figure(entry: dict):
    """Solid fraction against height, P(f/⟨f⟩) and kinetic energy against time, per source. What a panel
    cannot draw is said in it: a source without that output (or one that did not run), a packing without a
    periodic box (no profile), a source with fewer than MIN_CONTACTS contact forces or an unknown count (no
    distribution). No title of its own: report.html heads it with the packing's name."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from . import plots

    data = entry["packing"]
    order = sorted(data, key=plots.source_order)
    absent = [f"{src} ({v.get('status', 'no output')})" for src, v in entry.get("sources", {}).items()
              if src not in data]
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
    notes: dict = {a1: [], a2: [], a3: []}
    for src in order:
        d = data[src]
        prof = d.get("profile") or {}
        if prof.get("z"):
            plots.source_line(a1, prof["solid_fraction"], [z * 1e3 for z in prof["z"]], src, markers=False)
        else:
            notes[a1].append(src)
        ke = [k for k in d.get("ke") or [] if k[1] > 0]  # log axis: the start at rest left out
        if ke:
            plots.source_line(a3, [k[0] for k in ke], [k[1] for k in ke], src, markers=False)
        else:
            notes[a3].append(src)
        forces = d.get("forces") or {}
        n = force_count(forces)
        if n is not None and n >= MIN_CONTACTS:
            pts = [(x, p) for x, p in zip(forces["x"], forces["p"]) if p > 0]  # log axis: the empty bins left out
            plots.source_line(a2, [q[0] for q in pts], [q[1] for q in pts], src)
        elif n is None:
            notes[a2].append(f"{src}: count unknown" if forces.get("p") else f"{src}: no contact forces")
        else:
            notes[a2].append(f"{src}: {n} contact force(s)" if n else f"{src}: no contact forces")
    a3.set_yscale("log")
    if a2.get_lines():
        a2.set_yscale("log")
    a1.set(xlabel="solid fraction", ylabel="height (mm)", title="solid fraction against height")
    a2.set(xlabel=r"$f/\langle f\rangle$", ylabel=r"$P(f/\langle f\rangle)$", title="contact force distribution")
    a3.set(xlabel="time (s)", ylabel="kinetic energy (J)", title="kinetic energy")
    for a in (a1, a2, a3):
        a.grid(alpha=0.3)
        a.title.set_fontsize(9)
        plots.plain_ticks(a)
        if a.get_legend_handles_labels()[0]:
            plots.legend(a, fontsize=7)
    said = {a1: [], a2: [], a3: []}
    if notes[a1]:
        said[a1].append("no solid-fraction profile: the packing has no periodic box" if not a1.get_lines()
                        else "no profile from " + ", ".join(notes[a1]))
    if notes[a2]:
        said[a2].append(f"P(f) is drawn from {MIN_CONTACTS} contact forces or more; not for "
                        + "; ".join(notes[a2]))
    if notes[a3]:
        said[a3].append("no kinetic energy from " + ", ".join(notes[a3]))
    for a in (a1, a2, a3):
        if absent:
            said[a].append("no data from " + ", ".join(absent))
        if said[a]:
            plots.note(a, ". ".join(said[a]), centre=not a.get_lines())
    return fig


def _matrix_html(summary: dict) -> str:
    """The agreement matrix as a table: a column per source and metric, each cell coloured by its verdict
    (VERDICT_CLASS), with a legend."""
    esc = html.escape
    mat = matrix(summary)
    sources = _matrix_sources(summary)
    models = sorted({m for m, _, _ in mat})
    legend = "".join(f"<span class='{VERDICT_CLASS[v]}'>{esc(_LEGEND.get(v, _SHORT[v] + ' ' + v))}</span>"
                     for v in verdicts.VERDICTS) + "<span class='v-none'>· not compared</span>"
    out = [f"<p class='legend'>{legend}</p>",
           "<p>Worst verdict over the collision cases of each model (packings: their own table below).</p>",
           "<table class='matrix'><tr><th rowspan='2'>model</th>"
           + "".join(f"<th class='src' colspan='{len(MATRIX_METRICS)}'>{esc(s)}</th>" for s in sources) + "</tr><tr>"
           + "".join(f"<th title='{esc(name)}'{' class=src' if i == 0 else ''}>{esc(mark)}</th>"
                     for _ in sources for i, (_, mark, name) in enumerate(MATRIX_METRICS)) + "</tr>"]
    for m in models:
        cells = []
        for s in sources:
            if (m, s, "*") in mat:
                v = mat[(m, s, "*")]
                cells.append(f"<td class='mark first {VERDICT_CLASS[v]}' colspan='{len(MATRIX_METRICS)}' "
                             f"title='{esc(s)}: {esc(v)}'>{esc(_SHORT[v])}</td>")
                continue
            for i, (k, _, name) in enumerate(MATRIX_METRICS):
                first = " first" if i == 0 else ""
                v = mat.get((m, s, k))
                if v is None:
                    cells.append(f"<td class='mark{first} v-none' title='{esc(s)} {esc(name)}: not compared'>·</td>")
                else:
                    cells.append(f"<td class='mark{first} {VERDICT_CLASS[v]}' title='{esc(s)} {esc(name)}: "
                                 f"{esc(v)}'>{esc(_SHORT[v])}</td>")
        out.append(f"<tr><td>{esc(m)}</td>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _plot(what: str, render, draw: bool = True):
    """A plot (``render()``: its PNG, or a list of them) and the HTML said in its place: "" when drawn; a note
    when drawing it raised — the report is never lost to a plot (the numbers are in its tables) — and nothing
    when ``draw`` is off (the page says once that no plot was drawn)."""
    if not draw:
        return None, ""
    try:
        return render(), ""
    except Exception as exc:  # noqa: BLE001 — any plotting failure: the page is written without that plot
        import matplotlib.pyplot as plt

        plt.close("all")
        first = (str(exc).strip().splitlines() or [""])[0][:300]
        logging.getLogger("demcheck.report").warning("demcheck: report.html: %s could not be drawn: %s: %s",
                                                     what, type(exc).__name__, first)
        return None, (f"<p class='plot-error'>{html.escape(what)} could not be drawn "
                      f"({html.escape(type(exc).__name__)}: {html.escape(first)}); the numbers are in the tables.</p>")


def render_html(summary: dict, draw: bool = True) -> str:
    """report.html. ``draw`` off: no plot is drawn (write_all's page when the run was interrupted while they
    were), and the page says so."""
    from . import plots

    esc = html.escape
    parts = ["<!doctype html><html><head><meta charset='utf-8'>",
             f"<title>demcheck {'validate' if summary.get('validation') else 'verify'} {esc(summary['run_id'])}</title>"
             f"<style>{_STYLE}</style>{_SCRIPT}</head><body>",
             f"<h1>demcheck verification {esc(summary['run_id'])}</h1>"]
    if summary["partial"]:
        parts.append(f"<p class='partial'>PARTIAL REPORT: the run was interrupted; {len(summary['cases'])} of "
                     f"{summary['planned']} cases finished.</p>")
    header = _md_header({**summary, "partial": False})  # the partial note is above, in its own box
    parts.append(_markdown_html(header))
    parts.append("<h2>Agreement matrix</h2>" + _matrix_html(summary))
    parts.append(_markdown_html(_md_traps(summary)))
    parts.append(_markdown_html(_md_disagreements(summary)))
    parts.append("<h2>Suite plots</h2><p>Each source in its own colour and marker in every panel (hollow markers, "
                 "larger for the sources drawn first, so that sources that agree show one inside the other). A "
                 f"y axis spans at least {100 * plots.MIN_REL_SPAN:g} % of its panel's largest value: smaller differences "
                 "are read in the tables, not the plots.</p>")
    if not draw:
        parts.append("<p class='plot-error'>No plots in this page: the run was interrupted while they were drawn. "
                     "The numbers are in the tables.</p>")
    items, note = _plot("the suite plots", lambda: suite_plots(summary), draw)
    parts.append(note)
    for title, b64 in items or []:
        parts.append(f"<h3>{esc(title)}</h3>{_img(b64, title)}")
    packings = [c for c in summary["cases"] if c.get("kind") == "packing"]
    if packings:
        parts.append(_markdown_html(_md_packings(summary)))
        for c in packings:
            if c.get("packing"):
                b64, note = _plot(f"the packing panels of {c['case']}", lambda c=c: packing_plots(c), draw)
                parts.append(f"<h3>packing {esc(c['case'])}</h3>" + (_img(b64, f"packing {c['case']}") if b64 else note))
    if summary.get("validation"):
        parts.append(_markdown_html(validation_markdown(summary)))
        items, note = _plot("the validation plots", lambda: validation_plots(summary), draw)
        parts.append(note)
        parts += [f"<h3>{esc(title)}</h3>{_img(b64, title)}" for title, b64 in items or []]
    parts.append("<h2>Cases</h2>")
    # one plot per case file (its first variant), every case's numbers in a table
    shown = set()
    for c in summary["cases"]:
        cls = {"ok": "status-ok", "unexpected": "status-unexpected", "failed": "status-failed"}.get(c["status"], "")
        parts.append(f"<details><summary><span class='{cls}'>{esc(c['status'])}</span> {esc(c['case'])} — "
                     f"{esc(_model(c))}</summary>")
        if c.get("kind") != "packing" and c["file"] not in shown:
            b64, note = _plot(f"the force curves of {c['case']}", lambda c=c: case_panels(c), draw)
            if b64:
                parts.append(_img(b64, f"force curves of {c['case']}"))
            if b64 or note:
                parts.append(note)
                shown.add(c["file"])
        parts.append("<table><tr><th>source</th><th>metric</th><th>value</th><th>reference</th><th>scaled diff"
                     "</th><th>tolerance</th><th>verdict</th><th>reason</th></tr>")
        for k in c.get("comparisons", []):
            parts.append(f"<tr><td>{esc(k['source'])}</td><td>{esc(k['metric'])}</td><td>{number(k['value'])}</td>"
                         f"<td>{number(k['reference'])}</td><td>{number(k['rel_diff'], '.3g')}</td>"
                         f"<td>{number(k['tolerance'], '.3g')}</td>"
                         f"<td class='{VERDICT_CLASS.get(k['verdict'], '')}'>{esc(k['verdict'])}</td>"
                         f"<td>{esc(k['reason'])}</td></tr>")
        parts.append("</table></details>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"
