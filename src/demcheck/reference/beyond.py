"""Scenarios beyond sliding, each solved by integration over the laws' force functions (scipy's solve_ivp,
DOP853, with events) and each with its closed form:

* ``rolling``: a sphere rolling without slip on a horizontal plane under a rolling-resistance law — stopping time
  and distance (type A: a = −(5/7)μr g, t = 7v0/(5μr g), s = 7v0²/(10μr g) for Rr = R);
* ``incline``: the same sphere on a plane tilted by θ — it stays (type A or C) while tan θ ≤ μr Rr/R, and rolls
  down with a = (5/7) g (sin θ − μr cos θ) (Rr = R) once the torque is fully mobilised;
* ``twist``: a sphere spinning about the normal of a plane, its twisting torque at its limit μtw|Fn|: it stops at
  t = I ω0/(μtw |Fn|) (I = (2/5) m R²);
* ``pull_off``: two adhesive bodies pulled apart quasi-statically — the largest tension (pull_off_force: JKR
  (3/2)πwR̄, DMT 2πwR̄) and the overlap where the contact breaks (separation_at_pull_off: JKR −3a_f²/R̄ under an
  imposed displacement, a_f³ = πwR̄²/(8E*));
* ``adhesive_impact``: a head-on impact of elastic JKR bodies (Thornton & Ning 1998): the energy of the
  hysteresis loop W = −∫_{δf}^{0} F dδ captures them below v_s = √(2W/m̄) (capture_velocity) and leaves
  e = √(1 − (v_s/v)²) above;
* ``conduction``: two bodies held at a fixed overlap exchange heat: T1 − T0 decays as exp(−t/τ),
  τ = 1/(H(1/C0 + 1/C1)) (heat_time_constant), C = m c_p, towards (C0T0 + C1T1)/(C0 + C1).

The sphere on a plane: m, R, I = (2/5)mR², gravity g; the plane's normal is z, the sphere rolls along x with
ω_y = v/R (no slip is assumed: the tangential friction must hold |Ft| ≤ μ|Fn|, which ``rolling_on_plane`` checks).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from ..laws import rolling as _rolling
from ..laws import twisting as _twisting
from ..laws.adhesion import AREA_BAND, adhesive_force
from ..laws.heat import conductance, heat_flow
from ..laws.rolling import rolling_torque

RTOL = 1e-11
N_DOWN = np.array([0.0, 0.0, -1.0])  # from the sphere into the plane


# ----------------------------------------------------------------------------- closed forms


def rolling_stop_closed(mu_r: float, r_roll: float, radius: float, v0: float, g: float) -> tuple[float, float]:
    """(rolling_stop_time, rolling_distance) under a type A torque μr Rr m g on a level plane."""
    a = 5.0 / 7.0 * mu_r * g * r_roll / radius
    return v0 / a, v0 * v0 / (2.0 * a)


def rolling_viscous_closed(c_r: float, mass: float, radius: float, v0: float) -> tuple[float, float]:
    """(time constant, distance to rest) under a type B torque −Cr ω: v = v0 exp(−t/T), T = (7/5) m R²/Cr."""
    tau = 1.4 * mass * radius * radius / c_r
    return tau, v0 * tau


def incline_closed(mu_r: float, r_roll: float, radius: float, theta: float, g: float) -> tuple[float, float]:
    """(incline_critical_angle, the acceleration down the slope at θ: 0 below the critical angle)."""
    crit = math.atan(mu_r * r_roll / radius)
    acc = 5.0 / 7.0 * g * (math.sin(theta) - mu_r * r_roll / radius * math.cos(theta))
    return crit, max(acc, 0.0)


def twist_stop_closed(mass: float, radius: float, omega0: float, mu_tw: float, fn: float) -> float:
    return 0.4 * mass * radius * radius * abs(omega0) / (mu_tw * fn)


def jkr_loop_energy(r: float, e: float, w: float, break_at: str = "displacement") -> float:
    """W = −∫ F dδ from the break (δ_f, or δ_c when the law breaks at the load-controlled pull-off) to δ = 0
    along JKR's branch, by its antiderivative in a."""
    c = math.sqrt(2.0 * math.pi * w / e)
    k1, k2 = 4.0 * e / (3.0 * r), math.sqrt(8.0 * math.pi * w * e)

    def g(a):  # ∫ F(a) δ'(a) da
        return (2.0 * k1 * a ** 5 / (5.0 * r) - (k1 * c / 7.0 + 4.0 * k2 / (7.0 * r)) * a ** 3.5
                + k2 * c / 4.0 * a * a)

    a0 = (c * r) ** (2.0 / 3.0)
    af = ((1.0 if break_at == "displacement" else 9.0) * math.pi * w * r * r / (8.0 * e)) ** (1.0 / 3.0)
    return -(g(a0) - g(af))


