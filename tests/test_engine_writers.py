"""An engine's deck writers are handed the Engine object that runs them (issue 29, item 6): a deck is written
through the mapping of the engine (or build) it is written for, never through the engine registered under the
package's name. A test double whose ``map`` differs from its engine's, and a labelled build whose ``map`` differs
from the engine it wraps, must each find their own mapping in their decks; and no module of an engine package
looks its own engine up by name."""

from __future__ import annotations

import ast
import dataclasses
import inspect
from pathlib import Path

import pytest

from demcheck import case as C
from demcheck.engines import builds, registry, scenario
from demcheck.engines.base import APPROXIMATE, Mapping, PackageEngine

from .conftest import CASES

ENGINES = ("lammps", "liggghts", "yade", "kratos")
MARK = "mapped by the test double, not by the registered engine"
COLLISION = CASES / "suite" / "normal-hertz-pair.toml"
WALL = CASES / "hertz-wall.toml"
PACKING = CASES / "packing" / "poured.toml"
ROLLING = CASES / "suite" / "beyond-rolling-linear.toml"


def _marked(mp: Mapping) -> Mapping:
    """``mp`` with a reason and a native comment of the double's own (every deck header writes both)."""
    if mp.native is None:
        return mp
    native = dataclasses.replace(mp.native, comments=[*mp.native.comments, MARK])
    return Mapping(mp.engine, APPROXIMATE, [*mp.reasons, MARK], native, {**mp.keywords, MARK: "double"})


def _double(name: str):
    """A test double of the engine ``name``: a subclass whose ``map`` marks every mapping (named as a class of the
    engine's package, so that only its map differs from the engine's)."""
    engine_class = type(registry.get(name))

    class Double(engine_class):
        def map(self, model, contact_params):
            return _marked(super().map(model, contact_params))

    Double.name = f"{name}-double"
    Double.__module__ = engine_class.__module__
    return Double()


def test_a_subclass_defined_outside_its_engine_package_keeps_the_engine_parts():
    """A double defined in a test module writes its engine's decks (its parts are its engine package's)."""
    class Elsewhere(type(registry.get("lammps"))):
        name = "lammps-elsewhere"

    case = C.load(COLLISION)
    assert Elsewhere().collision_deck(case).text == registry.get("lammps").collision_deck(case).text


@pytest.mark.parametrize("name", ENGINES)
@pytest.mark.parametrize("path", [COLLISION, WALL], ids=["pair", "wall"])
def test_a_collision_deck_is_written_through_the_mapping_of_the_engine_that_writes_it(name, path):
    case = C.load(path)
    own = _double(name).collision_deck(case)
    registered = registry.get(name).collision_deck(case)
    assert MARK in own.text, f"the {name} double's deck was not written through its own map"
    assert MARK not in registered.text
    # the double changes comments only: the rest of the deck is the engine's
    strip = [line for line in own.text.splitlines() if MARK not in line and "mapping fidelity" not in line]
    assert strip == [line for line in registered.text.splitlines() if "mapping fidelity" not in line]


@pytest.mark.parametrize("name", ["lammps", "liggghts", "yade"])
def test_a_packing_deck_is_written_through_the_mapping_of_the_engine_that_writes_it(name):
    case = C.load(PACKING)
    assert MARK in _double(name).packing_deck(case).text
    assert MARK not in registry.get(name).packing_deck(case).text


@pytest.mark.parametrize("name", ["lammps", "liggghts", "kratos"])
def test_a_scenario_deck_is_written_through_the_mapping_of_the_engine_that_writes_it(name):
    """The rolling sphere's contact is the engine's collision mapping, extended by its scenario's slot."""
    case = C.load(ROLLING)
    double = _double(name)
    assert MARK in scenario.mapping(case, double).reasons
    assert MARK in scenario.deck(case, double).text
    assert MARK not in scenario.deck(case, name).text


@pytest.fixture
def build(tmp_path):
    """A labelled build of LAMMPS whose own ``map`` marks its mappings (the engine it wraps is untouched)."""
    exe = tmp_path / "lmp"
    exe.write_text("#!/bin/sh\n")
    exe.chmod(0o755)
    label = builds.register(builds.parse(f"lammps@double={exe}"))
    eng = registry.get(label)
    base_map = eng.base.map
    eng.map = lambda model, contact_params: _marked(base_map(model, contact_params))
    yield eng
    builds.unregister(label)


def test_a_build_is_handed_to_the_writers_as_itself(build):
    """A build's decks are the build's: its writers get the build (its map here), not the engine it wraps nor
    the engine registered under the engine's name."""
    assert isinstance(build, builds.BuildEngine) and build.name == "lammps@double"
    assert MARK in build.collision_deck(C.load(COLLISION)).text
    assert MARK in build.packing_deck(C.load(PACKING)).text
    assert MARK in scenario.deck(C.load(ROLLING), build.name).text
    assert MARK not in registry.get("lammps").collision_deck(C.load(COLLISION)).text


def test_a_build_runs_the_collision_deck_its_engine_writes_otherwise(build):
    """Handing the build changes nothing else: without a map of its own, a build writes the engine's deck to the
    byte."""
    del build.map
    case = C.load(COLLISION)
    assert build.collision_deck(case).text == registry.get("lammps").collision_deck(case).text


# ----------------------------------------------------------------------------- the writers' signature

WRITERS = {"deck": ["deck"], "packing": ["deck"], "scenario": ["mapping", "twin_laws", "deck", "read"]}


@pytest.mark.parametrize("name", ENGINES)
def test_every_writer_of_an_engine_package_takes_the_engine_first(name):
    import importlib

    eng = registry.get(name)
    assert isinstance(eng, PackageEngine)
    for part, functions in WRITERS.items():
        try:
            module = importlib.import_module(f"{type(eng).__module__}.{part}")
        except ModuleNotFoundError:
            continue
        for fn in functions:
            first = next(iter(inspect.signature(getattr(module, fn)).parameters))
            assert first == "engine", f"{module.__name__}.{fn} takes {first!r} first, not the engine"


LOOKUPS = ("contact_mapping", "pair_mapping", "map_model")


def _lookups_by_name(source: str) -> list[str]:
    """Calls in ``source`` that name an engine by a string (``contact_mapping(case, "lammps")``) or look one up
    in the registry."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Call):
            continue
        func = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
        text = ast.unparse(node.func)
        strings = [a for a in node.args if isinstance(a, ast.Constant) and isinstance(a.value, str)]
        if (func in LOOKUPS and strings) or text == "registry.get":
            out.append(f"{node.lineno}: {ast.unparse(node)[:100]}")
    return out


def test_no_engine_package_looks_its_own_engine_up_by_name():
    import demcheck

    root = Path(demcheck.__file__).parent
    found = []
    for path in sorted((root / "engines").glob("*/*.py")):
        found += [f"{path.relative_to(root)}:{hit}" for hit in _lookups_by_name(path.read_text(encoding="utf-8"))]
    assert not found, "\n".join(found)


def test_the_rule_sees_a_lookup_by_name():
    assert _lookups_by_name('mp = contact_mapping(case, "lammps", native)\n')
    assert _lookups_by_name('pm = mapping.pair_mapping(case, "yade", 0, None)\n')
    assert _lookups_by_name('eng = registry.get("kratos")\n')
    assert not _lookups_by_name("mp = contact_mapping(case, engine, native)\n")
