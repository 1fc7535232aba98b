"""The LIGGGHTS, Yade and Kratos workers (engines/<name>/worker.py on engines/serve.py, run by engines/run.py): one
process per engine that loads it once and runs case after case gives the numbers of a process per run; runs in
it do not see each other; an engine's error is EngineFailed with the log's tail and the next run is served; a
killed worker is replaced. (Timeouts and interrupts are the machinery's, engine-neutral: test_lammps_worker.py.)

Byte-identical, every engine and case here: the worker runs the same code on the same deck text as the process
— LIGGGHTS's executable and its worker load one libliggghts.so.3; Yade's worker is the same yade executable
running the same script in a copy of the same namespace; Kratos's worker is the same Python importing the same
modules — in one thread each (OMP_NUM_THREADS=1), so every dumped value (%.17g) is the same number."""

from __future__ import annotations

import math
import os
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

from demcheck.case import load
from demcheck.engines import collide as collisions, discovery, registry, run as runner
from demcheck.errors import EngineFailed, EngineInterrupted

from .conftest import CASES
from .test_lammps_worker import _alive, _clean  # noqa: F401 - _clean: the same autouse fixture (no worker left)

CASE_FILES = {
    "liggghts": ["glass-pair.toml", "oblique-lsd-wall.toml", "hertz-wall.toml"],
    "yade": ["glass-pair.toml", "oblique-lsd-wall.toml", "hertz-wall.toml"],
    "kratos": ["glass-pair.toml", "hertz-wall.toml", "lsd-energy-pair.toml"],
}


def _engines():
    return [pytest.param(e, marks=pytest.mark.engine(e)) for e in CASE_FILES]


def _engine_cases():
    return [pytest.param(e, n, marks=pytest.mark.engine(e), id=f"{e}-{n}") for e, names in CASE_FILES.items()
            for n in names]


@pytest.fixture(scope="module")
def alone(tmp_path_factory):
    """A case's collision in a process of its own (the subprocess path), run once per module: (Result, dump)."""
    done = {}
    root = tmp_path_factory.mktemp("alone")

    def get(engine: str, name: str):
        if (engine, name) not in done:
            wd = root / f"{engine}-{name}"
            res = collisions.collide(load(CASES / name), engine, workdir=wd)
            done[engine, name] = res, (wd / "dump.txt").read_bytes()
        return done[engine, name]

    return get


def _same_metrics(a, b) -> None:
    ma, mb = a.metrics(), b.metrics()
    assert ma.keys() == mb.keys()
    for k in ma:
        assert ma[k] == mb[k] or (math.isnan(ma[k]) and math.isnan(mb[k])), k


def _in_worker(engine: str, name: str, wd: Path):
    res = collisions.collide(load(CASES / name), engine, workdir=wd, worker=True)
    return res, (wd / "dump.txt").read_bytes()


# ----------------------------------------------------------------------------- the same numbers


@pytest.mark.parametrize("engine,name", _engine_cases())
def test_the_worker_gives_the_bytes_of_a_process_per_run(engine, name, alone, tmp_path):
    sub, sub_dump = alone(engine, name)
    wrk, wrk_dump = _in_worker(engine, name, tmp_path / "worker")
    assert sub.status == wrk.status == "ok", (sub.message, wrk.message)
    assert wrk.engine_version == sub.engine_version == discovery.find(engine).version
    assert wrk_dump == sub_dump
    _same_metrics(sub, wrk)
    assert len(runner.workers()) == 1


@pytest.mark.parametrize("engine", _engines())
def test_runs_in_one_worker_do_not_see_each_other(engine, alone, tmp_path):
    """Case after case in one worker (LIGGGHTS: ``clear``; Yade: a fresh namespace and ``O.reset()``; Kratos: a
    fresh namespace, its own Model, collected): each gives the bytes it gives alone, in a process of its own."""
    a, b, c = CASE_FILES[engine]
    pids = set()
    for i, name in enumerate([a, b, a, c, b, a]):
        _, dump = _in_worker(engine, name, tmp_path / f"{i}-{name}")
        assert dump == alone(engine, name)[1], (i, name)
        pids.update(runner.workers())
    assert len(pids) == 1  # one worker ran all six


