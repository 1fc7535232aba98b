"""The tangential slot's compiled force, as the solvers call it: the law array ``TangentialLaw.array()`` (the T_*
columns of laws/tangential_slot.py) and the pure functions of it — the force in the stick or slip state, the
slip surface and the return map (Coulomb truncation), a riding law's history rate and limit margin, a law's own
discrete slip rule — each a switch on the law's family id over the laws' modules (``laws/tangential_laws/``),
assembled by ``tangential_dispatch`` from the registered laws; what a law is (its traits: ``has(tl, F_…)``);
the stiffness and dashpot of a spring-like law. Vectors are 3-arrays; the normal law's array
(laws/normal_force.py) gives the dashpot prefactor η(δ) the TTIt and engine-twin dashpots reuse. The switch
names no law (a law is its module), and neither does this facade: the solvers, the packing loop included, ask
the traits; the packing loop's one fast path (the spring's scalars) imports the spring's module itself.
"""

from __future__ import annotations

from . import tangential  # noqa: F401  (every law registered, plug-ins included, before the switch is assembled)
from .tangential_dispatch import build
from .tangential_laws.common import _cross, _dot, _norm, eta_of, kt_of, reverses  # noqa: F401
from .tangential_slot import (F_CONSTRAINT, F_DISCRETE_SLIP, F_HISTORY, F_NO_FORCE, F_OWN_RATE,  # noqa: F401
                              F_REVERSAL, F_RIDES, F_SLIP_KEEPS, F_SLIP_READS_SURFACE, F_SLIP_SNAPS, F_STATES,
                              F_STICK_KINK, F_VISCOUS_KINK, has)

_dispatch = build()
tangential_force = _dispatch.tangential_force
slip_surface = _dispatch.slip_surface
return_map = _dispatch.return_map
history_rate = _dispatch.history_rate
limit_margin = _dispatch.limit_margin
discrete_slip = _dispatch.discrete_slip
