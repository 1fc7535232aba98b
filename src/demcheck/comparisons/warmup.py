"""``demcheck warmup``: compile every kernel specialisation the suite uses, once, into the on-disk cache.

The reference's kernels are numba functions compiled on first use and cached on disk (docs/performance.md,
"Compiled kernels"); a cold cache makes the first suite pay for the compilation. Numba compiles one
specialisation per set of argument types, so the warm-up runs the suite's own call sites — the 1-D and 3-D
collision solvers, adaptive and verlet, at a wall and between a pair, and the packing solver with a floor,
its periodic box and one with side walls, on one thread and on two — on tiny scenes: what it compiles is exactly
what the suite (and a threaded `pack`) would.
It needs no engine and writes nothing but numba's cache.
"""

from __future__ import annotations

import time

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
    from ..reference.collision import collide

    out = []
    for wall in (True, False):
        for oblique in (False, True):
            label = f"collision {'1-D' if not oblique else '3-D'} {'wall' if wall else 'pair'}"
            for method in ("adaptive", "verlet"):
                out.append((f"{label} {method}",
                            lambda w=wall, o=oblique, m=method: collide(_collision(w, o), m).metrics()))
    out.append(("packing", _packing))
    return out


def _packing():
    import numba

    from ..case import loads
    from ..reference import packing

    case = loads(_PACKING)
    packing.simulate(case, rest=0.0)
    if numba.config.NUMBA_NUM_THREADS >= 2:  # the threaded loop (threads > 1), where numba may run it
        packing.simulate(case, rest=0.0, threads=2)


def warm(progress=None) -> list[tuple[str, float]]:
    """Run every scene once; [(label, seconds)] (the first run of a scene compiles or loads its kernels)."""
    out = []
    for label, run in scenes():
        t = time.perf_counter()
        run()
        out.append((label, time.perf_counter() - t))
        if progress:
            progress(label, out[-1][1])
    return out