def test_the_worker_reports_its_loop_time():
    """RunOutput.loop_time: the log's ``Loop time of`` where the engine prints it, else the worker's own measure
    (Yade: the script; Kratos: the stage's solution loop); a process of Yade or Kratos has none."""
    log = "Loop time of 0.25 on 1 procs for 10 steps\nLoop time of 0.5 on 1 procs for 10 steps\n"
    assert runner.loop_time("lammps", log) == 0.75
    assert runner.loop_time("liggghts", log, 9.0) == 0.75
    assert runner.loop_time("lammps", "no loop here", 0.125) == 0.125
    assert runner.loop_time("lammps", "no loop here") is None
    assert runner.loop_time("yade", log, 0.125) == 0.125  # the LAMMPS family's log line is no Yade's


@pytest.mark.parametrize("engine", _engines())
def test_each_worker_run_has_a_loop_time(engine, tmp_path):
    text, files = _first_deck(engine)
    out = runner.run(engine, text, files=files, workdir=tmp_path / "w", worker=True)
    assert out.loop_time is not None and out.loop_time > 0


# ----------------------------------------------------------------------------- errors and dead workers


def _first_deck(engine: str) -> tuple[str, dict]:
    """The deck of the engine's first case: (text, files)."""
    deck = collisions.deck(load(CASES / CASE_FILES[engine][0]), engine)
    return deck.text, dict(deck.files)


def _bad(engine: str):
    """A deck the engine's guard admits and the engine refuses, and what the error names."""
    good = _first_deck(engine)
    text, files = good
    files = dict(files)
    if engine == "liggghts":
        text = text.replace("model hertz/stiffness", "model hertz/nosuch")
        why = "Invalid model specified"
    elif engine == "yade":
        text = text.replace("material=0", "material=7", 1)  # no such material
        why = "IndexError: Material id out of range."
    else:
        # an element on a node that does not exist
        element = "Begin Elements SphericParticle3D\n"
        files["caseDEM.mdpa"] = files["caseDEM.mdpa"].replace(f"{element}2 2 2\n", f"{element}2 2 9\n")
        why = "is not found"
    assert (text, files) != good
    return text, files, why


@pytest.mark.parametrize("engine", _engines())
def test_an_engine_error_is_engine_failed_with_the_log_tail_and_the_next_run_is_served(engine, alone, tmp_path):
    text, files, why = _bad(engine)
    with pytest.raises(EngineFailed) as in_process:
        runner.run(engine, text, files=files, workdir=tmp_path / "process")
    name = CASE_FILES[engine][0]
    _in_worker(engine, name, tmp_path / "before")
    [pid] = runner.workers()
    with pytest.raises(EngineFailed) as in_worker:
        runner.run(engine, text, files=files, workdir=tmp_path / "worker", worker=True)
    message = str(in_worker.value)
    assert not isinstance(in_worker.value, (runner.EngineTimeout, EngineInterrupted))
    assert message.startswith(f"{engine} failed (") and f"work directory kept: {tmp_path / 'worker'}" in message
    assert why in message.splitlines()[0]
    # as run.py reads it: LIGGGHTS's exit sometimes writes its message a second time, garbled (its executable
    # too, 4 runs in 25 measured)
    log = max((p.read_text(errors="replace") for p in (tmp_path / "worker" / "log.txt",
                                                       tmp_path / "worker" / "screen.txt") if p.exists()), key=len)
    assert why in log and message.endswith(runner.log_tail(log))  # the log's tail after the first line
    if engine == "liggghts":
        # its library ends the process on an error (exit(1)): the same first line as the process's, and a new
        # worker serves the next run
        assert message.splitlines()[0] == str(in_process.value).splitlines()[0].replace(
            str(tmp_path / "process"), str(tmp_path / "worker"))
        assert "ERROR: Invalid model specified" in message
        assert not _alive(pid)
    else:  # a Python exception: its traceback is the run's screen, and the worker goes on
        assert log.startswith("Traceback (most recent call last)")
        assert runner.workers() == [pid]
    _, dump = _in_worker(engine, name, tmp_path / "after")
    assert dump == alone(engine, name)[1]


