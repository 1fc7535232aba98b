"""A source: what yields a Result for a case — the reference (a method: adaptive, verlet, or the case's own), an
engine build (an engine, or a labelled build of one: engines/builds.py), or an engine's twin (the engine's
formula in the reference, with its scheme).

Every command and the API run a source through :meth:`Source.run` and ask which sources can run a case through
:func:`plan`. The labels a report, a cache key and a command line use — ``reference``, ``reference-verlet``,
``NAME``, ``NAME@LABEL``, ``NAME-twin`` — are a Source's rendering (:attr:`Source.label`) and parsed back in one
place (:meth:`Source.parse`). A Source pickles as its label (a campaign's task on a Dask worker gets the engine of
that worker's registry).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ..case import Case
from ..errors import ConfigError
from ..result import Result
from .verdicts import FAILED, MISSING, NOT_EXPRESSIBLE  # a Planned's status: the verdict of an engine that cannot run

REFERENCE, ENGINE, TWIN = "reference", "engine", "twin"
TWIN_SUFFIX = "-twin"
METHODS = ("adaptive", "verlet")
_SETTING = object()  # Source.run's ``native`` default: the case's own [engine.NAME] setting, if any


@dataclass(frozen=True, eq=False)
class Source:
    """One source (module docstring): ``kind`` reference | engine | twin; ``method`` the reference's (None: the
    case's run.method); ``engine`` the engines.base.Engine an engine source or a twin runs (a build: its
    BuildEngine)."""

    kind: str
    method: str | None = None
    engine: object = None

    @classmethod
    def reference(cls, method: str | None = None) -> "Source":
        return cls(REFERENCE, method)

    @classmethod
    def of(cls, engine, twin: bool = False) -> "Source":
        """An engine's source (or its twin's): ``engine`` an Engine or a registered name."""
        if isinstance(engine, str):
            from ..engines import registry

            engine = registry.get(engine)
        return cls(TWIN if twin else ENGINE, None, engine)

    @classmethod
    def parse(cls, label: str, key: str = "source", methods: bool = True) -> "Source":
        """A label (``reference``, ``reference-adaptive``, ``reference-verlet`` — unless not ``methods`` —, a
        registered engine or build, ``NAME-twin``) as its Source; else ConfigError naming ``key``."""
        from ..engines import registry

        if label == REFERENCE:
            return cls.reference()
        method = label.removeprefix(REFERENCE + "-") if isinstance(label, str) else None
        if methods and method in METHODS and label != method:
            return cls.reference(method)
        twin = isinstance(label, str) and label.endswith(TWIN_SUFFIX)
        name = label[:-len(TWIN_SUFFIX)] if twin else label
        if not isinstance(name, str) or name not in registry.names():
            names = [n for n in registry.names() if "@" not in n]
            raise ConfigError(key, label, "must be reference, an engine (" + ", ".join(names) + ") or an engine's "
                              "twin (" + ", ".join(f"{n}{TWIN_SUFFIX}" for n in names) + ")")
        return cls.of(registry.get(name), twin)

    # ------------------------------------------------------------------ identity

    @property
    def label(self) -> str:
        """The source's name in reports, columns, plots and cache keys."""
        if self.kind == REFERENCE:
            return REFERENCE if self.method is None else f"{REFERENCE}-{self.method}"
        return self.engine.name + (TWIN_SUFFIX if self.kind == TWIN else "")

    @property
    def name(self) -> str | None:
        """The engine's (or build's) name; None for the reference."""
        return None if self.engine is None else self.engine.name

    def twin(self) -> "Source":
        """The twin of an engine source."""
        return Source(TWIN, None, self.engine)

    def __str__(self) -> str:
        return self.label

    def __repr__(self) -> str:
        return f"Source({self.label!r})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Source) and self.label == other.label

    def __hash__(self) -> int:
        return hash(self.label)

    def __reduce__(self):
        return (Source.parse, (self.label,))

    # ------------------------------------------------------------------ running

    def native(self, case: Case):
        """The case's own setting for the source's engine (``[engine.NAME]``; a build reads its engine's table),
        None for the reference or a case without one."""
        return None if self.engine is None else self.engine.case_native(case)

    def setting(self, case: Case, dt: float | None = None):
        """(native, dt) the engine or its twin runs (engines.collide.setting: the native law's own step when the
        case gives one and neither ``dt`` nor run.dt does)."""
        from ..engines.collide import setting

        return setting(case, self.engine, dt)

    def run(self, case: Case, dt: float | None = None, *, rtol: float | None = None, native=_SETTING,
            timeout: float | None = None, restated: bool = False, converged: bool = False, model=None,
            **options) -> Result:
        """The source's Result for ``case`` at ``dt``. The reference: its method at ``dt`` (verlet) or ``rtol``
        (adaptive); ``model``: the contact it solves by the two-body kernel (reference/collision3d.py, the seed's
        kinematic rules) instead of the case's own solve — the seed model (laws.model.resolve) or an engine's law
        (engines.mapping.twin_model: the audit's converged answer of a deck's setting); ``restated``: by the
        two-body kernel (the seed model unless ``model``), read off its states as an engine's run is
        (engines.states.restate) — the seed model at an engine's step. An engine: its deck run for real
        (``timeout``; ``options`` — cache, worker, copies — go to engines.collide.collide). A twin: the reference
        computing the engine's formula with its scheme at the engine's dt; ``converged``: its converged answer
        (:func:`_converged_twin`). ``native``: the engine's setting (default the case's own, at its own step when
        ``dt`` is None; None: the engine's mapping of the seed model)."""
        if model is not None and self.kind != REFERENCE:
            raise TypeError(f"{self.label}: model= is the reference's (an engine and its twin run their own setting)")
        if model is not None and case.run.scenario != "collision":
            raise TypeError(f"{self.label}: model= solves a collision; a scenario's laws are its case's")
        if case.run.scenario != "collision":
            return self._scenario(case, timeout, options.get("cache"))
        if self.kind == REFERENCE:
            if restated or model is not None:
                return _two_body(case, model, self.method, dt, rtol, restated)
            from ..reference.collision import collide

            return collide(case, method=self.method, dt=dt, rtol=rtol)
        from ..engines.collide import native_step_named

        given = dt
        if native is _SETTING:
            native, dt = self.setting(case, dt)
        if self.kind == TWIN and converged:
            return _converged_twin(case, self.engine, native, dt)
        if self.kind == TWIN:
            from ..case import run_length
            from ..engines.collide import twin_states

            return twin_states(case, self.engine, dt or run_length(case)[0], native=native)
        from ..engines.collide import collide as run_engine

        if timeout is not None:
            options["timeout"] = timeout
        with native_step_named(case, self.engine, given, dt if native is not None else None):
            return run_engine(case, self.engine, dt=dt, native=native, **options)


    def _scenario(self, case: Case, timeout: float | None = None, cache=None) -> Result:
        """A scenario beyond sliding: the reference's solve (reference/scenarios.py), the engine's run of the deck
        its package writes (``cache``: engines.cache.Cache), or its twin (engines/scenario.py)."""
        if self.kind == ENGINE:
            from ..engines import scenario

            return scenario.run(case, self.engine, timeout=timeout, cache=cache)
        if self.kind == TWIN:
            from ..engines import scenario

            return scenario.twin(case, self.engine)
        if self.method == "verlet":
            raise ConfigError("method", "verlet", f"run.scenario = \"{case.run.scenario}\" is solved by the "
                                                  "adaptive reference only (an engine's step: its seed row)")
        from ..reference.scenarios import solve

        return solve(case)


