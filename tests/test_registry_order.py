"""The engines' order (a report's columns, docs/models.md's mapping table) does not depend on which engine package
was imported first: test_docs failed when test_engine_traps_yade_kratos ran before it in the same process."""

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
