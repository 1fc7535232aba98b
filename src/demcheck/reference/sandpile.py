"""A heap formed by batch insertion, and its height against time: the measure of Ai, Chen, Rotter & Ooi (2011)'s
sandpile, the rolling benchmark Lethe digitised (docs/benchmarks.md, docs/packing.md "A heap, inserted").

The packing solver runs the case (reference/packing.simulate: its batches come in every ``every`` s, its timed walls
go at their ``until``, the Verlet list and every contact's state carried from chunk to chunk); at each measuring
time — every ``[packing.height] every`` s from ``start`` to the end — the height is the largest centre coordinate
along ``axis`` plus ``offset`` (Lethe's: the highest centre's y + 0.57 m, the box's floor at y = −0.57 m).
"""

from __future__ import annotations

import numpy as np

from . import packing


def measure_steps(case, dt: float) -> np.ndarray:
    """The steps (from the start) at which the height is measured: each time start + k·every up to the end of the
    run (packing.duration), at the first step ending at or past it (packing.step_at)."""
    h = case.packing.height
    end = case.packing.duration
    count = int(np.floor((end - h.start) / h.every * (1.0 + 1e-12))) + 1
    return np.array([packing.step_at(h.start + k * h.every, dt) for k in range(count)], np.int64)


def height_curve(case, threads: int = 1, duration: float | None = None,
                 progress=None) -> tuple[np.ndarray, np.ndarray]:
    """(times, heights) of the case's heap (numpy arrays, s and m): the packing run by the reference solver
    (``threads`` of its loop: one is the fastest for a heap of a few thousand on a shared machine, docs/packing.md;
    ``duration``: instead of packing.duration, a shorter run for a size check — the measures up to it), measured as
    its ``[packing.height]`` table says; ``progress(t, height)`` is called at each measure (a long run's log). A case
    without that table is a ConfigError, before any work."""
    from ..case import packing_run
    from ..errors import ConfigError

    if case.kind != "packing" or case.packing is None or case.packing.height is None:
        raise ConfigError("packing.height", None, "missing: the height curve needs [packing.height] (axis, offset, "
                                                  "every, start)")
    dt, duration, total = packing_run(case, duration)
    steps = [k for k in measure_steps(case, dt) if k <= total]
    axis = np.asarray(case.packing.height.axis, float)
    offset = case.packing.height.offset
    times, heights = [], []

    def look(st):
        times.append(st.steps * dt)
        heights.append(float((st.x @ axis).max()) + offset)
        if progress is not None:
            progress(times[-1], heights[-1])

    packing.simulate(case, duration=duration, threads=threads, observe=(steps, look))
    return np.array(times), np.array(heights)
