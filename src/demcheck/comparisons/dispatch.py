"""Where a command's independent runs go: this process, a local Dask cluster, or an existing one.

verify (and validate, through the suite), sweep, stress, bench and calibrate each split their work into
independent tasks — a case, a sweep's point, a stability search, a bench point, a confirming engine run — and hand
them to a :class:`Campaign`:

* ``jobs`` 1 and no ``scheduler``: one after another in this process, in the calling thread — no cluster, nothing
  pickled; the place to debug or profile a task;
* ``jobs`` N ≥ 2: a Dask ``LocalCluster`` of N worker processes of one thread each, on 127.0.0.1, quiet (no
  dashboard; distributed's own log lines below ERROR silenced);
* ``scheduler`` ``tcp://HOST:PORT``: the workers of an existing Dask cluster (``dask scheduler`` and ``dask
  worker``, dask-jobqueue on SLURM, the Dask Helm chart on Kubernetes: docs/scaling.md). Its workers set the
  parallelism: ``jobs`` is then unused (the command line refuses the two together). An address that is not of that
  form, or where no Dask scheduler answers within CONNECT_TIMEOUT seconds, is a ConfigError naming the option,
  raised when the campaign starts, before any task.

A task is a top-level function called as ``fn(*args, cache=…)`` with plain, picklable arguments (cases, numbers,
names, dataclasses of them: no open handle, no closure). :meth:`Campaign.completed` yields ``(key, result)`` as the
tasks finish; the callers put the results back in their own order, so that no report depends on which finished
first. At most as many tasks are out on the cluster as it has threads; the others wait here.

On a worker a task runs the engines that worker's own discovery finds; :func:`missing_here` names the engines of
the campaign it lacks, with the worker, for the task to report (the engines a campaign runs are those the client
found). The task reads the client's engine-run cache where the worker sees its directory (the same machine, or a
shared filesystem) and sends back the entries it would have written, which the client stores (engines/cache.py:
atomically; a failed run is never among them), with its hits and misses and its ``demcheck`` log lines (a damaged
cache entry: each line once). A refreshing cache (``--no-cache``) reads no entry of an earlier run, but reads the
campaign's own (:class:`ThisRun`): a deck two tasks share runs once.

An interrupt (SIGINT, or SIGTERM or SIGHUP as engines.run.handle_sigterm makes them) while a campaign waits on its tasks: the
tasks not started are cancelled, the engines of the workers running its tasks are killed (engines.run.kill_all on
those workers), the tasks running are waited for — they end without their engines, or, needing none, finish and are
yielded — and the KeyboardInterrupt goes on to the caller; a second interrupt stops the wait. A local cluster's
workers ignore SIGINT and SIGHUP (a terminal's Ctrl-C or hang-up reaches every process of demcheck's group: the
client decides), keep their scratch space in a temporary directory removed with the cluster, print
nothing on stdout (demcheck's own, for --json) and end with the campaign; an existing cluster's workers may run
engines again once the campaign's tasks have ended.
"""

from __future__ import annotations

import itertools
import logging
import os
import re
import signal
import socket
import sys
import threading
import uuid
from collections.abc import Callable, Iterable, Iterator

from ..engines import run as runner
from ..errors import ConfigError

CONNECT_TIMEOUT = 10.0  # s for a scheduler to answer
ADDRESS_RULE = "must be a Dask scheduler's address, tcp://HOST:PORT (PORT 1 to 65535)"
_ADDRESS = re.compile(r"tcp://(?:[A-Za-z0-9][A-Za-z0-9.-]*|\[[0-9A-Fa-f:.]+\]):(?P<port>[0-9]{1,5})")


def check_address(text, key: str = "--scheduler") -> str:
    """``text`` as a scheduler's address (``tcp://HOST:PORT``), else ConfigError naming ``key``."""
    m = _ADDRESS.fullmatch(text) if isinstance(text, str) else None
    if m is None or not 0 < int(m["port"]) < 65536:
        raise ConfigError(key, text, ADDRESS_RULE)
    return text


