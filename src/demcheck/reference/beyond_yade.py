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
