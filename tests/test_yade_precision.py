"""Issue 15 item 6: Debian's extended-precision Yade (``yade-float128``, the same 2023.02a code with Real =
__float128) as a second build of the yade engine (``--engine yade@f128=/usr/bin/yade-float128``). One oblique
impact run in both builds at the same dt differs by round-off; the same case at dt and dt/2 differs by the
scheme's error, orders of magnitude more: a difference between an engine and the reference of the size of the
second is scheme error, not float64 round-off."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from demcheck import case as C
from demcheck.engines import collide as CO
from demcheck.engines import discovery

from .conftest import CASES

F128 = Path("/usr/bin/yade-float128")  # scripts/install-engines.sh installs it with yade
METRICS = ("restitution", "contact_time", "tangential_restitution")


def _rel(a: dict, b: dict) -> dict:
    return {k: abs(a[k] - b[k]) / abs(b[k]) for k in METRICS}


@pytest.fixture
def f128():
    if not F128.exists():
        if os.environ.get("DEMCHECK_REQUIRE_ENGINES") == "1":
            pytest.fail(f"{F128} is not installed (scripts/install-engines.sh installs yade-float128)")
        pytest.skip(f"{F128} is not installed")
    labels = discovery.resolve(f"yade@f128={F128}")
    yield labels[0]
    discovery.drop(labels[0])


@pytest.mark.engine("yade")
def test_float128_build_is_found_with_its_version(f128):
    """The build's own executable is asked for its version (Yade's -h does not print it): through the wrapper
    demcheck writes around that very binary (a copy of it under another name, off PATH, is found as well)."""
    info = discovery.find(f128)
    assert info.version == "2023.02a"
    assert str(F128.resolve()) in Path(info.executable).read_text()


@pytest.mark.engine("yade")
def test_float64_and_float128_differ_by_round_off_dt_and_half_dt_by_scheme_error(f128):
    """oblique-lsd-wall (45°, LSD normal and tangential with sliding): float64 vs float128 at equal dt ≤ 1e-12
    relative on restitution, contact time and tangential restitution (measured ≤ 2.4e-13: the float64 rows
    the dump carries and the metrics' own arithmetic); dt vs dt/2 in float64 on every metric ≥ 1e-5 and ≥ 1e6
    times that metric's round-off (measured 1.4e-4 to 1.3e-3: the scheme's error)."""
    case = C.load(CASES / "oblique-lsd-wall.toml")
    d64 = CO.collide(case, "yade")
    assert d64.ok, d64.message
    d128 = CO.collide(case, f128, dt=d64.dt)
    assert d128.ok, d128.message
    half = CO.collide(case, "yade", dt=d64.dt / 2.0)
    assert half.ok, half.message
    a, b, h = d64.metrics(), d128.metrics(), half.metrics()
    round_off = _rel(a, b)
    scheme = _rel(a, h)
    print("round-off", round_off, "scheme", scheme)
    assert max(round_off.values()) <= 1e-12, round_off
    for k in METRICS:
        assert scheme[k] >= 1e-5 and scheme[k] >= 1e6 * max(round_off[k], 1e-16), (k, scheme, round_off)


@pytest.mark.engine("yade")
def test_precision_option_runs_yades_float128_build():
    """demcheck collide --engine yade --precision float128: Yade's float128 program, as the build yade@float128
    (its version read from it), beside the reference; --precision where no listed engine has that build is one
    line, exit 2, before any run."""
    import json
    import subprocess
    import sys

    def demcheck(*args):
        return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                              timeout=600)

    p = demcheck("collide", CASES / "hertz-wall.toml", "--engine", "reference,yade", "--precision", "float128",
                 "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert set(out) == {"reference", "yade@float128"} and out["yade@float128"]["engine_version"] == "2023.02a"
    assert out["yade@float128"]["metrics"]["restitution"] == pytest.approx(1.0, abs=1e-5)  # elastic Hertz, O(dt)
    for engines in ("lammps", "reference"):
        bad = demcheck("collide", CASES / "hertz-wall.toml", "--engine", engines, "--precision", "float128")
        assert bad.returncode == 2 and bad.stderr.strip().count("\n") == 0 and "--precision" in bad.stderr, bad.stderr
