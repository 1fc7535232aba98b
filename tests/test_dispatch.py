"""Campaigns through Dask distributed (comparisons/dispatch.py): a local cluster gives what one process gives; an
existing cluster (a scheduler and a worker started apart, on localhost) runs the cases, a worker without an engine
says so, and the client stores the cache entries; a bad --scheduler is one line and exit 2 before any work; a
terminal's Ctrl-C leaves no worker and no engine behind. The expected values come from the same work done in one
process (--jobs 1), never from the code under test."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

import demcheck as demcheck_api
from demcheck import api
from demcheck.comparisons import bench, calibrate, stress, suite, sweep
from demcheck.comparisons.dispatch import Campaign
from demcheck.engines import discovery
from demcheck.engines.cache import Cache
from demcheck.errors import EngineNotFound
from demcheck.io import plain

from .conftest import CASES, ROOT
from .helpers import group_alive, proc_stat
from .test_interrupts import FAKE_LAMMPS, _descendants, _start, _wait_for_engine
from .test_native import TSUJI, _case

SMALL = [CASES / "glass-pair.toml", CASES / "hertz-wall.toml", CASES / "hls-constant-pair.toml"]
FAKE_LIGGGHTS = """#!/bin/sh
echo "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0, compiled 2026-01-01 by a test: never run)"
"""


def demcheck(*args, env=None, cwd=None, timeout=600):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=cwd or ROOT, timeout=timeout)


def verdicts(summary: dict) -> list:
    """Each case's verdict and every comparison (source, metric, verdict, value, reason), in report order."""
    return plain([(c["case"], c["verdict"], [(k["source"], k["metric"], k["verdict"], k["value"], k["reason"])
                                             for k in c["comparisons"]]) for c in summary["cases"]])


def entries(cache_dir: Path) -> set[str]:
    return {p.name for p in Path(cache_dir).rglob("*.npz")}


