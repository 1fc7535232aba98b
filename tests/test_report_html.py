"""The HTML report reads at a glance (issue 17, item 10): each source in its own colour in every panel, no
offset tick labels, one line per case file, no empty packing panel and no P(f) from a handful of contacts, no
overlapping titles, markdown rendered (and raw HTML never let through), the matrix coloured by verdict, and a
traps section naming the engine setting behind each expected difference — checked on the figures themselves,
and on the page as headless Chromium lays it out (layout, not pixels). Review findings: a ``$…$`` in a file's
name never reaches mathtext and a plot that fails never loses the page; a case name is never a link or
emphasis; an approximate mapping's difference carries its keyword (the real path, suite → results.json); one
trap per setting; pair or wall by the case's walls; a line per value of a file's other variant labels."""

import html as htmllib
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from demcheck.comparisons import packing_metrics, plots, report, suite, verdicts as V
from demcheck.comparisons.records import CaseResult
from demcheck.engines.base import APPROXIMATE
from demcheck.comparisons.sources import plan
from demcheck.comparisons.styles import style
from demcheck.engines.cache import Cache
from demcheck.errors import ConfigError

from .conftest import CASES, ROOT

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import to_hex  # noqa: E402

ENGINES = {"lammps": {"found": True, "version": "22 Jul 2025 - Update 4", "how_to_install": None},
           "liggghts": {"found": True, "version": "LIGGGHTS-PUBLIC 3.8.0", "how_to_install": None}}


def _summary(cases, engines=ENGINES):
    return {"run_id": "t", "started": "2026-01-01T00:00:00", "wall_time": 1.0, "partial": False,
            "planned": len(cases), "engines": engines, "failed": 0, "demcheck": "0", "cases": cases}


def _collision(case, file, values, model=("hertz", "none"), speed=1.0, angle=None, spin=0.0, e_in=0.8,
               metric="restitution", comparisons=(), walls=1, variant=None):
    """A collision entry as suite.run_case writes it: ``values`` {source: value of ``metric``}; ``variant``
    its labels [[key, text], …]."""
    return {"case": case, "file": file, "kind": "collision", "status": "ok", "walls": walls,
            "variant": [list(x) for x in variant or []],
            "model": {"normal": model[0], "tangential": model[1], "limit_force": False},
            "impact": {"speed": speed, "restitution_input": e_in, "angle": angle, "spin": spin},
            "sources": {s: {"status": "ok", "metrics": {metric: v}} for s, v in values.items()},
            "comparisons": list(comparisons), "curves": {}, "series": []}


def _forces(n, seed=1):
    return packing_metrics.force_distribution(np.random.default_rng(seed).exponential(1e-3, n))


def _packing(forces_n=None, profile=True, absent=None):
    """A packing entry: reference and lammps, each with kinetic energy, a profile (or none: no periodic box)
    and ``forces_n[source]`` contact forces; ``absent`` {source: status} sources that did not run."""
    forces_n = forces_n or {"reference": 400, "lammps": 400}
    prof = {"z": [1e-3 * k for k in range(1, 11)], "solid_fraction": [0.5 + 0.01 * k for k in range(10)]}
    data = {s: {"ke": [(0.01 * k, 10.0 ** -k) for k in range(8)], "forces": _forces(n, seed=k),
                "profile": prof if profile else None} for k, (s, n) in enumerate(forces_n.items())}
    sources = {s: {"status": "ok", "metrics": {}} for s in data}
    sources.update({s: {"status": st} for s, st in (absent or {}).items()})
    return {"case": "pack", "file": "pack.toml", "kind": "packing", "status": "ok", "sources": sources,
            "comparisons": [], "curves": {}, "series": [], "packing": data,
            "model": {"normal": "lsd", "tangential": "none", "limit_force": False}}


def _source_lines(fig):
    return [ln for ax in fig.axes for ln in ax.get_lines() if not ln.get_label().startswith("_")]


# ----------------------------------------------------------------------------- the figures


def test_restitution_against_speed_draws_one_line_per_case_file():
    # two case files of the same model and the same speeds: before, one panel joined their six points
    a = {0.1: 0.90, 1.0: 0.91, 10.0: 0.92}
    b = {0.1: 0.50, 1.0: 0.55, 10.0: 0.60}
    cases = [_collision(f"a-wall[speed={v}]", "cases/x/normal-a-wall.toml", {"reference": e, "lammps": e + 1e-4},
                        speed=v) for v, e in a.items()]
    cases += [_collision(f"b-wall[speed={v}]", "cases/x/normal-b-wall.toml", {"reference": e, "lammps": e + 1e-4},
                         speed=v) for v, e in b.items()]
    panels = report.speed_panels(cases)
    assert len(panels) == 2 and all(("normal-a-wall" in t) != ("normal-b-wall" in t) for t in panels)
    fig = report.panel_grid(panels, ["reference", "lammps"], "speed", "restitution", "v", "e", log_x=True)
    seen = set()
    for ln in _source_lines(fig):
        x, y = list(ln.get_xdata()), list(ln.get_ydata())
        assert x == [0.1, 1.0, 10.0]  # three points: one file's variants, never six
        shift = 1e-4 if ln.get_label() == "lammps" else 0.0
        file = "a" if abs(y[0] - 0.90 - shift) < 1e-12 else "b"
        assert y == pytest.approx([e + shift for e in (a if file == "a" else b).values()], abs=1e-12)
        seen.add((ln.get_label(), file))
    assert seen == {("reference", "a"), ("reference", "b"), ("lammps", "a"), ("lammps", "b")}
    plt.close(fig)