def capture_velocity_closed(r: float, e: float, w: float, m_eff: float, break_at: str = "displacement") -> float:
    return math.sqrt(2.0 * jkr_loop_energy(r, e, w, break_at) / m_eff)


def adhesive_restitution_closed(v: float, v_capture: float) -> float:
    return math.sqrt(1.0 - (v_capture / v) ** 2) if v > v_capture else 0.0


def sjkr_pull_off_closed(k_hertz: float, k_c: float, area: int, radius: float, r_eff: float) -> float:
    """The largest tension of an elastic Hertz contact F = k_H δ^{3/2} (k_H = (4/3)E*√R̄) with the simplified JKR
    cohesion −kc·A added while δ > 0, between like spheres of radius R (R̄ = R/2), at the overlap where dF/dδ = 0:
    ``band`` A = 2π·2R̄δ gives √δ* = 8πkcR̄/(3k_H) and a tension (4/3)πkcR̄δ*; ``lens`` A = π(Rδ − δ²/4) (the circle
    where the undeformed spheres intersect) gives (kcπ/2)s² + (3/2)k_H s − kcπR = 0 for s = √δ*. The contact ends
    at δ = 0 (separation_at_pull_off 0)."""
    if area == AREA_BAND:
        d = (8.0 * math.pi * k_c * r_eff / (3.0 * k_hertz)) ** 2
        return -(k_hertz * d ** 1.5 - 4.0 * math.pi * k_c * r_eff * d)
    a, b, c = 0.5 * math.pi * k_c, 1.5 * k_hertz, -math.pi * k_c * radius
    s = 2.0 * -c / (b + math.sqrt(b * b - 4.0 * a * c))  # the positive root, without cancellation
    d = s * s
    return -(k_hertz * d ** 1.5 - math.pi * k_c * (radius * d - 0.25 * d * d))


def heat_time_constant_closed(h: float, c0: float, c1: float) -> float:
    return 1.0 / (h * (1.0 / c0 + (1.0 / c1 if math.isfinite(c1) else 0.0)))


# ----------------------------------------------------------------------------- rolling and incline


def rolling_on_plane(law, mass: float, radius: float, v0: float, g: float, theta: float = 0.0,
                     t_end: float = 10.0) -> dict:
    """A sphere rolling without slip along x on a plane tilted by θ (gravity pulls it towards +x). The rolling
    law is evaluated by its compiled force function (type C's spring torque integrated as a state; its limit by
    events). Returns the stop time, the distance to the stop, and the acceleration at the end."""
    fn = mass * g * math.cos(theta)
    drive = mass * g * math.sin(theta)
    m_eff = mass + 0.4 * mass  # m + I/R²
    cap = getattr(law, "mu_r", 0.0) * getattr(law, "r_roll", 0.0) * fn

    def torque_y(v, mk, dt=0.0):
        m, _ = rolling_torque(law, np.array([0.0, v / radius, 0.0]), N_DOWN, fn, dt, np.array([0.0, mk, 0.0]))
        return m[1]

    def rhs_free(t, y):  # y = x, v, Mk (Mk only for a law with a spring torque: type C)
        v, mk = y[1], y[2]
        if law.spring:
            mk_rate = -law.k_r * v / radius if abs(mk) < cap or mk * v > 0.0 else 0.0
            m_tot = np.clip(mk, -cap, cap) + (-law.c_r * v / radius if abs(mk) < cap else 0.0)
            return [v, (drive + m_tot / radius) / m_eff, mk_rate]
        return [v, (drive + torque_y(v, 0.0) / radius) / m_eff, 0.0]

    stopped = _stop_event()
    stops = law.stops  # type A stops in finite time; B decays; C rocks
    sol = solve_ivp(rhs_free, (0.0, t_end), [0.0, v0, 0.0], method="DOP853", rtol=RTOL, atol=1e-14,
                    events=[stopped] if stops else None, dense_output=False)
    out = {"t": sol.t, "x": sol.y[0], "v": sol.y[1]}
    if stops and sol.t_events[0].size:
        out["rolling_stop_time"] = float(sol.t_events[0][0])
        out["rolling_distance"] = float(sol.y_events[0][0][0])
    out["acceleration"] = float(rhs_free(sol.t[-1], sol.y[:, -1])[1])
    return out


