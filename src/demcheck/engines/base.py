"""The engine contract: everything demcheck knows about one DEM engine, in one object.

An engine package (``demcheck/engines/<name>/``) defines one subclass of :class:`Engine` and registers an
instance (:mod:`demcheck.engines.registry`). Nothing outside ``engines/`` names an engine: the CLI's
choices, the suite's sources, the report's columns, colours and markers, bench and stress all iterate
over the registry. What an engine owns:

* discovery and version: :meth:`Engine.candidates` (executables to try) and :attr:`Engine.banner` (how its
  ``-h`` names its version);
* the vocabulary, seed model → native settings with a fidelity (:meth:`Engine.map`), and native settings →
  the reference laws that compute exactly what it computes (:meth:`Engine.twin`), with the kinematic rules
  its scheme uses (:attr:`Engine.rules`: slip arm, torque arms, rotation of the tangential history);
* deck writers for every scenario (:meth:`Engine.collision_deck`, :meth:`Engine.packing_deck`);
* how it is launched (:meth:`Engine.argv`, :meth:`Engine.mpi_launcher`, and :meth:`Engine.worker_argv`, a
  long-lived worker where it has one), what its log is and says (:attr:`Engine.log_files`, :meth:`Engine.errors`,
  :meth:`Engine.warnings`, :meth:`Engine.loop_time`) and how its output is read into one record per scenario
  (:meth:`Engine.read_collision`, :meth:`Engine.read_packing`: engines/output.py);
* how a report draws it (:attr:`Engine.style`).

Its expected differences live in ``data/expected_differences.toml``, keyed by the engine's name and version.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path

EXACT, APPROXIMATE, NONE_ = "exact", "approximate", "none"
NATIVE = "native"  # a configuration given in the engine's own terms, not mapped from a seed model
FIDELITIES = (EXACT, APPROXIMATE, NONE_)


@dataclass(frozen=True)
class Style:
    """How reports draw an engine's results: fixed per source, whatever else a report shows."""

    colour: str
    marker: str
    linestyle: str = "--"


@dataclass
class Native:
    """One type pair's contact in an engine's own terms. ``normal``, ``normal_args``, ``damping``,
    ``damping_coeff``, ``tangential``, ``tangential_args``, ``limit``, ``props`` and
    ``tangential_damping`` mean what the engine's package says they mean; ``comments`` are written into
    decks as they are (the engine's own words for what the numbers are)."""

    engine: str
    normal: str
    normal_args: tuple = ()
    damping: str = ""
    damping_coeff: float = 0.0
    tangential: str = "linear_nohistory"
    tangential_args: tuple = ()
    limit: bool = False
    props: dict = field(default_factory=dict)
    tangential_damping: bool = True
    comments: list[str] = field(default_factory=list)


@dataclass
class Mapping:
    """A seed model in an engine's terms: the fidelity (exact, approximate, none), the reasons, and the
    native configuration (None when the engine cannot express the model). ``keywords``: for a reason of an
    approximate mapping, the native setting it is about, in the engine's own words (a report's traps name it)."""

    engine: str
    fidelity: str
    reasons: list[str]
    native: Native | None
    keywords: dict[str, str] = field(default_factory=dict)  # reason → the native keyword that causes it

    def require(self) -> Native:
        from ..errors import UnsupportedByEngine

        if self.native is None:
            raise UnsupportedByEngine(f"{self.engine} cannot express this model: {'; '.join(self.reasons)}")
        return self.native


@dataclass
class Knob:
    """One native input that ``demcheck calibrate`` turns: its name in the engine's words, the bracket
    [lo, hi] (hi None: doubled from ``start`` until it brackets), and ``set(x)`` → the Native with that value."""

    name: str
    lo: float
    hi: float | None
    start: float
    set: object  # Callable[[float], Native]


def refused(engine: str, reason: str) -> Mapping:
    """The mapping of a model the engine cannot express, with the one reason why."""
    return Mapping(engine, NONE_, [reason], None)


TRACEBACK = "Traceback (most recent call last):"


def traceback_errors(log: str) -> list[str]:
    """The exception line of every Python traceback in ``log`` (an engine driven by a Python script: its deck's
    error, as a LAMMPS ERROR line is), first first."""
    lines = log.splitlines()
    out = []
    for k, line in enumerate(lines):
        if TRACEBACK in line:
            end = next((ln.strip() for ln in lines[k + 1:] if ln.strip() and not ln[0].isspace()), "")
            out.append(end or "a Python exception (its traceback cut short)")
    return out


