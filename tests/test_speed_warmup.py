"""`demcheck warmup` (issue 16, item 3): it runs the suite's call sites once, so every kernel the suite runs has a
compiled specialisation after it, and the command reports each scene."""

import subprocess
import sys
from pathlib import Path

from numba.core.registry import CPUDispatcher

ROOT = Path(__file__).resolve().parents[1]


def test_warmup_compiles_every_entry_kernel_of_the_suite():
    from demcheck.comparisons.warmup import warm
    from demcheck.reference import adaptive3d, kernels, packing, verlet3d

    labels = [label for label, _ in warm()]  # in this process (jobs = 1)
    assert len(labels) == len(set(labels)) == 9
    for kernel in (kernels.adaptive_normal, kernels.verlet_normal, adaptive3d.adaptive_3d, verlet3d.verlet_3d,
                   packing.run):
        assert isinstance(kernel, CPUDispatcher) and kernel.signatures, kernel
    # one specialisation per entry kernel: the suite's call sites pass one set of argument types
    assert all(len(k.signatures) == 1 for k in (kernels.adaptive_normal, kernels.verlet_normal,
                                               adaptive3d.adaptive_3d, verlet3d.verlet_3d, packing.run))


def test_the_command_lists_its_scenes():
    p = subprocess.run([sys.executable, "-m", "demcheck", "warmup"], cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "collision 3-D pair verlet" in p.stdout and "packing" in p.stdout and "total (wall)" in p.stdout


SPECIALISATIONS = r"""
import importlib, json, pkgutil
from numba.core.registry import CPUDispatcher
import demcheck.laws, demcheck.reference
from demcheck.comparisons.warmup import warm
warm()
mods = [importlib.import_module(f"{p.__name__}.{m.name}") for p in (demcheck.laws, demcheck.reference)
        for m in pkgutil.iter_modules(p.__path__)]
seen = {}
for m in [importlib.import_module("demcheck.metrics"), *mods]:  # every compiled function, wherever it is imported
    for v in vars(m).values():
        if isinstance(v, CPUDispatcher):
            seen[f"{v.py_func.__module__}.{v.py_func.__name__}"] = len(v.signatures)
print(json.dumps({k: n for k, n in seen.items() if n > 1}))
"""


def test_the_kernels_compile_one_specialisation_each(tmp_path):
    """A call that passes a literal (a constant, or a counter's first value while numba infers the loop's types)
    compiles a specialisation of the callee of its own: the 3-D adaptive solver compiled _locate and
    _event_value three times each, the packing loop its force loop twice. On an empty kernel cache (what a fresh
    clone compiles; in-process caches would hide the callees), every function is compiled once, but the normal
    laws: on a law's array (the collision solvers) and on its tuple (the packing's force loop)."""
    import json
    import os

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "kernels"))
    p = subprocess.run([sys.executable, "-c", SPECIALISATIONS], cwd=ROOT, env=env, capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    assert json.loads(p.stdout.strip().splitlines()[-1]) == {"demcheck.laws.normal_force.viscoelastic_force": 2,
                                                             "demcheck.laws.normal_force.normal_force": 2}


def test_warmup_in_two_processes_fills_the_cache_the_suite_loads(tmp_path):
    """`demcheck warmup --jobs 2` on an empty cache: every scene reported once, and afterwards every entry kernel
    loads from the cache (a scene in this process then compiles nothing)."""
    import os

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "kernels"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "warmup", "--jobs", "2"], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-2000:]
    assert "2 processes" in p.stdout and "total (wall)" in p.stdout
    from demcheck.comparisons.warmup import scenes

    assert all(p.stdout.count(f"  {label} ") == 1 for label, _ in scenes())
    probe = ("import time; from numba.core import event; rec = event.RecordingListener(); "
             "event.register('numba:compile', rec); from demcheck.comparisons.warmup import warm; warm(); "
             "print(sum(1 for _, ev in rec.buffer if ev.is_start))")
    q = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert q.returncode == 0, q.stderr[-2000:]
    assert q.stdout.strip().splitlines()[-1] == "0"
