"""The normal and damping slots' compiled force as the solvers call it: the law array ``NormalLaw.array()`` —
[family, k, a, eta, b, kl, ku, s, damping, limit], the L_* columns — and the pure functions of it every solver
calls (the 1-D and 3-D collision solvers and the packing's force loop). The normal laws are one module each
(``laws/normal_laws/``: hooke, hertz, hls), and so are the damping laws (``laws/damping_laws/``: none, constant,
sqrt, quarter — the dashpot η δ^b δ̇), each slot switched on its family column by a switch generated from its
registered laws (``normal_laws/dispatch.py``, ``damping_laws/dispatch.py``). The contact's force is composed here,
and only here: a one-branch law's spring plus the damping law's dashpot, clipped at 0 under ``limit_force``; a law
with loading and unloading branches is its own force. The solvers ask a law's trait (``loads_and_unloads``), never
its family id, and this module names no law.
"""

from __future__ import annotations

from numba import njit

from .. import KERNEL_CACHE
from .damping_laws import dispatch as _damping_dispatch
from .normal_laws import dispatch as _normal_dispatch
from .normal_laws.common import (KERNELS, L_A, L_B, L_DAMPING, L_ETA, L_FAMILY, L_K, L_KL, L_KU, L_LIMIT,  # noqa: F401
                                 L_S, spow)

# the laws whose force has loading and unloading branches with the largest overlap as history (the records'
# ``load_unload``): the solvers' modes (M_LOAD, M_UNLOAD beside M_VE) hold one such law, its loading branch
# K_L δ (L_KL); a second would need modes of its own
_BRANCHED = [float(k.family) for k in KERNELS.values() if k.load_unload]
assert len(_BRANCHED) == 1, "the solvers' loading/unloading modes hold one normal law"
BRANCHED_FAMILY = _BRANCHED[0]

_normal = _normal_dispatch.build()
spring_force = _normal.spring_force
spring_rate = _normal.spring_rate
branched_force = _normal.branched_force
unloading_branch = _normal.unloading_branch
hls_unloading = unloading_branch  # (the name reference/kernels.py and adaptive3d.py import for M_UNLOAD)

_damping = _damping_dispatch.build()
damping_force = _damping.damping_force
damping_rate = _damping.damping_rate


@njit(cache=KERNEL_CACHE, inline="always")
def loads_and_unloads(law):
    """Whether the law's force has loading and unloading branches with the largest overlap as history (the
    solvers' M_LOAD / M_UNLOAD modes; its record's ``load_unload``) — else one viscoelastic branch (M_VE), with
    no dashpot prefactor for a tangential dashpot to share (laws/tangential_laws/common.eta_of)."""
    return law[L_FAMILY] == BRANCHED_FAMILY


@njit(cache=KERNEL_CACHE)
def viscoelastic_force(law, delta, rate):
    """The one-branch force, unclipped: the law's spring plus the damping law's dashpot."""
    return spring_force(law, delta) + damping_force(law, delta, rate)


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_force_rate(law, delta, rate, acc):
    """d/dt of ``viscoelastic_force`` at the overlap's acceleration ``acc`` (the 1-D solver's peak-force event)."""
    return spring_rate(law, delta, rate) + damping_rate(law, delta, rate, acc)


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_contact_force(law, delta, rate):
    """The one-branch force at overlap δ > 0, held at 0 where limit_force forbids attraction."""
    f = viscoelastic_force(law, delta, rate)
    if law[L_LIMIT] != 0.0 and f < 0.0:
        return 0.0
    return f


@njit(cache=KERNEL_CACHE)
def normal_force(law, delta, rate, dmax):
    """Total normal force (+ repulsive) of a contact with overlap δ > 0, approach rate δ̇ and, for a law with
    loading and unloading branches, the largest overlap so far (the history). No force without overlap."""
    if delta <= 0.0:
        return 0.0
    if loads_and_unloads(law):
        return branched_force(law, delta, dmax)
    return viscoelastic_contact_force(law, delta, rate)