class Campaign:
    """The independent tasks of one command, in this process or on a Dask cluster (the module's notes); a context
    manager that starts or connects to the cluster on entry and closes what it started on exit. ``cache``: the
    client's engine-run cache (engines.cache.Cache or None); ``sources``: the engines and builds the tasks may run
    (a build's executable is registered on each worker as on the client)."""

    def __init__(self, jobs: int = 1, scheduler: str | None = None, cache=None, sources: Iterable[str] = (),
                 key: str = "--scheduler"):
        self.jobs = jobs
        self.scheduler = check_address(scheduler, key) if scheduler else None
        self.key = key
        self.cache = cache
        self.sources = tuple(sources)
        self.client = None
        self.cluster = None
        self._flying: dict = {}  # future → its task's key
        self._scratch = None  # a local cluster's scratch space (removed with it)
        self._logged: set = set()
        import time

        self.started = time.time()  # what a refreshing cache reads is what was written since (ThisRun)
        self._tasks_cache = ThisRun(cache, self.started) if cache is not None and cache.refresh else cache

    @property
    def in_process(self) -> bool:
        return self.scheduler is None and self.jobs <= 1

    def __enter__(self) -> Campaign:
        if self.in_process:
            return self
        from distributed import Client, LocalCluster

        try:
            if self.scheduler:
                _probe(self.scheduler, self.key)
                self.client = Client(self.scheduler, timeout=CONNECT_TIMEOUT, set_as_default=False)
            else:
                # no dashboard; the scheduler's own HTTP routes (health, metrics) on a free port of 127.0.0.1; the
                # workers' scratch space a directory of this campaign's (Dask's default outlives it in TMPDIR)
                import tempfile

                self._scratch = tempfile.mkdtemp(prefix="demcheck-dask-")
                self.cluster = LocalCluster(n_workers=self.jobs, threads_per_worker=1, processes=True,
                                            host="127.0.0.1", dashboard_address=None, local_directory=self._scratch,
                                            scheduler_kwargs={"dashboard_address": "127.0.0.1:0",
                                                              "local_directory": self._scratch},
                                            silence_logs=logging.CRITICAL, memory_limit=0)
                self.client = Client(self.cluster, set_as_default=False)
                self.client.run(_local_worker)
        except BaseException:
            self._close()
            raise
        return self

    def __exit__(self, kind, exc, tb) -> None:
        try:
            if self._flying:  # left with tasks out (an error, or an interrupt outside the wait): stop them
                self._wind_down(wait=False)
        finally:
            if self.in_process:
                runner.shutdown_workers()  # the engines' idle workers the tasks started here (engines/run.py)
            self._close()

    def completed(self, fn: Callable, tasks: Iterable[tuple[object, tuple]]) -> Iterator[tuple[object, object]]:
        """``(key, fn(*args, cache=…))`` for each ``(key, args)`` of ``tasks``, as each finishes (in this process:
        in order). A task's exception is raised here, as it is; an interrupt as the module's notes say."""
        if self.in_process:
            for key, args in tasks:
                yield key, fn(*args, cache=self._tasks_cache)
            return
        if self.client is None:
            raise RuntimeError("a campaign on a cluster runs inside `with Campaign(...)`")
        yield from self._on_cluster(fn, tasks)

    def running(self) -> set:
        """The keys of the tasks out on the cluster now (none in this process: a task there runs as it is asked
        for). ``completed``'s ``tasks`` may be an iterator that consults it, stopping (StopIteration) while every
        task it has left must wait for one of these: it is asked again as each task comes back."""
        return set(self._flying.values())

    # ------------------------------------------------------------------------- on a cluster

    def _on_cluster(self, fn, tasks):
        from distributed import as_completed

        todo = iter(tasks)
        context = self._context()
        arrived = as_completed(loop=self.client.loop)

        def launch():
            for key, args in itertools.islice(todo, max(0, self._threads() - len(self._flying))):
                fut = self.client.submit(_on_worker, fn, args, context,
                                         key=f"demcheck-{fn.__name__}-{uuid.uuid4().hex}")
                self._flying[fut] = key
                arrived.add(fut)

        try:
            launch()
            for fut in arrived:
                key = self._flying.pop(fut)
                value = self._receive(fut)
                launch()
                yield key, value
        except KeyboardInterrupt:
            for fut, key in self._wind_down(wait=True):
                yield key, self._receive(fut)
            raise

    def _threads(self) -> int:
        """The tasks the cluster runs at once (at least 1: a cluster whose workers are still coming gets one)."""
        if self.cluster is not None:
            return self.jobs
        return max(1, sum(self.client.nthreads().values()))

    def _context(self) -> dict:
        from ..engines.builds import engine_of, executable_of

        builds = [(engine_of(s), s, exe) for s in self.sources if (exe := executable_of(s))]
        cache = (str(self.cache.dir), self.cache.refresh, self.started) if self.cache is not None else None
        return {"builds": builds, "cache": cache}

    def _receive(self, fut):
        """A finished task's result; its cache entries stored in the client's cache, its log lines logged here."""
        value, entries, hits, misses, lines = fut.result()
        fut.release()
        if self.cache is not None:
            for k, table, meta in entries:
                self.cache.put(k, table, meta)
            self.cache.hits += hits
            self.cache.misses += misses
        for line in lines:
            if line not in self._logged:
                self._logged.add(line)
                logging.getLogger(line[0]).log(line[1], "%s", line[2])
        return value

    def _wind_down(self, wait: bool) -> list:
        """Stop the campaign's tasks: the ones not started cancelled, the engines of the workers running the others
        killed, and those (``wait``) waited for; a second interrupt stops the wait. [(future, key)] of the ones
        that finished."""
        from distributed import as_completed

        flying, self._flying = self._flying, {}
        by_key = {f.key: f for f in flying}
        busy = {w: [by_key[k] for k in keys if k in by_key] for w, keys in self.client.processing().items()}
        running = [f for futs in busy.values() for f in futs]
        workers = [w for w, futs in busy.items() if futs]
        self.client.cancel([f for f in flying if f not in running and f.status != "finished"])
        if workers:
            self.client.run(runner.kill_all, workers=workers, on_error="ignore")
        if wait and running:
            try:
                for _ in as_completed(running, loop=self.client.loop):
                    pass
            except KeyboardInterrupt:
                pass
        if workers and self.cluster is None:  # an existing cluster's workers may run engines again
            self.client.run(runner.reset, workers=workers, on_error="ignore")
        done = [(f, key) for f, key in flying.items() if f.status == "finished"]
        self.client.cancel([f for f in running if f.status != "finished"])
        return done

    def _close(self) -> None:
        client, cluster, self.client, self.cluster = self.client, self.cluster, None, None
        try:
            if client is not None:
                try:  # each worker's idle engine workers, before the worker goes (a pool per Dask worker process;
                    # one that cannot be reached: its engine workers die with its process, PR_SET_PDEATHSIG)
                    client.run(runner.shutdown_workers, on_error="ignore")
                except Exception:  # noqa: BLE001 — a cluster already gone
                    pass
                finally:
                    client.close()
        finally:
            try:
                if cluster is not None:
                    cluster.close()
            finally:
                if self._scratch is not None:
                    import shutil

                    shutil.rmtree(self._scratch, ignore_errors=True)
                    self._scratch = None