def _long_deck(engine: str):
    """A run that outlasts the test (a billion steps; no dump where the guard lets it go)."""
    text, files = _first_deck(engine)
    if engine == "liggghts":
        lines = [ln for ln in text.splitlines() if not ln.startswith("dump")]
        text = "\n".join(lines) + "\n"
        pairs = [("thermo 121", "thermo 1000000"), ("run 1217", "run 1000000000"),
                 ("timestep 4.754254083356427e-08", "timestep 1e-15")]
    elif engine == "yade":
        text = "\n".join(ln for ln in text.splitlines() if "out.write" not in ln) + "\n"
        pairs = [("STEPS = 1217", "STEPS = 1000000000")]
    else:
        pairs = [("'steps': 1217,", "'steps': 1000000000,")]
    for old, new in pairs:
        assert old in text, old
        text = text.replace(old, new)
    return text, files


@pytest.mark.parametrize("engine", _engines())
def test_a_killed_worker_is_replaced(engine, alone, tmp_path):
    name = CASE_FILES[engine][0]
    _in_worker(engine, name, tmp_path / "a")
    [pid] = runner.workers()
    os.kill(pid, signal.SIGKILL)  # while idle: the next run starts another, with no error
    while _alive(pid):
        time.sleep(0.01)
    _, dump = _in_worker(engine, name, tmp_path / "b")
    assert dump == alone(engine, name)[1]
    [second] = runner.workers()
    assert second != pid

    # killed during a run, by something other than an interrupt (a fault of the worker, not of the deck): the run
    # is made once more on a fresh worker; killed there too, it failed; the next one is served
    text, files = _long_deck(engine)
    taken = tmp_path / "c" / "screen.txt"  # the worker's first act on a run
    killed = []

    def kill_each_taken():
        for attempt in range(2):
            deadline = time.monotonic() + 120
            while not (taken.exists() and runner.workers()) and time.monotonic() < deadline:
                time.sleep(0.02)
            [taker] = runner.workers()
            os.kill(taker, signal.SIGKILL)
            killed.append(taker)
            while not attempt and taken.exists() and time.monotonic() < deadline:  # the second attempt starts afresh
                time.sleep(0.02)

    killer = threading.Thread(target=kill_each_taken)
    killer.start()
    with pytest.raises(EngineFailed, match=r"its worker process ended: killed by SIGKILL") as err:
        runner.run(engine, text, files=files, workdir=tmp_path / "c", timeout=300, worker=True)
    killer.join()
    assert "a first attempt, on another process, had failed too: its worker process ended: killed by SIGKILL" in str(
        err.value)
    assert taken.exists() and not isinstance(err.value, EngineInterrupted) and killed[0] == second
    _, dump = _in_worker(engine, name, tmp_path / "d")
    assert dump == alone(engine, name)[1]
    assert runner.workers() and runner.workers()[0] not in (pid, *killed)


# ----------------------------------------------------------------------------- which runs use it


@pytest.mark.engine("liggghts")
def test_the_liggghts_worker_loads_the_library_its_executable_loads(tmp_path):
    from demcheck.engines.liggghts import worker

    exe = discovery.find("liggghts").executable
    argv = registry.get("liggghts").worker_argv(exe)
    assert argv[:3] == [sys.executable, "-m", worker.MODULE]
    library = Path(argv[argv.index("--library") + 1])
    assert library.name.startswith("libliggghts.so") and library.exists()
    # not a dynamic executable, or one that loads no LIGGGHTS library: a process per run
    fake = tmp_path / "liggghts"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    assert registry.get("liggghts").worker_argv(str(fake)) is None
    assert registry.get("liggghts").worker_argv("/usr/bin/true") is None


