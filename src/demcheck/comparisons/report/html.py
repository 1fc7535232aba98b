"""report.html: the Markdown report with the matrix coloured by verdict and the figures inline, and a small script
that marks the page ``data-plots-ok`` once every plot has decoded (the browser test reads it back)."""

from __future__ import annotations

import functools
import html
import logging
from dataclasses import replace

from ...io import number
from .. import verdicts
from ..records import Summary
from .figures import _img, case_panels, packing_plots, suite_plots, validation_plots
from .markdown import _md_disagreements, _md_header, _md_packings, _md_traps, validation_markdown
from .matrix import MATRIX_METRICS, _LEGEND, _SHORT, _matrix_sources, _md, _model, matrix


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


def _matrix_html(summary: Summary) -> str:
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


def render_html(summary: Summary, draw: bool = True) -> str:
    """report.html. ``draw`` off: no plot is drawn (write_all's page when the run was interrupted while they
    were), and the page says so."""
    from .. import plots

    esc, summary = html.escape, Summary.of(summary)
    parts = ["<!doctype html><html><head><meta charset='utf-8'>",
             f"<title>demcheck {'validate' if summary.validation else 'verify'} {esc(summary.run_id)}</title>"
             f"<style>{_STYLE}</style>{_SCRIPT}</head><body>",
             f"<h1>demcheck verification {esc(summary.run_id)}</h1>"]
    if summary.partial:
        parts.append(f"<p class='partial'>PARTIAL REPORT: the run was interrupted; {len(summary.cases)} of "
                     f"{summary.planned} cases finished.</p>")
    header = _md_header(replace(summary, partial=False))  # the partial note is above, in its own box
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
    packings = [c for c in summary.cases if c.kind == "packing"]
    if packings:
        parts.append(_markdown_html(_md_packings(summary)))
        for c in packings:
            if c.packing:
                b64, note = _plot(f"the packing panels of {c.case}", lambda c=c: packing_plots(c), draw)
                parts.append(f"<h3>packing {esc(c.case)}</h3>" + (_img(b64, f"packing {c.case}") if b64 else note))
    if summary.validation:
        parts.append(_markdown_html(validation_markdown(summary)))
        items, note = _plot("the validation plots", lambda: validation_plots(summary), draw)
        parts.append(note)
        parts += [f"<h3>{esc(title)}</h3>{_img(b64, title)}" for title, b64 in items or []]
    parts.append("<h2>Cases</h2>")
    # one plot per case file (its first variant), every case's numbers in a table
    shown = set()
    for c in summary.cases:
        cls = {"ok": "status-ok", "unexpected": "status-unexpected", "failed": "status-failed"}.get(c.status, "")
        parts.append(f"<details><summary><span class='{cls}'>{esc(c.status)}</span> {esc(c.case)} — "
                     f"{esc(_model(c))}</summary>")
        if c.kind != "packing" and c.file not in shown:
            b64, note = _plot(f"the force curves of {c.case}", lambda c=c: case_panels(c), draw)
            if b64:
                parts.append(_img(b64, f"force curves of {c.case}"))
            if b64 or note:
                parts.append(note)
                shown.add(c.file)
        parts.append("<table><tr><th>source</th><th>metric</th><th>value</th><th>reference</th><th>scaled diff"
                     "</th><th>tolerance</th><th>verdict</th><th>reason</th></tr>")
        for k in c.comparisons:
            parts.append(f"<tr><td>{esc(k.source)}</td><td>{esc(k.metric)}</td><td>{number(k.value)}</td>"
                         f"<td>{number(k.reference)}</td><td>{number(k.rel_diff, '.3g')}</td>"
                         f"<td>{number(k.tolerance, '.3g')}</td>"
                         f"<td class='{VERDICT_CLASS.get(k.verdict, '')}'>{esc(k.verdict)}</td>"
                         f"<td>{esc(k.reason)}</td></tr>")
        parts.append("</table></details>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"