def test_every_line_is_drawn_in_its_sources_colour_and_marker():
    vals = lambda e: {"reference": e, "lammps": e + 1e-4, "liggghts": e - 1e-4}  # noqa: E731
    cases = [_collision(f"n[speed={v}]", "n.toml", vals(0.8), speed=v) for v in (0.1, 1.0, 10.0)]
    for f in ("o1.toml", "o2.toml"):
        for ang in (10.0, 40.0, 70.0):
            c = _collision(f"{f}[angle={ang}]", f, vals(0.5), model=("lsd", "spring_sliding"), angle=ang,
                           metric="tangential_restitution")
            for src, v in vals(100.0).items():
                c["sources"][src]["metrics"]["rebound_angular_velocity"] = v
            cases.append(c)
    series = [{"source": s, "t": [0, 1e-6, 2e-6], "delta": [0, 1e-6, 0], "fn": [0, 1.0, 0]}
              for s in ("reference", "reference-verlet", "lammps", "liggghts")]
    pack = _packing({"reference": 400, "lammps": 400, "liggghts": 400})
    figs = [f for _, f in report.suite_figures(_summary(cases))]
    figs += [report.packing_figure(pack), report.case_figure("n", series)]
    assert len(figs) == 6  # in vs out, speed, two angle plots, packing, case
    for fig in figs:
        lines = _source_lines(fig)
        assert {"reference", "lammps", "liggghts"} <= {ln.get_label() for ln in lines}
        for ln in lines:
            st = style(ln.get_label())
            assert to_hex(ln.get_color()) == st.colour, (fig, ln.get_label())
            if ln.get_marker() not in ("None", "", None):
                assert ln.get_marker() == st.marker
        plt.close(fig)
    # the fixed colours differ (the packing panels once drew the reference in matplotlib's first colour,
    # which is LAMMPS's)
    assert len({style(s).colour for s in ("reference", "lammps", "liggghts")}) == 3


@pytest.mark.parametrize("values", [[0.9, 0.9003, 0.9001], [1.0 - 1e-6, 1.0, 1.0 + 1e-6]])
def test_y_axes_carry_no_offset_and_a_tiny_spread_stays_small(values):
    """Engines 3e-4 apart on a restitution of 0.9 (matplotlib stretches that over the whole panel), and an
    elastic impact's 1e-6 (matplotlib labels its ticks with an offset, "1e-6 + 1")."""
    fig0, ax0 = plt.subplots()  # matplotlib's own range: the spread fills the panel
    ax0.plot([1, 2, 3], values)
    fig0.canvas.draw()
    assert (max(values) - min(values)) / (ax0.get_ylim()[1] - ax0.get_ylim()[0]) > 0.5
    default_offset = ax0.yaxis.get_offset_text().get_text()
    plots.plain_ticks(ax0)  # the tick rule alone, on matplotlib's range
    fig0.canvas.draw()
    assert ax0.yaxis.get_offset_text().get_text() == ""
    plt.close(fig0)
    cases = [_collision(f"c[speed={v}]", "c.toml", {"reference": e, "lammps": e}, speed=v)
             for v, e in zip((0.1, 1.0, 10.0), values)]
    fig = report.panel_grid(report.speed_panels(cases), ["reference", "lammps"], "speed", "restitution", "v", "e",
                            log_x=True)
    fig.canvas.draw()
    ax = fig.axes[0]
    assert ax.yaxis.get_offset_text().get_text() == ""
    if values[0] == 1.0 - 1e-6:
        assert default_offset != ""  # the case exercises the rule
    lo, hi = ax.get_ylim()
    # at least 5 % of the largest value (plots.MIN_REL_SPAN): the spread is under 1 % of the axis
    assert hi - lo >= 0.05 * max(values) and (max(values) - min(values)) / (hi - lo) < 0.01
    assert lo <= min(values) and hi >= max(values)
    # every tick label states its own value
    labelled = 0
    for tick in ax.yaxis.get_major_ticks():
        text = tick.label1.get_text().replace("\u2212", "-")
        if text and lo <= tick.get_loc() <= hi:
            assert float(text) == pytest.approx(tick.get_loc(), rel=1e-5, abs=1e-12)
            labelled += 1
    assert labelled >= 3
    plt.close(fig)


def test_the_contact_count_is_the_recorded_one_and_unknown_without_it():
    assert report.force_count(_forces(400)) == 400 and report.force_count(_forces(0)) == 0
    # a results.json from before force_distribution recorded n: the count is unknown, and nothing is drawn
    assert report.force_count({k: v for k, v in _forces(400).items() if k != "n"}) is None
    pack = _packing({"reference": 400, "lammps": 400})
    del pack["packing"]["lammps"]["forces"]["n"]
    fig = report.packing_figure(pack)
    a2 = fig.axes[1]
    assert [ln.get_label() for ln in a2.get_lines()] == ["reference"]
    assert "lammps: count unknown" in " ".join(t.get_text().replace("\n", " ") for t in a2.texts)
    plt.close(fig)


def test_p_of_f_is_drawn_only_from_enough_contacts():
    fig = report.packing_figure(_packing({"reference": 400, "lammps": 4}))
    a2 = fig.axes[1]
    assert [ln.get_label() for ln in a2.get_lines()] == ["reference"]
    text = " ".join(t.get_text().replace("\n", " ") for t in a2.texts)
    assert "lammps: 4 contact force(s)" in text and "50" in text
    plt.close(fig)
    fig = report.packing_figure(_packing({"reference": 4, "lammps": 4}))
    assert not fig.axes[1].get_lines() and fig.axes[1].texts  # nothing drawn, and the panel says why
    plt.close(fig)


def test_packing_panels_are_never_empty():
    # a column: no periodic box (no profile), four contacts, and an engine that did not run
    fig = report.packing_figure(_packing({"reference": 4, "lammps": 0}, profile=False,
                                         absent={"yade": "not expressible"}))
    for ax in fig.axes:
        text = " ".join(t.get_text().replace("\n", " ") for t in ax.texts)
        assert ax.get_lines() or text, ax.get_title()
        assert "no data from yade (not expressible)" in text
    prof, forces, ke = fig.axes
    assert not prof.get_lines() and "no periodic box" in " ".join(t.get_text().replace("\n", " ") for t in prof.texts)
    assert "lammps: no contact forces" in " ".join(t.get_text().replace("\n", " ") for t in forces.texts)
    assert {ln.get_label() for ln in ke.get_lines()} == {"reference", "lammps"}
    plt.close(fig)


def _overlap(a, b) -> float:
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return max(w, 0.0) * max(h, 0.0)


