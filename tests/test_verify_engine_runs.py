"""No engine run that a verdict does not need (issue 33 item 5): every engine run ``demcheck verify`` asks for, spied
where it happens, and the row of the results that reads it.

The spy (:class:`EngineRuns`) wraps, in this process, the three places a verify asks an engine for a run — a
collision (engines.collide.collide), a scenario beyond sliding (engines.scenario.run), a packing
(engines.packing.run_engine) — with the run cache's answer (a hit is a run the verdict asked for, read from the
cache) and every real run (engines.run.run: through the engine's worker or as a process of its own). Each request
is then mapped to its reader: the case's row of that engine in the results and the comparisons made of it. A run is
needless when nothing reads it (no row, or a row of an engine that cannot express the case or was not asked for) or
when it repeats a run of the same engine on the same deck — the deck's commands, its whole-line comments (the
case's name and notes) left out — within the verify. benchmarks/bench_verify_runs.py counts the whole default suite
with the same spy.
"""

from __future__ import annotations

import contextlib
import hashlib
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from demcheck.comparisons import verdicts as V

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
ENGINES = ("lammps", "liggghts", "kratos", "yade")
NOT_RUN = (V.NOT_EXPRESSIBLE, V.MISSING)  # an engine row that says the engine was not run


def commands(text: str) -> str:
    """A deck's (or a deck file's) text without its whole-line comments: what the engine runs."""
    return "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))


def deck_id(deck: str, files: dict | None = None) -> str:
    h = hashlib.sha256(commands(deck).encode())
    for name, text in sorted((files or {}).items()):
        h.update(f"\0{name}\0{commands(text)}".encode())
    return h.hexdigest()[:12]


@dataclass
class Request:
    """One engine run a case asked for: its kind (collision, scenario, packing), whether the run cache answered it
    (``hit``), the real runs it made (indices into EngineRuns.runs) and what it raised."""

    case: str
    engine: str
    kind: str
    asked: tuple
    hit: bool | None = None  # None: it raised (a refusal before any run: not a run; or a run that failed)
    runs: list = field(default_factory=list)
    error: str = ""
    reader: str = ""  # the row and comparisons that read it (EngineRuns.map_to); "" for none
    needless: str = ""  # why it is needless ("" for a needed run)

    @property
    def ran(self) -> bool:
        """A run was made for it, or read from the cache."""
        return bool(self.runs) or bool(self.hit)


@dataclass
class Run:
    """One real engine run (engines.run.run)."""

    case: str
    engine: str
    kind: str
    deck: str  # deck_id of the deck and its files
    worker: str  # how it was asked to run: the engine's worker (or a process after a failed worker run), a process
    seconds: float
    request: int | None
    needless: str = ""