def _two_body(case: Case, model, method: str | None, dt: float | None, rtol: float | None,
              restated: bool) -> Result:
    """``model`` (None: the seed model) solved by the two-body kernel; ``restated``: its contact table read off its
    states as an engine's is."""
    from ..engines import states
    from ..laws.model import resolve
    from ..reference import collision3d

    res = collision3d.collide(case, resolve(case) if model is None else model, method or case.run.method, dt=dt,
                              rtol=rtol)
    return states.restate(res, case) if restated else res


def _converged_twin(case: Case, engine, native, dt: float) -> Result:
    """The converged answer of ``engine``'s twin of ``native``: the adaptive method with the engine's kinematic
    rules, or — a twin without an adaptive solve: the engine's own kernel (Kratos' friction, Yade's Luding), a
    force history — its own scheme at ``dt``, saying why in ``meta["no_adaptive"]``."""
    from ..engines.collide import twin_states
    from ..engines.mapping import contact_mapping, twin_model
    from ..laws.model import resolve
    from ..reference import collision3d

    nat = contact_mapping(case, engine, native).require()
    model = twin_model(resolve(case), nat)
    tl = model.tangential_law
    if engine.own_twin(nat) or tl.force_history or tl.rescale_history:
        res = twin_states(case, engine, dt, native=nat)
        res.meta["no_adaptive"] = "the engine's own twin kernel" if engine.own_twin(nat) else "a force history"
        return res
    res = collision3d.collide(case, model, "adaptive", rules=engine.twin_rules(nat))
    res.source = engine.name + TWIN_SUFFIX
    return res


