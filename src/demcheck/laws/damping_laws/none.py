"""No normal dashpot: the elastic laws (hertz, and the hysteretic spring, which takes none)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import Damping, compiled

NONE = 0  # its family id (L_DAMPING)


@dataclass(frozen=True)
class NoDamping(Damping):
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no normal dashpot (elastic)"
    family: ClassVar[int] = NONE


@njit(cache=KERNEL_CACHE)
def none_damping_force(law, delta, rate):
    return 0.0


@njit(cache=KERNEL_CACHE)
def none_damping_rate(law, delta, rate, acc):
    return 0.0


compiled(NoDamping, force=none_damping_force, rate=none_damping_rate)