class EngineRuns:
    """The spy (module docstring) of one case's task: ``with EngineRuns() as spy: suite.case_task(...)`` in the
    process that runs it (:func:`spied_task`); the tasks' spies merged (:meth:`merge`), then ``spy.map_to(summary)``
    and ``spy.needless()``."""

    def __init__(self):
        self.requests: list[Request] = []
        self.runs: list[Run] = []
        self.probes: list[str] = []  # discovery's questions to an engine's executable (its banner: the version)
        self.workers: list[str] = []  # the engines' long-lived workers started (engines/run.py), by engine
        self._case = None
        self._engines: tuple = ()
        self._stack: list[int] = []
        self._patches = contextlib.ExitStack()

    # ------------------------------------------------------------------ the wrappers

    def __enter__(self) -> "EngineRuns":
        from demcheck.comparisons import suite
        from demcheck.engines import collide, discovery, packing, run as runner, scenario

        self._patch(suite, "run_case", self._run_case)
        self._patch(collide, "collide", self._request("collision"))
        self._patch(scenario, "run", self._request("scenario"))
        self._patch(packing, "run_engine", self._request("packing"))
        self._patch(runner, "run", self._run)
        self._patch(runner, "_start_worker", self._worker)
        self._patch(discovery, "output_of", self._probe)
        return self

    def __exit__(self, *exc) -> None:
        self._patches.close()

    def _patch(self, module, name: str, make) -> None:
        original = getattr(module, name)
        setattr(module, name, make(original))
        self._patches.callback(setattr, module, name, original)

    def _run_case(self, original):
        def run_case(case, file, opts, found):
            self._case, self._engines = case.name, tuple(opts.engines)
            try:
                return original(case, file, opts, found)
            finally:
                self._case = None
        return run_case

    def _request(self, kind: str):
        def wrap(original):
            def requested(case, engine, *args, **kwargs):
                name = engine if isinstance(engine, str) else engine.name
                self.requests.append(Request(case.name, name, kind, (self._case, tuple(self._engines))))
                index = len(self.requests) - 1
                self._stack.append(index)
                try:
                    result = original(case, engine, *args, **kwargs)
                except BaseException as exc:
                    self.requests[index].error = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
                    raise
                finally:
                    self._stack.pop()
                req = self.requests[index]
                # a collision's and a scenario's Result says whether its run came from the cache; a packing's, none
                req.hit = bool(result.meta.get("cached")) if kind != "packing" else not req.runs
                return result
            return requested
        return wrap

    def _worker(self, original):
        def start(engine, *args, **kwargs):
            self.workers.append(engine)
            return original(engine, *args, **kwargs)
        return start

    def _probe(self, original):
        def probe(argv, *args, **kwargs):
            self.probes.append(" ".join(map(str, argv)))
            return original(argv, *args, **kwargs)
        return probe

    def _run(self, original):
        def run(engine, deck, *args, files=None, worker=False, **kwargs):
            index = self._stack[-1] if self._stack else None
            kind = self.requests[index].kind if index is not None else "?"
            started = time.perf_counter()
            try:
                return original(engine, deck, *args, files=files, worker=worker, **kwargs)
            finally:
                how = "worker, else process" if worker == "or-process" else "worker" if worker else "process"
                self.runs.append(Run(self._case or "?", engine, kind, deck_id(deck, files), how,
                                     time.perf_counter() - started, index))
                if index is not None:
                    self.requests[index].runs.append(len(self.runs) - 1)
        return run

    # ------------------------------------------------------------------ what reads each run

    def map_to(self, summary) -> None:
        """Each request's reader in ``summary`` (the suite's records.Summary: results.json's rows), and why a request
        or a real run is needless."""
        entries = {c.case: c for c in summary.cases}
        for req in self.requests:
            if not req.ran:
                continue  # refused before any run (a packing deck the engine's package does not write): no run
            case, engines = req.asked
            entry = entries.get(req.case)
            row = entry.sources.get(req.engine) if entry is not None else None
            comps = [c for c in entry.comparisons if c.source == req.engine] if entry is not None else []
            if case != req.case:
                req.needless = f"asked outside its case's run ({case})"
            elif req.engine not in engines:
                req.needless = f"{req.engine} was not among the engines asked for ({', '.join(engines)})"
            elif entry is None:
                req.needless = "its case has no entry in the results"
            elif row is None:
                req.needless = "its case's entry has no row of this engine (the row was dropped)"
            elif row.status in NOT_RUN:
                req.needless = f"its row says {row.status}: the engine was not to run"
            elif not comps:
                req.needless = "no comparison reads its row"
            else:
                verdicts = sorted({c.verdict for c in comps})
                numeric = sum(c.metric != "*" for c in comps)
                req.reader = (f"cases[{req.case}].sources.{req.engine} ({row.status}); {len(comps)} comparison(s), "
                              f"{numeric} of metrics: {', '.join(verdicts)}")
        seen: dict = {}
        for i, run in enumerate(self.runs):
            key = (run.engine, run.deck)
            req = self.requests[run.request] if run.request is not None else None
            if key in seen:
                run.needless = f"repeats run {seen[key]} (the same deck's commands)"
            elif req is None:
                run.needless = "made outside any request of a case"
            elif req.needless:
                run.needless = req.needless
            elif req.runs and req.runs[-1] != i:
                run.needless = ""  # a shorter run extended (engines.collide: the contact had not ended): read by
                # the decision to run longer; counted apart (extended())
            seen.setdefault(key, i)

    def needless(self) -> list[str]:
        """Every needless request and real run, one line each ([] when every run is read)."""
        out = [f"request {r.kind} {r.case} / {r.engine}: {r.needless}" for r in self.requests if r.needless]
        out += [f"run {r.kind} {r.case} / {r.engine} deck {r.deck}: {r.needless}" for r in self.runs if r.needless]
        return out

    def extended(self) -> list[Run]:
        """The real runs a longer one replaced (a collision whose contact had not ended by the run's end)."""
        return [self.runs[i] for r in self.requests for i in r.runs[:-1]]


    def merge(self, other: "EngineRuns") -> None:
        """``other``'s records (one task's, from whichever process ran it) after this one's."""
        base = len(self.runs)
        offset = len(self.requests)
        for r in other.runs:
            r.request = None if r.request is None else r.request + offset
        for q in other.requests:
            q.runs = [i + base for i in q.runs]
        self.requests += other.requests
        self.runs += other.runs
        self.workers += other.workers
        self.probes += other.probes