def _executable(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    path.chmod(0o755)
    return path


# ----------------------------------------------------------------------------- a local cluster


def test_a_local_cluster_gives_the_verdicts_of_one_process(tmp_path):
    one = suite.run_suite(SMALL, tmp_path / "one", suite.Options(engines=(), jobs=1, cache=None), quiet=True).to_json()
    two = suite.run_suite(SMALL, tmp_path / "two", suite.Options(engines=(), jobs=2, cache=None), quiet=True).to_json()
    assert [c["case"] for c in two["cases"]] == ["glass-pair", "hertz-wall", "hls-constant-pair"]
    assert verdicts(two) == verdicts(one) and two["partial"] is False


def test_a_local_cluster_draws_the_case_panels_where_the_cases_ran(tmp_path, monkeypatch):
    """On a local cluster each file's first case draws its force curves into the plot cache on its worker, so the
    report, written in this process after the last case, draws none of them: here drawing one raises (monkeypatched
    in this process only — the workers are processes of their own), and the report still shows every case's
    curves, none "could not be drawn". One process (--jobs 1) draws them in its report, as before."""
    from demcheck.comparisons.report import figures

    def refused(*a, **k):
        raise RuntimeError("drawn in the client")

    monkeypatch.setattr(figures, "case_figure", refused)
    two = suite.run_suite(SMALL, tmp_path / "two", suite.Options(engines=(), jobs=2, cache=Cache(tmp_path / "c2")),
                          quiet=True)
    page = (Path(two.report) / "report.html").read_text()
    assert "could not be drawn" not in page and page.count("force curves of ") == len(SMALL)
    assert len(list((tmp_path / "c2" / "plots").glob("*.b64"))) >= len(SMALL)
    one = suite.run_suite(SMALL, tmp_path / "one", suite.Options(engines=(), jobs=1, cache=Cache(tmp_path / "c1")),
                          quiet=True)
    page = (Path(one.report) / "report.html").read_text()
    assert page.count("the force curves of") == len(SMALL) and "drawn in the client" in page


@pytest.mark.engine("lammps")
def test_a_local_cluster_runs_lammps_and_the_client_stores_its_runs(tmp_path, monkeypatch):
    from demcheck.comparisons import result_cache
    from demcheck.engines import cache as cache_mod

    # the reference's results too (comparisons/result_cache.py): keyed by the source's own fingerprint, as the
    # workers (other processes) key theirs
    monkeypatch.setattr(result_cache, "code_fingerprint", cache_mod.code_fingerprint)

    def run(jobs, where):
        opts = suite.Options(engines=("lammps",), jobs=jobs, cache=Cache(tmp_path / where))
        return suite.run_suite(SMALL, tmp_path / f"r-{where}", opts, quiet=True).to_json()

    one, two = run(1, "cache-one"), run(2, "cache-two")
    assert verdicts(two) == verdicts(one)
    assert {c["sources"]["lammps"]["status"] for c in two["cases"]} == {"ok", "not expressible"}
    # the workers' runs are in the client's cache, the same entries one process writes; a second campaign reads them
    assert entries(tmp_path / "cache-two") == entries(tmp_path / "cache-one") != set()
    assert two["cache"]["misses"] == one["cache"]["misses"] == len(entries(tmp_path / "cache-one"))
    again = run(2, "cache-two")
    assert again["cache"] == {"dir": str(tmp_path / "cache-two"), "hits": two["cache"]["misses"], "misses": 0}
    assert verdicts(again) == verdicts(one)


def _cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


@pytest.mark.engine("lammps")
def test_a_local_cluster_runs_the_engine_in_one_worker_per_dask_worker_and_ends_them(tmp_path):
    """verify --jobs 2: each Dask worker runs its LAMMPS decks in a LAMMPS worker of its own (at most one per Dask
    worker, started there), with the verdicts of one process, and none is left once the campaign has closed."""
    import threading

    seen, done = {}, threading.Event()

    def watch():  # the LAMMPS workers under this process (under the cluster's worker processes)
        while not done.is_set():
            for pid in _descendants(os.getpid()):
                if "demcheck.engines.lammps.worker" in (line := _cmdline(pid)):
                    seen.setdefault(pid, line)
            time.sleep(0.05)

    watcher = threading.Thread(target=watch)
    watcher.start()
    try:
        opts = suite.Options(engines=("lammps",), jobs=2, cache=None)
        two = suite.run_suite(SMALL + [CASES / "oblique-lsd-wall.toml"], tmp_path / "r", opts, quiet=True).to_json()
    finally:
        done.set()
        watcher.join()
    one = suite.run_suite(SMALL + [CASES / "oblique-lsd-wall.toml"], tmp_path / "one",
                          suite.Options(engines=("lammps",), jobs=1, cache=None), quiet=True).to_json()
    assert verdicts(two) == verdicts(one)
    assert 1 <= len(seen) <= 2, seen  # three LAMMPS runs, in at most one worker per Dask worker
    assert all(f"--parent {os.getpid()}" not in line for line in seen.values())  # started on the Dask workers
    assert not [pid for pid in seen if proc_stat(pid) is not None and proc_stat(pid)[0] != "Z"]


_NOISY = """
from demcheck.comparisons.dispatch import Campaign

def noisy(cache=None):
    print("a worker's noise")
    return 1

if __name__ == "__main__":
    with Campaign(2) as campaign:
        assert [v for _, v in campaign.completed(noisy, [(0, ())])] == [1]
    print("the client's own line")
"""


def test_a_local_cluster_keeps_stdout_for_the_client(tmp_path):
    """stdout is demcheck's (--json): what a local cluster's worker prints goes to stderr."""
    (tmp_path / "noisy.py").write_text(_NOISY)
    p = subprocess.run([sys.executable, "noisy.py"], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    assert p.stdout == "the client's own line\n" and "a worker's noise" in p.stderr


@pytest.fixture(scope="module")
def local():
    with Campaign(2) as campaign:
        yield campaign


def test_sweep_stress_and_bench_on_a_local_cluster_give_what_one_process_gives(local):
    points = api._sweep_points(CASES / "glass-pair.toml", {"impact.speed": [0.5, 1, 2]}, [])  # api.sweep's grid
    table = sweep.run_sweep(points, campaign=local)
    assert table.equals(sweep.run_sweep(points)) and list(table["impact.speed"]) == [0.5, 1.0, 2.0]

    raw = stress.read_table(CASES / "suite" / "normal-hertz-wall.toml")
    case = api.load(raw)
    got = stress.stress_case(raw, case, engines=(), only=["speed"], campaign=local).summary()
    assert got == stress.stress_case(raw, case, engines=(), only=["speed"]).summary() and len(got["limits"]) == 3

    def errors(result):  # the timings differ from run to run; the errors and statuses may not
        return plain([(p.source, p.steps_per_contact, p.rtol, p.errors, p.status) for p in result.points])

    b = bench.bench_case(case, engines=(), steps=(10, 20), rtols=(1e-6,), campaign=local)
    assert errors(b) == errors(bench.bench_case(case, engines=(), steps=(10, 20), rtols=(1e-6,)))
    assert [p.source for p in b.points] == ["reference-adaptive", "reference-verlet", "reference-verlet"]


@pytest.mark.engine("lammps")
def test_calibrate_confirms_on_a_local_cluster_what_it_confirms_here(local):
    case = demcheck_api.load(_case({"lammps": {"pair_coeff": TSUJI}}))
    here = calibrate.calibrate(case, "lammps", {"restitution": 0.6})
    there = calibrate.calibrate(case, "lammps", {"restitution": 0.6}, campaign=local)
    assert there == here and there["confirmed"] is True


# ----------------------------------------------------------------------------- an existing cluster


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(proc) -> None:
    """End a process started in a session of its own, and everything in its group."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            pass
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A scheduler and a worker started as processes of their own on localhost, as on a cluster: the worker's
    environment has no LIGGGHTS (DEMCHECK_LIGGGHTS names none) and a cache directory of its own."""
    from distributed import Client

    tmp = tmp_path_factory.mktemp("cluster")
    address = f"tcp://127.0.0.1:{_free_port()}"
    started = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                 "--port", address.rsplit(":", 1)[1], "--no-dashboard"], cwd=tmp,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)]
    env = dict(os.environ, DEMCHECK_LIGGGHTS=str(tmp / "no-liggghts-here"), DEMCHECK_CACHE=str(tmp / "worker-cache"))
    try:
        started.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads",
                                         "1", "--nworkers", "1", "--host", "127.0.0.1", "--no-dashboard",
                                         "--memory-limit", "0", "--local-directory", str(tmp / "worker")], cwd=tmp,
                                        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                        start_new_session=True))
        deadline = time.monotonic() + 120
        while True:  # the scheduler answers, and the worker has joined it
            try:
                with Client(address, timeout=5, set_as_default=False) as client:
                    client.wait_for_workers(1, timeout=120)
                    worker = next(iter(client.scheduler_info()["workers"]))
                break
            except OSError:
                assert time.monotonic() < deadline, "the scheduler did not start"
                time.sleep(0.5)
        yield {"address": address, "worker": worker, "worker_cache": tmp / "worker-cache"}
    finally:
        for proc in reversed(started):
            _stop(proc)


