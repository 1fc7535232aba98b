"""The engines are found and report their versions (real binaries)."""

import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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


# ----------------------------------------------------------------------------- version questions judged by their exit

# stand-ins that answer at once and leave a child holding their stdout (a wrapper that starts a helper): a question
# read to its pipe's end waits for the child (600 s), past its timeout
YADE_HOLDING = """#!/bin/sh
if [ "$1" = --version ]; then
  echo "Yade version: 2023.02a"
  sleep 600 &
  echo $! > "{pids}"
fi
"""
KRATOS_HOLDING = """#!/bin/sh
if [ "$1" = -h ]; then echo "usage: $0 [option] ... [-c cmd | -m mod | file | -] [arg] ..."; fi
if [ "$1" = -c ]; then
  echo "KratosMultiphysics 10.4.4 KratosDEMApplication 10.4.4"
  sleep 600 &
  echo $! > "{pids}"
fi
"""


def _program(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    path.chmod(0o755)
    return path


def test_yades_version_query_is_judged_by_its_exit_and_leaves_nothing_running(tmp_path, monkeypatch):
    from demcheck.engines import registry

    pids = tmp_path / "pids"
    _program(tmp_path / "bin" / "yade-standin", YADE_HOLDING.format(pids=pids))
    monkeypatch.setenv("PATH", f"{tmp_path / 'bin'}:{os.environ['PATH']}")
    # a build named directly prints Yade's usage line for -h: the program it names is asked --version
    usage = "usage: yade-standin [options] [ simulation.xml[.bz2] | script.py ... ]"
    match = registry.get("yade").banner.search(usage)
    assert match is not None and match.group(1) == "2023.02a"
    child = int(pids.read_text())
    assert not _alive(child), "the stand-in's child survived the version query"


def test_kratos_version_query_is_judged_by_its_exit_and_leaves_nothing_running(tmp_path, monkeypatch):
    pids = tmp_path / "pids"
    fake = _program(tmp_path / "bin" / "python-standin", KRATOS_HOLDING.format(pids=pids))
    monkeypatch.setenv("DEMCHECK_KRATOS", str(fake))
    discovery.find.cache_clear()
    try:
        info = discovery.find("kratos")
    finally:
        discovery.find.cache_clear()
    assert info is not None and info.version == "10.4.4 (DEMApplication 10.4.4)", discovery.missing("kratos")
    assert not _alive(int(pids.read_text())), "the stand-in's child survived the version query"


def test_liggghts_library_lookup_is_judged_by_its_exit(tmp_path, monkeypatch):
    """worker.library asks ``ldd``: a stand-in ldd that answers and leaves a child on its pipe."""
    from demcheck.engines.liggghts import worker

    pids = tmp_path / "pids"
    lib = tmp_path / "libliggghts.so.3.8.0"
    lib.write_text("")
    _program(tmp_path / "bin" / "ldd", f'#!/bin/sh\necho "\tlibliggghts.so.3 => {lib} (0x00007f)"\n'
                                        f'sleep 600 &\necho $! > "{pids}"\n')
    monkeypatch.setenv("PATH", f"{tmp_path / 'bin'}:{os.environ['PATH']}")
    worker.library.cache_clear()
    try:
        assert worker.library(str(tmp_path / "some-liggghts")) == str(lib)
    finally:
        worker.library.cache_clear()
    assert not _alive(int(pids.read_text()))


# ----------------------------------------------------------------------------- escape sequences in engine text

ESC = "\x1b"
COLOURED = {  # engine: (a stand-in's answer to each question discovery asks, the version it must read)
    "lammps": (f'echo "Large-scale Atomic/Molecular Massively Parallel Simulator - {ESC}[1;32m22 Jul 2025{ESC}[0m'
               f'{ESC}]0;pwned\a"', "22 Jul 2025"),
    "liggghts": (f'printf "{ESC}[1mLIGGGHTS (Version {ESC}[32mLIGGGHTS-PUBLIC 3.8.0{ESC}[0m, compiled)\\n"',
                 "LIGGGHTS-PUBLIC 3.8.0"),
    "yade": (f'[ "$1" = --version ] && printf "{ESC}[2J{ESC}[HYade version: {ESC}[33m2023.02a{ESC}[0m\\n"',
             "2023.02a"),
    "kratos": (f'[ "$1" = -h ] && printf "{ESC}[36musage: $0{ESC}[0m [option] ...\\n"\n'
               f'[ "$1" = -c ] && printf "KratosMultiphysics {ESC}[1m10.4.4{ESC}[0m KratosDEMApplication 10.4.4\\n"',
               "10.4.4 (DEMApplication 10.4.4)"),
}


@pytest.mark.parametrize("engine", sorted(COLOURED))
def test_a_coloured_banner_gives_a_plain_version(engine, tmp_path, monkeypatch):
    script, version = COLOURED[engine]
    fake = _program(tmp_path / "bin" / f"{engine}-standin", f"#!/bin/sh\n{script}\nexit 0\n")
    monkeypatch.setenv(f"DEMCHECK_{engine.upper()}", str(fake))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))  # Yade's wrapper
    discovery.find.cache_clear()
    try:
        info = discovery.find(engine)
    finally:
        discovery.find.cache_clear()
    assert info is not None, discovery.missing(engine)
    assert info.version == version