# ----------------------------------------------------------------------------- the suite under the spy

_CASE_TASK = None  # suite.case_task, kept where the spy replaced it (the client); a Dask worker has its own
RECORDS = "__engine_runs__"  # the key of a task's records in its CaseResult's extra, removed by the client


def spied_task(*args, cache=None):
    """suite.case_task under its own spy, in the process that runs it (this one, or a Dask worker's: this function
    is pickled by its name); its records ride back in the entry, taken off before the report is written."""
    from demcheck.comparisons import suite

    task = _CASE_TASK or suite.case_task
    with EngineRuns() as spy:
        entry = task(*args, cache=cache)
    spy._patches = None  # not picklable, and done with
    entry.extra[RECORDS] = spy
    return entry


def verify(files, cache_dir: Path, engines=ENGINES, refresh: bool = False, jobs: int = 1, report: bool = False):
    """``demcheck verify`` of ``files`` (``jobs`` 1: in this process; N: on a local Dask cluster of N workers, the
    command's default being 2), its engine-run cache in ``cache_dir``, every task under the spy: (summary, spy).
    ``report``: write the report's files too (its figures are most of a small verify's time; they render the rows
    the spy's readers are)."""
    global _CASE_TASK
    from demcheck.comparisons import dispatch, report as reports, suite
    from demcheck.comparisons.suite import Options, run_suite
    from demcheck.engines.cache import Cache

    spy = EngineRuns()
    completed = dispatch.Campaign.completed

    def taken_off(campaign, fn, tasks):
        for key, entry in completed(campaign, fn, tasks):
            spy.merge(entry.extra.pop(RECORDS))
            yield key, entry

    opts = Options(engines=tuple(engines), cache=Cache(cache_dir, refresh=refresh), jobs=jobs)
    _CASE_TASK = suite.case_task
    suite.case_task, dispatch.Campaign.completed = spied_task, taken_off
    write_all = reports.write_all
    if not report:
        reports.write_all = lambda *a, **k: None
    try:
        summary = run_suite([Path(f) for f in files], cache_dir.parent / "reports", opts, quiet=True)
    finally:
        suite.case_task, dispatch.Campaign.completed, _CASE_TASK = _CASE_TASK, completed, None
        reports.write_all = write_all
    spy.map_to(summary)
    return summary, spy


def files(tmp_path: Path) -> list[Path]:
    """A small, representative set of the suite's case files: a pair and a wall, an oblique impact, a case two
    engines cannot express, a scenario beyond sliding, a small packing — and the pair again under another name (its
    decks differ only in the comments that name the case: one run each)."""
    copy = tmp_path / "glass-pair-copy.toml"
    text = (CASES / "glass-pair.toml").read_text()
    assert 'name = "glass-pair"' in text
    copy.write_text(text.replace('name = "glass-pair"', 'name = "glass-pair-copy"'))
    return [CASES / "glass-pair.toml", copy, CASES / "hertz-wall.toml", CASES / "oblique-lsd-wall.toml",
            CASES / "kk-wall.toml", CASES / "suite" / "beyond-twist.toml", CASES / "packing" / "column-lsd.toml"]


def engine_marks(f):
    for e in ENGINES:
        f = pytest.mark.engine(e)(f)
    return f


