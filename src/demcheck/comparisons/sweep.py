"""Parameter sweeps: metrics over any case key (``--vary KEY=START:STOP:N``, several make a grid)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pandas as pd

from ..case import _read, apply_overrides, from_dict, parse_value
from ..errors import ConfigError, DemcheckError
from ..reference.collision import collide


FORM = "must be KEY=START:STOP:N (N values, ends included) or KEY=a,b,c"
MAX_POINTS = 10_000  # a grid's points, each a collision solved


def parse_vary(text: str) -> tuple[str, list]:
    """``KEY=START:STOP:N`` (N evenly spaced values, ends included) or ``KEY=a,b,c`` (TOML values; a bare
    word is a string, so a word that starts like a number — ``0-80`` — is refused, not taken as a string)."""
    key, sep, spec = text.partition("=")
    key, spec = key.strip(), spec.strip()
    if not sep or not key or not spec:
        raise ConfigError("--vary", text, FORM)
    if ":" in spec:
        if spec.count(":") != 2:
            raise ConfigError(f"--vary {key}", spec, FORM)
        start, stop, n = spec.split(":")
        try:
            a, b, count = float(start), float(stop), int(n)
        except ValueError:
            raise ConfigError(f"--vary {key}", spec, "START and STOP must be numbers and N an integer") from None
        if not (1 <= count <= MAX_POINTS) or not (math.isfinite(a) and math.isfinite(b)):
            raise ConfigError(f"--vary {key}", spec, f"N must be in [1, {MAX_POINTS}] and the ends finite")
        return key, list(np.linspace(a, b, count))
    values = []
    for part in spec.split(","):
        v = parse_value(part.strip()) if part.strip() else None
        if v is None or (isinstance(v, str) and v[:1] in "0123456789+-."):
            raise ConfigError(f"--vary {key}", spec, f"{part.strip()!r} is not a value; {FORM}")
        values.append(v)
    return key, values


def sweep_points(case_path, overrides, varies: list[str]) -> list[tuple[dict, object]]:
    """Every point of the grid as (its values by key, its Case), all loaded and validated before any is
    solved: a bad key or value is one ConfigError (exit 2), not a row of errors."""
    axes = [parse_vary(v) for v in varies]
    keys = [k for k, _ in axes]
    total = math.prod(len(vals) for _, vals in axes)
    if total > MAX_POINTS:
        raise ConfigError("--vary", " ".join(varies), f"makes a grid of {total} points; at most {MAX_POINTS}")
    raw = _read(case_path)  # the file is read once
    from_dict(apply_overrides(raw, list(overrides)))  # the base case must be valid on its own
    points = []
    for point in itertools.product(*[vals for _, vals in axes]):
        sets = list(overrides) + [f"{k}={_text(v)}" for k, v in zip(keys, point)]
        points.append((dict(zip(keys, point)), from_dict(apply_overrides(raw, sets))))
    return points


def run_sweep(points: list[tuple[dict, object]], method=None, dt=None, progress=None) -> pd.DataFrame:
    """Solve each point (``sweep_points``); a point whose solve fails keeps its row, with the status."""
    rows = []
    for values, case in points:
        row = dict(values)
        try:
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
