"""validate's benchmark catalogue is data (data/benchmarks.toml), apart from the judge, checked as it is read."""

from __future__ import annotations

import pytest

from demcheck.comparisons import validate as VA
from demcheck.errors import ConfigError


def test_the_shipped_catalogue_is_every_benchmark_with_its_limits_curves_and_quick_file():
    assert [b.name for b in VA.BENCHMARKS] == [f"chung-ooi-{i}" for i in range(1, 9)] + ["thornton"]
    assert VA.by_name("chung-ooi-3")[0].limits == (VA.GIVEN_E, VA.TTI_E)  # the judge's own Limit objects
    t5 = VA.by_name("chung-ooi-5")[0]
    assert [c.key for c in t5.curves] == ["", "", "fem", "fem"] and "finite-element" in t5.curves[2].why
    assert VA.by_name("chung-ooi-7")[0].final_spin and not VA.by_name("chung-ooi-6")[0].final_spin


def _catalogue(tmp_path, text: str):
    path = tmp_path / "benchmarks.toml"
    path.write_text("[notes]\nd = \"digitised\"\n\n" + text)
    return VA.catalogue(path)


GOOD = """[[benchmark]]
name = "b"
title = "B"
prefix = "chung-ooi-6-"
x = "beta1"
quantities = ["beta"]
limits = ["beta"]
quick = "chung-ooi-6-al-alloy-spring-sliding"
curves = [{ quantity = "beta", file = "chung-ooi-6-beta.dat", tolerance = 0.05, why = "β: {d}" }]
"""


def test_a_catalogue_is_read_with_its_notes(tmp_path):
    (b,) = _catalogue(tmp_path, GOOD)
    assert b.limits == (VA.BETA,) and b.curves[0].why == "β: digitised" and b.curves[0].tolerance == 0.05


@pytest.mark.parametrize("old, new, key", [
    ('limits = ["beta"]', 'limits = ["betta"]', "benchmark.0"),
    ("tolerance = 0.05", "tolerance = 0", "benchmark.0.curves.0.tolerance"),
    ('file = "chung-ooi-6-beta.dat"', 'file = "nosuch.dat"', "benchmark.0.curves.0.file"),
    ('quick = "chung-ooi-6-al-alloy-spring-sliding"', 'quick = "chung-ooi-6-nosuch"', "benchmark.0.quick"),
    ('x = "beta1"', 'x = "gamma"', "benchmark.0.x"),
])
def test_a_bad_catalogue_is_a_config_error_naming_its_key(tmp_path, old, new, key):
    with pytest.raises(ConfigError, match=f"^benchmarks.toml: {key} = "):
        _catalogue(tmp_path, GOOD.replace(old, new))
