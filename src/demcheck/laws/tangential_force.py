"""The tangential slot's compiled force, as the solvers call it: the law array ``TangentialLaw.array()`` (the T_*
columns of laws/tangential_slot.py) and the pure functions of it — the force in the stick or slip state, the
slip surface and the return map (Coulomb truncation), each a switch on the law's family id over the laws'
modules (``laws/tangential_laws/``), assembled by ``tangential_dispatch`` from the registered laws; the
stiffness and dashpot of a spring-like law; Walton's reversal rule and stiffness. Vectors are 3-arrays; the
normal law's array (laws/normal_force.py) gives the dashpot prefactor η(δ) the TTIt and engine-twin dashpots
reuse. The switch names no law (a law is its module); what is named here is Walton's reversal rule and
stiffness, which the solvers' history code still calls by name (docs/architecture.md, what is not yet one place).
"""

from __future__ import annotations

from . import tangential  # noqa: F401  (every law registered, plug-ins included, before the switch is assembled)
from .tangential_dispatch import build
from .tangential_laws.common import _cross, _dot, _norm, eta_of, kt_of  # noqa: F401
from .tangential_laws.walton import (WALTON_NEAR_LIMIT, WALTON_RIDE, walton_margin,  # noqa: F401
                                     walton_reverses, walton_stiffness)

_dispatch = build()
tangential_force = _dispatch.tangential_force
slip_surface = _dispatch.slip_surface
return_map = _dispatch.return_map