def _stop_event():
    def ev(t, y):
        return y[1]
    ev.terminal = True
    ev.direction = -1
    return ev


def incline_critical_angle(law, mass: float, radius: float, g: float) -> float:
    """The tilt at which a sphere at rest starts to roll: the static torque m g sin θ R reaches the law's limit
    μr Rr m g cos θ (type A, C). Found by bisection on the static balance, not from the closed form."""
    def excess(theta):
        fn = mass * g * math.cos(theta)
        limit = law.mu_r * law.r_roll * fn
        return mass * g * math.sin(theta) * radius - limit
    return brentq(excess, 0.0, 0.5 * math.pi - 1e-9, xtol=1e-15, rtol=4 * np.finfo(float).eps)


# ----------------------------------------------------------------------------- twist


def twist_decay(law, mass: float, radius: float, omega0: float, fn: float, t_end: float,
                preloaded: bool = True) -> dict:
    """A sphere spinning about the plane's normal, its twisting spring preloaded at the limit (slipping from the
    start; the closed form's assumption) or unstretched (it winds up first, as in an engine run that starts
    there): integrated with the law's limit as a state constraint; the stop is the event ω = 0."""
    inertia = 0.4 * mass * radius * radius
    cap = law.mu_tw * fn

    def rhs(t, y):
        w = y[0]
        m = -law.k_tw * y[1] - law.gamma_tw * w
        if abs(m) >= cap * (1.0 - 1e-12):  # on the slip surface: the torque stays at the limit
            m = math.copysign(cap, m)
            return [m / inertia, -law.gamma_tw * (m / inertia) / law.k_tw if law.k_tw > 0 else 0.0]
        return [m / inertia, w]

    phi0 = (cap - law.gamma_tw * omega0) / law.k_tw if law.k_tw > 0 and preloaded else 0.0
    ev = _stop_event_index(0)
    sol = solve_ivp(rhs, (0.0, t_end), [omega0, phi0], method="DOP853", rtol=RTOL, atol=1e-14, events=[ev])
    return {"twist_stop_time": float(sol.t_events[0][0]) if sol.t_events[0].size else math.nan}


def _stop_event_index(k):
    def ev(t, y):
        return y[k]
    ev.terminal = True
    return ev


# ----------------------------------------------------------------------------- adhesion


def pull_off(law, delta0: float | None = None) -> dict:
    """Two bodies pulled apart quasi-statically (imposed displacement) from overlap δ0: the largest tension on the
    way (by minimising the law's force over δ) and the overlap at which the law reports the contact broken
    (bisection on its ``touching`` state)."""
    if delta0 is None:
        delta0 = 10.0 * abs(law.separation_at_pull_off("displacement")) + 1e-9

    def f(d):
        return adhesive_force(law, d, 1.0)[0]

    if law.necks:  # JKR: the largest tension is past δ = 0, the break at a negative overlap
        lo, hi = law.separation_at_pull_off("displacement") * (1 - 1e-9), delta0
        r = minimize_scalar(f, bounds=(lo * 0.999999, hi), method="bounded", options={"xatol": 1e-18})
        tension = -r.fun
        brk = brentq(lambda d: adhesive_force(law, d, 1.0)[1] - 0.5, 2 * lo, 0.0, xtol=1e-22, rtol=1e-15)
    else:
        tension = -f(0.0)
        brk = 0.0
    return {"pull_off_force": tension, "separation_at_pull_off": brk}


def cohesive_pull_off(law, normal, delta0: float) -> dict:
    """Two bodies pulled apart quasi-statically from overlap δ0 where a cohesion record (sjkr) adds its force to
    the elastic normal law ``normal(δ)``: the largest tension (bounded minimisation of the sum over 0 < δ ≤ δ0) and
    the overlap at which the contact ends (the cohesion acts while δ > 0: 0)."""
    def f(d):
        return normal(d) + adhesive_force(law, d, 1.0)[0]

    r = minimize_scalar(f, bounds=(0.0, delta0), method="bounded", options={"xatol": 1e-15 * delta0})
    return {"pull_off_force": -r.fun, "separation_at_pull_off": 0.0}


