"""The frictionless law: no tangential force."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import TangentialSubModel, compiled

NONE = 0


@dataclass(frozen=True)
class NoTangential(TangentialSubModel):
    id: ClassVar[str] = "none"
    family: ClassVar[int] = NONE
    title: ClassVar[str] = "frictionless"
    no_force: ClassVar[bool] = True


@njit(cache=KERNEL_CACHE)
def none_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    return np.zeros(3)


compiled(NoTangential, force=none_tangential_force)
