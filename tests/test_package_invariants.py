"""Package-wide invariants: the engines' order (a report's columns, docs/models.md's mapping table) does not depend on
which engine package was imported first (test_docs failed when test_engine_traps_yade_kratos ran before it in the
same process), and the compiled kernels' cache key covers every package that holds kernels."""

import subprocess
import sys

IMPORT_ONE_FIRST = """
import demcheck.engines.{first}  # registers its engine before the registry loads the others
from demcheck.engines import registry
print(",".join(registry.names())); print(",".join(e.name for e in registry.all_engines()))
"""


def test_builtins_keep_their_order_whichever_is_imported_first():
    for first in ("yade", "kratos", "liggghts"):
        p = subprocess.run([sys.executable, "-c", IMPORT_ONE_FIRST.format(first=first)], capture_output=True,
                           text=True, timeout=120)
        assert p.returncode == 0, p.stderr
        assert p.stdout.split() == ["lammps,liggghts,kratos,yade"] * 2, (first, p.stdout)


FINGERPRINT = "import demcheck; print(demcheck.reference_fingerprint())"


def test_the_kernel_cache_key_changes_with_a_law_module(tmp_path):
    """The compiled force functions live in laws/ since the slot redesign: a change there must start a fresh kernel
    cache (numba keys a cached function by its own file only; a solver inlining a changed law would be stale)."""
    import shutil

    from .conftest import ROOT

    def fingerprint(tree):
        p = subprocess.run([sys.executable, "-c", FINGERPRINT], capture_output=True, text=True, timeout=120,
                           env={"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "NUMBA_CACHE_DIR": str(tmp_path)})
        assert p.returncode == 0, p.stderr
        return p.stdout.strip()

    tree = tmp_path / "src"
    shutil.copytree(ROOT / "src" / "demcheck", tree / "demcheck", ignore=shutil.ignore_patterns("__pycache__"))
    before = fingerprint(tree)
    for module in ("laws/normal_force.py", "reference/kernels.py"):
        with open(tree / "demcheck" / module, "a") as f:
            f.write("\n# changed\n")
        after = fingerprint(tree)
        assert after != before, module
        before = after