@engine_marks
def test_every_engine_run_is_read_by_a_row_and_made_once(monkeypatch, tmp_path):
    fs = files(tmp_path)
    summary, spy = verify(fs, tmp_path / "engine-runs")
    assert not summary.failed, [c.case for c in summary.cases if c.failing]
    by = {}
    for req in spy.requests:
        by.setdefault((req.case, req.engine), []).append(req)
    # each case asked each engine that expresses it for one run, and only those (kk-wall: Kratos and Yade cannot
    # express the KK dashpot; beyond-twist: LIGGGHTS and Kratos have no twisting torque; column-lsd: Kratos writes
    # no packing deck, its refusal comes before any run)
    asked = {(r.case, r.engine, r.kind) for r in spy.requests}
    for case in ("glass-pair", "glass-pair-copy", "hertz-wall", "oblique-lsd-wall"):
        assert {(case, e, "collision") for e in ENGINES} <= asked
    assert not {(n, e) for n, e, _ in asked if n == "kk-wall" and e in ("kratos", "yade")}
    assert not {r for r in spy.runs if r.case == "kk-wall" and r.engine in ("kratos", "yade")}
    assert not {(n, e) for n, e, _ in asked if n == "suite-beyond-twist" and e in ("liggghts", "kratos")}
    assert {("suite-beyond-twist", "lammps", "scenario"), ("suite-beyond-twist", "yade", "scenario")} <= asked
    assert not [r for r in spy.runs if r.case == "column-lsd" and r.engine == "kratos"]
    assert all(len(v) == 1 for v in by.values()), {k: len(v) for k, v in by.items() if len(v) > 1}
    # each real run's (engine, deck) once; every request read by its row
    decks = [(r.engine, r.deck) for r in spy.runs]
    assert len(decks) == len(set(decks)), spy.needless()
    assert spy.needless() == []
    assert all(r.reader for r in spy.requests if r.ran)
    # the copy of glass-pair asked for its four runs and the cache answered each: the same decks' commands
    copy = [r for r in spy.requests if r.case == "glass-pair-copy"]
    assert len(copy) == 4 and all(r.hit and not r.runs for r in copy), copy
    # its rows equal glass-pair's, number for number
    entries = {c.case: c for c in summary.cases}
    for e in ENGINES:
        assert entries["glass-pair-copy"].sources[e].metrics == entries["glass-pair"].sources[e].metrics
    assert not spy.extended()  # no collision here outlasts its deck's run
    # a warm verify after a change to demcheck's code that leaves every deck as it was (its fingerprint, which keys
    # the results demcheck computes itself): every engine run from the cache, none made
    from demcheck.engines import scenario

    monkeypatch.setattr(scenario, "code_fingerprint", lambda: "a-changed-demcheck")
    summary2, warm = verify(fs, tmp_path / "engine-runs")
    assert warm.runs == [] and warm.needless() == []
    assert [(r.case, r.engine, r.kind) for r in warm.requests] == [(r.case, r.engine, r.kind) for r in spy.requests]
    assert all(r.hit for r in warm.requests if r.ran) and sum(r.ran for r in warm.requests) == sum(
        r.ran for r in spy.requests)
    # and its rows are the cold run's, number for number
    cold, again = ({c.case: c for c in s.cases} for s in (summary, summary2))
    for name, entry in cold.items():
        for e in ENGINES:
            if e in entry.sources:
                a, b = entry.sources[e].metrics or {}, again[name].sources[e].metrics or {}
                assert a.keys() == b.keys() and all(a[m] == b[m] or (a[m] != a[m] and b[m] != b[m]) for m in a), \
                    (name, e, a, b)


@pytest.mark.engine("lammps")
def test_a_scenario_row_whose_twin_cannot_be_made_runs_no_engine(monkeypatch, tmp_path):
    """A scenario engine's row needs its twin and its seed run besides the engine's: where the twin fails the row is
    "failed" and the engine is not run (it ran first, and its output went unread)."""
    from demcheck.engines import scenario
    from demcheck.errors import UnsupportedByEngine

    def no_twin(case, engine):
        raise UnsupportedByEngine("planted: no twin")

    monkeypatch.setattr(scenario, "twin", no_twin)
    summary, spy = verify([CASES / "suite" / "beyond-twist.toml"], tmp_path / "engine-runs", engines=("lammps",))
    row = summary.cases[0].sources["lammps"]
    assert row.status == "failed" and "planted: no twin" in row.message
    assert spy.runs == [] and spy.requests == []



def test_a_refreshing_cache_reads_this_runs_entries_only(tmp_path):
    """--no-cache runs every deck again, but a deck two cases of one verify share runs once: the campaign's cache
    (dispatch.ThisRun) reads the entries written since it started, never an earlier run's."""
    import pandas as pd

    from demcheck.comparisons import dispatch
    from demcheck.engines.cache import Cache

    for k in ("old", "older"):
        Cache(tmp_path).put(k, pd.DataFrame({"x": [1.0]}), {})  # an earlier run's entries
    time.sleep(0.05)  # past the file system's clock tick
    with dispatch.Campaign(1, cache=Cache(tmp_path, refresh=True)) as campaign:
        got = dict(campaign.completed(_looked_up, [("task", (("old", "new"),))]))["task"]
    # each key missed first (the earlier run's entry unread, the new one absent), then, written, was read
    assert got == [("old", False, True), ("new", False, True)]
    fresh = Cache(tmp_path, refresh=True)  # the refreshing cache alone reads neither
    assert fresh.get("old") is None and fresh.get("new") is None
    # a Dask worker's view of the client's cache reads as the campaign's does
    worker = dispatch._Collecting(str(tmp_path), True, campaign.started)
    assert worker.get("new") is not None and worker.get("older") is None
    assert dispatch._Collecting(str(tmp_path), True).get("new") is None  # no start given: nothing read


