"""Issue 33 item 5: a warm suite's packing panels come from the plot cache, as its case panels do (drawing them took
most of a warm report: 2–3 s a packing, benchmarks/results/bench_verify.txt); different data, or a different
source status, draws them again."""

from __future__ import annotations

import json

import pytest

from demcheck.comparisons.report import figures

from .test_report_html import _packing


def test_packing_panels_are_drawn_once_for_the_same_data(tmp_path, monkeypatch):
    monkeypatch.setitem(figures.PLOT_CACHE, "dir", str(tmp_path))
    drawn = []
    real = figures.packing_figure
    monkeypatch.setattr(figures, "packing_figure", lambda e: drawn.append(1) or real(e))
    entry = _packing()
    first = figures.packing_plots(entry)
    again = figures.packing_plots(json.loads(json.dumps(entry)))  # the same data, as results.json holds it
    assert again == first and len(drawn) == 1
    assert figures._png_ok(first)
    other = _packing({"reference": 400, "lammps": 300})
    figures.packing_plots(other)
    figures.packing_plots(_packing(absent={"yade": "failed"}))
    assert len(drawn) == 3


def test_without_a_cache_the_panels_are_drawn(monkeypatch):
    monkeypatch.setitem(figures.PLOT_CACHE, "dir", None)
    drawn = []
    real = figures.packing_figure
    monkeypatch.setattr(figures, "packing_figure", lambda e: drawn.append(1) or real(e))
    figures.packing_plots(_packing())
    figures.packing_plots(_packing())
    assert len(drawn) == 2
