"""One collision case in an engine: deck → run → the engine's record of it (engines.output.CollisionOutput, read by
the engine itself) → Result (with the engine's version)."""

from __future__ import annotations

import contextlib
import re
import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..case import Case
from ..errors import ConfigError
from ..inputs import common
from ..reference import health
from ..result import Result
from . import cache as cache_checks, dumps, run as runner, states
from .output import STATE_COLUMNS
from .mapping import as_engine, contact_mapping, native_summary, twin_model


def deck(case: Case, engine, dt: float | None = None, length: float = 1.0, native=None,
         **options) -> common.Deck:
    return finite(as_engine(engine).collision_deck(case, dt, length, native=native, **options), case)


# a number an engine cannot read (NaN, inf), as a word of a deck's command (comments aside)
NON_FINITE = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w.])", re.I)


def finite(dk: common.Deck, case: Case) -> common.Deck:
    """``dk`` when every number in its commands and files is finite; else a ConfigError naming the case's most
    extreme number (a coefficient derived from the case's numbers overflowed: 4/3·Ē·√R̄ of E = 1e308), before
    the deck is written or run."""
    for text in (dk.text, *dk.files.values()):
        for line in text.splitlines():
            command = line.split("#", 1)[0]
            if NON_FINITE.search(command):
                from ..case import extreme_number

                key, value = extreme_number(case)
                raise ConfigError(key, value, f"makes the {dk.engine} deck hold a number that is not finite "
                                              f"({command.strip()[:80]!r}): beyond what the engine's input can "
                                              "express")
    return dk


def setting(case: Case, engine, dt: float | None = None):
    """(native, dt): what ``engine`` (or a build of it) runs for the case — the case's ``[engine.NAME]`` setting
    (None: the engine's mapping of the seed model) and its step: ``dt`` (--dt), else the case's run.dt, else, for a
    native law, its twin's elastic contact time over run.steps_per_contact (the seed model's contact time would
    leave a stiffer native law unresolved; None: the deck's own auto step). ``demcheck collide``, ``deck`` and the
    API's collide all take it from here, so that the deck written is the deck run."""
    native = as_engine(engine).case_native(case)
    if native is not None and not dt and not case.run.dt:
        from ..laws.model import characteristic_time, resolve

        dt = characteristic_time(twin_model(resolve(case), native)) / case.run.steps_per_contact
    return native, dt or None


def setting_deck(case: Case, engine, dt: float | None = None) -> common.Deck:
    """The deck ``collide(case, engine, *setting(case, engine, dt))`` runs first: what ``demcheck deck`` writes."""
    native, step = setting(case, engine, dt)
    with native_step_named(case, engine, dt, step):
        return deck(case, engine, step, native=native)


@contextlib.contextmanager
def native_step_named(case: Case, engine, given: float | None, step: float | None):
    """A ConfigError about the step ``setting`` chose for a native law (none was given: ``given`` None) names what
    set it — run.steps_per_contact and the [engine.NAME] setting's own contact time —, never ``--dt``."""
    try:
        yield
    except ConfigError as exc:
        if given or not step or exc.key != "--dt":
            raise
        from .builds import engine_of

        name = engine_of(as_engine(engine).name)
        raise ConfigError("run.steps_per_contact", case.run.steps_per_contact,
                          f"gives the case's [engine.{name}] setting a step of {step:.3g} s (its native law's elastic "
                          f"contact time over run.steps_per_contact; no --dt given), at which {exc.rule}") from None


# what a cached run's metadata must hold (engines/cache.py checks each value)
META_KEYS = {"version": cache_checks.text, "workdir": cache_checks.text, "wall_time": cache_checks.number,
             "warnings": cache_checks.texts}


def _every_body(bodies: int):
    """The check of a cached run's states: every body's rows, as many for each (at every step the run wrote)."""
    def check(table: pd.DataFrame, meta: dict) -> str | None:
        counts = table["id"].value_counts()
        if set(counts.index) != set(range(1, bodies + 1)) or counts.nunique() != 1:
            return f"the dump's bodies {sorted(int(i) for i in counts.index)[:10]} are not 1..{bodies} at every step"
        return None
    return check