def test_the_kratos_worker_serves_only_this_python(tmp_path):
    kratos = registry.get("kratos")
    assert kratos.worker_argv(sys.executable) == [sys.executable, "-m", "demcheck.engines.kratos.worker"]
    assert kratos.worker_argv("/usr/bin/true") is None
    other = tmp_path / "python"
    other.symlink_to(Path(sys.executable).resolve())  # the same binary outside this environment: another Python
    assert kratos.worker_argv(str(other)) is None


def test_the_yade_worker_is_the_executable_discovery_found():
    yade = registry.get("yade")
    argv = yade.worker_argv("/opt/yade/bin/yade-float128")
    assert argv[:3] == ["/opt/yade/bin/yade-float128", "-x", "-n"] and argv[3].endswith("worker.py")


F128 = Path("/usr/bin/yade-float128")


@pytest.mark.engine("yade")
def test_a_float128_build_runs_in_its_own_worker(tmp_path):
    """``--precision float128`` (the yade@f128 build): its worker is yade-float128, with the bytes of its process."""
    if not F128.exists():
        pytest.skip(f"{F128} is not installed")
    [label] = discovery.resolve(f"yade@f128={F128}")
    try:
        case = load(CASES / "oblique-lsd-wall.toml")
        sub = collisions.collide(case, label, workdir=tmp_path / "process")
        wrk = collisions.collide(case, label, workdir=tmp_path / "worker", worker=True)
        assert sub.ok and wrk.ok and wrk.engine_version == sub.engine_version == "2023.02a"
        assert (tmp_path / "worker" / "dump.txt").read_bytes() == (tmp_path / "process" / "dump.txt").read_bytes()
        [pid] = runner.workers()  # its own worker: yade-float128's, not the float64 build's
        assert str(F128) in Path(f"/proc/{pid}/cmdline").read_bytes().decode().split("\0")
    finally:
        runner.shutdown_workers()
        discovery.drop(label)


@pytest.mark.parametrize("engine", _engines())
def test_a_sweep_runs_the_engine_in_its_worker_with_the_numbers_of_a_process_per_run(engine):
    """demcheck sweep --engine NAME (here the API's sweep, which the command calls): its points run in the worker
    (one is left idle afterwards) and give exactly what collide gives with a process per run."""
    import demcheck

    name = CASE_FILES[engine][0]
    table = demcheck.sweep(demcheck.load(CASES / name), {"impact.speed": [0.5, 1.0]}, source=engine)
    assert len(runner.workers()) == 1  # the sweep's worker, idle now
    runner.shutdown_workers()
    for speed, (_, row) in zip((0.5, 1.0), table.iterrows()):
        alone = collisions.collide(demcheck.load(CASES / name, {"impact.speed": speed}), engine).metrics()
        assert row["restitution"] == alone["restitution"] and row["contact_time"] == alone["contact_time"]


