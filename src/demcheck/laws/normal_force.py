"""The normal and damping slots' compiled force as the solvers call it: the law array ``NormalLaw.array()`` —
[family, k, a, eta, b, kl, ku, s, damping, limit], the L_* columns — and the pure functions of it every solver
calls (the 1-D and 3-D collision solvers and the packing's force loop). The normal laws are one module each
(``laws/normal_laws/``: the viscoelastic spring k δ^a, the hysteretic linear spring hls), and so are the damping
laws (``laws/damping_laws/``: none, constant, sqrt, quarter — the dashpot η δ^b δ̇), switched on their family
id (``damping_force``, assembled from the registered laws). The contact's force is composed here, and only here:
the spring's plus the dashpot's, clipped at 0 under ``limit_force``. The solvers ask a law's trait
(``loads_and_unloads``), never its family id.
"""

from __future__ import annotations

from numba import njit

from .. import KERNEL_CACHE
from .damping_laws import dispatch as _dispatch
from .normal_laws import LAWS
from .normal_laws.common import (L_A, L_B, L_DAMPING, L_ETA, L_FAMILY, L_K, L_KL, L_KU, L_LIMIT, L_S,  # noqa: F401
                                 spow)
from .normal_laws.hls import hls_contact_force, hls_unloading  # noqa: F401
from .normal_laws.viscoelastic import viscoelastic_elastic_force, viscoelastic_elastic_rate

# the one law whose force has loading and unloading branches with the largest overlap as history: the solvers'
# modes (M_LOAD, M_UNLOAD beside M_VE) hold one such law; a second would need its own modes
_BRANCHED = [float(m.FAMILY) for m in LAWS if m.LOAD_UNLOAD]
assert len(_BRANCHED) == 1, "the solvers' loading/unloading modes hold one normal law"
BRANCHED_FAMILY = _BRANCHED[0]

_switch = _dispatch.build()
damping_force = _switch.damping_force
damping_rate = _switch.damping_rate


@njit(cache=KERNEL_CACHE, inline="always")
def loads_and_unloads(law):
    """Whether the law's force has loading and unloading branches with the largest overlap as history (the
    solvers' M_LOAD / M_UNLOAD modes; ``LOAD_UNLOAD`` of its module) — else one viscoelastic branch (M_VE), with
    no dashpot prefactor for a tangential dashpot to share (laws/tangential_laws/common.eta_of)."""
    return law[L_FAMILY] == BRANCHED_FAMILY


@njit(cache=KERNEL_CACHE)
def viscoelastic_force(law, delta, rate):
    """The viscoelastic branch's force, unclipped: the spring's k δ^a plus the damping law's dashpot."""
    return viscoelastic_elastic_force(law, delta) + damping_force(law, delta, rate)


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_force_rate(law, delta, rate, acc):
    """d/dt of ``viscoelastic_force`` at the overlap's acceleration ``acc`` (the 1-D solver's peak-force event)."""
    return viscoelastic_elastic_rate(law, delta, rate) + damping_rate(law, delta, rate, acc)


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_contact_force(law, delta, rate):
    """The viscoelastic force at overlap δ > 0, held at 0 where limit_force forbids attraction."""
    f = viscoelastic_force(law, delta, rate)
    if law[L_LIMIT] != 0.0 and f < 0.0:
        return 0.0
    return f


@njit(cache=KERNEL_CACHE)
def normal_force(law, delta, rate, dmax):
    """Total normal force (+ repulsive) of a contact with overlap δ > 0, approach rate δ̇ and, for the
    hysteretic law, the largest overlap so far (the history). No force without overlap."""
    if delta <= 0.0:
        return 0.0
    if loads_and_unloads(law):
        return hls_contact_force(law, delta, dmax)
    return viscoelastic_contact_force(law, delta, rate)