def _probe(address: str, key: str) -> None:
    """A Dask scheduler answers at ``address`` within CONNECT_TIMEOUT seconds, else ConfigError naming ``key``."""
    import asyncio

    from distributed.core import rpc

    async def identity():
        r = rpc(address, timeout=CONNECT_TIMEOUT)
        try:
            return await r.identity()
        finally:
            await r.close_rpc()

    try:
        kind = asyncio.run(asyncio.wait_for(identity(), CONNECT_TIMEOUT)).get("type")
    except Exception:  # noqa: BLE001 — refused, unreachable, unresolvable, timed out, or not Dask's protocol
        raise ConfigError(key, address, f"no Dask scheduler answers there within {CONNECT_TIMEOUT:g} s (start one "
                                        "with `dask scheduler`, or leave out --scheduler to run on this machine)"
                          ) from None
    if kind != "Scheduler":
        raise ConfigError(key, address, f"a Dask {kind or 'server'} answers there, not a scheduler")


def _local_worker() -> None:
    """A local cluster's worker (client.run calls it in the worker's main thread), which shares demcheck's terminal:
    it ignores SIGINT and SIGHUP (a terminal's Ctrl-C, and its hang-up when it closes, reach every process of
    demcheck's process group; the client stops the engines and the workers, in that order), and what it might print goes to stderr (stdout is demcheck's: --json)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # a closed terminal's hang-up as well: the client stops them
    sys.stdout.flush()
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())


# ----------------------------------------------------------------------------- on a worker


def missing_here(engines: Iterable[str]) -> dict[str, str]:
    """On a Dask worker: the engines among ``engines`` its discovery does not find, each with the line that names
    the worker and why. {} in the client's own process (each command says what the client lacks)."""
    worker = _worker()
    if worker is None:
        return {}
    from ..engines import discovery

    return {e: f"{e} is missing on the Dask worker {worker.address} (host {socket.gethostname()}): "
               f"{discovery.missing(e)}" for e in engines if discovery.find(e) is None}