@pytest.fixture
def fake_liggghts(tmp_path, monkeypatch):
    """A LIGGGHTS this process finds (a banner, never run: the worker has none)."""
    monkeypatch.setenv("DEMCHECK_LIGGGHTS", str(_executable(tmp_path / "bin" / "liggghts", FAKE_LIGGGHTS)))
    discovery.find.cache_clear()
    yield
    discovery.find.cache_clear()


@pytest.mark.engine("lammps")
def test_verify_on_an_existing_cluster_says_which_worker_lacks_an_engine(cluster, fake_liggghts, tmp_path):
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "client-cache"))
    files = SMALL[:2]
    p = demcheck("verify", *files, "--engines", "lammps,liggghts", "--scheduler", cluster["address"], "--report",
                 tmp_path / "r", "--json", env=env)
    assert p.returncode == 1, p.stderr[-3000:]  # a named engine the worker lacks fails there (issue 32)
    there = json.loads(p.stdout)
    # LAMMPS ran on the worker, with the verdicts of one process that has it
    one = demcheck("verify", *files, "--engines", "lammps", "--jobs", "1", "--report", tmp_path / "one", "--json",
                   env=dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "one-cache")))
    assert one.returncode == 0, one.stderr[-3000:]
    lammps = [[k for k in c[2] if k[0] != "liggghts"] for c in verdicts(there)]
    assert lammps == [c[2] for c in verdicts(json.loads(one.stdout))]
    # LIGGGHTS, found here and named, is missing on the worker: its source fails in each case, the worker named
    for c in there["cases"]:
        src = c["sources"]["liggghts"]
        assert src["status"] == "failed" and c["status"] == "failed", src
        assert src["message"].startswith(f"liggghts is missing on the Dask worker {cluster['worker']} (host ")
    # the client stored the worker's runs; the worker's own cache directory is not used
    assert entries(tmp_path / "client-cache") == entries(tmp_path / "one-cache") != set()
    assert not entries(cluster["worker_cache"])


