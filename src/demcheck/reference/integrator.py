"""The one integrator core of the adaptive solvers: a Dormand–Prince 5(4) step, the event locator (Illinois
regula falsi on the step fraction), the crossing rule, the earliest-event search, the graze test of free flight
and the simultaneous-event rule. The 1-D normal solver (kernels.adaptive_normal) and the 3-D two-body solver
(kernels3d.adaptive_3d) both build their integrator from :func:`make_core`.

A solver supplies three compiled functions of its state ``y`` and a tuple ``args`` of everything else the right-
hand side reads (law arrays, mode, history):

* ``rhs(y, args)`` → ẏ, of the type of y;
* ``event(y, args, slot)`` → the value of event function ``slot`` (slot 0 must be the overlap δ, slot 2 the
  approach rate δ̇: the graze test reads them);
* ``direction(args, slot)`` → +1 (a rising root), −1 (a falling one), 2 (either) or 0 (not live).

The state is a 2-tuple of floats (the 1-D solver: (δ, δ̇), kept in registers) or a float array (the 3-D solver).
The stage sums are written once (``_combine``) for both: the same floating-point operations, in the same
order, as the two hand-written steps they replace.

Why a factory and not the right-hand side as a first-class argument: numba (0.68) compiles a function that takes
a jitted function as an argument, but will not cache it on disk once it also allocates an array ("uses dynamic
globals") — and the 3-D step allocates its stages. A closure over the solver's functions is a direct call, as
fast as hand-written code, and its callers cache as before (benchmarks/bench_integrator.py).
"""

from __future__ import annotations

import math

from numba import njit, types
from numba.extending import overload

# Dormand–Prince 5(4): the stage rows (a_ij), the 5th-order weights (b_i) and the error weights (b_i − b*_i)
A3 = (3 / 40, 9 / 40)
A4 = (44 / 45, -56 / 15, 32 / 9)
A5 = (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729)
A6 = (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656)
B5 = (35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)  # on k1, k3, k4, k5, k6
E5 = (71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)  # on k1, k3, k4, k5, k6, k7

TOL_THETA = 1e-15  # the event locator's bracket, as a fraction of the step


def _combine(y, h, c, k):
    """y + h · Σ c_i k_i (y None: h · Σ c_i k_i), summed left to right; for a 2-tuple state or an array."""


def _combine_source(n, tuple_state, with_y):
    def one(j):
        idx = "" if j is None else f"[{j}]"
        s = " + ".join(f"c[{i}] * k[{i}]{idx}" for i in range(n))
        return (f"y{idx} + h * ({s})" if with_y else f"h * ({s})")
    body = f"({one(0)}, {one(1)})" if tuple_state else one(None)
    ns: dict = {}
    exec(f"def impl(y, h, c, k):\n    return {body}\n", ns)
    return ns["impl"]


@overload(_combine, inline="always")
def _combine_impl(y, h, c, k):
    with_y = not isinstance(y, (types.NoneType, types.Omitted))
    state = y if with_y else k[0]
    return _combine_source(len(k), isinstance(state, types.BaseTuple), with_y)


def _first_stage(y, h, k1):
    """y + h (k1 / 5) (a division, as the tableau's 1/5 is not a double)."""


@overload(_first_stage, inline="always")
def _first_stage_impl(y, h, k1):
    if isinstance(y, types.BaseTuple):
        return lambda y, h, k1: (y[0] + h * (k1[0] / 5), y[1] + h * (k1[1] / 5))
    return lambda y, h, k1: y + h * (k1 / 5)


@njit(cache=True)
def crossed(g0, g1, direction):
    """The one crossing rule of both solvers: did event value g go from g0 to g1 through its root in the
    ``direction`` it is live for (−1 falling, +1 rising, 2 either)? A fall needs g0 > 0 and counts a landing
    on exactly 0; a rise counts both a start from exactly 0 and a landing on it — an event function that sits at
    0 when its event becomes possible (the slip function of a fresh history at contact start; an overlap that
    starts at exactly 0; a force that ended at exactly 0 and rises again) must still fire. The 1-D solver had
    g0 < 0 only for a rise: the two rules differ only where a rising event value is exactly 0.0 at the start of
    an accepted step, which no case under cases/ meets (benchmarks/results/bench_integrator.txt)."""
    if direction == 2:
        return (g0 > 0.0 and g1 <= 0.0) or (g0 < 0.0 and g1 >= 0.0)
    if direction < 0:
        return g0 > 0.0 and g1 <= 0.0
    return (g0 < 0.0 and g1 >= 0.0) or (g0 == 0.0 and g1 > 0.0)