def _worker():
    """The Dask worker running this task, or None (a task of this process; distributed is then often not loaded)."""
    if "distributed" not in sys.modules:
        return None
    from distributed import get_worker

    try:
        return get_worker()
    except ValueError:
        return None


def _on_worker(fn: Callable, args: tuple, context: dict):
    """A task on a worker: the campaign's builds registered here, the client's cache read where this worker sees
    it; returns (the result, the cache entries to store, hits, misses, log lines)."""
    _register(context["builds"])
    cache = _Collecting(*context["cache"]) if context["cache"] else None
    lines = _Lines()
    logger = logging.getLogger("demcheck")
    logger.addHandler(lines)
    try:
        value = fn(*args, cache=cache)
    finally:
        logger.removeHandler(lines)
    if cache is None:
        return value, [], 0, 0, lines.lines
    return value, cache.entries, cache.hits, cache.misses, lines.lines


def _register(builds) -> None:
    """The client's builds (``--engines lammps@2024=/opt/…/lmp``) as sources of this worker too."""
    from ..engines import builds as builds_mod, discovery

    for engine, label, exe in builds:
        if builds_mod.executable_of(label) != exe:
            builds_mod.register(builds_mod.Build(engine, label, exe))
            discovery.find.cache_clear()


class ThisRun:
    """A refreshing run cache (``--no-cache``, ``refresh``: every deck run again, never one of an earlier run) that
    reads the entries written since ``since`` (the campaign's start: this run's own), so that a deck two cases of one
    verify share (the same commands) is run once, not once per case. Anything else is the cache's own."""

    def __init__(self, cache, since: float):
        self._cache = cache
        self._since = since

    def __getattr__(self, name):  # put, dir, refresh, hits, misses: the cache's own
        return getattr(self._cache, name)

    def get(self, k, *args, **kwargs):
        c = self._cache
        if not c.refresh or not _written_since(c._path(k), self._since):
            return c.get(k, *args, **kwargs)
        c.refresh = False  # one task at a time uses this cache object (a campaign's task, in its thread)
        try:
            return c.get(k, *args, **kwargs)
        finally:
            c.refresh = True


def _written_since(path, since: float) -> bool:
    try:
        return path.stat().st_mtime >= since
    except OSError:
        return False


class _Collecting:
    """A worker's view of the client's engine-run cache: entries are read from its directory (where the worker
    sees it) as engines.cache.Cache reads them (refreshing: those written since the campaign started, ThisRun);
    what a run would store is kept for the client to store."""

    def __init__(self, directory: str, refresh: bool, since: float | None = None):
        from ..engines.cache import Cache

        self._cache = Cache(directory, refresh)
        self._read = ThisRun(self._cache, since) if refresh and since is not None else self._cache
        self.entries: list = []

    def __getattr__(self, name):  # dir, refresh, hits, misses: the cache's own
        return getattr(self._cache, name)

    def get(self, k, *args, **kwargs):
        return self._read.get(k, *args, **kwargs)

    def put(self, k, table, meta) -> bool:
        self.entries.append((k, table, meta))
        return True


class _Lines(logging.Handler):
    """The ``demcheck`` log lines of the task running in this thread (a worker may run several at once)."""

    def __init__(self):
        super().__init__()
        self.thread = threading.get_ident()
        self.lines: list[tuple[str, int, str]] = []

    def emit(self, record: logging.LogRecord) -> None:
        if record.thread == self.thread:
            self.lines.append((record.name, record.levelno, record.getMessage()))