def test_a_sweep_point_on_a_worker_without_the_engine_names_it(cluster, fake_liggghts):
    p = demcheck("sweep", CASES / "glass-pair.toml", "--vary", "impact.speed=0.5,1", "--engine", "liggghts",
                 "--scheduler", cluster["address"], "--json")
    assert p.returncode == 1, p.stderr[-3000:]
    rows = json.loads(p.stdout)["rows"]
    assert [r["impact.speed"] for r in rows] == [0.5, 1.0]
    assert all(r["status"].startswith(f"error: liggghts is missing on the Dask worker {cluster['worker']}")
               for r in rows), rows


def test_stress_bench_and_calibrate_on_a_worker_without_the_engine_say_so(cluster, fake_liggghts):
    raw = stress.read_table(CASES / "suite" / "normal-hertz-wall.toml")
    case = api.load(raw)
    with Campaign(scheduler=cluster["address"], sources=["liggghts"]) as there:
        s = stress.stress_case(raw, case, engines=("liggghts",), only=["speed"], campaign=there)
        b = bench.bench_case(case, engines=("liggghts",), steps=(10,), rtols=(), campaign=there)
        native = {"liggghts": {"pair_style": "gran model hertz tangential history"}}
        with pytest.raises(EngineNotFound, match=f"liggghts is missing on the Dask worker {cluster['worker']}"):
            calibrate.calibrate(demcheck_api.load(_case(native)), "liggghts", {"restitution": 0.6}, campaign=there)
    worker = f"liggghts is missing on the Dask worker {cluster['worker']}"
    assert s.skipped["liggghts"].startswith(worker) and {l.source for l in s.limits} == {"reference-verlet"}
    assert b.skipped["liggghts"].startswith(worker) and {p.source for p in b.points} == {"reference-verlet"}


# ----------------------------------------------------------------------------- bad addresses


FORM = "must be a Dask scheduler's address, tcp://HOST:PORT (PORT 1 to 65535)"
COMMANDS = [  # each command that takes --scheduler ({r}: an output that must not appear)
    ["verify", CASES / "glass-pair.toml", "--engines", "none", "--report", "{r}"],
    ["validate", "chung-ooi-1", "--engines", "none", "--report", "{r}"],
    ["sweep", CASES / "glass-pair.toml", "--vary", "impact.speed=1,2", "--csv", "{r}/s.csv"],
    ["stress", CASES / "glass-pair.toml", "--engines", "none", "--report", "{r}"],
    ["bench", CASES / "glass-pair.toml", "--engines", "none", "--report", "{r}"],
    ["calibrate", CASES / "glass-pair.toml", "--engine", "lammps", "--target", "restitution=0.5"],
]


@pytest.mark.parametrize("command,address", [*[(c, "localhost:8786") for c in COMMANDS],
                                             (COMMANDS[0], "tcp://127.0.0.1:99999"),
                                             (COMMANDS[0], "tcp://127.0.0.1:8786; rm -rf /")])
