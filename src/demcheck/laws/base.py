"""A contact is slots: the sub-model record every law is, and the contact that holds one record per slot.

LAMMPS's ``pair_style granular`` (GranularModel with its gran_sub_mod_* sub-models) is the model: a contact is
one sub-model per slot, in the order they act —

    normal · damping · tangential · rolling · twisting · adhesion · heat

and an unused slot holds its ``none`` record. (The seed models of ``normal.py`` and ``tangential.py`` —
``lsd``, ``tti``, … — are the users' names: presets that resolve, for a pair, to records of these slots.)

The sub-model interface (what a law module writes; ``normal.py``, ``damping.py`` and ``tangential.py`` are
examples, and ``rolling``, ``twisting``, ``adhesion`` and ``heat`` laws write the same):

* **The record** is a frozen dataclass subclassing :class:`SubModel`, one class per law, with its numbers as
  named fields (floats, or bools and ints for flags and choices) and three class attributes:

  - ``slot``: one of :data:`SLOTS`;
  - ``id``: the law's id in its slot, lower case (unique per slot; ``none`` is the empty law). Subclassing
    registers the class in :data:`SUBMODELS` under ``(slot, id)``; a second class with the same pair is a
    ValueError;
  - ``history_size``: how many floats of per-contact state the law keeps between steps (the tangential
    spring's displacement: 3; Walton's load, load at the last reversal and last slip direction: 9; none: 0).
    :class:`Contact` sums them and gives each slot its offset, as GranularModel does.

  Nothing outside the compiled kernels reads a record by position: :meth:`SubModel.param_names` names its
  fields, and :meth:`SubModel.array` / :meth:`SubModel.from_array` are the coefficient layout — the fields in
  declaration order as float64 (a bool as 0.0/1.0, an int as its float) and back, exactly.

* **Nothing names a law by its id to decide what to compute.** The solvers ask a law's traits (the tangential
  laws' flag word, ``has(tl, F_…)``; the normal laws' ``loads_and_unloads``; the beyond-sliding records'
  ``stops``, ``decays``, ``spring``, ``replaces_normal``, ``scenarios``, …), and the engines map records by their
  class (``isinstance(contact.damping, QuarterDamping)``) — never by exponents or by the kernels' family numbers:
  an engine that cannot express a record refuses the mapping with its reason (tests/test_laws_by_record.py and
  tests/test_beyond_by_record.py read the source to hold that).

* **The compiled force function** of a law lives in the law's own module — one module per law, in its slot's
  package (``normal_laws/``, ``damping_laws/``, ``tangential_laws/``, ``rolling_laws/``, ``twisting_laws/``,
  ``adhesion_laws/``, ``heat_laws/``) — ``@njit(cache=KERNEL_CACHE)``, named ``<id>_<slot>_force`` (the
  tangential laws add their slip surface and return map), and takes the law's coefficients first. Its signature
  is its slot's, stated once in the slot's interface module, which also dispatches to it:

  - normal and damping: ``normal_laws/common.py``, ``damping_laws/common.py``, composed (spring + dashpot,
    with limit_force's clip) by ``normal_force.py`` for every solver;
  - tangential: ``tangential_slot.py`` (the law array's ``T_*`` layout, the traits) and the generated switch of
    ``tangential_dispatch.py`` behind ``tangential_force.py``;
  - rolling, twisting, adhesion, heat: ``<slot>_laws/slot.py`` (its base record, traits and ``KERNELS``
    table: record class → compiled function).

  Numba compiles a function once per set of argument types: pass numbers as float64 and arrays as arrays
  (docs/architecture.md, "Compiled kernels, one specialisation each").

  The seed's normal, damping and tangential laws are stepped through the kernels' composed arrays,
  ``NormalLaw.array()`` (normal + damping) and ``TangentialLaw.array()``, which ``NormalLaw.from_slots`` /
  ``TangentialLaw.from_slot`` build from the records and ``slots()`` / ``slot()`` turn back into them, exactly.

A law module registers its record classes (the subclass statement does it) and, for the users' names, its
seed models in its slot's :class:`~demcheck.laws.registry.Registry`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

SLOTS = ("normal", "damping", "tangential", "rolling", "twisting", "adhesion", "heat")

# (slot, id) → the record class
SUBMODELS: dict[tuple[str, str], type] = {}


@dataclass(frozen=True)
class SubModel:
    """One sub-model of one slot (see the module docstring for the interface)."""

    slot: ClassVar[str] = ""
    id: ClassVar[str] = ""
    history_size: ClassVar[int] = 0
    title: ClassVar[str] = ""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "id" not in cls.__dict__:
            return  # an abstract intermediate class
        if cls.slot not in SLOTS:
            raise ValueError(f"sub-model {cls.__name__}: slot {cls.slot!r} is not one of {', '.join(SLOTS)}")
        key = (cls.slot, cls.id)
        if key in SUBMODELS and SUBMODELS[key].__qualname__ != cls.__qualname__:
            raise ValueError(f"{cls.slot} sub-model id {cls.id!r} registered twice "
                             f"({SUBMODELS[key].__name__} and {cls.__name__})")
        SUBMODELS[key] = cls

    @classmethod
    def param_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    def array(self) -> np.ndarray:
        """The coefficient layout: the fields in declaration order, as float64."""
        return np.array([float(getattr(self, name)) for name in self.param_names()], dtype=np.float64)

    @classmethod
    def from_array(cls, c) -> SubModel:
        values = {}
        for f, x in zip(dataclasses.fields(cls), c, strict=True):
            kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "float")
            values[f.name] = (float(x) != 0.0) if kind == "bool" else (int(x) if kind == "int" else float(x))
        return cls(**values)

    def describe(self) -> dict:
        return {"slot": self.slot, "id": self.id, **{k: getattr(self, k) for k in self.param_names()}}


def sub_model(slot: str, id_: str) -> type:
    """The record class of ``id_`` in ``slot`` (KeyError naming both when there is none)."""
    try:
        return SUBMODELS[(slot, id_)]
    except KeyError:
        raise KeyError(f"no {slot} sub-model {id_!r} (known: {', '.join(ids(slot))})") from None


def ids(slot: str) -> list[str]:
    """The registered ids of one slot, sorted."""
    return sorted(i for s, i in SUBMODELS if s == slot)


@dataclass(frozen=True)
class NoRolling(SubModel):
    slot: ClassVar[str] = "rolling"
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no rolling resistance"


@dataclass(frozen=True)
class NoTwisting(SubModel):
    slot: ClassVar[str] = "twisting"
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no twisting resistance"


@dataclass(frozen=True)
class NoAdhesion(SubModel):
    slot: ClassVar[str] = "adhesion"
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no adhesion"


@dataclass(frozen=True)
class NoHeat(SubModel):
    slot: ClassVar[str] = "heat"
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no heat conduction"


@dataclass(frozen=True)
class Contact:
    """One record per slot, in the order they act, and the contact's option ``limit_force`` (the total normal
    force held at ≥ 0, LAMMPS's limit_damping). Each record must belong to its slot."""

    normal: SubModel
    damping: SubModel
    tangential: SubModel
    rolling: SubModel = NoRolling()
    twisting: SubModel = NoTwisting()
    adhesion: SubModel = NoAdhesion()
    heat: SubModel = NoHeat()
    limit_force: bool = False

    def __post_init__(self):
        for slot in SLOTS:
            record = getattr(self, slot)
            if not isinstance(record, SubModel) or record.slot != slot:
                raise ValueError(f"contact slot {slot!r} holds {record!r}, not a {slot} sub-model")

    def slots(self) -> tuple[tuple[str, SubModel], ...]:
        return tuple((slot, getattr(self, slot)) for slot in SLOTS)

    def ids(self) -> dict[str, str]:
        return {slot: record.id for slot, record in self.slots()}

    @property
    def history_size(self) -> int:
        return sum(record.history_size for _, record in self.slots())

    def history_offsets(self) -> dict[str, int]:
        """Each slot's first index in the contact's history (slots in order, each ``history_size`` long)."""
        out, k = {}, 0
        for slot, record in self.slots():
            out[slot] = k
            k += record.history_size
        return out
