"""The tangential slot's interface: the composed law array's layout (the ``T_*`` columns the compiled kernels
read), the record every tangential law is (:class:`TangentialSubModel`) and the registry of the laws' compiled
functions (:func:`compiled`), from which ``tangential_dispatch`` assembles the kernels' switch on the family id.

A tangential law is one module (``laws/tangential_laws/<law>.py``, or a plug-in module named in
``$DEMCHECK_LAW_PLUGINS``): its record, its family id, its compiled functions and their registration here —
docs/architecture.md, "Adding a tangential law".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from .. import KERNEL_CACHE
from .base import SUBMODELS, SubModel

# layout of TangentialLaw.array()
T_FAMILY, T_KT, T_KT_SQRT, T_ETA, T_ETA_NORMAL, T_MU_S, T_MU_K, T_TRUNC, T_R, T_M, T_XI, T_ETA1, T_G, T_K0 = range(14)
# engine-twin variants of SPRING (verlet method only): the history stores the elastic force (LAMMPS
# mindlin/force), and is scaled by a/a_prev when the contact radius shrinks (mindlin_rescale)
T_FORCE, T_RESCALE = 14, 15
# a law's own numbers that no column above names (its record's other fields, in declaration order)
T_P0, T_PARAMS = 16, 4
# what the law declares of itself (its record's traits, TangentialSubModel.trait_columns): the F_* flags, the
# unloading margin of its slip→stick test, and the band below its Coulomb limit in which a riding load rides it
T_TRAITS, T_UNLOAD_MARGIN, T_NEAR_LIMIT, T_RIDE_BAND = 20, 21, 22, 23
T_SIZE = 24

# the flags of T_TRAITS (``has(tl, F_…)``): what the solvers ask of a law instead of its family id
F_HISTORY = 1  # it keeps a history ξ, integrated (ξ̇ = v_t, or its history_rate) and turned with the contact
F_STATES = 2  # it sticks and slips, the switch on its slip surface (slip_surface, return_map)
F_CONSTRAINT = 4  # its stick is the constraint v_t = 0 (the solver's force, ≤ μs|Fn|), its slip along tref
F_SLIP_KEEPS = 8  # its slip caps the force and leaves the history alone: it sticks when the trial force drops
F_SLIP_READS_SURFACE = 16  # slipping, its force reads the return-mapped history (ξ on its surface by definition)
F_SLIP_SNAPS = 32  # slipping, its history is put back on its surface after each step
F_STICK_KINK = 64  # its stick force can reverse through 0 within a step (a kink the error control misses)
F_REVERSAL = 128  # a reversal of the slip is an event: the history at it is stored (the law's lstar)
F_RIDES = 256  # no slip state: its history is a load that rides its Coulomb limit μk|Fn| (limit_margin)
F_VISCOUS_KINK = 512  # its force switches from the dashpot ηt|v_t| to the cap μk|Fn| (a kink, an event)
F_OWN_RATE = 1024  # its history grows at its own rate (its history_rate function, not v_t)
F_DISCRETE_SLIP = 2048  # the engines' scheme slips it by its own rule (its discrete_slip function)
F_NO_FORCE = 4096  # it applies no tangential force (frictionless): the solvers skip it

TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING = 0, 1, 2
TRUNCATIONS = {"force": TRUNC_CAP, "overlap": TRUNC_MAW, "spring": TRUNC_SPRING}


@dataclass(frozen=True)
class TangentialSubModel(SubModel):
    """A tangential law's record. ``family``: its id in the kernels' law array (unique per law module; records
    that share one compiled law share it, as ``spring`` and ``sqrt_spring``); ``caps``: whether it limits |Ft| by
    Coulomb in its slip state."""

    slot: ClassVar[str] = "tangential"
    family: ClassVar[int | None] = None  # None: a record with no compiled law (yet)
    kt_sqrt: ClassVar[bool] = False
    caps: ClassVar[bool] = False

    # its traits (docs/architecture.md, "Slots"): the flags above and their numbers
    states: ClassVar[bool] = False
    constraint: ClassVar[bool] = False
    slip_reads_surface: ClassVar[bool] = False
    stick_kink: ClassVar[bool] = False
    reversal: ClassVar[bool] = False
    viscous_kink: ClassVar[bool] = False
    no_force: ClassVar[bool] = False
    history_is_load: ClassVar[bool] = False  # its history is a force (its error scale is a force's)
    unload_margin: ClassVar[float] = 0.0  # of |v_t|: a slip ends where λ < −margin |v_t|
    near_limit: ClassVar[float] = 0.0  # > 0: F_RIDES, the load within this fraction of a falling limit is on it
    ride_band: ClassVar[float] = 0.0  # the band below a rising limit in which the load rides it

    @property
    def slip_keeps_history(self) -> bool:
        """Whether its slip caps the force and leaves the history alone (F_SLIP_KEEPS)."""
        return False

    @property
    def slip_snaps(self) -> bool:
        """Whether, slipping, its history is put back on its slip surface after each step (F_SLIP_SNAPS)."""
        return False

    def flags(self) -> int:
        """The F_* flags of this law: its traits, and the functions it registered (history_rate, discrete_slip)."""
        k = KERNELS.get(self.family)
        pairs = ((self.history_size > 0, F_HISTORY), (self.states, F_STATES), (self.constraint, F_CONSTRAINT),
                 (self.slip_keeps_history, F_SLIP_KEEPS), (self.slip_reads_surface, F_SLIP_READS_SURFACE),
                 (self.slip_snaps, F_SLIP_SNAPS), (self.stick_kink, F_STICK_KINK), (self.reversal, F_REVERSAL),
                 (self.near_limit > 0.0, F_RIDES), (self.viscous_kink, F_VISCOUS_KINK),
                 (self.no_force, F_NO_FORCE),
                 (k is not None and k.history_rate is not None, F_OWN_RATE),
                 (k is not None and k.discrete_slip is not None, F_DISCRETE_SLIP))
        return sum(flag for on, flag in pairs if on)

    def trait_columns(self) -> list[float]:
        """Columns T_TRAITS.. of the law array."""
        return [float(self.flags()), self.unload_margin, self.near_limit, self.ride_band]

    @property
    def passive(self) -> bool:
        """Whether the law can only store or dissipate energy (TangentialLaw.passive)."""
        return True

    @property
    def pushes_at_onset(self) -> bool:
        """Whether the friction can push along the slip at contact onset (TangentialLaw.pushes_at_onset)."""
        return False


def records(family: int) -> list[type]:
    """The registered tangential record classes of one family id."""
    return [cls for (slot, _), cls in SUBMODELS.items() if slot == "tangential" and cls.family == family]


def record_class(family: int, kt_sqrt: bool = False) -> type:
    """The record class of a kernel family (``kt_sqrt`` tells the records of one family apart)."""
    found = records(family)
    if len(found) > 1:
        found = [cls for cls in found if cls.kt_sqrt == kt_sqrt]
    if len(found) != 1:
        raise ValueError(f"no tangential record for family {family} (kt_sqrt={kt_sqrt})")
    return found[0]


@njit(cache=KERNEL_CACHE, inline="always")
def has(tl, flag):
    """Whether the law array ``tl`` declares the trait ``flag`` (an F_* constant)."""
    return (int(tl[T_TRAITS]) & flag) != 0


@dataclass(frozen=True)
class Kernels:
    """One tangential law's compiled functions (numba dispatchers), each with the signature of the dispatch
    function of its name in ``tangential_force``: ``force`` (every law), ``slip_surface`` and ``return_map``
    (the laws with a history; without them the law has no slip surface and its history maps radially)."""

    family: int
    force: object
    slip_surface: object = None
    return_map: object = None
    history_rate: object = None
    limit_margin: object = None
    discrete_slip: object = None


KERNELS: dict[int, Kernels] = {}
_BUILT: list[bool] = []  # set once the dispatch is assembled: a later law would be missing from it


def compiled(record: type, *, force, slip_surface=None, return_map=None, history_rate=None, limit_margin=None,
             discrete_slip=None) -> Kernels:
    """Registers the compiled functions of the law whose record class is ``record`` under its family id."""
    if not (isinstance(record, type) and issubclass(record, TangentialSubModel)):
        raise TypeError(f"{record!r} is not a tangential record class")
    if not isinstance(record.family, int) or isinstance(record.family, bool) or record.family < 0:
        raise ValueError(f"tangential record {record.id!r}: family must be an int >= 0, not {record.family!r}")
    k = Kernels(record.family, force, slip_surface, return_map, history_rate, limit_margin, discrete_slip)
    if KERNELS.get(k.family, k) != k:
        raise ValueError(f"tangential family {k.family} ({record.id!r}) registered twice with other functions")
    if _BUILT and k.family not in KERNELS:
        raise RuntimeError(f"tangential law {record.id!r} registered after the kernels' dispatch was assembled: "
                           "import it before any solver (name it in $DEMCHECK_LAW_PLUGINS)")
    KERNELS[k.family] = k
    return k


PLUGINS_VARIABLE = "DEMCHECK_LAW_PLUGINS"


def plugin_modules() -> list[str]:
    """The plug-in law modules named in ``$DEMCHECK_LAW_PLUGINS`` (comma-separated, importable)."""
    import os

    return [m for m in (m.strip() for m in os.environ.get(PLUGINS_VARIABLE, "").split(",")) if m]


def load_plugins() -> None:
    """Imports the plug-in law modules (each registers itself); one that cannot be imported is a ConfigError
    naming it."""
    import importlib

    for module in plugin_modules():
        try:
            importlib.import_module(module)
        except Exception as exc:  # noqa: BLE001 - whatever the plug-in's fault, one line names it
            from ..errors import ConfigError

            raise ConfigError(PLUGINS_VARIABLE, module, f"module {module!r} cannot be imported "
                              f"({type(exc).__name__}: {exc})") from None
