"""The report's figures: per-case force panels, the suite's speed and angle panels, a packing's panels and a
validation's curves, drawn with matplotlib as inline PNGs (base64), each cached by its content (PLOT_CACHE)."""

from __future__ import annotations

import base64
import html
import io
import logging
import math
from collections import defaultdict
from pathlib import Path

from ...io import number, plain, write_text
from ..records import CaseResult, Summary
from ..styles import engine_sources
from .matrix import _model


def validation_plots(summary: Summary) -> list[tuple[str, str]]:
    """One panel per case file and quantity, drawn like the papers' figures: each source a line over the
    benchmark's axis, the paper's points over them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import plots

    out = []
    val = Summary.of(summary).validation
    for line in val.series if val else []:
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
# what a plot draws, in every plot-cache key: raise it when a plot changes, so that no stale PNG is reused
PLOT_VERSION = 3
# P(f/⟨f⟩) is drawn for a source with at least this many contact forces: a histogram of a handful (a column
# of five spheres has four) shows the few forces' values, not a distribution
MIN_CONTACTS = 50


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


def draw_ahead(entry: CaseResult, plot_dir: Path, panels: bool) -> None:
    """Draw a finished case's report panels into the plot cache at ``plot_dir`` where the case ran (a worker of
    the local cluster, beside the other cases), for the report to read: a packing's panels, and a collision's force
    curves when ``panels``. Only the cost moves — the report draws whatever is not there; a failure here is the
    report's to meet and say, never the case's."""
    saved = PLOT_CACHE["dir"]
    PLOT_CACHE["dir"] = plot_dir
    try:
        if entry.kind == "packing":
            if entry.packing:
                packing_plots(entry)
        elif panels:
            case_panels(entry)
    except Exception:  # noqa: BLE001 - drawn again by the report, which says what failed
        import matplotlib.pyplot as plt

        plt.close("all")
    finally:
        PLOT_CACHE["dir"] = saved


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


def case_panels(entry: CaseResult) -> str | None:
    """Force–overlap loop and force–time curve of one case, one line per source."""
    entry = CaseResult.from_json(entry)
    series = entry.series
    if not series:
        return None
    return _cached({"case": entry.case, "series": series, "v": PLOT_VERSION},
                   lambda: _png(case_figure(entry.case, series)), _png_ok)


def case_figure(name, series):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import plots

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


def suite_plots(summary: Summary) -> list[tuple[str, str]]:
    """Restitution in vs out; restitution against impact speed; tangential restitution and rebound spin
    against incidence angle — each per model and source."""
    import json

    key = [(c.case, c.file, _model(c), c.impact, c.walls, c.variant, {s: v.metrics for s, v in c.sources.items()})
           for c in summary.cases]
    text = _cached({"suite": key, "v": PLOT_VERSION}, lambda: json.dumps(_suite_plots(summary)), _plot_list_ok)
    return [tuple(x) for x in json.loads(text)]


def _suite_plots(summary: Summary) -> list[tuple[str, str]]:
    return [(title, _png(fig)) for title, fig in suite_figures(summary)]


def _kind(c: CaseResult) -> str:
    """A wall impact or a pair, by the case's number of walls (never its name); "" when the entry does not say
    (a results.json from before entries carried it)."""
    walls = c.walls
    return "" if walls is None else "wall" if walls else "pair"


def _lines(cases: list[CaseResult], x_key: str) -> dict:
    """The cases of each file split into lines along ``x_key``: a file's variant labels (``CaseResult.variant``)
    other than those that set x keep cases apart — a file varying the speed and limit_force draws a line per
    limit_force. A label sets x when, within the file, its texts and the x values go one to one (``speed``
    for impact.speed, ``velocity`` for a particle's velocity that sets the incidence angle, a group zipping
    x with other keys). {(file, ((key, text), …)): cases}; the labels are None for a file whose entries carry
    none (a file without variants, a results.json from before entries carried them)."""
    by_file = defaultdict(list)
    for c in cases:
        by_file[c.file or c.case].append(c)
    out = {}
    for file, cs in by_file.items():
        keys = [k for k, _ in cs[0].variant or []]
        labelled = bool(keys) and all([k for k, _ in c.variant or []] == keys for c in cs)
        keep = []
        for i in range(len(keys) if labelled else 0):
            pairs = {(c.variant[i][1], round(float(c.impact[x_key]), 9)) for c in cs}
            if not len(pairs) == len({t for t, _ in pairs}) == len({x for _, x in pairs}):
                keep.append(i)  # not x's own label: its values are lines of their own
        for c in cs:
            labels = tuple((keys[i], c.variant[i][1]) for i in keep) if labelled else None
            out.setdefault((file, labels), []).append(c)
    return out


def _label_text(labels) -> str:
    return "".join(f", {k}={v}" for k, v in labels or ())


def speed_panels(cases: list[CaseResult]) -> dict:
    """The panels of "restitution against impact speed": one per case file (its variants over speed) and
    value of its other variant labels (:func:`_lines`), titled by the model, pair or wall, the file and those
    labels — a line never joins the cases of two files, nor two values of another key."""
    groups, cases = defaultdict(list), [CaseResult.from_json(c) for c in cases]
    with_speed = [c for c in cases if c.impact.get("speed") is not None]
    for (file, labels), cs in _lines(with_speed, "speed").items():
        for c in cs:
            groups[(_model(c), _kind(c), file, labels)].append(c)
    return {" ".join(x for x in (model, kind) if x) + f" ({Path(file).stem}{_label_text(labels)})": cs
            for (model, kind, file, labels), cs in groups.items() if len({c.impact["speed"] for c in cs}) > 1}


def angle_panels(cases: list[CaseResult]) -> dict:
    """The panels against incidence angle: one per case file and value of its other variant labels
    (:func:`_lines`: the initial spin's among them, titled by them); a file whose entries carry no labels, one
    per initial spin (titled by it)."""
    groups, cases = defaultdict(list), [CaseResult.from_json(c) for c in cases]
    with_angle = [c for c in cases if c.impact.get("angle") is not None]
    for (file, labels), cs in _lines(with_angle, "angle").items():
        for c in cs:
            spin = round(c.impact.get("spin") or 0.0, 6) if labels is None else None
            groups[(file, labels, spin)].append(c)
    return {f"{_model(cs[0])}{'' if spin is None else f', spin {spin:g}'} ({Path(file).stem}{_label_text(labels)})": cs
            for (file, labels, spin), cs in groups.items() if len(cs) > 1}


def suite_figures(summary: Summary) -> list[tuple[str, object]]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import plots

    out = []
    sources = ["reference", *engine_sources()]
    collisions = [c for c in Summary.of(summary).cases if c.kind != "packing" and c.impact]
    normal = [c for c in collisions if c.model and c.model["tangential"] == "none"]
    with_input = [c for c in normal if c.impact.get("restitution_input") is not None]
    if with_input:
        fig, ax = plt.subplots(figsize=(4.6, 4.2), layout="constrained")
        for src in sources:
            pts = [(c.impact["restitution_input"], c.metric(src, "restitution")) for c in with_input]
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
    oblique = [c for c in collisions if c.model and c.model["tangential"] != "none"
               and c.impact.get("angle") is not None]
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

    from .. import plots

    n = len(panels)
    cols = min(4, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.1 * cols + 0.6, 2.7 * rows + 0.9), squeeze=False,
                             layout="constrained")
    handles = {}
    for ax, (name, cs) in zip(axes.ravel(), sorted(panels.items())):
        cs = sorted((CaseResult.from_json(c) for c in cs), key=lambda c: c.impact[x_key])
        ys = []
        for src in sources:
            pts = [(c.impact[x_key], c.metric(src, metric)) for c in cs]
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


def packing_plots(entry: CaseResult) -> str:
    """The packing's panels, from the plot cache when the same data was drawn before (its three panels took
    2–3 s a packing to lay out and draw: most of a warm suite's report)."""
    entry = CaseResult.from_json(entry)
    panels = {src: p.to_json() for src, p in (entry.packing or {}).items()}
    key = {"packing": panels, "case": entry.case, "v": PLOT_VERSION,
           "sources": {src: v.status for src, v in entry.sources.items()}}
    return _cached(key, lambda: _png(packing_figure(entry)), _png_ok)


def force_count(forces: dict) -> int | None:
    """How many contact forces a P(f/⟨f⟩) histogram holds: its ``n`` (packing_metrics.force_distribution
    records it); None — unknown — for one without (a results.json from before it was recorded)."""
    n = forces.get("n")
    return None if n is None else int(n)


def packing_figure(entry: CaseResult):
    """Solid fraction against height, P(f/⟨f⟩) and kinetic energy against time, per source. What a panel
    cannot draw is said in it: a source without that output (or one that did not run), a packing without a
    periodic box (no profile), a source with fewer than MIN_CONTACTS contact forces or an unknown count (no
    distribution). No title of its own: report.html heads it with the packing's name."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import plots

    entry = CaseResult.from_json(entry)
    data = entry.packing or {}
    order = sorted(data, key=plots.source_order)
    absent = [f"{src} ({v.status if 'status' in v.keys else 'no output'})" for src, v in entry.sources.items()
              if src not in data]
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
    notes: dict = {a1: [], a2: [], a3: []}
    for src in order:
        d = data[src]
        prof = d.profile or {}
        if prof.get("z"):
            plots.source_line(a1, prof["solid_fraction"], [z * 1e3 for z in prof["z"]], src, markers=False)
        else:
            notes[a1].append(src)
        ke = [k for k in d.ke if k[1] > 0]  # log axis: the start at rest left out
        if ke:
            plots.source_line(a3, [k[0] for k in ke], [k[1] for k in ke], src, markers=False)
        else:
            notes[a3].append(src)
        forces = d.forces
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