def test_titles_legends_and_panels_do_not_overlap():
    long = "a-rather-long-case-file-name-that-goes-on"
    cases = []
    for k in range(6):
        for ang in (10.0, 40.0, 70.0):
            cases.append(_collision(f"{long}-{k}[angle={ang}]", f"{long}-{k}.toml", {"reference": 0.5, "lammps": 0.5},
                                    model=("lsd", "spring_sliding (limit_force)"), angle=ang, spin=1500.0,
                                    metric="tangential_restitution"))
    fig = report.panel_grid(report.angle_panels(cases), ["reference", "lammps"], "angle", "tangential_restitution",
                            "incidence angle (°)", "tangential restitution")
    figs = [fig, report.packing_figure(_packing()), report.case_figure(long * 3, [
        {"source": "reference", "t": [0, 1e-6], "delta": [0, 1e-6], "fn": [0, 1.0]}])]
    for f in figs:
        f.canvas.draw()
        r = f.canvas.get_renderer()
        axes = [ax for ax in f.axes if ax.axison]
        titles = [ax.title.get_window_extent(r) for ax in axes if ax.get_title()]
        if f._suptitle is not None:
            titles.append(f._suptitle.get_window_extent(r))
        titles += [leg.get_window_extent(r) for leg in f.legends]
        assert len(titles) >= 3
        for i, a in enumerate(titles):
            for b in titles[i + 1:]:
                assert _overlap(a, b) == 0.0, (a, b)
            # a title lies on no panel (its own stands above it)
            for ax in axes:
                assert _overlap(a, ax.get_window_extent(r)) < 1.0, (a, ax.get_title())
        width, height = f.bbox.width, f.bbox.height
        for a in titles:
            assert a.x0 >= -1 and a.x1 <= width + 1 and a.y1 <= height + 1  # inside the figure
        plt.close(f)


# ----------------------------------------------------------------------------- the page


class _Text(HTMLParser):
    """The visible text of a page (no script, no style) and its tables' cells (tag attributes, text)."""

    def __init__(self):
        super().__init__()
        self.text, self.cells, self._skip, self._cell = [], [], 0, None

    def handle_starttag(self, tag, attrs):
        if tag in ("script", "style"):
            self._skip += 1
        if tag == "td":
            self._cell = [dict(attrs), ""]

    def handle_endtag(self, tag):
        if tag in ("script", "style"):
            self._skip -= 1
        if tag == "td" and self._cell is not None:
            self.cells.append(tuple(self._cell))
            self._cell = None

    def handle_data(self, data):
        if not self._skip:
            self.text.append(data)
            if self._cell is not None:
                self._cell[1] += data


def _parse(page: str) -> _Text:
    p = _Text()
    p.feed(page)
    return p


# a name the case-name rule lets through (letters, spaces, [ ] ( ) : / _ .) that markdown would read as a link
# and emphasis
HOSTILE = "[click me](https://evil.example/x) _em_ wall"


def _all_verdicts_summary():
    """One model, every verdict: lammps agrees on e, differs as expected on et, unexpectedly on E;
    liggghts is missing; a hostile case name and reason (from a user's case file, an engine's message)."""
    comps = [V.Comparison("lammps", "restitution", 0.8, 0.8, 0, 0, 1e-6, V.AGREE).as_dict(),
             V.Comparison("lammps", "tangential_restitution", 0.5, 0.49, 0.01, 0.01, 1e-6, V.EXPECTED,
                          "approximate mapping: a **regularised** slider <b>bold</b>", setting="tangential linear_nohistory").as_dict(),
             V.Comparison("lammps", "energy_dissipated", 1, 2, 1, 1, 1e-6, V.UNEXPECTED, f"no documented difference in {HOSTILE}").as_dict(),
             V.status_comparison("liggghts", V.MISSING, "liggghts is not installed").as_dict()]
    c = _collision(HOSTILE, "x.toml", {"reference": 0.8, "lammps": 0.8}, model=("lsd", "sliding"), comparisons=comps)
    c["settings"] = {"lammps": "hooke damping coeff_restitution tangential linear_nohistory"}
    c["status"] = "unexpected"
    n_e = _collision("other", "y.toml", {"reference": 0.8}, model=("kk", "none"),
                     comparisons=[V.status_comparison("lammps", V.NOT_EXPRESSIBLE, "no law").as_dict(),
                                  V.status_comparison("liggghts", V.FAILED, "crashed").as_dict()])
    pack = _packing()
    pack["case"] = HOSTILE + " pack"  # in the packings table's cells too
    s = _summary([c, n_e, pack])
    s["failed"] = 2
    return s


def _rendered_text(md: str) -> tuple[str, str]:
    """report.md as a markdown viewer shows it: (its HTML, its visible text)."""
    from markdown_it import MarkdownIt

    page = MarkdownIt("commonmark").enable("table").render(md)
    return page, "".join(_parse(page).text)


def test_markdown_is_rendered_and_raw_html_never_let_through():
    page = report.render_html(_all_verdicts_summary())
    assert page.count("<script>") == 1  # the page's own (plots-ok)
    assert "<b>bold</b>" not in page and "&lt;b&gt;bold&lt;/b&gt;" in page
    assert "<strong>differs unexpectedly</strong>" in page  # the report's own markdown is rendered
    # a reason is text, not markdown: shown as written
    assert "<strong>regularised</strong>" not in page and "a **regularised** slider" in "".join(_parse(page).text)
    assert "<h2>Traps</h2>" in page and "<code>tangential linear_nohistory</code>" in page


def test_a_case_name_is_never_a_link_or_emphasis():
    """Review finding: the name rule allows [ ] ( ) : / _, and the traps' and disagreements' case lists and the
    tables' cells put names into markdown unescaped — the name became <a href> and <em> in report.html."""
    from demcheck.case import check_name

    assert check_name("name", HOSTILE) == HOSTILE  # the real route: a case file may carry this name
    s = _all_verdicts_summary()
    page = report.render_html(s)
    assert "<a " not in page and "<em>" not in page and "evil.example/x" in page
    text = "".join(_parse(page).text)
    assert text.count(HOSTILE) >= 3  # traps, disagreements (markdown), cases (HTML), each literally
    md = report.render_markdown(s)
    html_md, text_md = _rendered_text(md)
    assert "<a " not in html_md and "<em>" not in html_md
    # literally in the traps' and disagreements' case lists, a reason, the cases' and the packings' table cells
    assert text_md.count(HOSTILE) >= 5, text_md
    assert "no documented difference in " + HOSTILE in text_md


