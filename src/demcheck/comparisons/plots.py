"""Plots of collisions (force–overlap loops and force–time curves, one line per source), and the drawing rules
every plot of the reports follows:

* each source in its own colour, marker and line style (:func:`styles.style`), the same in every panel;
* hollow markers, larger for the sources drawn first (:func:`marker_size`; thicker lines likewise,
  :func:`line_width`), so that sources that agree — most of them, most of the time — stay visible one
  inside the other instead of the last one drawn hiding the rest;
* plain tick labels, never an offset or a common ×10ⁿ factor (:func:`plain_ticks`): "1e−6 + 1" above ticks
  of 0.2 makes a difference of a millionth read as a large one;
* a y range of at least ``MIN_REL_SPAN`` of the panel's largest |value| (:func:`min_span`);
* titles wrapped (:func:`wrap_title`) and every figure laid out by matplotlib's constrained layout, so that
  no title, suptitle or legend overlaps another;
* text from outside demcheck's own words (a case's name, a file's, a source's) drawn as it is, never read as
  mathtext (:func:`literal`: a ``$…$`` in a file name once stopped the report);
* a panel with nothing to draw says why in the panel (:func:`note`), never left empty.
"""

from __future__ import annotations

import math
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ..io import atomic_path  # noqa: E402
from .styles import engine_sources, style  # noqa: E402

# The smallest y range of a linear panel, as a fraction of its largest |value|. Chosen at 5 %: autoscaling
# stretches whatever spread the data has over the whole panel, so that engines agreeing to 3e-4 on a
# restitution of 0.9 looked as far apart as 0.1 and 0.9. With 5 % a difference of 3e-4 of a value is 0.6 %
# of the panel's height (the markers overlap: they agree to the eye), while a difference of a few per cent
# still shows. The numbers themselves are in the report's tables; the verdicts do not depend on the plots.
MIN_REL_SPAN = 0.05


def source_order(source: str) -> int:
    """Where a source is drawn: 0 the reference, 1 its other methods, then the engines in the registry's order
    from 2 (a build after them)."""
    if source in ("reference", "reference-adaptive"):
        return 0
    if source in ("reference-verlet", "closed-form"):
        return 1
    engines = engine_sources()
    return 2 + (engines.index(source) if source in engines else len(engines))


def marker_size(source: str) -> float:
    """Hollow markers shrinking in drawing order: 9 pt for the reference, 1.1 pt less for each next source,
    3 pt at least."""
    return max(3.0, 9.0 - 1.1 * source_order(source))


def line_width(source: str) -> float:
    """Lines thinning in drawing order: 2.6 for the reference, 0.35 less for each next source, 0.8 at least."""
    return max(0.8, 2.6 - 0.35 * source_order(source))


def source_line(ax, x, y, source: str, markers: bool = True, line: bool = True, **kw):
    """One source's line in its own colour, line style and (hollow) marker; labelled with the source."""
    st = style(source)
    opts = {"color": st.colour, "label": source, "linestyle": st.linestyle if line else "none",
            "lw": line_width(source) if not markers else 1.0}
    if markers:
        opts.update(marker=st.marker, ms=marker_size(source), mfc="none", mew=1.1)
    opts.update(kw)
    return ax.plot(list(x), list(y), **opts)[0]


def _tick(value, _pos=None) -> str:
    return "0" if value == 0 else f"{value:.6g}"


def plain_ticks(ax, axes: str = "xy") -> None:
    """Every tick labelled with its own value (six significant digits at most): no offset, no ×10ⁿ factor.
    Log axes keep their own labels (they have no offset)."""
    from matplotlib.ticker import FuncFormatter

    for name in axes:
        axis, scale = (ax.xaxis, ax.get_xscale()) if name == "x" else (ax.yaxis, ax.get_yscale())
        if scale == "linear":
            axis.set_major_formatter(FuncFormatter(_tick))


def min_span(ax, values, rel: float = MIN_REL_SPAN) -> None:
    """Widen a linear y axis to at least ``rel`` × the largest |value| (centred on the data) when the data
    spread less; a wider spread keeps matplotlib's own range."""
    v = [float(x) for x in values if x is not None and math.isfinite(x)]
    if not v or ax.get_yscale() != "linear":
        return
    lo, hi = min(v), max(v)
    need = rel * max(abs(lo), abs(hi))
    if need > 0 and hi - lo < need:
        mid = 0.5 * (lo + hi)
        ax.set_ylim(mid - 0.55 * need, mid + 0.55 * need)


def literal(text) -> str:
    """Text that matplotlib draws as it is: every ``$`` escaped (``\\$``), so that no ``$…$`` in it is parsed
    as mathtext (an unbalanced one raised, and the report was lost). For every text that is not demcheck's own
    words: titles (:func:`wrap_title`), notes (:func:`note`), axis labels taken from data. (Escaping, not
    ``parse_math=False``: a wrapped text is measured as mathtext whatever its parse_math says, matplotlib 3.11.)"""
    return str(text).replace("$", "\\$")


def wrap_title(text: str, width: int = 34) -> str:
    """A title wrapped at ``width`` characters, drawn literally (:func:`literal`)."""
    return literal(textwrap.fill(str(text), width=width, break_long_words=True, break_on_hyphens=False))


def note(ax, text: str, centre: bool = True) -> None:
    """A note in a panel: in its middle when the panel has nothing else to show, else along its bottom; drawn
    literally (it names sources and their statuses)."""
    kw = {"transform": ax.transAxes, "fontsize": 7, "color": "0.25", "wrap": True}
    if centre:
        ax.set_xticks([])
        ax.set_yticks([])
        ax.text(0.5, 0.5, literal(textwrap.fill(text, 40)), ha="center", va="center", **kw)
    else:
        ax.text(0.03, 0.03, literal(textwrap.fill(text, 48)), ha="left", va="bottom",
                bbox={"facecolor": "white", "edgecolor": "0.8", "alpha": 0.85, "pad": 2}, **kw)


def legend(where, *args, **kw):
    """``where.legend(…)`` (an Axes or a Figure) with its labels — source names, a build's label — drawn
    literally, never as mathtext."""
    leg = where.legend(*args, **kw)
    for t in leg.get_texts():
        t.set_parse_math(False)
    return leg


def _label(result) -> str:
    if result.source == "reference":
        return f"reference ({result.method}" + (f", dt={result.dt:.3g} s)" if result.dt else ")")
    return f"{result.source} {result.engine_version or ''}".strip()


def collision_panels(results, path) -> None:
    """Force against overlap, and force against time from contact start, for each result."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for res in results:
        c = res.contact
        inside = c[(c["delta"] > 0) | (c["fn"] != 0)]
        if inside.empty:
            continue
        t0 = inside["t"].iloc[0]
        source = "reference-verlet" if res.source == "reference" and res.method != "adaptive" else res.source
        for ax, x in ((ax1, inside["delta"] * 1e6), (ax2, (inside["t"] - t0) * 1e6)):
            source_line(ax, x, inside["fn"], source, markers=False, label=_label(res))
    first = results[0]
    title = wrap_title(f"{first.case_name}: normal={first.model['normal']}", 60)
    ax1.set(xlabel="overlap δ (µm)", ylabel="normal force Fn (N)", title=title)
    ax2.set(xlabel="time since contact start (µs)", ylabel="normal force Fn (N)", title="force–time")
    for ax in (ax1, ax2):
        ax.axhline(0, color="0.6", lw=0.6)
        ax.grid(alpha=0.3)
        plain_ticks(ax)
        if ax.get_legend_handles_labels()[0]:
            legend(ax, fontsize=8)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
