"""The engine contract has no engine's conventions (issue 29 item 6): an engine of another family must say how it
is run, how its decks are guarded, how its errors are found and how its collision output is read; LAMMPS and LIGGGHTS share theirs in
engines/family.LammpsFamily, and no other engine inherits them."""

from __future__ import annotations

import re

import pytest

from demcheck.engines import registry
from demcheck.engines.base import Engine, PackageEngine, Style
from demcheck.engines.family import LammpsFamily


def _bare(**methods):
    body = {"name": "bare", "title": "Bare", "release": "bare 1", "how_to_install": "-", "rules": {},
            "banner": re.compile("x"), "style": Style("#000000", "o", "-"),
            "map": lambda self, model, params: None, "twin": lambda self, native, m, r: None,
            "summary": lambda self, native: "", "collision_deck": lambda self, case, *a, **k: None, **methods}
    return type("Bare", (Engine,), body)


OWN = ("argv", "check_deck", "errors", "read_collision")


@pytest.mark.parametrize("missing", OWN)
def test_an_engine_must_give_its_own_command_line_guard_errors_and_reader(missing):
    given = {m: (lambda self, *a, **k: None) for m in OWN if m != missing}
    with pytest.raises(TypeError, match=missing):
        _bare(**given)()
    _bare(**{m: (lambda self, *a, **k: None) for m in OWN})()


def test_only_lammps_and_liggghts_are_of_the_lammps_family():
    family = {e.name for e in map(registry.get, registry.names()) if isinstance(e, LammpsFamily)}
    assert family == {"lammps", "liggghts"}
    for name in ("yade", "kratos"):
        eng = registry.get(name)
        assert isinstance(eng, PackageEngine) and eng.argv("exe", "deck.py")[:1] == ["exe"]
        assert "-in" not in eng.argv("exe", "deck.py")


def test_an_engine_without_packings_says_so_when_asked_for_its_packing_output(tmp_path):
    from demcheck.errors import UnsupportedByEngine

    with pytest.raises(UnsupportedByEngine, match="kratos writes no packing output"):
        registry.get("kratos").read_packing(tmp_path, "")