ADAPTIVE, VERLET = Source.reference("adaptive"), Source.reference("verlet")


def collision_only(case: Case, why: str) -> Case:
    """``case`` when it is a collision (run.scenario "collision"); a scenario beyond sliding is a ConfigError naming
    run.scenario, its value and ``why`` — what the command measures is an impact's (calibrate, bench, stress: each
    refuses it as it loads the case, before any work)."""
    if case.run.scenario != "collision":
        raise ConfigError("run.scenario", case.run.scenario, f"must be \"collision\": {why}")
    return case


@dataclass(frozen=True)
class Planned:
    """An engine source for one case, as :func:`plan` found it: the case's own setting (``native``), the mapping of
    the case's contact (engines.mapping.Mapping), and, when it cannot run, its ``status`` (NOT_EXPRESSIBLE,
    MISSING, or FAILED: a named engine a Dask worker lacks — verdicts') and why."""

    source: Source
    native: object
    mapping: object
    status: str = ""
    why: str = ""

    @property
    def runs(self) -> bool:
        return not self.status



def engines_of(engines) -> list:
    """Engine objects of ``engines`` (Engines, registered names or labels; None: every registered one)."""
    from ..engines import registry

    if engines is None:
        return list(registry.all_engines())
    return [registry.get(e) if isinstance(e, str) else e for e in engines]


def plan(case: Case, engines: Iterable | None = None, found: dict | None = None, mapping=None) -> list[Planned]:
    """Which engines (and builds) among ``engines`` can run ``case``, and why not: per engine its case's own
    setting, its mapping of the contact (of a scenario case: the contact with its scenario's slot,
    engines/scenario.mapping), and "not expressible" (the mapping's reasons) or "engine missing" (not
    found: ``found``, the suite's discovery record by name, else discovery now). The order of ``engines``.
    ``mapping(case, name, native)``: the mapping that decides (default engines.mapping.contact_mapping; a packing
    asks for its type pair's)."""
    from ..engines.mapping import contact_mapping
    from ..engines.scenario import mapping as scenario_mapping

    mapping = mapping or (contact_mapping if case.run.scenario == "collision" else
                          lambda c, name, native: scenario_mapping(c, name))
    out = []
    for engine in engines_of(engines):
        native = engine.case_native(case)
        mp = mapping(case, engine.name, native)
        entry = Planned(Source.of(engine), native, mp)
        if mp.native is None:
            entry = Planned(entry.source, native, mp, NOT_EXPRESSIBLE, "; ".join(mp.reasons))
        elif (why := _missing(engine.name, found)) is not None:
            # an engine the user named that a Dask worker lacks fails there (the suite's record says "required")
            required = found is not None and found[engine.name].get("required")
            entry = Planned(entry.source, native, mp, FAILED if required else MISSING, why)
        out.append(entry)
    return out


def _missing(name: str, found: dict | None) -> str | None:
    """Why the engine ``name`` cannot run here (None: it can)."""
    from ..engines import discovery

    if found is None:
        return None if discovery.find(name) is not None else discovery.missing(name)
    f = found[name]
    if f["found"]:
        return None
    return f.get("why") or f"{name} is not installed: {f['how_to_install']}"
