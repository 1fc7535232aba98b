"""The reports of a verification run: results.json, report.md, junit.xml and report.html.

Every file is written atomically (io.atomic_path); ``<root>/latest`` is switched to the new run only after
its files exist. report.html carries its plots inline (PNG, base64) and a small script that marks the page
``data-plots-ok`` once every plot has decoded, which the browser test reads back.
"""

from __future__ import annotations

import base64
import html
import io
import logging
import math
import os
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

from ..io import number, plain, write_json, write_text
from . import verdicts
from .styles import engine_sources, style

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
    write_text(out_dir / "report.html", render_html(summary))
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
        parts.append(f"{name} {e['version']}" if e["found"] else f"{name}: missing ({e['how_to_install']})")
    return "; ".join(parts) if parts else "none selected (reference only)"


def matrix(summary: dict) -> dict:
    """(model, source, metric) → worst verdict over the cases."""
    out: dict = defaultdict(list)
    for c in summary["cases"]:
        for k in c.get("comparisons", []):
            out[(_model(c), k["source"], k["metric"])].append(k["verdict"])
    return {key: verdicts.worst(vs) for key, vs in out.items()}


_SHORT = {verdicts.AGREE: "✓", verdicts.EXPECTED: "≈", verdicts.UNEXPECTED: "✗", verdicts.NOT_EXPRESSIBLE: "n/e", verdicts.MISSING: "missing",
          verdicts.FAILED: "FAIL"}


# ----------------------------------------------------------------------------- markdown