def test_a_malformed_scheduler_address_is_one_line_and_exit_2(command, address, tmp_path):
    p = demcheck(*[str(a).format(r=tmp_path / "r") for a in command], "--scheduler", address)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr[-2000:]
    assert lines[0] == f"demcheck: error: --scheduler = {address!r}: {FORM}", lines
    assert not (tmp_path / "r").exists()


def test_a_scheduler_that_does_not_answer_is_one_line_and_exit_2_before_any_work(tmp_path):
    address = f"tcp://127.0.0.1:{_free_port()}"  # nothing listens there
    p = demcheck("verify", CASES / "glass-pair.toml", "--engines", "none", "--report", tmp_path / "r", "--scheduler",
                 address)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr[-2000:]
    assert lines[0] == (f"demcheck: error: --scheduler = {address!r}: no Dask scheduler answers there within 10 s "
                        "(start one with `dask scheduler`, or leave out --scheduler to run on this machine)")
    assert p.stdout == "" and not (tmp_path / "r").exists()


def test_a_worker_address_is_not_a_scheduler(cluster, tmp_path):
    p = demcheck("verify", CASES / "glass-pair.toml", "--engines", "none", "--scheduler", cluster["worker"],
                 "--report", tmp_path / "r")
    assert p.returncode == 2 and p.stderr.strip() == (f"demcheck: error: --scheduler = {cluster['worker']!r}: a Dask "
                                                      "Worker answers there, not a scheduler")


def test_jobs_and_scheduler_together_are_refused(tmp_path):
    p = demcheck("verify", CASES / "glass-pair.toml", "--engines", "none", "--jobs", "2", "--scheduler",
                 "tcp://127.0.0.1:8786", "--report", tmp_path / "r")
    assert p.returncode == 2 and p.stderr.strip() == (
        "demcheck: error: --jobs = 2: sizes a local cluster; with --scheduler the cluster's workers run the tasks: "
        "leave out --jobs")
    assert not (tmp_path / "r").exists()


# ----------------------------------------------------------------------------- interrupts


def test_a_terminal_ctrl_c_stops_the_local_cluster_and_its_engines(tmp_path):
    """Ctrl-C in a terminal signals demcheck's whole process group (its local cluster's workers too): the
    partial report is written, exit 130, and no worker and no engine is left. demcheck is started as a terminal's
    foreground job, with SIGINT at its default even where pytest ignores it (test_interrupts._start)."""
    fake = _executable(tmp_path / "bin" / "lmp", FAKE_LAMMPS)
    env = dict(os.environ, DEMCHECK_LAMMPS=str(fake), DEMCHECK_CACHE=str(tmp_path / "cache"))
    proc = _start(["verify", CASES / "hls-constant-pair.toml", CASES / "glass-pair.toml", "--engines", "lammps",
                   "--jobs", "2", "--report", tmp_path / "reports"], tmp_path, env, session=True)
    engine = _wait_for_engine(proc)
    under = _descendants(proc.pid)  # the cluster's worker processes, the engine and what it started
    assert engine in under and len(under) >= 4
    os.killpg(proc.pid, signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("demcheck did not exit within 240 s of the Ctrl-C")
    assert proc.returncode == 130, err[-3000:]
    assert err.strip().splitlines()[-1].startswith("demcheck: interrupted; the engines were stopped")
    assert "Traceback" not in err and "distributed" not in err, err[-3000:]
    deadline = time.monotonic() + 30
    while [p for p in under if proc_stat(p) and proc_stat(p)[0] != "Z"] and time.monotonic() < deadline:
        time.sleep(0.2)
    assert [p for p in under if proc_stat(p) and proc_stat(p)[0] != "Z"] == []
    assert group_alive(engine) == []
    data = json.loads((tmp_path / "reports" / "latest" / "results.json").read_text())
    # the engine-less case is reported if it had finished; the Ctrl-C reaches its worker too, and whether it had
    # started, or finished, depends on when the second worker came up (a loaded machine: after the engine started).
    # The case the engine was stopped in is never reported.
    assert data["partial"] is True and [c["case"] for c in data["cases"]] in ([], ["hls-constant-pair"])