@njit(cache=True, inline="always")
def illinois_trial(lo, hi, glo, ghi):
    """The regula falsi point of the bracket [lo, hi] (event values glo, ghi), or its midpoint where the
    secant is undefined or leaves the bracket."""
    theta = lo - glo * (hi - lo) / (ghi - glo) if (math.isfinite(glo) and math.isfinite(ghi)
                                                    and ghi != glo) else 0.5 * (lo + hi)
    if not (lo < theta < hi) or not math.isfinite(theta):
        theta = 0.5 * (lo + hi)
    return theta


@njit(cache=True, inline="always")
def illinois_update(lo, hi, glo, ghi, side, theta, g, crossed):
    """Shrink the bracket to the side of θ that holds the root (``crossed``: between lo and θ), halving the
    value kept on the other side when the same side moves twice (Illinois). Returns (lo, hi, glo, ghi,
    side)."""
    if crossed:
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


@njit(cache=True, inline="always")
def simultaneous_end(terminal, started, in_contact, delta, rate):
    """The simultaneous-event rule: an event that is not the contact's end (nor its start) but leaves a contact
    with δ ≤ 0 and receding (δ̇ < 0) had its root together with δ = 0 — elastic Hertz: the force and the overlap
    vanish at the same instant, and the located root lands a hair past δ = 0. The contact has ended there too."""
    return not terminal and not started and in_contact and delta <= 0.0 and rate < 0.0


def make_core(rhs, event, direction, nslot):
    """The integrator of one solver (see the module's docstring): returns (dp5, locate, earliest, graze)."""

    @njit
    def dp5(y, h, args):
        """One Dormand–Prince 5(4) step of length h from y: (the 5th-order state, the error estimate)."""
        k1 = rhs(y, args)
        k2 = rhs(_first_stage(y, h, k1), args)
        k3 = rhs(_combine(y, h, A3, (k1, k2)), args)
        k4 = rhs(_combine(y, h, A4, (k1, k2, k3)), args)
        k5 = rhs(_combine(y, h, A5, (k1, k2, k3, k4)), args)
        k6 = rhs(_combine(y, h, A6, (k1, k2, k3, k4, k5)), args)
        yn = _combine(y, h, B5, (k1, k3, k4, k5, k6))
        k7 = rhs(yn, args)
        return yn, _combine(None, h, E5, (k1, k3, k4, k5, k6, k7))

    @njit
    def locate(y, h, args, slot, sense, g0, g1):
        """The step fraction θ ∈ (0, 1] of the root of event ``slot`` in the step [0, h] from y (event values
        g0, g1 at its ends): Illinois regula falsi with a bisection fallback, each trial a fresh DP5 step of
        length θh (5th-order accurate). The bracket's crossed end: the state there has fired the event."""
        lo, hi, glo, ghi = 0.0, 1.0, g0, g1
        side = 0
        for _ in range(200):
            if hi - lo <= TOL_THETA:
                break
            theta = illinois_trial(lo, hi, glo, ghi)
            yt, _ = dp5(y, theta * h, args)
            g = event(yt, args, slot)
            lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, theta, g,
                                                     crossed(glo, g, sense) or g == 0.0)
        return hi

    @njit
    def earliest(y, yn, h, args):
        """The earliest live event of the accepted step y → yn: (θ, slot, direction), slot −1 for none."""
        best_theta, best_slot, best_dir = 2.0, -1, 0
        for slot in range(nslot):
            sense = direction(args, slot)
            if sense == 0:
                continue
            g0 = event(y, args, slot)
            g1 = event(yn, args, slot)
            if crossed(g0, g1, sense):
                theta = locate(y, h, args, slot, sense, g0, g1)
                if theta < best_theta:
                    best_theta, best_slot, best_dir = theta, slot, sense
        return best_theta, best_slot, best_dir

    @njit
    def graze(y, yn, h, args):
        """A free-flight step whose ends both have a gap (δ < 0) but whose approach turned into recession
        (δ̇: + → −) may hold a touch between them (δ has its maximum inside): the step fraction of the touch
        (the root of δ before the maximum), or 2 when there is none."""
        r0 = event(y, args, 2)
        r1 = event(yn, args, 2)
        if not (r0 > 0.0 and r1 <= 0.0):
            return 2.0
        tm = locate(y, h, args, 2, -1, r0, r1)
        ym, _ = dp5(y, tm * h, args)
        dm = event(ym, args, 0)
        if not (dm > 0.0):
            return 2.0
        return tm * locate(y, tm * h, args, 0, 1, event(y, args, 0), dm)

    return dp5, locate, earliest, graze
