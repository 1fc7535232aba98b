"""The normal law array's layout ``NormalLaw.array()`` — [family, k, a, eta, b, kl, ku, s, damping, limit], the
L_* columns (``damping``: the damping law's family id, laws/damping_laws/) — and the sign-preserving power the
laws (and the tangential dashpots) use."""

from __future__ import annotations

import math

from numba import njit

from ... import KERNEL_CACHE

L_FAMILY, L_K, L_A, L_ETA, L_B, L_KL, L_KU, L_S, L_DAMPING, L_LIMIT = range(10)
# (limit stays the last column: the array's length is L_LIMIT + 1 where the packing loop and the warm-up use it)


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
