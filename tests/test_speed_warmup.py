"""`demcheck warmup` (issue 16, item 3): it runs the suite's call sites once, so every kernel the suite runs has a
compiled specialisation after it, and the command reports each scene."""

import subprocess
import sys
from pathlib import Path

from numba.core.registry import CPUDispatcher

ROOT = Path(__file__).resolve().parents[1]


def test_warmup_compiles_every_entry_kernel_of_the_suite():
    from demcheck.comparisons.warmup import warm
    from demcheck.reference import kernels, kernels3d, packing

    labels = [label for label, _ in warm()]
    assert len(labels) == len(set(labels)) == 9
    for kernel in (kernels.adaptive_normal, kernels.verlet_normal, kernels3d.adaptive_3d, kernels3d.verlet_3d,
                   packing.run):
        assert isinstance(kernel, CPUDispatcher) and kernel.signatures, kernel
    # one specialisation per entry kernel: the suite's call sites pass one set of argument types
    assert all(len(k.signatures) == 1 for k in (kernels.adaptive_normal, kernels.verlet_normal,
                                               kernels3d.adaptive_3d, kernels3d.verlet_3d, packing.run))


def test_the_command_lists_its_scenes():
    p = subprocess.run([sys.executable, "-m", "demcheck", "warmup"], cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "collision 3-D pair verlet" in p.stdout and "packing" in p.stdout and "total" in p.stdout