def _looked_up(keys, cache=None):
    """A task: each key looked up, written on a miss (as an engine run is), looked up again."""
    import pandas as pd

    out = []
    for k in keys:
        first = cache.get(k) is not None
        if not first:
            cache.put(k, pd.DataFrame({"x": [2.0]}), {})
        out.append((k, first, cache.get(k) is not None))
    return out


@pytest.mark.parametrize("data", [
    {"t": np.arange(5) * 0.1, "x": np.random.default_rng(1).normal(size=(5, 3)),
     "v": np.random.default_rng(2).normal(size=(5, 3)), "omega": np.random.default_rng(3).normal(size=(5, 3))},
    {"delta": np.linspace(1e-6, -1e-6, 7), "fn": np.random.default_rng(4).normal(size=7)},
    {"v_rel": 0.123456789, "touching": False},
    {"v_rel": -0.5, "touching": True},
    {"t": np.arange(3) * 0.5, "dT": np.array([10.0, 5.0, 2.5])},
])
def test_a_scenario_run_is_kept_as_its_output_and_read_back_to_the_bit(tmp_path, data):
    """A scenario engine run is cached as what the engine's reader made of its output, keyed by its deck's commands
    and the engine's version, not by demcheck's code: a change to demcheck that leaves the deck as it was runs no
    engine again (the metrics are computed from the kept output each time)."""
    from demcheck.engines import scenario
    from demcheck.engines.cache import Cache

    cache = Cache(tmp_path)
    scenario._put_run(cache, "k", data, {"engine_version": "v", "warnings": ["w"]})
    got, meta = scenario._cached_run(Cache(tmp_path), "k")
    assert meta["engine_version"] == "v" and meta["warnings"] == ["w"]
    assert got.keys() == data.keys()
    for name, value in data.items():
        assert type(got[name]) is type(value)
        if isinstance(value, np.ndarray):
            assert got[name].shape == value.shape and np.array_equal(got[name], value)
        else:
            assert got[name] == value


def test_cases_that_share_an_engine_run_never_run_it_at_once_on_a_cluster(tmp_path):
    """On a Dask cluster two cases run at once: two that share a deck (a case and its copy; variants an engine's
    mapping cannot tell apart) would both miss the cache and both run it. suite.sharers finds them, and suite.Apart
    holds one back while the other is out (the next case goes first)."""
    from demcheck.comparisons import suite

    fs = files(tmp_path)[:3] + [CASES / "suite" / "normal-tti-pair.toml"]
    cases = suite.collect(fs)
    names = [c.name for _, c in cases]
    found = {e: {"found": True, "version": "x", "executable": "x", "how_to_install": None, "why": None}
             for e in ENGINES}
    shared = suite.sharers([c for _, c in cases], ENGINES, found)
    at = {n: i for i, n in enumerate(names)}
    assert shared[at["glass-pair"]] == {at["glass-pair-copy"]} and shared[at["glass-pair-copy"]] == {at["glass-pair"]}
    assert at["hertz-wall"] not in shared
    # Kratos and Yade cannot express limit_force: each speed's two variants share their decks (LAMMPS and LIGGGHTS
    # can: theirs differ)
    tti = [n for n in names if n.startswith("suite-tti-pair[")]
    assert len(tti) == 6
    for n in tti:
        twin = n.replace("limit_force=false", "limit_force=true") if "false" in n else n.replace("true", "false")
        assert shared[at[n]] == {at[twin]}, (n, [names[j] for j in shared[at[n]]])

    busy = set()
    apart = suite.Apart([(i, n) for i, n in enumerate(names)], shared, lambda: busy)
    first = next(apart)
    assert first == (0, "glass-pair")
    busy.add(0)
    assert next(apart)[1] == "hertz-wall"  # the copy waits while glass-pair is out
    busy.add(2)
    taken = []
    for _ in range(3):  # the tti variants, each sent out: one of each speed's pair, the other waits
        taken.append(next(apart)[1])
        busy.add(at[taken[-1]])
    assert {n.split(",")[0] for n in taken} == {n.split(",")[0] for n in tti}
    with pytest.raises(StopIteration):  # every case left waits: asked again when one comes back
        next(apart)
    busy -= {0}
    assert next(apart)[1] == "glass-pair-copy"
    busy.clear()
    assert len(list(apart)) == 3  # nothing here asks an engine: the decks are written, never run