def test_a_case_name_in_the_baseline_section_is_never_a_link():
    s = _all_verdicts_summary()
    s["baseline"] = {"path": "/tmp/_b_/x.json", "old": {"run_id": "r"}, "checked": 1, "unchanged": 0,
                     "regressions": 1, "counts": {"worse": 1, "moved": 0, "removed": 0, "better": 0},
                     "engines": {"lammps": {"old": "22 Jul 2025", "new": "[v](https://evil.example/y)"}},
                     "rows": [{"case": HOSTILE, "source": "lammps", "metric": "restitution", "old": 0.8, "new": 0.7,
                               "moved": 0.1, "tolerance": 1e-6, "old_verdict": "agree",
                               "new_verdict": "differs unexpectedly", "regression": True}]}
    html_md, text_md = _rendered_text(report.render_markdown(s))
    assert "<a " not in html_md and "<em>" not in html_md
    assert HOSTILE in text_md and "/tmp/_b_/x.json" in text_md and "[v](https://evil.example/y)" in text_md
    assert "<a " not in report.render_html(s)


@pytest.fixture(scope="module")
def hostile_run(tmp_path_factory):
    """A real verify run (the reference alone) of normal-hertz-wall.toml saved as ``a$\frac$b.toml`` under the
    hostile name: the review reproduced a ParseSyntaxException with it, exit 1 and no report.html."""
    tmp = tmp_path_factory.mktemp("hostile")
    text = (CASES / "suite" / "normal-hertz-wall.toml").read_text()
    text = re.sub(r'(?m)^name = ".*"$', f'name = "{HOSTILE}"', text, count=1)
    case = tmp / "a$\\frac$b.toml"
    case.write_text(text)
    s = suite.run_suite([case], tmp / "reports", suite.Options(engines=()), quiet=True, argv=["demcheck", "verify"]).to_json()
    return s, Path(s["report"])


def test_a_dollar_in_a_file_name_is_drawn_as_text_and_the_report_is_written(hostile_run):
    s, out = hostile_run
    assert len(s["cases"]) == 3 and (out / "report.html").exists()
    assert (out.parent / "latest").resolve() == out.resolve()
    page = (out / "report.html").read_text()
    assert "class='plot-error'" not in page and page.count('<img class="plot"') >= 2  # the speed panel, the curves
    titles = [t for t, _ in report.suite_figures(s)]
    assert titles == ["restitution in vs out", "restitution against impact speed"]
    # the panel's title carries the file's name as it is
    panels = report.speed_panels([c for c in s["cases"] if c.get("impact")])
    assert list(panels) == ["hertz / none wall (a$\\frac$b)"]
    fig = report.panel_grid(panels, ["reference"], "speed", "restitution", "v", "e", log_x=True)
    fig.canvas.draw()
    assert fig.axes[0].title.get_text().replace("\n", " ") == "hertz / none wall (a\\$\\frac\\$b)"  # no mathtext
    plt.close(fig)


def test_a_real_name_is_never_a_link_or_emphasis(hostile_run):
    _, out = hostile_run
    page = (out / "report.html").read_text()
    assert "<a " not in page and "<em>" not in page
    assert HOSTILE in "".join(_parse(page).text)
    html_md, text_md = _rendered_text((out / "report.md").read_text())
    assert "<a " not in html_md and "<em>" not in html_md and HOSTILE in text_md


@pytest.mark.parametrize("text", ["a$\\frac$b", "$x$", "cost $5 and $", "a\\$b$c"])
def test_user_text_never_reaches_mathtext(text):
    series = [{"source": "reference", "t": [0, 1e-6, 2e-6], "delta": [0, 1e-6, 0], "fn": [0, 1.0, 0]}]
    fig = report.case_figure(text, series)
    plots.note(fig.axes[0], f"no data from {text}")  # a wrapped text
    plots.note(fig.axes[1], text, centre=False)
    fig.canvas.draw()  # mathtext would raise here (or draw $x$ as an italic x)
    for t in (fig._suptitle, *fig.axes[0].texts, *fig.axes[1].texts):
        assert t._preprocess_math(t.get_text()) == (t.get_text().replace("\\$", "$"), False)  # drawn as text
        assert text in t.get_text().replace("\\$", "$").replace("\n", " ")
    plt.close(fig)


def test_a_plot_that_fails_leaves_a_note_and_the_report(tmp_path, monkeypatch):
    def broken(*a, **k):
        raise ValueError("Expected \\frac{num}{den}")

    s = _summary([_collision(f"c[speed={v}]", "c.toml", {"reference": 0.8 + v / 100}, speed=v) for v in (0.1, 1.0)])
    s["cases"][0]["series"] = [{"source": "reference", "t": [0, 1e-6], "delta": [0, 1e-6], "fn": [0, 1.0]}]
    monkeypatch.setattr(report.figures, "case_figure", broken)
    page = report.render_html(s)
    assert "the force curves of c[speed=0.1] could not be drawn (ValueError: Expected \\frac{num}{den})" in page
    assert page.count('<img class="plot"') == 2  # the suite plots still drawn
    monkeypatch.setattr(report.figures, "suite_figures", broken)
    s["cache"] = {"dir": str(tmp_path / "cache"), "hits": 0, "misses": 0}
    report.write_all(s, tmp_path / "run", tmp_path)
    page = (tmp_path / "run" / "report.html").read_text()
    assert "the suite plots could not be drawn" in page and (tmp_path / "latest").resolve() == tmp_path / "run"
    assert not list((tmp_path / "cache" / "plots").glob("*"))  # a failure is never cached


def test_an_interrupt_while_drawing_still_writes_the_page(tmp_path, monkeypatch):
    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(report.figures, "suite_figures", interrupted)
    s = _summary([_collision(f"c[speed={v}]", "c.toml", {"reference": 0.8}, speed=v) for v in (0.1, 1.0)])
    with pytest.raises(KeyboardInterrupt):
        report.write_all(s, tmp_path / "run", tmp_path)
    page = (tmp_path / "run" / "report.html").read_text()
    assert "No plots in this page: the run was interrupted" in page and "<h2>Cases</h2>" in page
    assert (tmp_path / "latest").resolve() == tmp_path / "run"


