"""Parameter sweeps: metrics over any case key (``--vary KEY=START:STOP:N``, several make a grid)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pandas as pd

from ..case import load, parse_value
from ..errors import ConfigError, DemcheckError
from ..reference.collision import collide


def parse_vary(text: str) -> tuple[str, list]:
    """``KEY=START:STOP:N`` (N evenly spaced values, ends included) or ``KEY=a,b,c``."""
    if "=" not in text:
        raise ConfigError("--vary", text, "must be KEY=START:STOP:N or KEY=a,b,c")
    key, _, spec = text.partition("=")
    key = key.strip()
    if spec.count(":") == 2:
        start, stop, n = spec.split(":")
        try:
            a, b, count = float(start), float(stop), int(n)
        except ValueError:
            raise ConfigError(f"--vary {key}", spec, "START and STOP must be numbers and N an integer") from None
        if count < 1 or not (math.isfinite(a) and math.isfinite(b)):
            raise ConfigError(f"--vary {key}", spec, "N must be >= 1 and the ends finite")
        return key, list(np.linspace(a, b, count))
    values = [parse_value(v.strip()) for v in spec.split(",") if v.strip()]
    if not values:
        raise ConfigError(f"--vary {key}", spec, "needs at least one value")
    return key, values


def run_sweep(case_path, overrides, varies: list[str], method=None, dt=None, progress=None) -> pd.DataFrame:
    axes = [parse_vary(v) for v in varies]
    keys = [k for k, _ in axes]
    load(case_path, list(overrides))  # the base case must be valid on its own
    rows = []
    points = list(itertools.product(*[vals for _, vals in axes]))
    for point in points:
        sets = list(overrides) + [f"{k}={_text(v)}" for k, v in zip(keys, point)]
        row = dict(zip(keys, point))
        try:
            case = load(case_path, sets)
            result = collide(case, method=method, dt=dt)
            row.update(result.metrics())
            row["status"] = result.status
        except DemcheckError as exc:
            row["status"] = f"error: {exc}"
        rows.append(row)
        if progress:
            progress()
    return pd.DataFrame(rows)


def _text(v) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, bool):
        return str(v).lower()
    return repr(float(v)) if isinstance(v, (float, np.floating)) else repr(v)


def plot_sweep(table: pd.DataFrame, key: str, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..io import atomic_path

    metrics = [c for c in ("restitution", "tangential_restitution", "contact_time", "max_overlap", "peak_force",
                           "rebound_angle", "rebound_angular_velocity", "energy_dissipated")
               if c in table and table[c].notna().any()]
    cols = 2
    rows = math.ceil(len(metrics) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(10, 3.0 * rows), squeeze=False)
    others = [c for c in table.columns if c not in metrics and c not in ("status", key, "force_contact_time")
              and not c.startswith(("restitution", "tangential"))]
    groups = table.groupby(others) if others else [(None, table)]
    for ax, metric in zip(axes.flat, metrics):
        for label, part in groups:
            ax.plot(part[key], part[metric], "o-", ms=3, label=None if label is None else f"{others}={label}")
        ax.set(xlabel=key, ylabel=metric)
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(metrics):]:
        ax.axis("off")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