def worst(*fidelities: str) -> str:
    order = {EXACT: 0, APPROXIMATE: 1, NONE_: 2}
    return max(fidelities, key=order.__getitem__)


class Engine(ABC):
    """One DEM engine. Subclasses set the class attributes and implement the abstract methods."""

    name: str  # lower-case id: CLI choices, report columns, cache keys, expected differences
    title: str  # for people: "LAMMPS", "LIGGGHTS"
    release: str  # the release its vocabulary is written for, as a column heading: "LAMMPS 22Jul2025"
    how_to_install: str
    banner: re.Pattern  # group 1 of a match on the output of ``<exe> -h`` is the version
    rules: dict  # kinematic rules of its scheme for the twin (reference/collision3d.SEED_RULES's keys)
    style: Style
    # builds of the same code in another floating-point precision: precision → program (``--precision``)
    precisions: dict = {}

    # ------------------------------------------------------------------ discovery and launch

    def candidates(self) -> list[str]:
        """Executables to try, in order: ``$DEMCHECK_<NAME>`` alone when set, else :meth:`default_candidates`."""
        env = os.environ.get(f"DEMCHECK_{self.name.upper()}")
        if env:
            return [env]
        return self.default_candidates()

    def default_candidates(self) -> list[str]:
        out = []
        for exe in self.executables():
            beside = Path(sys.executable).parent / exe
            if beside.exists():
                out.append(str(beside))
            found = shutil.which(exe)
            if found:
                out.append(found)
        return out

    def executables(self) -> tuple[str, ...]:
        return ()

    def build_executable(self, path: str) -> str:
        """What discovery and runs call for a build given by path (``ENGINE@LABEL=PATH``): the path itself, unless
        the engine needs a wrapper around it (Yade: one that names its version for ``-h``)."""
        return path

    @abstractmethod
    def argv(self, executable: str, deck: str) -> list[str]:
        """The command that runs ``deck`` (a file name in the work directory), its log written there (into
        :attr:`log_files`) or printed (engines/run.py keeps what a process prints)."""

    # ------------------------------------------------------------------ what a run leaves (engines/run.py asks)

    # the files in a run's work directory the engine writes its log into (the longest is the log), besides what its
    # process prints and a worker's screen (engines/run.py and engines/serve.py own those)
    log_files: tuple[str, ...] = ()

    @abstractmethod
    def errors(self, log: str) -> list[str]:
        """The engine's own error messages in a run's log, first first: a run with one failed by its deck (a
        run without one that fails is a fault of the process, made once more: engines/run.py)."""

    def warnings(self, log: str) -> list[str]:
        """The engine's own warnings in a run's log (a Result carries them); the default: none."""
        return []

    def loop_time(self, log: str) -> float | None:
        """The seconds of the engine's own stepping loop, where its log says; None (the default): it does not
        (a worker's own measure is taken instead)."""
        return None

    def worker_argv(self, executable: str) -> list[str] | None:
        """The command of a long-lived worker that runs this engine's decks case after case in one process
        (engines/serve.py's protocol, which engines/run.py speaks), when ``executable`` is the build the worker
        loads; None (the default): every run is a process of its own. run.py appends ``--parent PID``. The
        worker's runs must give a process's dumps: the engine is loaded once and put back to its state at start
        between runs (serve.Server.reset)."""
        return None

    @abstractmethod
    def check_deck(self, text: str, files: dict | None = None) -> None:
        """The final guard before the engine runs a deck: every line is one demcheck writes (raises
        otherwise)."""

    @abstractmethod
    def read_collision(self, workdir, log: str = ""):
        """A collision deck's output in ``workdir`` and its run's ``log``, read into one record
        (engines.output.CollisionOutput: the bodies' states step by step, every value as the engine computed it,
        the log, the loop's time): the collision driver reads nothing else."""

    def mpi_launcher(self, executable: str, ranks: int) -> list[str]:
        from ..errors import EngineNotFound

        raise EngineNotFound(f"{self.name} has no MPI launcher")

    # ------------------------------------------------------------------ vocabulary

    @abstractmethod
    def map(self, model, contact_params: dict) -> Mapping:
        """A resolved seed model (laws.model.ResolvedModel) of one type pair in the engine's terms."""

    @abstractmethod
    def twin(self, native: Native, m_eff: float, r_eff: float):
        """(NormalLaw, TangentialLaw) computing exactly what ``native`` computes for a pair (m̄, R̄)."""

    def twin_rules(self, native: Native) -> dict:
        """The kinematic rules of the twin of ``native`` (:attr:`rules`, unless a law of the engine computes
        its slip or turns its history in its own way)."""
        return self.rules

    def own_twin(self, native: Native) -> bool:
        """Whether :meth:`twin_collide` steps ``native`` with a kernel of the engine's own (its twin laws from
        :meth:`twin` then only describe it): such a twin exists for the engines' scheme only."""
        return False

    def twin_collide(self, case, model, native: Native, dt: float):
        """The verlet twin's run of ``native`` at ``dt`` (``model`` the twin model, engines.mapping.twin_model):
        the shared two-body kernel with :meth:`twin_rules`, unless a law of the engine steps its history in a
        way of its own (Kratos' tangential force: reference/twins_kratos.py)."""
        from ..reference import collision3d

        return collision3d.collide(case, model, "verlet", dt=dt, rules=self.twin_rules(native))

    @abstractmethod
    def summary(self, native: Native) -> str:
        """A native configuration in one line of the engine's own words."""

    def native_from_case(self, table: dict, case) -> Native:
        """A case's ``[engine.<name>]`` table (keys to text, shape checked by case.py) as the Native it sets
        for the case's contact, read with the engine's own deck reader (never pasted into a deck). Raises a
        ConfigError naming the key for a key or a setting it cannot read. The default reads none."""
        from ..errors import ConfigError

        raise ConfigError(f"engine.{self.name}", sorted(table), f"{self.title} takes no native settings in case "
                                                                 "files")

    def knob(self, native: Native, metric: str):
        """The native input that sets ``metric`` (restitution, tangential_restitution) for ``demcheck
        calibrate``: a :class:`Knob`, or None when the configuration has none."""
        return None

    def native_lines(self, native: Native) -> list[str]:
        """The native configuration as the lines a user pastes into a deck (for a like pair)."""
        return [self.summary(native)]

    def native_limits(self, native: Native) -> list[tuple[str, object, str]]:
        """What the engine itself would refuse in ``native`` when it runs it: [(its keyword, the value, the
        engine's rule)], checked before any work (a case's ``[engine.NAME]`` table, a calibrated input before
        its confirming run). The default: nothing."""
        return []

    def check_native(self, native: Native, where: str) -> Native:
        """``native`` when the engine accepts it (native_limits), else a ConfigError naming ``where``.KEYWORD."""
        from ..errors import ConfigError

        for key, value, rule in self.native_limits(native):
            raise ConfigError(f"{where}.{key}", value, f"{rule} ({self.title} refuses the run otherwise)")
        return native

    def case_native(self, case) -> Native | None:
        """The Native of the case's ``[engine.<name>]`` table (read once per case), or None without one."""
        table = getattr(case, "natives", {}).get(self.name)
        if table is None:
            return None
        key = ("native", self.name)
        if key not in case.prepared:
            case.prepared[key] = self.check_native(self.native_from_case(table, case), f"engine.{self.name}")
        return case.prepared[key]

    # ------------------------------------------------------------------ decks and output

    @abstractmethod
    def collision_deck(self, case, dt: float | None = None, length: float = 1.0, native: Native | None = None,
                       **options):
        """The deck (inputs.common.Deck) of a two-body collision case."""

    def packing_deck(self, case, duration=None, dt=None):
        from ..errors import UnsupportedByEngine

        raise UnsupportedByEngine(f"{self.name} decks are not written for packings")

    def read_packing(self, workdir, log: str, box=None):
        """A packing deck's output in ``workdir`` and its run's ``log``, read into one record
        (engines.output.PackingOutput: the settled particles sorted by id, their contacts, the kinetic energy
        series); ``box`` the packing's periodic [lx, ly] (None: none)."""
        from ..errors import UnsupportedByEngine

        raise UnsupportedByEngine(f"{self.name} writes no packing output")

    def scenario_mapping(self, case) -> Mapping:
        """The case's contact with its scenario's slot (``[run] scenario``, beyond sliding) in the engine's terms;
        the default: none, no deck is written for it."""
        return refused(self.name, f"no {self.title} deck is written for run.scenario = \"{case.run.scenario}\" "
                                  "(the scenarios beyond sliding)")

    def scenario_twin_laws(self, case, native: Native) -> dict:
        """The laws ``native`` computes in a scenario, as engines/scenario.step takes them."""
        from ..errors import UnsupportedByEngine
        raise UnsupportedByEngine(f"{self.name} has no scenario twin")

    def scenario_deck(self, case, native: Native, layout):
        """The deck (inputs.common.Deck) of a scenario case run as ``layout`` (engines/scenario.Layout)."""
        from ..errors import UnsupportedByEngine
        raise UnsupportedByEngine(f"{self.name} decks are not written for the scenarios beyond sliding")

    def read_scenario(self, case, layout, workdir) -> dict:
        """A scenario run's output (in ``workdir``) as reference/scenarios.stepped_metrics reads it."""
        from ..errors import UnsupportedByEngine
        raise UnsupportedByEngine(f"{self.name} writes no scenario output")