def test_matrix_cells_carry_their_verdicts_class():
    page = report.render_html(_all_verdicts_summary())
    matrix = page[page.index("<table class='matrix'>"):]
    matrix = matrix[:matrix.index("</table>")]
    cells = [(a.get("class", "").split(), t) for a, t in _parse(matrix).cells if "mark" in a.get("class", "")]
    want = {"✓": "v-agree", "≈": "v-expected", "✗": "v-unexpected", "missing": "v-missing", "n/e": "v-not-expressible",
            "FAIL": "v-failed", "·": "v-none"}
    assert {t for _, t in cells} == set(want)  # every verdict met, each in a cell
    for classes, t in cells:
        assert want[t] in classes and sum(c.startswith("v-") for c in classes) == 1, (classes, t)
    legend = page[page.index("<p class='legend'>"):]
    assert all(f"class='{c}'" in legend[:legend.index("</p>")] for c in want.values())


def _engine_words(engine: str) -> str:
    return "".join(p.read_text() for p in (ROOT / "src" / "demcheck" / "engines" / engine).glob("*.py"))


def test_traps_name_the_setting_of_each_expected_difference():
    entries = V.load_expected()
    assert entries and all(e.setting for e in entries)
    # each setting names what demcheck's own decks for that engine write (identifiers: words with _ or /)
    for e in entries:
        words = re.findall(r"[A-Za-z0-9]+(?:[_/][A-Za-z0-9]+)+", e.setting)
        assert words, e.setting
        for w in words:
            assert w in _engine_words(e.engine), (e.engine, w)
    # the shipped lammps entry, on a comparison of a results.json written before comparisons carried a setting
    lam = next(e for e in entries if e.engine == "lammps")
    old = V.Comparison("lammps", "tangential_restitution", 0.5, 0.49, 0.01, 0.01, 1e-6, V.EXPECTED,
                       f"{lam.reason} ({lam.source})").as_dict()
    del old["setting"]
    poured = V.Comparison("lammps", "solid_fraction (range)", 0.5, 0.55, 0, 0, 0.09, V.EXPECTED,
                          "outside the physical range").as_dict()
    c = _collision("k", "k.toml", {}, comparisons=[old, poured])
    found = report.traps(_summary([c]))
    assert [(t["engine"], t["settings"], t["source"]) for t in found] == [("lammps", [lam.setting], lam.source)]
    md = report.render_markdown(_summary([c]))
    traps = md[md.index("## Traps"):md.index("## Disagreements")]
    assert f"`{lam.setting}`" in traps and "physical range" not in traps


def _approximate(engine, metric, reason, setting):
    return V.Comparison(engine, metric, 1, 1.1, 0.1, 0.1, 1e-6, V.EXPECTED, "approximate mapping: " + reason,
                        setting=setting).as_dict()


def test_one_trap_per_setting_whatever_the_cases_numbers():
    """Review finding: a trap named the whole native configuration and was keyed by a reason carrying the
    case's numbers (gammat = 5.038e+08), so one setting was listed once per mass in a large suite."""
    why = "simple sliding friction as no_history with gammat = {:.4g} 1/s: a regularised slider near v_t = 0"
    cases = []
    for k, gammat in enumerate((5.038e8, 2.1e7, 9.9e9)):
        comps = [_approximate("liggghts", m, why.format(gammat), "tangential no_history")
                 for m in ("tangential_restitution", "rebound_angular_velocity")]
        comps.append(_approximate("liggghts", "energy_dissipated", f"hertz + history: ηt = {0.9 + k / 100:.4f} ηn",
                                  "model hertz tangential history"))
        comps.append(_approximate("lammps", "tangential_restitution", why.format(gammat), "tangential linear_nohistory"))
        c = _collision(f"s{k}", f"s{k}.toml", {}, comparisons=comps)
        c["settings"] = {"liggghts": f"model hooke/stiffness tangential no_history gammat={gammat}"}
        cases.append(c)
    found = report.traps(_summary(cases))
    assert [(t["engine"], t["settings"], t["comparisons"], len(t["cases"])) for t in found] == [
        ("liggghts", ["tangential no_history"], 6, 3),
        ("lammps", ["tangential linear_nohistory"], 3, 3),
        ("liggghts", ["model hertz tangential history"], 3, 3)]
    assert found[0]["reason"] == why.replace("{:.4g}", "…")
    assert found[2]["reason"] == "hertz + history: ηt = … ηn"
    md = report.render_markdown(_summary(cases))
    traps = md[md.index("## Traps"):md.index("## Disagreements")]
    assert traps.count("`tangential no_history`") == 1 and "5.038e+08" not in traps
    # a comparison whose mapping has two reasons names both keywords
    two = _approximate("lammps", "tangential_restitution", "limit_damping …; one friction coefficient only",
                       "limit_damping; tangential linear_nohistory mu")
    assert report.traps(_summary([_collision("t", "t.toml", {}, comparisons=[two])]))[0]["settings"] == [
        "limit_damping", "tangential linear_nohistory mu"]
    # a results.json from before comparisons carried a setting: the case's native configuration, numbers out
    old = _approximate("liggghts", "tangential_restitution", why.format(1e8), "")
    del old["setting"]
    c = _collision("o", "o.toml", {}, comparisons=[old])
    c["settings"] = {"liggghts": "model hooke/stiffness tangential no_history gammat=1e+08"}
    assert report.traps(_summary([c]))[0]["settings"] == ["model hooke/stiffness tangential no_history gammat=…"]


def _mappings():
    """Every mapping of the cases under cases/, and of every registered normal and tangential law on the mapping
    table's glass pair (docs/models.md), with μk = μs and μk ≠ μs: (engine, Mapping)."""
    import copy
    import tomllib

    from demcheck.case import apply_overrides, expand, from_dict
    from demcheck.engines import mapping, registry
    from demcheck.laws import normal, tangential
    from demcheck.laws.model import resolve

    out = []
    for f in sorted(CASES.rglob("*.toml")):
        if "optin" in f.parts:
            continue
        try:
            cases = expand(f)
        except ConfigError:
            continue
        for case in cases:
            if case.kind != "packing":
                out += [(e, mapping.contact_mapping(case, e)) for e in registry.names()]
    for nid in normal.REGISTRY:
        for tid in tangential.REGISTRY:
            for extra in ({}, {"friction_kinetic": 0.2}):
                params = {**normal.REGISTRY[nid].example, **tangential.REGISTRY[tid].example, **extra}
                params.pop("friction", None)
                sets = [f"contact.normal={nid}", f"contact.tangential={tid}"]
                sets += [f"contact.{k}={mapping._toml(v)}" for k, v in params.items()]
                try:
                    case = from_dict(apply_overrides(copy.deepcopy(tomllib.loads(mapping._TABLE_CASE)), sets))
                    model = resolve(case)
                except ConfigError:
                    continue
                out += [(e, mapping.map_model(model, e, case.contact.params)) for e in registry.names()]
    return out


