"""The engines are found and report their versions (real binaries)."""

import pytest

from demcheck.engines import discovery


@pytest.mark.engine("lammps")
def test_lammps_is_found_with_its_version():
    info = discovery.find("lammps")
    assert info is not None, discovery.HOW_TO_INSTALL["lammps"]
    assert "22 Jul 2025" in info.version


@pytest.mark.engine("liggghts")
def test_liggghts_is_found_with_its_version():
    info = discovery.find("liggghts")
    assert info is not None, discovery.HOW_TO_INSTALL["liggghts"]
    assert info.version.startswith("LIGGGHTS-PUBLIC 3.8.0")


def test_missing_engine_is_none(monkeypatch):
    discovery.find.cache_clear()
    monkeypatch.setenv("DEMCHECK_LIGGGHTS", "/nonexistent/liggghts")
    try:
        assert discovery.find("liggghts") is None
    finally:
        discovery.find.cache_clear()
