"""Yade's scheme for a sphere on a wall (the scenarios beyond sliding): ``Law2_ScGeom6D_CohFrictPhys_CohesionMoment``
(incremental form) on a sphere–box contact (``Ig2_Box_Sphere_ScGeom6D``), stepped by ``NewtonIntegrator``'s
leap-frog.

Yade's step k computes the forces at x_k with the velocities v_{k−½}, ω_{k−½} (the state it holds), then
v_{k+½} = v_{k−½} + dt (F_k/m + g), ω_{k+½} = ω_{k−½} + dt T_k/I, x_{k+1} = x_k + dt v_{k+½}. Every force call
updates the histories, the first one too (the contact is new at step 0 and already takes its increment): this is
where it differs from ``reference.beyond.verlet_wall`` (``fix nve/sphere``'s set-up call adds none), and the
reason for this module. The law, as read in Yade's CohesiveFrictionalContactLaw.cpp, ScGeom.cpp and
Ig2_Box_Sphere_ScGeom.cpp (a flat axis-aligned box: the normal never turns, so ScGeom's rotation of the
histories is the identity here):

* Fn = kn δ (held at ≥ 0: a contact without cohesion has no tension), kn = 2EaRaEbRb/(EaRa + EbRb) with both
  radii the sphere's (the box takes the sphere's radius);
* the shear force: Fs −= ks v_t dt, v_t the slip velocity of the contact point (midway between the sphere's
  lowest point and the box's face: the arm R − δ/2), scaled back to μ|Fn| past it; no dashpot;
* the bending moment: Mb −= kr w_b dt (w_b the relative spin's part normal to n), scaled back to
  maxRollPl·|Fn|; the twisting moment: Mt −= ktw (w·n) n dt, scaled back to maxTwistPl·|Fn|; no dashpots.

A sample (every ``every`` steps from step 0) holds x_k and the full-step velocities v_k = v_{k−½} + ½dt F_k/m,
ω_k = ω_{k−½} + ½dt T_k/I (F_k with the weight), as the deck writes them.

The pair scenarios (engines/yade/pair.py): :func:`pull`, Mindlin's DMT (HertzMindlin.cpp) along a pull that moves
body 1 by pos += vel·dt; :func:`held`, ThermalEngine's conductance (Thermal.cpp) by its forward Euler.
"""

from __future__ import annotations

import math

import numpy as np


def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def wall(radius: float, mass: float, x0, v_half, omega_half, gravity, wall_point, wall_normal, dt: float,
         samples: int, every: int, *, kn: float, ks: float, mu: float, kr: float, max_roll: float, ktw: float,
         max_twist: float) -> dict:
    """The sphere from x0 with v_{−½} = ``v_half``, ω_{−½} = ``omega_half``, stepped ``samples``·``every`` steps;
    ``max_roll``, ``max_twist``: Yade's maxRollPl, maxTwistPl (the limits are these × |Fn|; < 0: none).
    Returns t, x, v, ω at the samples (rows × 3)."""
    inertia = 0.4 * mass * radius * radius
    n = np.asarray(wall_normal, dtype=float)
    p = np.asarray(wall_point, dtype=float)
    g = np.asarray(gravity, dtype=float)
    x, v, w = (np.array(a, dtype=float) for a in (x0, v_half, omega_half))
    hist = {"fs": np.zeros(3), "mb": np.zeros(3), "mt": np.zeros(3)}

    def capped(vec, limit):
        size = math.sqrt(float(vec @ vec))
        return vec * (limit / size) if limit >= 0.0 and size > limit else vec

    def forces():
        delta = radius - float((x - p) @ n)
        if delta <= 0.0:
            hist.update(fs=np.zeros(3), mb=np.zeros(3), mt=np.zeros(3))
            return mass * g, np.zeros(3)
        c2x = -(radius - 0.5 * delta) * n  # the contact point from the sphere's centre
        vrel = v + _cross(w, c2x)
        vt = vrel - (vrel @ n) * n
        fn = max(kn * delta, 0.0)
        fs = capped(hist["fs"] - ks * (vt * dt), fn * mu)
        spin = float(n @ w)
        mb = capped(hist["mb"] - kr * ((w - spin * n) * dt), max_roll * fn)
        mt = capped(hist["mt"] - ktw * ((spin * n) * dt), max_twist * fn)
        hist.update(fs=fs, mb=mb, mt=mt)
        f = fn * n + fs
        return f + mass * g, _cross(c2x, f) + mb + mt

    rows = {"x": [], "v": [], "omega": []}
    for k in range(samples * every):
        f, tq = forces()
        if k % every == 0:
            rows["x"].append(np.copy(x))
            rows["v"].append(v + (0.5 * dt / mass) * f)
            rows["omega"].append(w + (0.5 * dt / inertia) * tq)
        v += dt * (f / mass)
        w += dt * (tq / inertia)
        x += dt * v
    out = {k: np.array(a) for k, a in rows.items()}
    out["t"] = np.arange(samples) * every * dt
    return out