def test_every_approximate_reason_names_its_native_keyword():
    """Each reason of an approximate mapping names the setting it is about, in its engine's own words (what the
    traps show): never a reason without one, never a word the engine's package does not use."""
    seen = set()
    for engine, mp in _mappings():
        if mp.fidelity != APPROXIMATE:
            continue
        for r in mp.reasons:
            assert mp.keywords.get(r), (engine, r)
            seen.add((engine, mp.keywords[r]))
        assert V.mapping_setting(mp) == "; ".join(dict.fromkeys(mp.keywords[r] for r in mp.reasons))
    for engine, keyword in seen:
        for w in re.findall(r"[A-Za-z0-9_/]+", keyword):
            assert w in _engine_words(engine), (engine, w)
    assert {("lammps", "tangential linear_nohistory"), ("liggghts", "tangential no_history"),
            ("liggghts", "model hertz tangential history"), ("liggghts", "coefficientFriction"),
            ("lammps", "tangential linear_history mu"), ("kratos", "DEM_D_Hertz_viscous_Coulomb"),
            ("yade", "Law2_ScGeom_ViscElPhys_Basic")} <= seen


@pytest.mark.parametrize("value,message", [(3, "setting = 3: must be a non-empty string"),
                                           ("  ", "setting = '  ': must be a non-empty string")])
def test_a_bad_setting_in_the_expected_differences_is_one_clear_line(tmp_path, value, message):
    path = tmp_path / "expected.toml"
    path.write_text(f'[[difference]]\nengine = "lammps"\nversions = ["*"]\nreason = "x"\nsetting = {json.dumps(value)}\n')
    with pytest.raises(ConfigError) as exc:
        V.load_expected(path)
    assert message in str(exc.value) and len(str(exc.value).splitlines()) == 1


@pytest.mark.parametrize("value", ["[]", "[1]", "3"])
def test_a_bad_model_pattern_in_the_expected_differences_is_one_clear_line(tmp_path, value):
    path = tmp_path / "expected.toml"
    path.write_text(f'[[difference]]\nengine = "lammps"\nversions = ["*"]\nreason = "x"\ntangential = {value}\n')
    with pytest.raises(ConfigError) as exc:
        V.load_expected(path)
    assert "tangential" in str(exc.value) and len(str(exc.value).splitlines()) == 1


def test_the_expected_differences_fit_their_settings():
    """Review finding: the LIGGGHTS entry ("with tangential history") matched every tangential law, simple
    sliding's no_history too; Yade's kinematic entry named ViscElPhys's law alone, though it matches MindlinPhys."""
    from demcheck.engines import mapping

    lig = next(e for e in V.load_expected() if e.engine == "liggghts")
    history = {r["tangential"] for r in mapping.table() if "tangential history" in r["liggghts_config"]}
    assert history == {"spring_sliding", "lsd_sliding", "ddt", "tti"} and set(lig.tangential) == history
    for tid, want in (("tti", True), ("lsd_sliding", True), ("sliding", False), ("viscous_sliding", False)):
        model = {"normal": "lsd", "tangential": tid}
        assert lig.matches("liggghts", "LIGGGHTS-PUBLIC 3.8.0", model, "tangential_restitution") is want, tid
    yade = next(e for e in V.load_expected() if e.engine == "yade" and "ScGeom" in e.setting)
    assert "Law2_ScGeom_ViscElPhys_Basic" in yade.setting and "Law2_ScGeom_MindlinPhys_Mindlin" in yade.setting
    assert yade.tangential == "*" and yade.normal == "*"


def test_the_verdicts_carry_the_setting_and_the_suite_records_the_mapping():
    from demcheck.case import expand
    from demcheck.engines.mapping import contact_mapping

    rule = V.ExpectedDifference(engine="lammps", versions=("*",), reason="kinematic rules", source="docs",
                                setting="pair_style granular")
    model = {"normal": "lsd", "tangential": "spring_sliding"}
    scales = {"impact_energy": 1.0, "spin": 1.0}

    def judge(value, fidelity, expected=(), **kw):  # the engine meets its twin; the seed's verlet run is exact
        return V.judge_engine("lammps", "22 Jul 2025", model, "tangential_restitution", value, 0.5, value, 0.5,
                              fidelity, ["why"], scales, V.Tolerances(), list(expected), **kw)

    c = judge(0.52, "exact", [rule])
    assert (c.verdict, c.setting) == (V.EXPECTED, "pair_style granular") and c.as_dict()["setting"] == c.setting
    c = judge(0.5, "approximate", setting="mindlin")
    assert (c.verdict, c.setting) == (V.AGREE, "")  # an agreement names no trap
    # what the suite passes for oblique-sliding: the keyword of the mapping's reason, not its whole configuration
    case = expand(CASES / "suite" / "oblique-sliding.toml")[0]
    mp = contact_mapping(case, "lammps")
    c = judge(0.52, mp.fidelity, setting=V.mapping_setting(mp))
    assert (c.verdict, c.setting) == (V.EXPECTED, "tangential linear_nohistory")
    entry = CaseResult(case.name)
    found = {e: {"found": True} for e in ("lammps", "yade")}
    for planned in plan(case, ("lammps", "yade"), found):
        entry.note_plan(planned)
    assert entry.settings == {"lammps": "hooke damping coeff_restitution tangential linear_nohistory"}
    assert entry.sources["yade"].status == "not expressible"


# ----------------------------------------------------------------------------- panels: pair or wall, lines


