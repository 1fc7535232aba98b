"""Parameter sweeps: metrics over any case key (``--vary KEY=START:STOP:N``, several make a grid), from one
source: the reference (the seed model of ``[contact]``), an engine (its deck run for real) or an engine's twin.

An engine or its twin runs the case's own setting for that engine (``[engine.NAME]``) when it has one, by
default at that law's own step (engines.collide.setting: its twin's contact time over run.steps_per_contact). A
``contact.*`` key, varied or set, does not change that native law (``[contact]`` is the seed model it is judged
against), nor does a ``materials.*`` key the setting does not read (LAMMPS's ``pair_coeff`` gives its own modulus
and restitution): such a sweep is refused before any work, rather than a table of one law repeated."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..case import parse_value
from ..errors import ConfigError, DemcheckError


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


class Points(list):
    """A sweep's grid: [(its values by key, its Case)], with the overrides (``--set``: ``KEY=VALUE`` texts, or the
    API's (key, value) pairs) every point was built with, for ``native_vary_rule``."""

    def __init__(self, points=(), overrides=()):
        super().__init__(points)
        self.overrides = list(overrides)


def check_source(source: str, method=None, keys: tuple[str, str, str] = ("--engine", "--method", "--dt")) -> str:
    """``source`` as a sweep runs it: reference, a registered engine (or build), or ``NAME-twin``; ``method``
    is the reference's. Else ConfigError naming the option, before any work: ``keys`` are the names of the
    source, the method and the step (the command's options; the API's ``source``, ``method``, ``dt``)."""
    from .sources import REFERENCE, Source

    src = Source.parse(source, keys[0], methods=False)
    if src.kind != REFERENCE and method is not None:
        raise ConfigError(keys[1], method, "is the reference's (adaptive or verlet); an engine and its twin "
                                           f"run velocity Verlet at {keys[2]}")
    return source


def sweep_source(text: str, method=None, key: str = "--engine") -> tuple[str, str | None]:
    """The command line's ``--engine`` of a sweep: (the source's label, the name of the engine or build it runs,
    None for the reference) — one source: reference, an engine or a build of one (registered under its label and
    required to be found: EngineNotFound), or an engine's twin; ``method`` the reference's (check_source)."""
    from ..engines import discovery
    from ..errors import EngineNotFound
    from .sources import ENGINE, Source

    if "=" not in text and Source.parse(check_source(text, method), key, methods=False).kind != ENGINE:
        return text, Source.parse(text).name
    labels = discovery.resolve(text, key)  # an engine, or a build registered under its label
    if len(labels) != 1:
        raise ConfigError(key, text, "a sweep runs one source (collide and verify compare several)")
    if discovery.find(labels[0]) is None:
        raise EngineNotFound(discovery.missing(labels[0]))
    check_source(labels[0], method)
    return labels[0], labels[0]


def _contact_key(key: str) -> bool:
    return key == "contact" or key.startswith("contact.")