def render_markdown(summary: dict) -> str:
    lines = [f"# demcheck verification {summary['run_id']}", ""]
    if summary["partial"]:
        lines += [f"**PARTIAL REPORT: the run was interrupted; {len(summary['cases'])} of {summary['planned']} "
                  "cases finished and are reported below.**", ""]
    lines += [f"demcheck {summary['demcheck']} · started {summary['started']} · wall time "
              f"{summary.get('wall_time', 0):.1f} s", "", f"Engines: {_engine_text(summary)}", ""]
    if "cache" in summary:
        lines += [f"Engine-run cache: {summary['cache']['hits']} hits, {summary['cache']['misses']} misses "
                  f"({summary['cache']['dir']})", ""]
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

    # the agreement matrix: models × sources × metrics
    mat = matrix(summary)
    sources = ["closed-form", "reference-verlet", *[s for s in engine_sources() if s in summary["engines"]]]
    models = sorted({m for m, _, _ in mat})
    lines += ["## Agreement matrix", "",
              "Worst verdict over the cases of each model: ✓ agree, ≈ differs as expected, ✗ differs unexpectedly, "
              "n/e not expressible, missing (engine not installed), FAIL (a run failed). Columns: "
              "restitution, contact time, max overlap, peak force, energy, tangential restitution, rebound spin.",
              ""]
    keys = ("restitution", "contact_time", "max_overlap", "peak_force", "energy_dissipated",
            "tangential_restitution", "rebound_angular_velocity")
    head = "| model | " + " | ".join(f"{s}: e · t · δ · F · E · et · ω" for s in sources) + " |"
    lines += [head, "|---|" + "---|" * len(sources)]
    for m in models:
        cells = []
        for s in sources:
            if (m, s, "*") in mat:
                cells.append(_SHORT[mat[(m, s, "*")]])
                continue
            marks = [_SHORT.get(mat.get((m, s, k)), "·") if (m, s, k) in mat else "·" for k in keys]
            cells.append(" ".join(marks))
        lines.append(f"| {m} | " + " | ".join(cells) + " |")

    # every disagreement, explained
    lines += ["", "## Disagreements and their reasons", ""]
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
        lines += [f"* **{verdict}** — {source}: {reason}",
                  f"  {len(hits)} comparison(s) in {len(cases)} case(s); metrics {', '.join(metrics)}"
                  + (f"; largest scaled difference {worst:.3g}" if worst is not None else "")
                  + f". Cases: {', '.join(cases[:6])}{' …' if len(cases) > 6 else ''}"]

    packings = [c for c in summary["cases"] if c.get("kind") == "packing"]
    if packings:
        lines += ["", "## Packings", "", "Bulk values per source (the trajectories are chaotic: compared by these, "
                  "within statistical tolerances; column and layer against their static closed form).", "",
                  "| case | source | solid fraction | coordination | bed height (m) | mean contact force (N) | "
                  "force distribution: KS distance to the reference (critical) | max overlap / d | static closed form |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for c in packings:
            for src, v in c["sources"].items():
                m = v.get("metrics") or {}

                def comp(metric, src=src, c=c):
                    return next((k for k in c["comparisons"] if k["source"] == src and k["metric"] == metric), None)

                cf, ks = comp("static_overlap"), comp("force_distribution_ks")
                lines.append(f"| {c['case']} | {src} | {number(m.get('solid_fraction'), '.4f')} | "
                             f"{number(m.get('coordination_number'), '.3f')} | {number(m.get('bed_height'), '.5g')} | "
                             f"{number(m.get('mean_contact_force'), '.4g')} | "
                             f"{number(ks['value'], '.3f') + ' (' + number(ks['tolerance'], '.3f') + ') ' + ks['verdict'] if ks else '—'} | "
                             f"{number(m.get('max_overlap_ratio'), '.3g')} | "
                             f"{number(cf['value'], '.2e') + ' ' + cf['verdict'] if cf else '—'} |")
    # per case
    lines += ["", "## Cases", "", "| case | model | status | sources | worst curve distance (force–time max) |",
              "|---|---|---|---|---|"]
    for c in summary["cases"]:
        srcs = ", ".join(f"{k}: {v.get('status', '—')}" for k, v in c.get("sources", {}).items())
        worst_curve = max((d.get("force_time_max") or 0.0 for d in c.get("curves", {}).values()), default=0.0)
        lines.append(f"| {c['case']} | {_model(c)} | {c['status']} | {srcs} | {number(worst_curve, '.3g')} |")
    return "\n".join(lines + validation_markdown(summary)) + "\n"


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
        lines.append(f"| {c['file']} | {c['source']} | {c['quantity']} | {c['kind']}: {c['expected']} | "
                     f"{number(c['deviation'], '.3g')} | {number(c['at'], '.3g')} | {number(c['tolerance'], '.3g')} | "
                     f"{c['verdict']} |")
    lines += ["", "Tolerances:", ""] + sorted({f"* {c['quantity']} ({c['kind']}): {c['why']}" for c in val["checks"]})
    return lines


def validation_plots(summary: dict) -> list[tuple[str, str]]:
    """One panel per case file and quantity, drawn like the papers' figures: each source a line over the
    benchmark's axis, the paper's points over them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    for line in (summary.get("validation") or {}).get("series", []):
        if not line["x_label"]:
            continue
        fig, ax = plt.subplots(figsize=(5.2, 3.4))
        for src, xy in line["sources"].items():
            pts = sorted((x, y) for x, y in zip(xy["x"], xy["y"]) if y is not None)
            if pts:
                st = style(src)
                ax.plot([p[0] for p in pts], [p[1] for p in pts], color=st.colour, linestyle=st.linestyle,
                        marker=st.marker, ms=3, label=src)
        if line["paper"]:
            ax.plot([p[0] for p in line["paper"]], [p[1] for p in line["paper"]], "k*", ms=7, label="paper")
        ax.set(xlabel=line["x_label"], ylabel=line["label"], title=f"{line['file']}: {line['quantity']}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
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

_STYLE = """
body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:13px}td,th{border:1px solid #ccc;padding:3px 6px}
th{background:#f3f3f3}.agree{color:#1a7f37}.expected{color:#9a6700}.unexpected,.failed{color:#cf222e;font-weight:bold}
.partial{background:#fff3cd;padding:.5em;border:1px solid #e0c060}img{max-width:100%;border:1px solid #ddd;margin:4px 0}
details{margin:.4em 0}summary{cursor:pointer}
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
    return _cached({"case": entry["case"], "series": series}, lambda: _draw_case(entry["case"], series), _png_ok)


def _draw_case(name, series) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.2))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.16, top=0.85, wspace=0.25)
    for s in series:
        st = style(s["source"])
        lw = 2.0 if s["source"] == "reference" else 1.2
        for ax, x in ((a1, [d * 1e6 for d in s["delta"]]), (a2, [t * 1e6 for t in s["t"]])):
            ax.plot(x, s["fn"], st.linestyle, color=st.colour, lw=lw, label=s["source"])
    a1.set(xlabel="overlap δ (µm)", ylabel="Fn (N)", title="force–overlap")
    a2.set(xlabel="time since contact start (µs)", ylabel="Fn (N)", title="force–time")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.axhline(0, color="0.6", lw=0.5)
    a1.legend(fontsize=7)
    fig.suptitle(name, fontsize=9)
    return _png(fig)


def _metric_of(entry, source, metric):
    s = entry.get("sources", {}).get(source, {})
    return (s.get("metrics") or {}).get(metric)


def suite_plots(summary: dict) -> list[tuple[str, str]]:
    """Restitution in vs out; restitution against impact speed; tangential restitution and rebound spin
    against incidence angle — each per model and source."""
    import json

    key = [(c["case"], c.get("impact"), {s: (v.get("metrics") or {}) for s, v in c.get("sources", {}).items()})
           for c in summary["cases"]]
    text = _cached({"suite": key}, lambda: json.dumps(_suite_plots(summary)), _plot_list_ok)
    return [tuple(x) for x in json.loads(text)]