def test_pair_or_wall_is_the_cases_walls_not_its_name():
    cases = [_collision(f"wallace-pair[speed={v}]", "wallace-pair.toml", {"reference": 0.8}, speed=v, walls=0)
             for v in (0.1, 1.0)]
    cases += [_collision(f"x[speed={v}]", "x.toml", {"reference": 0.8}, speed=v, walls=1) for v in (0.1, 1.0)]
    old = [_collision(f"o[speed={v}]", "o.toml", {"reference": 0.8}, speed=v) for v in (0.1, 1.0)]
    for c in old:
        del c["walls"]  # a results.json from before entries carried it: neither said
    assert sorted(report.speed_panels(cases + old)) == ["hertz / none (o)", "hertz / none pair (wallace-pair)",
                                                        "hertz / none wall (x)"]


def test_a_line_per_value_of_a_files_other_variant_labels():
    """Review finding: the panels grouped by file alone, so a file varying a second key joined its values in
    one line. normal-tti-wall varies the speed and limit_force; a file may vary a restitution with the speed."""
    cases = []
    for e_in in (0.5, 0.9):
        for v in (0.1, 1.0, 10.0):
            cases.append(_collision(f"f[speed={v:g},restitution={e_in:g}]", "f.toml", {"reference": e_in}, speed=v,
                                    e_in=e_in, variant=[("speed", f"{v:g}"), ("restitution", f"{e_in:g}")]))
    panels = report.speed_panels(cases)
    assert sorted(panels) == ["hertz / none wall (f, restitution=0.5)", "hertz / none wall (f, restitution=0.9)"]
    assert all(len({c.impact["restitution_input"] for c in cs}) == 1 and len(cs) == 3 for cs in panels.values())
    # a label that sets x itself (a velocity setting the angle; a group zipping angle and spin) is the line
    vel = [_collision(f"g[velocity=[{a}]]", "g.toml", {"reference": 0.5}, model=("lsd", "tti"), angle=a, speed=5 + a,
                      variant=[("velocity", f"[{a}, 0.0, -5.0]")]) for a in (5.0, 30.0, 60.0)]
    zipped = [_collision(f"h[g={k}]", "h.toml", {"reference": 0.5}, model=("lsd", "tti"), angle=a, spin=10.0 * k,
                         variant=[("g", str(k))]) for k, a in enumerate((5.0, 30.0, 60.0))]
    both = [_collision(f"o[angle={a:g},spin={w:g}]", "o.toml", {"reference": 0.5}, model=("lsd", "tti"), angle=a,
                       spin=w, variant=[("angle", f"{a:g}"), ("spin", f"{w:g}")]) for a in (5.0, 30.0) for w in (0.0, 1500.0)]
    panels = report.angle_panels(vel + zipped + both)
    assert sorted((t, len(cs)) for t, cs in panels.items()) == [
        ("lsd / tti (g)", 3), ("lsd / tti (h)", 3), ("lsd / tti (o, spin=0)", 2), ("lsd / tti (o, spin=1500)", 2)]


def test_the_suite_records_walls_and_variant_labels():
    from demcheck.case import expand

    f = CASES / "suite" / "normal-tti-wall.toml"
    names = [c.name for c in expand(f)]
    assert suite.variant_labels(names[1], f) == [["speed", "0.1"], ["limit_force", "true"]]
    g = next(CASES.rglob("chung-ooi-7-copper-tti.toml"))  # a [variants.GROUP]
    assert [suite.variant_labels(c.name, g) for c in expand(g)] == [[["spin", "1"]], [["spin", "10"]]]
    assert suite.variant_labels("glass", CASES / "glass-pair.toml") == []


def test_the_packing_panels_carry_no_second_title_and_the_table_its_fabric():
    fig = report.packing_figure(_packing())
    assert fig._suptitle is None  # report.html heads the plot with an h3 of its own
    plt.close(fig)
    pack = _packing()
    for src, phi in (("reference", 0.3312), ("lammps", 0.3345)):
        pack["sources"][src]["metrics"]["fabric_zz"] = phi
    pack["comparisons"] = [V.Comparison("lammps", "fabric_zz", 0.3345, 0.3312, 0.0021, 0.0021, 0.021, V.AGREE).as_dict()]
    md = "\n".join(report._md_packings(_summary([pack])))
    assert "φ_zz" in md.splitlines()[4]
    rows = {line.split(" | ")[1]: line for line in md.splitlines() if line.startswith("| pack |")}
    assert "| 0.3312 |" in rows["reference"] and "| 0.3345; 0.0021 (0.0210) agree |" in rows["lammps"]
    page = report.render_html(_summary([pack]))
    assert page.count("<h3>packing pack</h3>") == 1


# ----------------------------------------------------------------------------- with the engines, in a browser


def _chromium():
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


# measured in the page after load: every <details> opened first (a closed one lays its plots out at 0 × 0)
_LAYOUT = """
<script>
window.addEventListener('load', function () {
  document.querySelectorAll('details').forEach(function (d) { d.open = true; });
  function box(e) { var r = e.getBoundingClientRect();
    return {tag: e.tagName, text: e.textContent.slice(0, 60), x: r.left + scrollX, y: r.top + scrollY,
            w: r.width, h: r.height}; }
  var out = {width: document.documentElement.clientWidth, cells: {}, text: document.body.innerText,
             headings: [].map.call(document.querySelectorAll('h1,h2,h3'), box),
             images: [].map.call(document.querySelectorAll('img.plot'), function (i) {
               var b = box(i); b.natural = i.naturalWidth; return b; }),
             traps: []};
  ['v-agree', 'v-expected', 'v-unexpected', 'v-failed', 'v-not-expressible', 'v-missing'].forEach(function (c) {
    var e = document.querySelector('table.matrix td.' + c);
    if (e) out.cells[c] = getComputedStyle(e).backgroundColor;
  });
  var h = [].filter.call(document.querySelectorAll('h2'), function (e) { return e.textContent === 'Traps'; })[0];
  for (var e = h && h.nextElementSibling; e && e.tagName !== 'H2'; e = e.nextElementSibling)
    [].forEach.call(e.querySelectorAll('code'), function (c) { out.traps.push(c.textContent); });
  out.plots = +document.body.getAttribute('data-plots');
  out.plots_ok = +document.body.getAttribute('data-plots-ok');
  document.body.setAttribute('data-layout', JSON.stringify(out));
});
</script>
"""