class PackageEngine(Engine):
    """An engine whose package keeps its parts in the usual modules, imported when first needed: ``mapping.py``
    (the vocabulary: ``map_model(model, contact_params)``, ``twin(native, m̄, R̄)``), ``deck.py`` (``deck(engine,
    case, dt, length, native=…, **options)``, ``VERSION_NOTE``), ``packing.py`` (``deck(engine, case, duration,
    dt)``) and ``scenario.py`` (``mapping(engine, case)``, ``twin_laws(engine, case, native)``, ``deck(engine,
    case, native, layout)``, ``read(engine, case, layout, workdir)``).

    Every function of deck.py, packing.py and scenario.py called here gets the Engine object first — this one, or
    the build (builds.BuildEngine) it runs as — and reaches the vocabulary through it (``engine.map``,
    ``engine.twin``, ``engines.mapping.contact_mapping(case, engine, …)``), never by looking its engine up by name:
    a deck is written by the engine that runs it. The package is the one of the class's first package module (a
    subclass defined elsewhere, a test's double, keeps its engine's parts)."""

    _package: str = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if hasattr(sys.modules.get(cls.__module__), "__path__"):  # defined in an engine package's __init__
            cls._package = cls.__module__

    def _part(self, name: str):
        import importlib

        return importlib.import_module(f"{self._package}.{name}")

    def _has_part(self, name: str) -> bool:
        import importlib.util

        return importlib.util.find_spec(f"{self._package}.{name}") is not None

    def map(self, model, contact_params: dict) -> Mapping:
        return self._part("mapping").map_model(model, contact_params)

    def twin(self, native: Native, m_eff: float, r_eff: float):
        return self._part("mapping").twin(native, m_eff, r_eff)

    # the writers below are run as the build too (builds.BuildEngine.HANDED): ``self`` is the engine that runs them,
    # so they call Engine's defaults by name, not through super() (a build is no subclass)

    def collision_deck(self, case, dt=None, length=1.0, native=None, **options):
        return self._part("deck").deck(self, case, dt, length, native=native, **options)

    def scenario_mapping(self, case) -> Mapping:
        if not self._has_part("scenario"):
            return Engine.scenario_mapping(self, case)
        return self._part("scenario").mapping(self, case)

    def scenario_twin_laws(self, case, native: Native) -> dict:
        return self._part("scenario").twin_laws(self, case, native)

    def scenario_deck(self, case, native: Native, layout):
        return self._part("scenario").deck(self, case, native, layout)

    def read_scenario(self, case, layout, workdir) -> dict:
        return self._part("scenario").read(self, case, layout, workdir)

    def packing_deck(self, case, duration=None, dt=None):
        if not self._has_part("packing"):  # a package without packings
            return Engine.packing_deck(self, case, duration, dt)
        return self._part("packing").deck(self, case, duration, dt)


def case_natives(case, engines) -> dict:
    """Every ``[engine.NAME]`` table of a case read by its engine (``engines``: the registered ones), before any
    work: a ConfigError names an unknown engine, or the key its engine cannot read."""
    from ..errors import ConfigError

    known = {e.name: e for e in engines}
    out = {}
    for name in getattr(case, "natives", {}):
        if name not in known:
            raise ConfigError(f"engine.{name}", sorted(case.natives[name]), "is not a registered engine ("
                              + ", ".join(known) + ")")
        out[name] = known[name].case_native(case)
    return out
