"""Discovery's leftovers of issue 32: a version read off a coloured banner is plain text; Yade's and Kratos' version
queries are judged by the process's exit, not by their output pipe's end (a helper left behind holds it open)."""

from __future__ import annotations

import os
import stat

import pytest

from demcheck.engines import discovery


def _script(path, text: str):
    path.write_text("#!/bin/sh\n" + text)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return path


@pytest.mark.engine("lammps")
def test_a_build_whose_banner_is_coloured_gives_its_version_without_the_escapes(tmp_path):
    exe = _script(tmp_path / "lmp", "printf 'Large-scale Atomic/Molecular Massively Parallel Simulator - "
                                    "\\033[1;32m22 Jul 2025\\033[0m \\033]0;title\\007- Update 4\\n'\n")
    try:
        (label,) = discovery.resolve(f"lammps@ansi={exe}", "--engines", required=False)
        version = discovery.find(label).version
    finally:
        discovery.drop("lammps@ansi")
    assert version == "22 Jul 2025 - Update 4"
    assert discovery.plain_version("\x1b[31m3.8\x1b[0m\x07") == "3.8"


def _lingering(tmp_path, answer: str):
    """An executable that answers its version query at once and leaves a child holding its stdout for 30 s."""
    return _script(tmp_path / "prog", f"(sleep 30) &\nprintf '{answer}'\nexit 0\n")


def test_yades_version_query_does_not_wait_on_its_pipe(tmp_path, monkeypatch):
    from demcheck.engines.yade import _Banner

    _lingering(tmp_path, "Yade version: 2023.02a\\n")
    os.rename(tmp_path / "prog", tmp_path / "yade-lingering")
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    found = _Banner(timeout=5.0).search("usage: yade-lingering [options] [ simulation.xml ]\n")
    assert found is not None and found.group(1) == "2023.02a"


def test_kratos_version_query_does_not_wait_on_its_pipe(tmp_path):
    from demcheck.engines.kratos import _Banner

    exe = _lingering(tmp_path, "KratosMultiphysics 10.4.4 KratosDEMApplication 10.4.4\\n")
    found = _Banner(timeout=5.0).search(f"usage: {exe} [option] ...\n")
    assert found is not None and found.group(1).startswith("10.4.4")
