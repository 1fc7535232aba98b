"""A metric whose reference is 0 is judged in a unit of its own, not in "1 of its unit": the separation at pull-off
of a contact that lets go at δ = 0 (DMT, sjkr) is measured in the pull's overlap scale (engines/scenario.py
``overlap_scale``), so a separation a thousand times that scale is never "small" because it is small in metres."""

from __future__ import annotations

from demcheck.case import load
from demcheck.comparisons import suite, verdicts
from demcheck.engines.scenario import overlap_scale
from demcheck.resources import case_path


def test_a_zero_separation_is_judged_in_the_pulls_overlap_scale():
    case = load(case_path("suite/beyond-pull-off-sjkr.toml"))
    entry = suite.run_case(case, case_path("suite/beyond-pull-off-sjkr.toml"), suite.Options(engines=()), {}).to_json()
    scale = entry["scales"]["overlap"]
    assert scale == overlap_scale(case) and 0.0 < scale < 1e-4
    assert entry["sources"]["reference"]["metrics"]["separation_at_pull_off"] == 0.0
    off = 1000.0 * scale  # far outside the contact, still well under a metre
    assert abs(verdicts.scaled(off, 0.0, "separation_at_pull_off", entry["scales"]) - 1000.0) < 1e-9
    assert verdicts.scaled(off, 0.0, "separation_at_pull_off", {}) == off  # no scale: the old unit of 1 m


def test_a_nonzero_separation_keeps_its_own_scale():
    """JKR's separation is δ_f ≠ 0: its difference is relative to it, as before."""
    assert verdicts.scale("separation_at_pull_off", -2e-7, {"overlap": 5e-7}) == 2e-7