def collide(case: Case, engine, dt: float | None = None, workdir: str | Path | None = None,
            timeout: float = runner.DEFAULT_TIMEOUT, native=None, cache=None, worker: bool = False,
            **options) -> Result:
    """Run the case's deck in ``engine`` (an Engine or its name); if the contact has not ended by the end of the
    run, run again four times longer (a strongly damped or plastic contact outlasts its elastic estimate). ``native`` and
    ``options`` go to the deck writer; ``cache`` (engines.cache.Cache) skips decks already run; ``worker``
    runs the decks in the engine's long-lived worker where it has one (engines/run.py), the same numbers
    without a process start per run.

    The Result's status is the reference's own rules for a time-stepped run (reference/health.py): "ok",
    or "failed" (NaN or infinite output: never cached), "unresolved", "unstable", "out-of-range",
    "no-contact", "no-separation", with the reason in its message. The work directory of a run that is
    not "ok" is kept and named."""
    eng = as_engine(engine)  # an Engine, or its registered name
    engine = eng.name
    mp = contact_mapping(case, eng, native)
    mp.require()  # the decks get ``native`` as given (None: the seed model's mapping, type pair by type pair), so
    # that the deck run is the deck `demcheck deck` writes
    started = time.perf_counter()
    length = 1.0
    cached = False
    non_finite = ""
    copies = max(1, int(options.get("copies", 1)))
    fresh = []  # (key, table, meta) of the runs made here, cached once the result is known to be healthy
    for attempt in range(4):
        if attempt:
            try:  # a longer run past the step bound: the contact did not end within what may be run
                longer = deck(case, eng, dt, length * 4.0, native=native, **options)
            except ConfigError:
                break
            length *= 4.0
            dk = longer
        else:
            dk = deck(case, eng, dt, length, native=native, **options)
        k, hit = _cached(cache, engine, dk, len(case.particles) * copies)
        if attempt and not cached:
            _discard(out.workdir, workdir, engine)  # the shorter run, extended: only the run reported is kept
        cached = hit is not None  # the run reported is this one
        if hit is not None:
            table, meta = hit
            out = runner.RunOutput(engine, meta["version"], Path(meta["workdir"]), "", meta["wall_time"],
                                   meta["warnings"])
        else:
            out = runner.run(engine, dk.text, workdir=workdir, timeout=timeout, files=dk.files, worker=worker)
            table = eng.read_collision(out.workdir, out.log).states
            non_finite = dumps.non_finite(table)
            if cache is not None and not non_finite:
                fresh.append((k, table, {"version": out.version, "workdir": str(out.workdir),
                                         "wall_time": out.wall_time, "warnings": out.warnings}))
        n = len(case.particles)
        if copies > 1:
            spread = _copies_spread(table, n, copies)
            table = table[table["id"] <= n]
        with np.errstate(all="ignore"):
            particles = _particles(table, case, dk.dt)
            contact = states.trim(states.from_particles(particles, case))
        if non_finite:
            break
        d = contact["delta"].to_numpy()
        if (d > 0).any() and d[-1] <= 0:
            break
    sc = common.scene(case, dt, length)
    result = _result(case, engine, sc, mp, out, dk, contact, particles, started, cached,
                     {"copies": copies, "copies_spread": spread if copies > 1 else 0.0})
    return _judged(result, case, sc, out, non_finite, fresh, cache, length, workdir)


def _judged(result: Result, case: Case, sc, out, non_finite: str, fresh: list, cache, length: float,
            workdir) -> Result:
    """The Result judged: failed on NaN or infinite output, else the reference's health rules; the healthy runs
    made here cached, the work directory of a run that is not "ok" kept and named, a temporary one removed."""
    engine, cached = result.source, result.meta["cached"]
    if non_finite:
        result.status = "failed"
        result.message = (f"{engine} wrote NaN or infinite values ({non_finite}): the run is not used and not "
                          f"cached; work directory kept: {_kept(out.workdir)}")
        return result
    health.apply(result, case, sc.model)
    # the shorter runs that were extended are sound, only short; the final one is cached only when healthy
    for k, table, meta in fresh if result.ok else fresh[:-1]:
        cache.put(k, table, meta)
    if not result.ok:
        if length > 1.0:
            result.message += f" (after runs up to {length:g}× the expected duration)"
        if not cached:
            result.message += f"; work directory kept: {_kept(out.workdir)}"
    elif not cached:
        _discard(out.workdir, workdir, engine)  # a temporary directory of a run that succeeded
    return result


def _cached(cache, engine: str, dk: common.Deck, bodies: int):
    """(the run cache's key of the deck, its entry: (table, meta) or None); (None, None) without a cache. An
    engine not found here is EngineNotFound: its version is part of the key."""
    if cache is None:
        return None, None
    from . import discovery
    from .cache import key as cache_key

    info = discovery.find(engine)
    if info is None:
        from ..errors import EngineNotFound

        raise EngineNotFound(discovery.missing(engine))
    k = cache_key(engine, info.version, *run_identity(dk))
    return k, cache.get(k, columns=("step",) + STATE_COLUMNS, meta_keys=META_KEYS, min_rows=1,
                        check=_every_body(bodies))