def native_vary_rule(points: list[tuple[dict, object]], source: str, where: str = "--vary ",
                     set_where: str = "--set ") -> None:
    """Refuse, before any work, a key that cannot move what ``source`` runs: with the case's own setting for the
    source's engine (``[engine.NAME]``), a ``contact.*`` key (the seed model's, not the native law's) varied or
    set (``points.overrides``: api.sweep's Points), or a ``materials.*`` key that leaves what the native run
    sees (bench.native_seen: its law, the masses, …) unchanged at every point. The error's key is ``where`` +
    the case key (``--vary contact.kn``; the API's ``vary.contact.kn``), or ``set_where`` + it for an override
    (``--set contact.kn``; the API's ``overrides.contact.kn``)."""
    from ..engines.builds import engine_of
    from .bench import native_contact, native_seen
    from .sources import REFERENCE, Source

    if source == REFERENCE or not points:
        return
    engine = Source.parse(source).engine
    base = points[0][1]
    if engine.case_native(base) is None:
        return
    table = f"[engine.{engine_of(engine.name)}]"
    why = (f"{source} runs the case's {table} setting, which {{key}} does not change ([contact] is the seed "
           f"model it is judged against)")
    for item in getattr(points, "overrides", ()):
        key, value = item.partition("=")[::2] if isinstance(item, str) else item
        if _contact_key(key.strip()):
            raise ConfigError(f"{set_where}{key.strip()}", _plain(value), why.format(key=key.strip()) + ": leave it "
                              f"out, set a {table[1:-1]}.* key, or sweep the reference")
    for key in points[0][0]:
        values = list(dict.fromkeys(_plain(v[key]) for v, _ in points))
        if _contact_key(key):
            raise ConfigError(f"{where}{key}", values, why.format(key=key) + ": vary an impact, particle or "
                              f"{table[1:-1]}.* key, or sweep the reference")
        if key.startswith("materials."):
            seen = {native_seen(case, native_contact(case, engine.case_native(case))[0]) for _, case in points}
            if len(seen) == 1:
                raise ConfigError(f"{where}{key}", values, f"{source} runs the case's {table} setting, and {key} "
                                  "changes neither that law nor the masses at any point (the setting gives its "
                                  f"own): vary {table[1:-1]}.* instead")


def _plain(v):
    return v.item() if hasattr(v, "item") else v


def _run(case, source: str, method, dt):
    """One point's Result from ``source`` (check_source): an engine and its twin run the case's own setting at
    its own step (bench and dt count in it too)."""
    from ..errors import EngineNotFound
    from .dispatch import missing_here
    from .sources import ENGINE, Source

    src = Source.reference(method) if source == "reference" else Source.parse(source, "--engine")
    if src.kind != ENGINE:
        return src.run(case, dt)
    lacking = missing_here([src.name])  # on a Dask worker without the engine: this point's error names the worker
    if lacking:
        raise EngineNotFound(lacking[src.name])
    # a sweep runs one engine many times: in its long-lived worker where it has one (no start-up per point)
    return src.run(case, dt, worker=True)


def point_task(values: dict, case, source: str, method, dt, cache=None) -> dict:
    """One point's row (its values, metrics and status), where the campaign runs it (comparisons/dispatch.py); a
    solve that fails keeps its row, with the status."""
    from ..errors import EngineInterrupted

    row = dict(values)
    try:
        result = _run(case, source, method, dt)
        row.update(result.metrics())
        row["status"] = result.status
    except EngineInterrupted:
        raise
    except DemcheckError as exc:
        row["status"] = f"error: {exc}"
    return row


BATCH = 256  # points a compiled call of the reference solves (the progress bar moves a batch at a time)


def run_sweep(points: list[tuple[dict, object]], method=None, dt=None, progress=None,
              source: str = "reference", campaign=None) -> pd.DataFrame:
    """Solve each point (api.sweep's grid: its values by key and its Case) from ``source`` (``check_source``), in ``campaign``
    (dispatch.Campaign; default this process), the rows in the points' order. The reference's points in this
    process are solved BATCH at a time (reference/batch.py: the 1-D verlet ones in one compiled call)."""
    from .dispatch import Campaign

    campaign = campaign or Campaign()
    if source == "reference" and campaign.in_process:
        from ..reference.batch import collide_many

        out = []
        for lo in range(0, len(points), BATCH):
            part = points[lo:lo + BATCH]
            for (values, _), got in zip(part, collide_many([case for _, case in part], method, dt)):
                got.pop("message")
                out.append({**values, **got})  # point_task's row: the values, the metrics, the status
                if progress:
                    progress()
        return pd.DataFrame(out)
    rows = {}
    tasks = [(i, (values, case, source, method, dt)) for i, (values, case) in enumerate(points)]
    for i, row in campaign.completed(point_task, tasks):
        rows[i] = row
        if progress:
            progress()
    return pd.DataFrame([rows[i] for i in sorted(rows)])


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