# ----------------------------------------------------------------------------- the pair scenarios


def mindlin_constants(young0: float, poisson0: float, r0: float, young1: float, poisson1: float, r1: float,
                      gamma: float) -> tuple[float, float]:
    """(kno, adhesionForce) of ``Ip2_FrictMat_FrictMat_MindlinPhys`` as HertzMindlin.cpp computes them (in its
    order of operations): E* = EaEb/((1 − νa²)Eb + (1 − νb²)Ea), R̄ = RaRb/(Ra + Rb), kno = (4/3)E*√R̄ and the
    DMT adhesion 4πR̄γ (γ the functor's ``gamma``, a surface energy: 2πwR̄ for w = 2γ)."""
    e = young0 * young1 / ((1.0 - poisson0 ** 2) * young1 + (1.0 - poisson1 ** 2) * young0)
    r = r0 * r1 / (r0 + r1)
    return 4.0 / 3.0 * e * math.sqrt(r), 4.0 * math.pi * r * gamma


def mindlin_dmt_force(kno: float, adhesion: float, delta: float) -> float:
    """``Law2_ScGeom_MindlinPhys_Mindlin`` with ``includeAdhesion`` and no damping: Fn = kno δ^{3/2} − adhesion
    while δ ≥ 0 (> 0 repels), none below (the law erases the contact)."""
    if delta < 0.0:
        return 0.0
    return kno * delta ** 1.5 - adhesion


def pull(kno: float, adhesion: float, r_sum: float, x1: float, speed: float, dt: float, steps: int) -> dict:
    """Body 0 held at the origin, body 1 from x1 along +x with its velocity held at ``speed`` (all its degrees of
    freedom blocked): NewtonIntegrator moves it by pos += vel·dt each step, after the forces at its position
    (δ = r0 + r1 − x). The overlap and Mindlin's force at each step (pull_off's ``delta`` and ``fn``)."""
    x, deltas, forces = float(x1), [], []
    for _ in range(steps + 1):
        d = r_sum - x
        deltas.append(d)
        forces.append(mindlin_dmt_force(kno, adhesion, d))
        x += speed * dt
    return {"delta": np.array(deltas), "fn": np.array(forces)}


def thermal_conductance(k0: float, k1: float, r0: float, r1: float, delta: float) -> float:
    """``ThermalEngine``'s conductance between two spheres (Thermal.cpp, neither useKernMethod nor useHertzMethod):
    H = 2(k0 + k1) r0 r1 / d, d = r0 + r1 − δ the distance of the centres — the size of the contact does not
    enter."""
    return 2.0 * (k0 + k1) * r0 * r1 / (r0 + r1 - delta)


def thermal_capacity(cp: float, density: float, radius: float) -> float:
    """A body's heat capacity as ThermalEngine takes it: Cp·ρ·(4/3)πr³ (the material's density)."""
    return cp * density * (4.0 / 3.0 * math.pi * radius ** 3)


def euler_factor(h: float, cap0: float, cap1: float, dt: float) -> float:
    """x = dt·H(1/C0 + 1/C1): each step of :func:`held` multiplies T1 − T0 by 1 − x. Below 1 it decays
    monotonically (its e-fold time −dt/ln(1 − x), the exponential's τ = dt/x to O(x)); between 1 and 2 it flips
    sign every step while it shrinks — samples an even number of steps apart hide the flips and read a decay of
    |1 − x| per step, a time constant that is no exchange of heat; from 2 on it grows without bound."""
    return dt * h * (1.0 / cap0 + 1.0 / cap1)


def held(h: float, cap0: float, cap1: float, t0: float, t1: float, dt: float, steps: int, every: int) -> dict:
    """Two bodies held together exchanging Q = H (T1 − T0) by ThermalEngine's forward Euler (T += Q·dt/C, each
    step, ``tsSafetyFactor`` ≤ 0), sampled every ``every`` steps from step 0: t and dT = T1 − T0."""
    diffs = [t1 - t0]
    for k in range(1, steps + 1):
        flux = h * (t0 - t1)  # ThermalEngine's fluxij of the pair (body 0 first)
        t0, t1 = -flux * dt / cap0 + t0, flux * dt / cap1 + t1
        if k % every == 0:
            diffs.append(t1 - t0)
    return {"t": np.arange(len(diffs)) * every * dt, "dT": np.array(diffs)}