def adhesive_impact(law, m_eff: float, v: float, t_end: float | None = None) -> dict:
    """A head-on impact at approach speed v of two bodies interacting by an elastic JKR (or DMT) law: free
    flight to δ = 0, contact until the law breaks it (δ_f) or t_end. Returns the restitution (0 if captured)."""
    brk = law.separation_at_pull_off()
    t_end = t_end if t_end is not None else 200.0 * _contact_time_scale(law, m_eff, v)

    def rhs(t, y):
        return [y[1], -adhesive_force(law, y[0], 1.0)[0] / m_eff]

    def out(t, y):
        return y[0] - brk
    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, v], method="DOP853", rtol=RTOL, atol=1e-18, events=[out])
    if not sol.t_events[0].size:
        return {"restitution": 0.0, "captured": True}
    v_out = float(sol.y_events[0][0][1])
    # after the break the bodies fly apart freely: the speed at the break is the rebound speed
    return {"restitution": abs(v_out) / v, "captured": False}


def _contact_time_scale(law, m_eff, v):
    k = 4.0 / 3.0 * law.e_eff * math.sqrt(law.r_eff)
    return (m_eff ** 2 / (k * k * max(v, 1e-6))) ** 0.2


# ----------------------------------------------------------------------------- conduction


def conduction(law, delta: float, c0: float, c1: float, t0: float, t1: float, t_end: float) -> dict:
    """Two bodies at fixed overlap δ, heat capacities C0, C1: integrated, and τ read as the time at which the
    temperature difference has fallen by e."""
    h = conductance(law, delta)

    def rhs(t, y):
        q = h * (y[1] - y[0])
        return [q / c0, -q / c1]

    def efold(t, y):
        return (y[1] - y[0]) - (t1 - t0) / math.e
    efold.terminal = True
    sol = solve_ivp(rhs, (0.0, t_end), [t0, t1], method="DOP853", rtol=RTOL, atol=1e-14, events=[efold])
    return {"heat_time_constant": float(sol.t_events[0][0]) if sol.t_events[0].size else math.nan,
            "conductance": h}


# ----------------------------------------------------------------------------- the engines' discrete scheme