def run_identity(dk: common.Deck) -> tuple[str, dict[str, str]]:
    """(deck, files): what of a deck the engine runs, the part of the run cache's key (engines/cache.py) that is the
    deck's — its text and its files' without their whole-line comments, which name the case, its hash, its model and
    the mapping's notes, and change nothing the engine does (every deck language demcheck writes, the LAMMPS family's
    input and data files and Yade's and Kratos' Python, reads a line whose first printable character is "#" as a
    comment; JSON and mdpa files have no such line). Two cases whose decks differ only there (a case and its copy
    under another name; variants whose difference the engine's mapping cannot express: a truncation rule,
    limit_force) share one run. A text that holds a triple quote (a string across lines), or a comment line ending
    in "&" (the LAMMPS family continues it onto the next line), is kept whole: two decks that may run differently
    never share a key."""
    return _commands(dk.text), {name: _commands(text) for name, text in dk.files.items()}


def _commands(text: str) -> str:
    lines = text.splitlines()
    comments = [line for line in lines if line.lstrip().startswith("#")]
    if '"""' in text or "'''" in text or any(line.rstrip().endswith("&") for line in comments):
        return text
    return "\n".join(line for line in lines if not line.lstrip().startswith("#"))


def _result(case: Case, engine: str, sc, mp, out, dk: common.Deck, contact, particles, started: float,
            cached: bool, copies: dict) -> Result:
    """The engine's Result of a run (``out``, engines.run.RunOutput) of the deck ``dk``: its tables, its mapping's
    fidelity and reasons, and what a diagnosis needs (work directory, warnings, the deck)."""
    return Result(
        source=engine, method="engine", case_name=case.name, case_hash=case.hash,
        model={"normal": case.contact.normal, "tangential": case.contact.tangential,
               "limit_force": case.contact.limit_force},
        params={**sc.model.params, "mapping": mp.fidelity, "native": _native_summary(mp.native)},
        contact=contact, particles=particles, dt=dk.dt, wall_time=time.perf_counter() - started,
        engine_version=out.version, status="ok",
        message="; ".join(mp.reasons),
        meta={"workdir": str(out.workdir), "warnings": out.warnings, "deck": dk.text, "fidelity": mp.fidelity,
              "cached": cached, "engine_wall_time": out.wall_time, "reasons": list(mp.reasons), **copies},
    )


def _discard(wd: Path, workdir, engine: str) -> None:
    """A run's temporary work directory removed (never one the caller gave: ``workdir``)."""
    if workdir is None and wd.name.startswith(f"demcheck-{engine}-"):
        import shutil

        shutil.rmtree(wd, ignore_errors=True)


def _kept(wd: Path) -> str:
    """A work directory kept for a diagnosis, within runner.keep_for_diagnosis's bound, and what is in it."""
    return f"{wd} ({', '.join(runner.keep_for_diagnosis(wd)) or 'empty'})"


def _copies_spread(table: pd.DataFrame, n: int, copies: int) -> float:
    """Largest difference between any copy's final velocities and copy 0's (they are the same collision;
    far apart, they must agree to round-off)."""
    last = table[table["step"] == table["step"].max()].sort_values("id")
    v = last[["vx", "vy", "vz", "omegax", "omegay", "omegaz"]].to_numpy().reshape(copies, n, 6)
    return float(np.max(np.abs(v - v[0])))


def _particles(table: pd.DataFrame, case: Case, dt: float) -> pd.DataFrame:
    out = pd.DataFrame({
        "t": table["step"].to_numpy() * dt, "id": table["id"].to_numpy() - 1,
        "x": table["x"], "y": table["y"], "z": table["z"], "vx": table["vx"], "vy": table["vy"], "vz": table["vz"],
        "wx": table["omegax"], "wy": table["omegay"], "wz": table["omegaz"],
        "fx": table["fx"], "fy": table["fy"], "fz": table["fz"], "tx": table["tqx"], "ty": table["tqy"],
        "tz": table["tqz"]})
    return out.reset_index(drop=True)


def _native_summary(native) -> dict:

    return {"engine": native.engine, "config": native_summary(native)}


def twin_states(case: Case, engine, dt: float, native=None) -> Result:
    """The reference's verlet twin of the engine configuration at the engine's dt, its contact table read
    off its states exactly as an engine's is (states.restate: the bodies' forces with their weights, as an
    engine dumps them, read back less the weights)."""
    from ..laws.model import resolve

    eng = as_engine(engine)
    mp = contact_mapping(case, eng, native)
    nat = mp.require()
    model = twin_model(resolve(case), nat)
    res = states.restate(eng.twin_collide(case, model, nat, dt), case)
    res.source = f"{eng.name}-twin"
    res.meta["fidelity"] = mp.fidelity
    return res
