"""The Python API (docs/api.md): its examples run as doctests here (a block after ``<!-- engine: NAME -->``
carries that engine's marker: it runs where the engine is installed); import demcheck stays cheap; bad input
is one ConfigError before any work."""

from __future__ import annotations

import doctest
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import demcheck
from demcheck.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "api.md"
BLOCK = re.compile(r"(?:<!-- engine: (\w+) -->\n)?```pycon\n(.*?)```", re.S)


def _blocks():
    text = DOC.read_text()
    out = []
    for k, m in enumerate(BLOCK.finditer(text)):
        line = text[:m.start(2)].count("\n")
        marks = [pytest.mark.engine(m.group(1))] if m.group(1) else []
        out.append(pytest.param(m.group(2), line, id=f"block{k}-line{line + 1}", marks=marks))
    return out


BLOCKS = _blocks()
GLOBS: dict = {}  # the examples build on each other, as a reader runs them in order


def test_the_doc_has_examples():
    assert len(BLOCKS) >= 6


@pytest.mark.parametrize("source, line", BLOCKS)
def test_api_md_examples(source, line, monkeypatch):
    monkeypatch.chdir(ROOT)
    test = doctest.DocTestParser().get_doctest(source, GLOBS, "docs/api.md", str(DOC), line)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    runner.run(test, out=lambda s: pytest.fail(s, pytrace=False), clear_globs=False)
    GLOBS.update(test.globs)
    assert runner.failures == 0


def test_a_failing_example_fails():
    test = doctest.DocTestParser().get_doctest(">>> 1 + 1\n3\n", {}, "x", "x", 0)
    runner = doctest.DocTestRunner()
    runner.run(test, out=lambda s: None)
    assert runner.failures == 1


def test_import_demcheck_is_cheap():
    code = ("import sys, demcheck; heavy = [m for m in ('pandas', 'numba', 'scipy', 'demcheck.api', "
            "'demcheck.engines.registry', 'demcheck.reference.collision') if m in sys.modules]; print(heavy); "
            "print(callable(demcheck.collide), 'pandas' in sys.modules)")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    assert p.returncode == 0, p.stderr
    assert p.stdout.split("\n")[:2] == ["[]", "True True"]


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError):
        demcheck.no_such_function


@pytest.mark.parametrize("call, key", [
    (lambda: demcheck.collide("cases/glass-pair.toml", source="lammpz"), "source"),
    (lambda: demcheck.collide("cases/glass-pair.toml", dt=-1.0), "dt"),
    (lambda: demcheck.collide("cases/glass-pair.toml", source="lammps", method="adaptive"), "method"),
    (lambda: demcheck.load("cases/glass-pair.toml", "contact.normal=tti"), "overrides"),
    (lambda: demcheck.load("cases/glass-pair.toml", ["contact.normal"]), "overrides"),
    (lambda: demcheck.load(42), "case"),
    (lambda: demcheck.load("cases/no-such.toml"), "CASE"),
    (lambda: demcheck.sweep("cases/glass-pair.toml", {}), "vary"),
    (lambda: demcheck.sweep("cases/glass-pair.toml", {"impact.speed": []}), "vary.impact.speed"),
    (lambda: demcheck.sweep("cases/glass-pair.toml", {"impact.speed": [1.0, -1.0]}), "impact.speed"),
    (lambda: demcheck.verify(["cases/glass-pair.toml"], engines=["lammpz"]), "engines"),
    (lambda: demcheck.verify(["cases/no-such.toml"]), "paths"),
    (lambda: demcheck.audit("x.in", speed=0.0), "speed"),
])
def test_bad_input_is_one_config_error(call, key, monkeypatch):
    monkeypatch.chdir(ROOT)
    with pytest.raises(ConfigError) as err:
        call()
    assert err.value.key == key, str(err.value)


def test_load_forms_agree(monkeypatch):
    monkeypatch.chdir(ROOT)
    a = demcheck.load("cases/glass-pair.toml", ["contact.normal=tti", "impact.speed=2.0"])
    b = demcheck.load("cases/glass-pair.toml", {"contact.normal": "tti", "impact.speed": 2.0})
    c = demcheck.load("cases/glass-pair.toml", contact__normal="tti", impact__speed=2.0)
    assert a.hash == b.hash == c.hash and a.contact.normal == "tti"
    assert demcheck.load(a) is a


def test_verify_reference_only_returns_the_results(monkeypatch, tmp_path):
    monkeypatch.chdir(ROOT)
    out = demcheck.verify(["cases/glass-pair.toml"], engines="none", cache=False)
    assert out["report"] is None and out["failed"] == 0
    (entry,) = out["cases"]
    assert entry["status"] == "ok" and set(entry["sources"]) == {"reference", "reference-verlet"}
    written = demcheck.verify(["cases/glass-pair.toml"], engines=(), report=tmp_path, cache=False)
    assert (Path(written["report"]) / "results.json").is_file()


def test_packing_universe_reads_a_lammps_style_dump(tmp_path):
    """demcheck.packing_universe: a hand-written two-atom dump read back with its radii, masses and positions
    (float32: each within |x|·2^-24 of the text)."""
    import numpy as np

    import demcheck

    (tmp_path / "d.txt").write_text(
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.01\n0 0.02\n"
        "ITEM: ATOMS id type radius mass x y z\n1 1 0.001 1.2e-05 0.002 0.003 0.0011\n"
        "2 1 0.0015 3.1e-05 0.004 0.0035 0.0031\n")
    u = demcheck.packing_universe(tmp_path / "d.txt")
    assert len(u.atoms) == 2
    np.testing.assert_array_equal(u.atoms.radii, [0.001, 0.0015])
    np.testing.assert_allclose(u.atoms.masses, [1.2e-05, 3.1e-05], rtol=1e-7)
    want = np.array([[0.002, 0.003, 0.0011], [0.004, 0.0035, 0.0031]])
    assert np.all(np.abs(u.atoms.positions - want) <= np.abs(want) * 2.0**-24)


def test_packing_universe_says_unknown_masses_without_a_mass_column(tmp_path):
    """A dump with no mass column: NaN masses (MDAnalysis alone would guess 1.0 from the atom names)."""
    import numpy as np

    import demcheck

    (tmp_path / "d.txt").write_text(
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp ff\n0 0.01\n0 0.01\n0 0.02\n"
        "ITEM: ATOMS id type radius x y z\n1 1 0.001 0.002 0.003 0.0011\n")
    u = demcheck.packing_universe(tmp_path / "d.txt")
    assert np.isnan(u.atoms.masses).all() and u.atoms.radii[0] == 0.001