def _suite_plots(summary: dict) -> list[tuple[str, str]]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    sources = ["reference", *engine_sources()]
    collisions = [c for c in summary["cases"] if c.get("kind") != "packing"]
    normal = [c for c in collisions if c.get("model") and c["model"]["tangential"] == "none"]
    if normal:
        fig, ax = plt.subplots(figsize=(4.5, 4))
        for src in sources:
            xs = [c["impact"]["restitution_input"] for c in normal if c["impact"].get("restitution_input") is not None]
            ys = [_metric_of(c, src, "restitution") for c in normal if c["impact"].get("restitution_input") is not None]
            pts = [(x, y) for x, y in zip(xs, ys) if y is not None and math.isfinite(y)]
            if pts:
                st = style(src)
                ax.plot(*zip(*pts), st.marker, color=st.colour, ms=4, alpha=0.6, label=src)
        ax.plot([0, 1], [0, 1], color="0.5", lw=0.8)
        ax.set(xlabel="input restitution", ylabel="measured restitution", title="restitution: in vs out")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        out.append(("restitution in vs out", _png(fig)))
        groups = defaultdict(list)
        for c in normal:
            groups[_model(c) + (" wall" if "wall" in c["case"] else " pair")].append(c)
        groups = {k: v for k, v in groups.items() if len({c["impact"]["speed"] for c in v}) > 1}
        if groups:
            panels = {name: cs for name, cs in groups.items()}
            out.append(("restitution against impact speed",
                        _panel_grid(panels, sources, "speed", "restitution", "impact speed (m/s)", "restitution",
                                    log_x=True)))
    oblique = [c for c in collisions if c.get("model") and c["model"]["tangential"] != "none"
               and c["impact"].get("angle") is not None]
    groups = defaultdict(list)
    for c in oblique:
        groups[(c["file"], round(c["impact"].get("spin") or 0.0, 6))].append(c)
    groups = {k: v for k, v in groups.items() if len(v) > 1}
    panels = {f"{_model(cs[0])}, spin {spin:g} ({Path(file).stem})": cs for (file, spin), cs in groups.items()}
    for metric, label in (("tangential_restitution", "tangential restitution"),
                          ("rebound_angular_velocity", "rebound spin (rad/s)")):
        if panels:
            out.append((f"{label} against incidence angle",
                        _panel_grid(panels, sources, "angle", metric, "incidence angle (°)", label)))
    return out


def _panel_grid(panels: dict, sources, x_key: str, metric: str, x_label: str, y_label: str,
                log_x: bool = False) -> str:
    """One panel per group of cases: a metric against an impact parameter, a line per source."""
    import matplotlib.pyplot as plt

    n = len(panels)
    cols = 4
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(12, 2.6 * rows), squeeze=False)
    for ax, (name, cs) in zip(axes.ravel(), sorted(panels.items())):
        cs = sorted(cs, key=lambda c: c["impact"][x_key])
        for src in sources:
            st = style(src)
            pts = [(c["impact"][x_key], _metric_of(c, src, metric)) for c in cs]
            pts = [p for p in pts if p[1] is not None and math.isfinite(p[1])]
            if pts:
                ax.plot(*zip(*pts), st.marker + "-", color=st.colour, ms=4, lw=0.8, label=src)
        if log_x:
            ax.set_xscale("log")
        ax.set_title(name, fontsize=8)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    axes[0][0].legend(fontsize=6)
    fig.supxlabel(x_label, fontsize=8)
    fig.supylabel(y_label, fontsize=8)
    fig.tight_layout()
    return _png(fig)


