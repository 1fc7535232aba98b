import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=40,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, max_examples=25)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"


def pytest_collection_modifyitems(config, items):
    """Engine tests run for real where the engine is installed. Under DEMCHECK_REQUIRE_ENGINES=1 a missing
    engine is a failure, never a skip."""
    from demcheck.engines import discovery

    import shutil

    require = os.environ.get("DEMCHECK_REQUIRE_ENGINES") == "1"
    browser = any(shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome"))
    for item in items:
        if item.get_closest_marker("browser") is not None and not browser and not require:
            item.add_marker(pytest.mark.skip(reason="no chromium (scripts/install-browser.sh)"))
        # every engine a test names (a test that needs several stacks one marker per engine)
        missing = [m.args[0] for m in item.iter_markers("engine") if discovery.find(m.args[0]) is None]
        if missing and not require:
            item.add_marker(pytest.mark.skip(reason=f"{missing[0]} not installed "
                                                    f"({discovery.how_to_install(missing[0])})"))


@pytest.fixture
def glass_pair():
    return CASES / "glass-pair.toml"


@pytest.fixture(autouse=True)
def _results_of_this_test_only(monkeypatch):
    """What demcheck computes itself is cached under a fingerprint of its source (comparisons/result_cache.py). A
    test that plants a fault in that code at run time (monkeypatch) changes no source file: it must not read a
    result another test stored. Each test gets a fingerprint of its own (its results are its own, cold then warm
    within it); tests/test_result_cache.py sets its own where it needs to."""
    import uuid

    from demcheck.comparisons import result_cache

    monkeypatch.setattr(result_cache, "code_fingerprint", lambda tag=f"test-{uuid.uuid4().hex[:12]}": tag)
