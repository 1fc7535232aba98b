"""The HTML report reads at a glance (issue 17, item 10): each source in its own colour in every panel, no
offset tick labels, one line per case file, no empty packing panel and no P(f) from a handful of contacts, no
overlapping titles, markdown rendered (and raw HTML never let through), the matrix coloured by verdict, and a
traps section naming the engine setting behind each expected difference — checked on the figures themselves,
and on the page as headless Chromium lays it out (layout, not pixels)."""

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
               metric="restitution", comparisons=()):
    """A collision entry as suite.run_case writes it: ``values`` {source: value of ``metric``}."""
    return {"case": case, "file": file, "kind": "collision", "status": "ok",
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
    data = {s: {"ke": [(0.01 * k, 10.0 ** -k) for k in range(8)], "forces": _forces(n, seed=k) if n else {"x": [], "p": []},
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


@pytest.mark.parametrize("n", [4, 16, 49, 50, 400, 1234])
def test_the_contact_count_is_read_off_a_histogram(n):
    # the histogram of n forces holds n of them (a recorded count wins)
    assert report.force_count(_forces(n, seed=n)) == n
    assert report.force_count({**_forces(n), "n": 7}) == 7
    assert report.force_count({"x": [], "p": []}) == 0


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


def _all_verdicts_summary():
    """One model, every verdict: lammps agrees on e, differs as expected on et, unexpectedly on E;
    liggghts is missing; a hostile case name and reason (from a user's case file)."""
    hostile = '<script>alert("x")</script>'
    comps = [V.Comparison("lammps", "restitution", 0.8, 0.8, 0, 0, 1e-6, V.AGREE).as_dict(),
             V.Comparison("lammps", "tangential_restitution", 0.5, 0.49, 0.01, 0.01, 1e-6, V.EXPECTED,
                          "approximate mapping: a **regularised** slider <b>bold</b>").as_dict(),
             V.Comparison("lammps", "energy_dissipated", 1, 2, 1, 1, 1e-6, V.UNEXPECTED, "no documented difference").as_dict(),
             V.status_comparison("liggghts", V.MISSING, "liggghts is not installed").as_dict()]
    c = _collision(hostile, "x.toml", {"reference": 0.8, "lammps": 0.8}, model=("lsd", "sliding"), comparisons=comps)
    c["settings"] = {"lammps": "hooke damping coeff_restitution tangential linear_nohistory"}
    c["status"] = "unexpected"
    n_e = _collision("other", "y.toml", {"reference": 0.8}, model=("kk", "none"),
                     comparisons=[V.status_comparison("lammps", V.NOT_EXPRESSIBLE, "no law").as_dict(),
                                  V.status_comparison("liggghts", V.FAILED, "crashed").as_dict()])
    s = _summary([c, n_e])
    s["failed"] = 2
    return s


def test_markdown_is_rendered_and_raw_html_never_let_through():
    page = report.render_html(_all_verdicts_summary())
    assert page.count("<script>") == 1  # the page's own (plots-ok), not the case name's
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in page and "<b>bold</b>" not in page
    text = "".join(_parse(page).text)
    assert "**" not in text
    assert '<script>alert("x")</script>' in text  # shown as text
    assert "<strong>differs unexpectedly</strong>" in page and "<strong>regularised</strong>" in page
    assert "<h2>Traps</h2>" in page and "<code>hooke damping coeff_restitution tangential linear_nohistory</code>" in page


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


def test_traps_name_the_setting_of_each_expected_difference():
    entries = V.load_expected()
    assert entries and all(e.setting for e in entries)
    # each setting names what demcheck's own decks for that engine write (identifiers: words with _ or /)
    for e in entries:
        package = "".join(p.read_text() for p in (ROOT / "src" / "demcheck" / "engines" / e.engine).glob("*.py"))
        words = re.findall(r"[A-Za-z0-9]+(?:[_/][A-Za-z0-9]+)+", e.setting)
        assert words, e.setting
        for w in words:
            assert w in package, (e.engine, w)
    # the shipped lammps entry, on a comparison of a results.json written before comparisons carried a setting
    lam = next(e for e in entries if e.engine == "lammps")
    old = V.Comparison("lammps", "tangential_restitution", 0.5, 0.49, 0.01, 0.01, 1e-6, V.EXPECTED,
                       f"{lam.reason} ({lam.source})").as_dict()
    del old["setting"]
    kratos = [V.Comparison("kratos", m, 1, 1.1, 0.1, 0.1, 1e-6, V.EXPECTED,
                           "approximate mapping: the force is held at >= 0").as_dict()
              for m in ("restitution", "contact_time")]
    poured = V.Comparison("lammps", "solid_fraction (range)", 0.5, 0.55, 0, 0, 0.09, V.EXPECTED,
                          "outside the physical range").as_dict()
    c1 = _collision("k1", "k.toml", {}, comparisons=kratos)
    c1["settings"] = {"kratos": "DEM_D_Linear_viscous_Coulomb E*=1.80578e+09 DAMPING_GAMMA=0.0335184 no friction"}
    c2 = _collision("k2", "k.toml", {}, comparisons=kratos + [old, poured])
    c2["settings"] = {"kratos": "DEM_D_Linear_viscous_Coulomb E*=3.2e+10 DAMPING_GAMMA=0.1 no friction"}
    found = report.traps(_summary([c1, c2]))
    assert [(t["engine"], t["comparisons"], len(t["cases"])) for t in found] == [("kratos", 4, 2), ("lammps", 1, 1)]
    assert found[0]["settings"] == ["DEM_D_Linear_viscous_Coulomb E*=… DAMPING_GAMMA=… no friction"]
    assert found[1]["settings"] == [lam.setting] and found[1]["source"] == lam.source
    md = report.render_markdown(_summary([c1, c2]))
    traps = md[md.index("## Traps"):md.index("## Disagreements")]
    assert f"`{lam.setting}`" in traps and "physical range" not in traps


@pytest.mark.parametrize("value,message", [(3, "setting = 3: must be a non-empty string"),
                                           ("  ", "setting = '  ': must be a non-empty string")])
def test_a_bad_setting_in_the_expected_differences_is_one_clear_line(tmp_path, value, message):
    path = tmp_path / "expected.toml"
    path.write_text(f'[[difference]]\nengine = "lammps"\nversions = ["*"]\nreason = "x"\nsetting = {json.dumps(value)}\n')
    with pytest.raises(ConfigError) as exc:
        V.load_expected(path)
    assert message in str(exc.value) and len(str(exc.value).splitlines()) == 1


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
    c = judge(0.52, "approximate", setting="mindlin")
    assert (c.verdict, c.setting) == (V.EXPECTED, "mindlin")
    c = judge(0.5, "approximate", setting="mindlin")
    assert (c.verdict, c.setting) == (V.AGREE, "")  # an agreement names no trap
    # the mapping's native configuration, as docs/models.md's table gives it for lsd / sliding
    case = expand(CASES / "suite" / "oblique-sliding.toml")[0]
    entry, comps = {"sources": {}}, []
    found = {e: {"found": True} for e in ("lammps", "yade")}
    for e in ("lammps", "yade"):
        V.unavailable(entry, comps, e, contact_mapping(case, e), found)
    assert entry["settings"] == {"lammps": "hooke damping coeff_restitution tangential linear_nohistory"}
    assert entry["sources"]["yade"]["status"] == "not expressible"


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
    s = suite.run_suite(files, tmp / "reports", opts, quiet=True, argv=["demcheck", "verify"])
    return s, Path(s["report"])


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_a_real_run_names_its_traps(engine_report):
    s, out = engine_report
    assert s["failed"] == 0
    md = (out / "report.md").read_text()
    traps = md[md.index("## Traps"):md.index("## Disagreements")]
    lam = next(e for e in V.load_expected() if e.engine == "lammps")
    assert f"**lammps** — `{lam.setting}` (expected difference)" in traps  # oblique-spring-sliding
    # the approximate mappings of simple sliding, by the setting each engine runs (docs/models.md's table)
    assert "**lammps** — `hooke damping coeff_restitution tangential linear_nohistory` (approximate mapping)" in traps
    assert "**liggghts** — `model hooke/stiffness tangential no_history` (approximate mapping)" in traps
    data = json.loads((out / "results.json").read_text())  # the settings are kept for demcheck diff and others
    sliding = next(c for c in data["cases"] if c["case"].startswith("suite-sliding"))
    assert set(sliding["settings"]) == {"lammps", "liggghts"}


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
    assert any("pair_style granular" in t for t in lay["traps"]) and any("linear_nohistory" in t for t in lay["traps"])
    # and a screenshot at the window's size: the page renders (its pixels are not compared)
    shot = tmp_path / "report.png"
    subprocess.run([_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1400,3000",
                    f"--screenshot={shot}", page.as_uri()], capture_output=True, timeout=180)
    head = shot.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(head[16:20], "big") == 1400
    assert int.from_bytes(head[20:24], "big") == 3000
