"""``demcheck warmup``: compile every kernel specialisation the suite uses, once, into the on-disk cache.

The reference's kernels are numba functions compiled on first use and cached on disk (docs/performance.md,
"Compiled kernels"); a cold cache makes the first suite pay for the compilation. Numba compiles one
specialisation per set of argument types, so the warm-up runs the suite's own call sites — the 1-D and 3-D
collision solvers, adaptive and verlet, at a wall and between a pair (the 1-D verlet one also batched, as a sweep
runs it), and the packing solver with a floor,
its periodic box and one with side walls, on one thread and on two — on tiny scenes: what it compiles is exactly
what the suite (and a threaded `pack`) would.
It needs no engine and writes nothing but numba's cache.

With ``jobs`` > 1 the kernels compile side by side in as many processes (numba compiles one function at a time in
a process): one task per entry kernel (a wall scene and a pair scene share their kernel, so they are one task),
the longest first. Two processes that compile different specialisations of one function at once could write
its cache index over each other's (numba's index is not safe against that), so the functions compiled for two
argument types (the normal laws: ``_shared``) are compiled here first; the tasks then only load them.
"""

from __future__ import annotations

import time
from concurrent.futures import ProcessPoolExecutor, as_completed

_MATERIAL = """
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = 0.9
friction = 0.3
"""
_BODY = """
[[particles]]
material = "glass"
radius = 1.59e-3
"""
_WALL = """
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""
_PACKING = """
name = "warmup-packing"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.5
[packing]
layout = "layer"
count = 4
material = "glass"
radius = 1e-3
duration = 1e-4
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
normal = "hertz"
[run]
gravity = [0.0, 0.0, -9.81]
"""


def _collision(wall: bool, oblique: bool):
    from ..case import loads

    text = (f'name = "warmup-{"wall" if wall else "pair"}-{"oblique" if oblique else "head-on"}"\n'
            f'kind = "collision"\n{_MATERIAL}{_BODY}{_WALL if wall else _BODY}\n[impact]\nspeed = 1.0\n'
            f'angle = {30.0 if oblique else 0.0}\n\n[contact]\nnormal = "hertz"\n'
            f'tangential = "{"viscous_sliding" if oblique else "none"}"\n'
            + ("eta_t = 0.5\n" if oblique else ""))
    return loads(text)


def scenes() -> list[tuple[str, callable]]:
    """(label, run) for every call site the suite compiles a kernel at."""
    out = []
    for wall in (True, False):
        for oblique in (False, True):
            label = f"collision {'1-D' if not oblique else '3-D'} {'wall' if wall else 'pair'}"
            for method in ("adaptive", "verlet"):
                out.append((f"{label} {method}", lambda w=wall, o=oblique, m=method: _collide(w, o, m)))
    out.append(("packing", _packing))
    return out


def _collide(wall: bool, oblique: bool, method: str) -> None:
    """A collision's Result and its metrics; a 1-D verlet one also batched, as a sweep solves it (its compiled
    batch kernel, reference/batch.py)."""
    from ..reference.batch import collide_many
    from ..reference.collision import collide

    case = _collision(wall, oblique)
    collide(case, method).metrics()
    if method == "verlet" and not oblique:
        collide_many([case], method)


def _packing():
    import numba

    from ..case import loads
    from ..reference import packing

    case = loads(_PACKING)
    packing.simulate(case, rest=0.0)
    if numba.config.NUMBA_NUM_THREADS >= 2:  # the threaded loop (threads > 1), where numba may run it
        packing.simulate(case, rest=0.0, threads=2)


def tasks() -> list[list[str]]:
    """The scenes' labels grouped by the entry kernel they compile, the longest compile first (measured:
    docs/performance.md, "Cold start")."""
    order = ("collision 3-D adaptive", "packing", "collision 3-D verlet", "collision 1-D adaptive",
             "collision 1-D verlet")
    groups = {key: [] for key in order}
    for label, _ in scenes():
        groups[label.replace(" wall", "").replace(" pair", "")].append(label)
    return [groups[k] for k in order]


def _shared() -> None:
    """Compile (or load) the functions that the tasks specialise for two argument types: the normal laws, on a
    law's array (the collision solvers) and on its tuple (the packing's force loop)."""
    import numpy as np

    from ..reference import kernels

    for law in (np.zeros(kernels.L_LIMIT + 1), (0.0,) * (kernels.L_LIMIT + 1)):
        kernels.viscoelastic_force(law, 0.0, 0.0)
        kernels.normal_force(law, 0.0, 0.0, 0.0)


def _run(labels: list[str]) -> list[tuple[str, float]]:
    """Run the scenes ``labels`` in order, in this process; [(label, seconds)]."""
    by_label = dict(scenes())
    out = []
    for label in labels:
        t = time.perf_counter()
        by_label[label]()
        out.append((label, time.perf_counter() - t))
    return out


def warm(progress=None, jobs: int = 1) -> list[tuple[str, float]]:
    """Run every scene once; [(label, seconds)] (the first run of a scene compiles or loads its kernels), in this
    process (``jobs`` = 1, in the scenes' order), or in ``jobs`` processes (as each task ends)."""
    out = []
    if jobs <= 1:
        for label, _ in scenes():
            out += _run([label])
            if progress:
                progress(*out[-1])
        return out
    import multiprocessing

    _shared()
    with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        for done in as_completed([pool.submit(_run, labels) for labels in tasks()]):
            for label, seconds in done.result():
                out.append((label, seconds))
                if progress:
                    progress(label, seconds)
    return out
