"""What the two adaptive solvers share: the 1-D normal solver (kernels.adaptive_normal, a state of two
scalars δ, δ̇) and the 3-D two-body solver (kernels3d.adaptive_3d, a state array of 21).

Written once here and compiled into each solver (every function is inlined, and generic over the state: a
float in the 1-D solver, an array in the 3-D one):

* the Dormand–Prince 5(4) method: its stages, its 5th-order solution and its error estimate (``stage2`` …
  ``error``) — a solver's step function only evaluates its right-hand side at the states these give;
* the step-size control: ``shrink`` after a rejected step, ``grow`` after an accepted one, ``resume`` after an
  event, ``H_MIN`` (the smallest step, of the time scale) and ``H_START``;
* the event location: ``crossed`` (when a step crosses an event function; one rule for both solvers),
  ``THETA_TOL`` and ``LOCATE_ITERATIONS`` (the locator's bracket width and iteration cap) and the Illinois
  bracket arithmetic (``illinois_trial``, ``illinois_step``);
* the simultaneous-event rule (``ended_with_it``).

What stays with each solver is what it alone knows: its right-hand side, its event functions and their
directions, its error norm (the 1-D one on the overlap and its rate; the 3-D one on the bodies' positions,
velocities, spins and, while sticking, the history). A step function or a locator taking the right-hand side
as an argument was built and measured (benchmarks/bench_integrator.py): numba 0.68 does not cache a compiled
function that takes another as an argument once it allocates, and a factory building each solver's loop
from its functions made the 1-D solver 1.27x slower per collision and a cold compile 1.41x longer.
"""

from __future__ import annotations

import math

from numba import njit

from .. import KERNEL_CACHE

# ----------------------------------------------------------------------------- Dormand–Prince 5(4)
# (the tableau's fractions written as the stages use them: a stage's state must not depend on which solver
# computes it, to the last bit)


@njit(cache=KERNEL_CACHE, inline="always")
def stage2(y, h, k1):
    return y + h * (k1 / 5)


@njit(cache=KERNEL_CACHE, inline="always")
def stage3(y, h, k1, k2):
    return y + h * (3 / 40 * k1 + 9 / 40 * k2)


@njit(cache=KERNEL_CACHE, inline="always")
def stage4(y, h, k1, k2, k3):
    return y + h * (44 / 45 * k1 - 56 / 15 * k2 + 32 / 9 * k3)


@njit(cache=KERNEL_CACHE, inline="always")
def stage5(y, h, k1, k2, k3, k4):
    return y + h * (19372 / 6561 * k1 - 25360 / 2187 * k2 + 64448 / 6561 * k3 - 212 / 729 * k4)


@njit(cache=KERNEL_CACHE, inline="always")
def stage6(y, h, k1, k2, k3, k4, k5):
    return y + h * (9017 / 3168 * k1 - 355 / 33 * k2 + 46732 / 5247 * k3 + 49 / 176 * k4 - 5103 / 18656 * k5)


@njit(cache=KERNEL_CACHE, inline="always")
def solution(y, h, k1, k3, k4, k5, k6):
    """The 5th-order state at the end of the step (also the 7th stage's state: first same as last)."""
    return y + h * (35 / 384 * k1 + 500 / 1113 * k3 + 125 / 192 * k4 - 2187 / 6784 * k5 + 11 / 84 * k6)


@njit(cache=KERNEL_CACHE, inline="always")
def error(h, k1, k3, k4, k5, k6, k7):
    """The difference between the 5th- and the embedded 4th-order solutions."""
    return h * (71 / 57600 * k1 - 71 / 16695 * k3 + 71 / 1920 * k4 - 17253 / 339200 * k5 + 22 / 525 * k6
                - 1 / 40 * k7)


# ----------------------------------------------------------------------------- step-size control

H_START = 1e-3  # the first step, of the solver's time scale
H_MIN = 1e-14  # below this (of the time scale) a step that still fails the tolerance ends the run
H_AFTER_EVENT = 1e-6  # the least step after an event, of the time scale


@njit(cache=KERNEL_CACHE, inline="always")
def shrink(err):
    """The factor on a rejected step of error norm ``err`` (> 1; a non-finite error takes a tenth)."""
    return 0.1 if not math.isfinite(err) else max(0.1, 0.9 * err ** -0.2)


@njit(cache=KERNEL_CACHE, inline="always")
def grow(err):
    """The factor on the next step after an accepted one of error norm ``err`` (≤ 1), within [0.2, 5]."""
    return 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 * err ** -0.2))


@njit(cache=KERNEL_CACHE, inline="always")
def resume(h, theta, t_scale):
    """The step after an event found at the fraction ``theta`` of a step ``h``: what was left of it."""
    return max(h * (1.0 - theta), H_AFTER_EVENT * t_scale) if theta < 1.0 else h


# ----------------------------------------------------------------------------- event location

THETA_TOL = 1e-15  # the locator stops when its bracket (a fraction of the step) is this narrow
LOCATE_ITERATIONS = 200


@njit(cache=KERNEL_CACHE, inline="always")
def crossed(g0, g1, direction):
    """Whether an event function goes from ``g0`` to ``g1`` across zero in its ``direction``: −1 falling,
    +1 rising (a rise from exactly 0 counts: at contact start the slip function of a fresh history is 0),
    2 either way."""
    if direction == 2:
        return (g0 > 0.0 and g1 <= 0.0) or (g0 < 0.0 and g1 >= 0.0)
    if direction < 0:
        return g0 > 0.0 and g1 <= 0.0
    return (g0 < 0.0 and g1 >= 0.0) or (g0 == 0.0 and g1 > 0.0)


@njit(cache=KERNEL_CACHE, inline="always")
def illinois_trial(lo, hi, glo, ghi):
    """The regula falsi point of the bracket [lo, hi] (event values glo, ghi), or its midpoint where the
    secant is undefined or leaves the bracket."""
    theta = lo - glo * (hi - lo) / (ghi - glo) if (math.isfinite(glo) and math.isfinite(ghi)
                                                    and ghi != glo) else 0.5 * (lo + hi)
    if not (lo < theta < hi) or not math.isfinite(theta):
        theta = 0.5 * (lo + hi)
    return theta


@njit(cache=KERNEL_CACHE, inline="always")
def illinois_step(lo, hi, glo, ghi, side, theta, g, direction):
    """Shrink the bracket to the side of θ (event value ``g``) that holds the root — between lo and θ when
    the function has crossed there or is 0 at θ — halving the value kept on the other side when the same
    side moves twice (Illinois). Returns (lo, hi, glo, ghi, side)."""
    if crossed(glo, g, direction) or g == 0.0:
        hi, ghi = theta, g
        if side == -1:
            glo *= 0.5
        side = -1
    else:
        lo, glo = theta, g
        if side == 1:
            ghi *= 0.5
        side = 1
    return lo, hi, glo, ghi, side


# ----------------------------------------------------------------------------- simultaneous events


@njit(cache=KERNEL_CACHE, inline="always")
def ended_with_it(terminal, started, in_contact, delta, rate):
    """The simultaneous-event rule: an event that is neither the contact's end nor its start, located in
    contact, whose state lies past δ = 0 and receding, was found together with the contact's end (elastic
    Hertz: force and overlap vanish at the same instant; the locator lands on either side of it). The contact
    has then ended too."""
    return not terminal and not started and in_contact and delta <= 0.0 and rate < 0.0
