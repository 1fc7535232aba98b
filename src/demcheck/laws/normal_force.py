"""The normal and damping slots' compiled force: the law array ``NormalLaw.array()`` — [family, k, a, eta, b, kl,
ku, s, limit], the L_* columns — and the pure functions of it every solver calls (the 1-D and 3-D collision
solvers and the packing's force loop).

The elastic part k δ^a (hooke a = 1, hertz a = 3/2) and the dashpot η δ^b δ̇ (damping none, constant, sqrt,
quarter) of a viscoelastic law, or the hysteretic linear spring (hls) with its largest overlap as history.
"""

from __future__ import annotations

import math

from numba import njit

from .. import KERNEL_CACHE

L_FAMILY, L_K, L_A, L_ETA, L_B, L_KL, L_KU, L_S, L_LIMIT = range(9)


@njit(cache=KERNEL_CACHE, inline="always")
def spow(x, p):
    """Sign-preserving power; p = 0 gives 1 (so LSD's dashpot stays linear through δ = 0). The exponents the
    laws use (1, 1/2, 3/2, 1/4) without a pow call: the packing solver's inner loop calls this per contact
    (sqrt is correctly rounded, pow to within an ulp: the results agree to that)."""
    if p == 0.0:
        return 1.0
    a = abs(x)
    if p == 1.0:
        y = a
    elif p == 0.5:
        y = math.sqrt(a)
    elif p == 1.5:
        y = a * math.sqrt(a)
    elif p == 0.25:
        y = math.sqrt(math.sqrt(a))
    else:
        y = a**p
    return y if x >= 0.0 else -y


@njit(cache=KERNEL_CACHE, inline="always")
def hls_unloading(law, dmax):
    """(K_U, δ₀) for the largest overlap reached so far."""
    kl = law[L_KL]
    ku = law[L_KU] if law[L_KU] > 0.0 else kl + law[L_S] * kl * dmax
    return ku, dmax * (1.0 - kl / ku)


@njit(cache=KERNEL_CACHE)
def viscoelastic_force(law, delta, rate):
    return law[L_K] * spow(delta, law[L_A]) + law[L_ETA] * spow(delta, law[L_B]) * rate


@njit(cache=KERNEL_CACHE)
def normal_force(law, delta, rate, dmax):
    """Total normal force (+ repulsive) of a contact with overlap δ > 0, approach rate δ̇ and, for the
    hysteretic law, the largest overlap so far (the history). No force without overlap."""
    if delta <= 0.0:
        return 0.0
    if law[L_FAMILY] == 1.0:
        ku, d0 = hls_unloading(law, dmax)
        f = min(law[L_KL] * delta, ku * (delta - d0))
        return max(f, 0.0)
    f = viscoelastic_force(law, delta, rate)
    if law[L_LIMIT] != 0.0 and f < 0.0:
        return 0.0
    return f