def verlet_pair(radius: float, density: float, x1: float, v1: float, omega0, omega1, dt: float, steps: int, *,
                kn: float = 0.0, eta_n: float = 0.0, elastic_limit: bool = False, adhesion=None, rolling=None,
                twisting=None, heat=None, cp: float = 0.0, temps=(300.0, 400.0),
                setup_increment: bool = False) -> dict:
    """Two like spheres, body 0 at the origin, body 1 at (x1, 0, 0) moving at (v1, 0, 0), stepped the way the
    engines' ``fix nve/sphere`` does (half kick, drift, forces at full-step positions and half-step velocities,
    half kick; histories updated from the first step on, not at set-up; temperatures by explicit Euler after the
    step). The normal force is a linear spring kn·δ (plus a cohesion record's force), or the adhesion record's
    when it replaces the normal law; the limit of the rolling and twisting torques is the adhesion record's
    ``limit_force`` (|Fn|; |Fn + 2·(3/2)πwR̄| for jkr: the engine's critical force; the elastic kn·δ alone with
    ``elastic_limit``); a linear dashpot eta_n·δ̇ (δ̇ > 0 approaching) joins the linear spring; the twisting law
    sees the contact radius √(R̄δ).
    ``setup_increment``: the set-up force call already adds one step's spring increment to the torques it applies
    (and forgets it: the history still starts at step 1), as LIGGGHTS's rolling models do.
    Returns per step (after it): x, v, ω, f, τ (steps×2×3 each), T (steps×2) and the heat flow Q into body 0."""
    mass = density * 4.0 / 3.0 * math.pi * radius ** 3
    inertia = 0.4 * mass * radius * radius
    rbar = radius / 2.0
    x = np.array([[0.0, 0.0, 0.0], [x1, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [v1, 0.0, 0.0]])
    w = np.array([omega0, omega1], dtype=float)
    temp = np.array(temps, dtype=float)
    state = {"roll": np.zeros(3), "twist": 0.0, "touch": 0.0}
    rolling_at, twisting_at = _rolling_kernel(rolling), _twisting_kernel(twisting)

    def normal(delta, rate):
        if adhesion is not None and adhesion.replaces_normal:
            fn, touch = adhesive_force(adhesion, delta, state["touch"])
            return fn, adhesion.limit_force(fn), touch
        fn, touch = kn * delta + eta_n * rate, float(delta > 0.0)
        if adhesion is not None and touch:  # a cohesion added to the normal force (and to its limit)
            fn += adhesive_force(adhesion, delta, 1.0)[0]
        return fn, abs(kn * delta) if elastic_limit else abs(fn), touch

    def forces(update):
        d = x[1] - x[0]
        dist = math.sqrt(d @ d)
        n = d / dist
        delta = 2.0 * radius - dist
        f, tq = np.zeros((2, 3)), np.zeros((2, 3))
        fn, fcrit, touch = normal(delta, -((v[1] - v[0]) @ n))
        if not touch:
            state.update(roll=np.zeros(3), twist=0.0, touch=0.0)
            return f, tq, 0.0
        state["touch"] = 1.0
        f[0], f[1] = -fn * n, fn * n
        wrel = w[0] - w[1]
        h = dt if update or setup_increment else 0.0
        m_roll, hist = rolling_at(wrel, n, fcrit, h, state["roll"])
        m_tw, phi = twisting_at(wrel, n, fcrit, math.sqrt(rbar * max(delta, 0.0)), h, state["twist"])
        if update:
            state.update(roll=hist, twist=phi)
        tq[0] += m_roll + m_tw
        tq[1] -= m_roll + m_tw
        return f, tq, heat_flow(heat, delta, temp[0], temp[1])

    f, tq, q = forces(False)
    out = {k: [] for k in ("x", "v", "omega", "f", "torque", "T", "Q")}
    for _ in range(steps):
        v += 0.5 * dt * f / mass
        x += dt * v
        w += 0.5 * dt * tq / inertia
        f, tq, q = forces(True)
        v += 0.5 * dt * f / mass
        w += 0.5 * dt * tq / inertia
        if heat is not None:
            temp += dt * np.array([q, -q]) / (mass * cp)
        for k, val in (("x", x), ("v", v), ("omega", w), ("f", f), ("torque", tq), ("T", temp), ("Q", q)):
            out[k].append(np.copy(val))
    return {k: np.array(val) for k, val in out.items()}


def verlet_wall(radius: float, mass: float, x0, v0, omega0, gravity, wall_point, wall_normal, dt: float,
                steps: int, every: int, *, normal, fcrit=None, tangential=None, rolling=None,
                twisting=None, roll_fcrit=None, arm: float = 0.0, truncation: str = "maw",
                setup_increment: bool = False, roll_surface_w: bool = False) -> dict:
    """One sphere on a flat wall (its plane through ``wall_point``, ``wall_normal`` pointing to the sphere's
    side) under ``gravity``, stepped the way ``fix nve/sphere`` with ``fix wall/gran`` and ``fix gravity`` does
    (half kick, drift, forces at full-step positions and half-step velocities, half kick). ``normal(δ, δ̇)`` is the
    normal force (> 0 repulsive), ``fcrit(δ, δ̇)`` the force the limits scale with (default |normal|);
    ``tangential`` = (kt, x_t·η, μ): the linear history spring on the slip velocity v_t − r ω × n_w, its
    history rescaled after Maw when |F_t| passes μ|Fn| (``truncation`` "maw": LAMMPS ``linear_history``) or the
    spring alone capped and the dashpot added only while it sticks ("spring": LIGGGHTS ``tangential history``);
    the slip and torque arm r is R − ``arm``·δ (0: LAMMPS's R; ½: LIGGGHTS's contact point). The rolling and
    twisting records see the wall as body 1 (at rest, n from the sphere into the wall); ``roll_fcrit(δ, δ̇)`` the
    rolling limit's force when it is not ``fcrit``'s (LIGGGHTS cdt: the elastic part); ``setup_increment``: the
    set-up call adds one step's increment to the rolling torque it applies and forgets it (LIGGGHTS's epsd
    family, as ``verlet_pair``); ``roll_surface_w``: the rolling record reads ω (R − ``arm``·δ)/(R − δ), the
    relative rotation LIGGGHTS's surface model hands its rolling models on a wall (wr = cr·ω/r, cr the contact
    point's arm, r = R − δ the centre's distance from the wall), not ω. Returns, at steps 0, every, 2·every, …:
    t, x, v, ω (rows × 3)."""
    inertia = 0.4 * mass * radius * radius
    nw = np.asarray(wall_normal, dtype=float)
    p = np.asarray(wall_point, dtype=float)
    g = np.asarray(gravity, dtype=float)
    x, v, w = (np.array(a, dtype=float) for a in (x0, v0, omega0))
    state = {"t": np.zeros(3), "roll": np.zeros(3), "twist": 0.0}
    fcrit = fcrit or (lambda d, rate: abs(normal(d, rate)))
    rolling_at, twisting_at = _rolling_kernel(rolling), _twisting_kernel(twisting)
    into_wall = -nw

    def forces(update):
        delta = radius - float((x - p) @ nw)
        if delta <= 0.0:
            state.update(t=np.zeros(3), roll=np.zeros(3), twist=0.0)
            return mass * g, np.zeros(3)
        rate = -float(v @ nw)
        fn, crit = normal(delta, rate), fcrit(delta, rate)
        r_arm = radius - arm * delta
        vt = v - (v @ nw) * nw - _cross(r_arm * w, nw)
        fs, hist = np.zeros(3), state["t"]
        if tangential is not None:
            spring = _maw_spring if truncation == "maw" else _capped_spring
            fs, hist = spring(hist, vt, dt if update else 0.0, *tangential, crit)
        h = dt if update else 0.0
        w_roll = w * (r_arm / (radius - delta)) if roll_surface_w else w
        m_roll, roll = rolling_at(w_roll, into_wall, roll_fcrit(delta, rate) if roll_fcrit else crit,
                                  dt if update or setup_increment else 0.0, state["roll"])
        m_tw, phi = twisting_at(w, into_wall, crit, math.sqrt(radius * delta), h, state["twist"])
        if update:
            state.update(t=hist, roll=roll, twist=phi)
        torque = -r_arm * _cross(nw, fs) + m_roll + m_tw
        return fn * nw + fs + mass * g, torque

    f, tq = forces(False)
    rows = {k: [np.copy(a)] for k, a in (("x", x), ("v", v), ("omega", w))}
    for k in range(1, steps + 1):
        v += 0.5 * dt * f / mass
        x += dt * v
        w += 0.5 * dt * tq / inertia
        f, tq = forces(True)
        v += 0.5 * dt * f / mass
        w += 0.5 * dt * tq / inertia
        if k % every == 0:
            for key, a in (("x", x), ("v", v), ("omega", w)):
                rows[key].append(np.copy(a))
    out = {k: np.array(a) for k, a in rows.items()}
    out["t"] = np.arange(len(out["x"])) * every * dt
    return out


def _cross(a, b):
    """a × b of two 3-vectors: numpy.cross's products and differences, in its order (the same bits), without its
    per-call axis handling (the wall twin's largest cost)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _norm(a) -> float:
    """|a|: numpy.linalg.norm's √(a·a), as a float."""
    return math.sqrt(float(a @ a))


def _rolling_kernel(law):
    """``rolling_torque`` of ``law`` with its coefficients laid out once: (w, n, |Fn|, dt, history) → (torque,
    history), the compiled force function called as rolling_torque calls it."""
    force = _rolling.KERNELS.of(law)
    if force is None:
        return lambda w, n, fn_abs, dt, history: (np.zeros(3), np.asarray(history, dtype=np.float64))
    c = law.array()
    return lambda w, n, fn_abs, dt, history: force(c, np.asarray(w, dtype=np.float64), n, float(fn_abs), float(dt),
                                                   np.asarray(history, dtype=np.float64))


def _twisting_kernel(law):
    """``twisting_torque`` of ``law`` with its coefficients laid out once: (w, n, |Fn|, a, dt, φ) → (torque, φ)."""
    force = _twisting.KERNELS.of(law)
    if force is None:
        return lambda w, n, fn_abs, a, dt, phi: (np.zeros(3), phi)
    c = law.array()
    return lambda w, n, fn_abs, a, dt, phi: force(c, np.asarray(w, dtype=np.float64), n, float(fn_abs), float(a),
                                                  float(dt), float(phi))


def _maw_spring(hist, vt, h, kt, damp, mu, fncrit):
    """LAMMPS's ``linear_history`` on a flat wall (the normal fixed, so the history is never rotated): ξ += h v_t,
    F = −kt ξ − damp v_t, and past μ Fcrit the force scaled to it and ξ set so that it is the spring's (Maw)."""
    hist = hist + h * vt
    fs = -kt * hist - damp * vt
    cap = mu * fncrit
    mag = _norm(fs)
    if mag > cap:
        if _norm(hist) != 0.0:
            hist = -(cap / mag * fs + damp * vt) / kt
            fs = cap / mag * fs
        else:
            fs = np.zeros(3)
    return fs, hist


def _capped_spring(hist, vt, h, kt, damp, mu, fncrit):
    """LIGGGHTS's ``tangential history`` on a flat wall: ξ += h v_t; past μ Fcrit the spring force kt|ξ| is scaled
    to it (ξ with it) and the dashpot dropped, else F = −kt ξ − damp v_t."""
    hist = hist + h * vt
    fs = -kt * hist
    cap = mu * fncrit
    shear = kt * _norm(hist)
    if shear > cap:
        if shear != 0.0:
            fs = fs * (cap / shear)
            hist = -fs / kt
        else:
            fs = np.zeros(3)
        return fs, hist
    return fs - damp * vt, hist


# ----------------------------------------------------------------------------- metrics of a stepped run


def first_stop(t, speed, position=None) -> tuple[float, float]:
    """(time, position) where ``speed`` (positive at the start) first reaches 0, linear between the samples;
    (nan, nan) when it never does."""
    speed = np.asarray(speed, dtype=float)
    hit = np.nonzero(speed <= 0.0)[0]
    if not speed.size or speed[0] <= 0.0 or not hit.size:
        return math.nan, math.nan
    k = int(hit[0])
    f = speed[k - 1] / (speed[k - 1] - speed[k])
    pos = math.nan if position is None else float(position[k - 1] + f * (position[k] - position[k - 1]))
    return float(t[k - 1] + f * (t[k] - t[k - 1])), pos


def critical_angle_from_acceleration(acc: float, theta: float, g: float) -> float:
    """The tilt at which the sphere starts to roll, inferred from its acceleration a down a slope θ past it:
    a = (5/7) g (sin θ − tan θc cos θ) (type A or a mobilised type C) gives
    tan θc = tan θ − 7a/(5 g cos θ)."""
    return math.atan(math.tan(theta) - 1.4 * acc / (g * math.cos(theta)))


def fitted_acceleration(t, speed) -> float:
    """The least-squares slope of ``speed`` over the second half of the samples (past the start's transient)."""
    t, speed = np.asarray(t, dtype=float), np.asarray(speed, dtype=float)
    k = len(t) // 2
    if len(t) - k < 3:
        return math.nan
    return float(np.polyfit(t[k:] - t[k], speed[k:], 1)[0])


def pull_off_of_path(delta, force) -> dict:
    """A displacement-controlled pull sampled along ``delta`` (decreasing) with the normal ``force`` (> 0
    repulsive; exactly 0 once the contact is broken): the largest tension and the last overlap in contact."""
    delta, force = np.asarray(delta, dtype=float), np.asarray(force, dtype=float)
    touching = np.nonzero(force != 0.0)[0]
    if not touching.size or touching[-1] + 1 >= len(force) or force.min() >= 0.0:
        return {"pull_off_force": math.nan, "separation_at_pull_off": math.nan}
    return {"pull_off_force": float(-force.min()), "separation_at_pull_off": float(delta[touching[-1]])}


def efold_time(t, diff) -> float:
    """The time at which ``diff`` (a temperature difference) has fallen to diff[0]/e, ln(diff) linear between the
    samples; nan when it never does."""
    t, diff = np.asarray(t, dtype=float), np.asarray(diff, dtype=float)
    ratio = diff / diff[0]
    hit = np.nonzero(ratio <= 1.0 / math.e)[0]
    if not hit.size or hit[0] == 0 or not (ratio[hit[0]] > 0.0):
        return math.nan
    k = int(hit[0])
    la, lb = math.log(ratio[k - 1]), math.log(ratio[k])
    return float(t[k - 1] + (-1.0 - la) / (lb - la) * (t[k] - t[k - 1]))