def render_html(summary: dict) -> str:
    esc = html.escape
    parts = ["<!doctype html><html><head><meta charset='utf-8'>",
             f"<title>demcheck {'validate' if summary.get('validation') else 'verify'} {esc(summary['run_id'])}</title>"
             f"<style>{_STYLE}</style>{_SCRIPT}</head><body>",
             f"<h1>demcheck verification {esc(summary['run_id'])}</h1>"]
    if summary["partial"]:
        parts.append(f"<p class='partial'>PARTIAL REPORT: the run was interrupted; {len(summary['cases'])} of "
                     f"{summary['planned']} cases finished.</p>")
    parts.append(f"<p>demcheck {esc(summary['demcheck'])} · engines: {esc(_engine_text(summary))} · "
                 f"{summary['failed']} case(s) failing</p>")
    # matrix
    md = render_markdown(summary)
    mat_start = md.index("## Agreement matrix")
    mat_end = md.index("## Disagreements")
    parts.append("<h2>Agreement matrix</h2>" + _md_table_to_html(md[mat_start:mat_end]))
    parts.append("<h2>Suite plots</h2>")
    for title, b64 in suite_plots(summary):
        parts.append(f"<h3>{esc(title)}</h3>{_img(b64, title)}")
    for c in summary["cases"]:
        if c.get("kind") == "packing" and c.get("packing"):
            parts.append(f"<h3>packing {esc(c['case'])}</h3>" + _img(packing_plots(c), f"packing {c['case']}"))
    if summary.get("validation"):
        val_md = "\n".join(validation_markdown(summary)[3:])
        parts.append("<h2>Validation against published benchmarks</h2>" + _md_table_to_html(val_md.split("\n\nTolerances:")[0]))
        parts += [f"<h3>{esc(title)}</h3>{_img(b64, title)}" for title, b64 in validation_plots(summary)]
    parts.append("<h2>Disagreements</h2>" + "".join(
        f"<p>{esc(line.strip('* '))}</p>" for line in md[mat_end:md.index('## Cases')].splitlines()[2:] if line.strip()))
    parts.append("<h2>Cases</h2>")
    # one plot per case file (its first variant), every case's numbers in a table
    shown = set()
    for c in summary["cases"]:
        cls = {"ok": "agree", "unexpected": "unexpected", "failed": "failed"}.get(c["status"], "expected")
        parts.append(f"<details><summary><span class='{cls}'>{esc(c['status'])}</span> {esc(c['case'])} — "
                     f"{esc(_model(c))}</summary>")
        if c.get("kind") != "packing" and c["file"] not in shown:
            b64 = case_panels(c)
            if b64:
                parts.append(_img(b64, f"force curves of {c['case']}"))
                shown.add(c["file"])
        rows = [k for k in c.get("comparisons", [])]
        parts.append("<table><tr><th>source</th><th>metric</th><th>value</th><th>reference</th><th>scaled diff"
                     "</th><th>tolerance</th><th>verdict</th><th>reason</th></tr>")
        for k in rows:
            vcls = {verdicts.AGREE: "agree", verdicts.EXPECTED: "expected", verdicts.UNEXPECTED: "unexpected", verdicts.FAILED: "failed"}.get(
                k["verdict"], "")
            parts.append(f"<tr><td>{esc(k['source'])}</td><td>{esc(k['metric'])}</td><td>{number(k['value'])}</td>"
                         f"<td>{number(k['reference'])}</td><td>{number(k['rel_diff'], '.3g')}</td>"
                         f"<td>{number(k['tolerance'], '.3g')}</td><td class='{vcls}'>{esc(k['verdict'])}</td>"
                         f"<td>{esc(k['reason'])}</td></tr>")
        parts.append("</table></details>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def packing_plots(entry: dict) -> str:
    """Solid fraction against height, P(f/⟨f⟩) and kinetic energy against time, per source."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = entry["packing"]
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(12, 3.2))
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.16, top=0.86, wspace=0.3)
    for src, d in data.items():
        if d.get("profile"):
            a1.plot(d["profile"]["solid_fraction"], [z * 1e3 for z in d["profile"]["z"]], label=src)
        if d.get("ke"):
            pts = [k for k in d["ke"] if k[1] > 0]  # log axis: the start at rest left out
            a3.semilogy([k[0] for k in pts], [k[1] for k in pts], label=src)
        forces = d.get("forces") or {}
        if forces.get("x"):
            pts = [(x, p) for x, p in zip(forces["x"], forces["p"]) if p > 0]  # log axis: the empty bins left out
            a2.semilogy([q[0] for q in pts], [q[1] for q in pts], "o-", ms=3, label=src)
    a1.set(xlabel="solid fraction", ylabel="height (mm)", title="solid fraction against height")
    a2.set(xlabel=r"$f/\langle f\rangle$", ylabel=r"$P(f/\langle f\rangle)$", title="contact force distribution")
    a3.set(xlabel="time (s)", ylabel="kinetic energy (J)", title="kinetic energy")
    for a in (a1, a2, a3):
        a.grid(alpha=0.3)
        if a.get_legend_handles_labels()[0]:
            a.legend(fontsize=7)
    fig.suptitle(entry["case"], fontsize=9)
    return _png(fig)


def _md_table_to_html(text: str) -> str:
    rows = [line for line in text.splitlines() if line.startswith("|")]
    if not rows:
        return ""
    out = ["<table>"]
    for i, row in enumerate(rows):
        if set(row.replace("|", "").strip()) <= {"-"}:
            continue
        cells = [html.escape(c.strip()) for c in row.strip("|").split("|")]
        tag = "th" if i == 0 else "td"
        out.append("<tr>" + "".join(f"<{tag}>{c}</{tag}>" for c in cells) + "</tr>")
    out.append("</table>")
    return "".join(out)