@pytest.mark.parametrize("raw,plain", [
    (f"{ESC}[1;31mERROR{ESC}[0m: bad", "ERROR: bad"),
    (f"{ESC}]0;title\a22 Jul 2025", "22 Jul 2025"),  # a window title, ended by BEL
    (f"{ESC}]2;title{ESC}\\v1", "v1"),  # ... by ST
    (f"{ESC}]0;never ended\nnext line", "\nnext line"),  # an unended string stops at its line's end
    (f"\x9b31mred\x9b0m", "red"),  # the 8-bit CSI
    (f"{ESC}(Bascii{ESC}=", "ascii"),  # two-character escapes
    ("a\r\nb\rc\n", "a\nb\nc\n"),
    (f"bell\a, back\b, lone {ESC}", "bell\\x07, back\\x08, lone \\x1b"),
    ("tab\tstays, ünïcode stays", "tab\tstays, ünïcode stays"),
])
def test_plain_text_removes_escape_sequences_and_shows_other_controls(raw, plain):
    from demcheck.engines.serve import plain_text

    assert plain_text(raw) == plain


@given(st.text(alphabet=st.characters(codec="utf-8"), max_size=200))
@settings(max_examples=300, derandomize=True, deadline=None)
def test_plain_text_never_lets_a_control_character_through(text):
    from demcheck.engines.serve import plain_text

    out = plain_text(text)
    assert all(ch in "\t\n" or (ch.isprintable() or ord(ch) >= 160) for ch in out), repr(out)


COLOURED_SERVER = """
import sys
from demcheck.engines import serve

class Coloured(serve.Server):
    def start(self):
        return "\\x1b[1;32m2023.02a\\x1b[0m"

    def run(self, deck):
        raise RuntimeError("\\x1b[31mERROR:\\x1b[0m the deck failed\\x1b]0;pwned\\x07")

sys.exit(serve.serve(Coloured(), []))
"""


def test_a_workers_version_and_errors_reach_demcheck_plain(tmp_path):
    """A worker (engines/serve.py) answers with the engine's version and errors as plain text, as discovery reads
    the version: a coloured one would not match discovery's (run.py refuses a worker whose version differs)."""
    import json
    import subprocess
    import sys

    request = json.dumps({"workdir": str(tmp_path), "deck": "in.deck"}) + "\n"
    done = subprocess.run([sys.executable, "-c", COLOURED_SERVER], input=request, capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    hello, answer = (json.loads(line) for line in done.stdout.splitlines())
    assert hello["ready"] and hello["version"] == "2023.02a"
    assert answer == {"ok": False, "error": "ERROR: the deck failed"}
