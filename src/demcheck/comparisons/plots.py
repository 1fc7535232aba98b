"""Plots of collisions: force–overlap loops and force–time curves, one line per source."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from ..io import atomic_path  # noqa: E402


def _label(result) -> str:
    if result.source == "reference":
        return f"reference ({result.method}" + (f", dt={result.dt:.3g} s)" if result.dt else ")")
    return f"{result.source} {result.engine_version or ''}".strip()


def collision_panels(results, path) -> None:
    """Force against overlap, and force against time from contact start, for each result."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for res in results:
        c = res.contact
        inside = c[(c["delta"] > 0) | (c["fn"] != 0)]
        if inside.empty:
            continue
        t0 = inside["t"].iloc[0]
        style = "-" if res.method == "adaptive" else "--"
        ax1.plot(inside["delta"] * 1e6, inside["fn"], style, label=_label(res))
        ax2.plot((inside["t"] - t0) * 1e6, inside["fn"], style, label=_label(res))
    first = results[0]
    title = f"{first.case_name}: normal={first.model['normal']}"
    ax1.set(xlabel="overlap δ (µm)", ylabel="normal force Fn (N)", title=title)
    ax2.set(xlabel="time since contact start (µs)", ylabel="normal force Fn (N)", title="force–time")
    for ax in (ax1, ax2):
        ax.axhline(0, color="0.6", lw=0.6)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