_KILLED_PARENT = """
import os, signal, sys
from demcheck.case import load
from demcheck.engines import collide, run
collide.collide(load(sys.argv[1]), sys.argv[2], worker=True)
print(*run.workers(), flush=True)
os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.parametrize("engine", _engines())
def test_the_worker_dies_with_demcheck(engine, tmp_path):
    """demcheck killed outright (no exit handler runs): its worker dies with it (PR_SET_PDEATHSIG, set by the
    worker itself — inside Yade's process for Yade's)."""
    import subprocess

    done = subprocess.run([sys.executable, "-c", _KILLED_PARENT, str(CASES / CASE_FILES[engine][0]), engine],
                          cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == -signal.SIGKILL, done.stderr[-3000:]
    [pid] = map(int, done.stdout.split())
    deadline = time.monotonic() + 60
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(pid), f"{engine}'s worker {pid} outlived demcheck"


# ----------------------------------------------------------------------------- the worker, or else a process


@pytest.mark.parametrize("engine", _engines())
def test_a_deck_error_in_the_worker_is_run_again_as_a_process_and_both_are_kept(engine, tmp_path):
    """run(worker=OR_PROCESS) (the suite's engine runs): a run its worker fails is made once more as a process of
    its own, whose failure is the run's; the worker attempt's files are kept beside it and its reason named."""
    text, files, why = _bad(engine)
    wd = tmp_path / "w"
    with pytest.raises(EngineFailed) as err:
        runner.run(engine, text, files=files, workdir=wd, worker=runner.OR_PROCESS)
    message = str(err.value)
    assert message.startswith(f"{engine} failed (") and why in message  # the process's error, its log's tail
    assert f"(the run in {engine}'s worker had failed first: " in message
    kept = wd / runner.WORKER_ATTEMPT
    assert str(kept) in message
    assert any(why in p.read_text(errors="replace") for p in kept.iterdir() if p.is_file())
    assert (wd / runner.OUTPUT).exists()  # the process's own output, beside what the worker wrote


_FAKE_WORKER = """
import json, os, sys
how, version = sys.argv[1], sys.argv[2]
if how == "not-started":
    sys.exit(3)
print(json.dumps({"ready": True, "version": version}), flush=True)
request = json.loads(sys.stdin.readline())
with open(os.path.join(request["workdir"], "screen.txt"), "w") as f:
    f.write("the worker's last words\\n")
os._exit(9)
"""


@pytest.mark.parametrize("how", ["not-started", "died"])
@pytest.mark.parametrize("engine", _engines())
def test_a_worker_that_fails_gives_the_run_to_a_process_with_the_same_bytes(engine, how, alone, tmp_path,
                                                                              monkeypatch):
    """A worker that does not start, or dies during a run (a stand-in for the engine's worker, told the version
    discovery read): the run is made as a process and gives the bytes of a process per run, with a warning that
    names the worker's failure; a worker that died keeps what it wrote in WORKER_ATTEMPT."""
    eng = registry.get(engine)
    script = tmp_path / "fake_worker.py"
    script.write_text(_FAKE_WORKER)
    version = discovery.find(engine).version
    monkeypatch.setattr(type(eng), "worker_argv", lambda self, exe: [sys.executable, str(script), how, version])
    name = CASE_FILES[engine][0]
    wd = tmp_path / "run"
    res = collisions.collide(load(CASES / name), engine, workdir=wd, worker=runner.OR_PROCESS)
    assert res.status == "ok", res.message
    assert (wd / "dump.txt").read_bytes() == alone(engine, name)[1]
    _same_metrics(res, alone(engine, name)[0])
    [note] = [w for w in res.meta["warnings"] if "the run in its worker failed" in w]
    assert ("did not start" if how == "not-started" else "its worker process ended: exit code 9") in note
    assert "it was run again as a process" in note
    if how == "died":
        assert (wd / runner.WORKER_ATTEMPT / "screen.txt").read_text() == "the worker's last words\n"


@pytest.mark.engine("lammps")
@pytest.mark.engine("yade")
def test_verify_runs_the_engines_in_their_workers_and_ends_them(tmp_path, monkeypatch):
    """The suite's engine runs go through one worker per engine (started on the first run, serving the rest), with
    the numbers of a process per run, and no worker is left once the suite has ended."""
    import demcheck

    started = []
    real = runner._start_worker

    def counted(engine, argv, info):
        w = real(engine, argv, info)
        started.append((engine, w.proc.pid))
        return w

    monkeypatch.setattr(runner, "_start_worker", counted)
    names = ["glass-pair.toml", "hertz-wall.toml"]
    out = demcheck.verify([CASES / n for n in names], engines="lammps,yade", cache=False, report=None)
    assert sorted(e for e, _ in started) == ["lammps", "yade"]  # one each, for both cases
    assert runner.workers() == [] and not any(_alive(pid) for _, pid in started)
    for case, name in zip(out["cases"], names):
        for engine in ("lammps", "yade"):
            got = case["sources"][engine]
            assert got["status"] == "ok", got
            alone = collisions.collide(load(CASES / name), engine).metrics()
            assert got["metrics"].keys() == alone.keys()
            for k, v in alone.items():
                assert got["metrics"][k] == v or (math.isnan(v) and math.isnan(got["metrics"][k])), (name, engine, k)
