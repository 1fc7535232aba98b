"""The engines are found and report their versions (real binaries)."""

import pytest

from demcheck.engines import discovery


@pytest.mark.engine("lammps")
def test_lammps_is_found_with_its_version():
    info = discovery.find("lammps")
    assert info is not None, discovery.how_to_install("lammps")
    assert "22 Jul 2025" in info.version


@pytest.mark.engine("liggghts")
def test_liggghts_is_found_with_its_version():
    info = discovery.find("liggghts")
    assert info is not None, discovery.how_to_install("liggghts")
    assert info.version.startswith("LIGGGHTS-PUBLIC 3.8.0")


def test_missing_engine_is_none(monkeypatch):
    discovery.find.cache_clear()
    monkeypatch.setenv("DEMCHECK_LIGGGHTS", "/nonexistent/liggghts")
    try:
        assert discovery.find("liggghts") is None
    finally:
        discovery.find.cache_clear()


# ----------------------------------------------------------------------------- an engine that hangs

HANGING = """#!/bin/sh
# a fake engine: starts a child, records both pids, and never answers
sleep 300 &
echo $$ $! > "{pids}"
sleep 300
"""


def _alive(pid: int) -> bool:
    """The process exists and is not a zombie (a zombie has stopped; only its exit status is left)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_an_engine_whose_banner_hangs_is_given_up_and_killed_with_what_it_started(tmp_path, monkeypatch):
    fake, pids = tmp_path / "lmp", tmp_path / "pids"
    fake.write_text(HANGING.format(pids=pids))
    fake.chmod(0o755)
    monkeypatch.setenv("DEMCHECK_LAMMPS", str(fake))
    monkeypatch.setenv("DEMCHECK_DISCOVERY_TIMEOUT", "1")
    discovery.find.cache_clear()
    try:
        assert discovery.find("lammps") is None
        why = discovery.missing("lammps")
    finally:
        discovery.find.cache_clear()
    assert f"{fake} did not answer `-h` within 1 s" in why
    started = [int(p) for p in pids.read_text().split()]
    assert len(started) == 2 and not any(_alive(p) for p in started), "the fake engine or its child survived"


def test_the_discovery_timeout_is_short_by_default_and_checked(monkeypatch):
    from demcheck.errors import ConfigError

    monkeypatch.delenv("DEMCHECK_DISCOVERY_TIMEOUT", raising=False)
    assert discovery.timeout() <= 10
    for bad in ("nan", "inf", "-1", "0", "soon"):
        monkeypatch.setenv("DEMCHECK_DISCOVERY_TIMEOUT", bad)
        with pytest.raises(ConfigError, match="DEMCHECK_DISCOVERY_TIMEOUT = '.*': must be a number of seconds"):
            discovery.timeout()


def test_a_missing_engine_says_which_path_failed(monkeypatch):
    discovery.find.cache_clear()
    monkeypatch.setenv("DEMCHECK_LIGGGHTS", "/nonexistent/liggghts")
    try:
        assert discovery.find("liggghts") is None
        assert discovery.missing("liggghts").startswith("liggghts is not usable: /nonexistent/liggghts does not "
                                                        "start (No such file or directory)")
    finally:
        discovery.find.cache_clear()


@pytest.mark.engine("liggghts")
def test_discovery_writes_nothing_into_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    discovery.find.cache_clear()
    try:
        assert discovery.find("liggghts") is not None
    finally:
        discovery.find.cache_clear()
    assert list(tmp_path.iterdir()) == []  # LIGGGHTS writes log.liggghts for -h too: not here