def _layout(page: Path, tmp_path: Path) -> dict:
    """The page as headless Chromium lays it out (the measuring script added to a copy)."""
    probe = tmp_path / f"probe-{page.parent.name}.html"
    probe.write_text(page.read_text().replace("</body>", _LAYOUT + "</body>"))
    browser = _chromium()
    assert browser, "chromium is not installed (scripts/install-browser.sh)"
    proc = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1400,3000",
                           "--virtual-time-budget=5000", "--dump-dom", probe.as_uri()],
                          capture_output=True, text=True, timeout=180)
    m = re.search(r'data-layout="([^"]*)"', proc.stdout)
    assert m, proc.stderr[-2000:]
    probe.unlink()
    return json.loads(htmllib.unescape(m.group(1)))


def _rgb(css: str) -> tuple:
    return tuple(int(v) for v in re.findall(r"\d+", css)[:3])


def _boxes_overlap(a, b) -> bool:
    return min(a["x"] + a["w"], b["x"] + b["w"]) > max(a["x"], b["x"]) and \
        min(a["y"] + a["h"], b["y"] + b["h"]) > max(a["y"], b["y"])


@pytest.mark.browser
def test_the_matrix_colours_in_a_browser(tmp_path):
    """Every verdict's cell, as the browser computes its background: green, amber, red, grey — by the order of
    the colour channels, not by exact values."""
    page = tmp_path / "r" / "report.html"
    page.parent.mkdir()
    page.write_text(report.render_html(_all_verdicts_summary()))
    cells = {k: _rgb(v) for k, v in _layout(page, tmp_path)["cells"].items()}
    assert set(cells) == set(report.VERDICT_CLASS.values())
    r, g, b = cells["v-agree"]
    assert g > r and g > b  # green
    r, g, b = cells["v-expected"]
    assert r > b + 60 and g > b + 60  # amber: red and green over blue
    for c in ("v-unexpected", "v-failed"):
        r, g, b = cells[c]
        assert r > g + 60 and r > b + 60  # red
    for c in ("v-not-expressible", "v-missing"):
        assert max(cells[c]) - min(cells[c]) <= 8 and cells[c][0] < 250  # grey
    groups = {cells["v-agree"], cells["v-expected"], cells["v-unexpected"], cells["v-not-expressible"]}
    assert len(groups) == 4


@pytest.fixture(scope="module")
def engine_report(tmp_path_factory):
    """A small real run: LAMMPS and LIGGGHTS on a normal impact at three speeds, two oblique files (an
    approximate mapping in both engines; LAMMPS's kinematic rules, an expected difference), a model LAMMPS
    cannot express, and the column packing (four contacts)."""
    tmp = tmp_path_factory.mktemp("engine-report")
    files = [CASES / "suite" / "normal-hertz-wall.toml", CASES / "suite" / "oblique-sliding.toml",
             CASES / "suite" / "oblique-spring-sliding.toml", CASES / "hls-constant-pair.toml",
             CASES / "packing" / "column-lsd.toml"]
    opts = suite.Options(engines=("lammps", "liggghts"), jobs=2, cache=Cache(tmp / "cache"))
    s = suite.run_suite(files, tmp / "reports", opts, quiet=True, argv=["demcheck", "verify"]).to_json()
    return s, Path(s["report"])


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_a_real_run_names_its_traps(engine_report):
    """The real path (review finding: the suite never passed a setting, so the traps read only the case's
    whole native configuration): run_case → judge_engine(setting=the mapping's keywords) → results.json."""
    s, out = engine_report
    assert s["failed"] == 0
    md = (out / "report.md").read_text()
    traps = md[md.index("## Traps"):md.index("## Disagreements")]
    lam = next(e for e in V.load_expected() if e.engine == "lammps")
    assert f"**lammps** — `{lam.setting}` (expected difference)" in traps  # oblique-spring-sliding
    # simple sliding's approximate mappings, by the keyword each is about — once each
    assert traps.count("**liggghts** — `tangential no_history` (approximate mapping)") == 1
    assert "hooke/stiffness" not in traps and "coeff_restitution" not in traps  # not the whole configuration
    data = json.loads((out / "results.json").read_text())
    sliding = next(c for c in data["cases"] if c["case"].startswith("suite-sliding"))
    assert set(sliding["settings"]) == {"lammps", "liggghts"}  # the whole configurations are kept too
    documented = {f"{e.reason} ({e.source})": e.setting for e in V.load_expected()}
    seen = set()
    for c in data["cases"]:
        for k in c["comparisons"]:
            if k["verdict"] != V.EXPECTED or k["source"] not in ("lammps", "liggghts"):
                continue
            if k["reason"].startswith(report.APPROXIMATE):
                seen.add((k["source"], k["setting"]))
            else:
                assert k["setting"] == documented[k["reason"]], k
    assert seen == {("lammps", "tangential linear_nohistory"), ("liggghts", "tangential no_history")}


@pytest.mark.browser
@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_the_report_lays_out_in_headless_chromium(engine_report, tmp_path):
    _, out = engine_report
    page = out / "report.html"
    lay = _layout(page, tmp_path)
    heads = lay["headings"]
    assert {h["text"] for h in heads} >= {"Agreement matrix", "Traps", "Suite plots", "Cases"}
    for i, a in enumerate(heads):
        assert a["w"] > 0 and a["h"] > 0, a
        for b in heads[i + 1:]:
            assert not _boxes_overlap(a, b), (a, b)
    imgs = lay["images"]
    assert len(imgs) >= 6  # in vs out, speed, two angle plots, the packing, case panels
    for im in imgs:
        assert im["natural"] > 0 and im["w"] > 0 and im["h"] > 0, im
        assert im["x"] >= 0 and im["x"] + im["w"] <= lay["width"] + 1, im  # within the page's width
        for h in heads:
            assert not _boxes_overlap(im, h), (im, h)
    cells = {k: _rgb(v) for k, v in lay["cells"].items()}
    assert {"v-agree", "v-expected", "v-not-expressible"} <= set(cells)  # HLS in LAMMPS: not expressible
    assert len(set(cells.values())) == len(cells)  # each verdict its own background
    assert "**" not in lay["text"]
    assert any("pair_style granular" in t for t in lay["traps"]) and "tangential no_history" in lay["traps"]
    # every plot decoded (the page's own script sets data-plots-ok once they have)
    assert lay["plots_ok"] == lay["plots"] == len(imgs)
