"""Closed forms of the normal models (seed 000 §3, seed 001), derived again rather than copied.

Symbols: m = m̄ (effective mass), R = R̄, E = Ē, v = impact speed (approach rate δ̇⁰ > 0), e = ε_n.
Every function is checked against the converged integration of its model in tests/test_analytic.py;
where the notes differ, docs/models.md ("Findings in the notes") records it.
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import beta as _beta

# ----------------------------------------------------------------------------- elastic power laws


def power_law_integral(a: float) -> float:
    """∫₀¹ (1 − x^{a+1})^{-1/2} dx = B(1/(a+1), 1/2)/(a+1): the shape factor of an elastic contact
    F = k δ^a (half the duration is this times δ_max / v)."""
    p = a + 1.0
    return _beta(1.0 / p, 0.5) / p


def power_law_max_overlap(k: float, a: float, m: float, v: float) -> float:
    """Elastic F = kδ^a: ½mv² = kδ_max^{a+1}/(a+1). A stiffness, mass or speed that is not a positive finite
    number (one that under- or overflowed) is a ValueError naming it, never a ZeroDivisionError."""
    for name, x in (("stiffness", k), ("mass", m), ("speed", v)):
        if not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
            raise ValueError(f"the contact's {name} {x:g} is not a positive finite number (it under- or overflows "
                             "in floating point)")
    try:
        x = ((a + 1.0) * m * v * v / (2.0 * k)) ** (1.0 / (a + 1.0))
    except (OverflowError, ZeroDivisionError) as exc:
        raise ValueError(f"the largest overlap overflows ({exc}): stiffness {k:g}, mass {m:g}") from None
    if not (math.isfinite(x) and x > 0):
        raise ValueError(f"the largest overlap {x:g} under- or overflows: stiffness {k:g}, mass {m:g}")
    return x


def power_law_duration(k: float, a: float, m: float, v: float) -> float:
    return 2.0 * power_law_max_overlap(k, a, m, v) / v * power_law_integral(a)


# ----------------------------------------------------------------------------- Hertz


def hertz_stiffness(r_eff: float, e_eff: float) -> float:
    """K_HZ = (4/3) Ē √R̄."""
    return 4.0 / 3.0 * e_eff * math.sqrt(r_eff)


HERTZ_DURATION_CONSTANT = 2.0 * (15.0 / 16.0) ** 0.4 * power_law_integral(1.5)
"""T_c = C (m̄²/(R̄Ē²v))^{1/5} with C = 2(15/16)^{2/5}·(2/5)B(2/5, 1/2) = 2.868265…
The notes round it to 2.86 (seed 000) and 2.870 (seed 001)."""

HERTZ_DURATION_CONSTANT_NOTES = 2.870


def hertz_max_overlap(m: float, r_eff: float, e_eff: float, v: float) -> float:
    """δ_max = (15 m v² / (16 √R Ē))^{2/5}."""
    return (15.0 / 16.0 * m * v * v / (math.sqrt(r_eff) * e_eff)) ** 0.4


def hertz_duration(m: float, r_eff: float, e_eff: float, v: float,
                   constant: float = HERTZ_DURATION_CONSTANT) -> float:
    return constant * (m * m / (r_eff * e_eff * e_eff * v)) ** 0.2


def hertz_peak_force(m: float, r_eff: float, e_eff: float, v: float) -> float:
    return hertz_stiffness(r_eff, e_eff) * hertz_max_overlap(m, r_eff, e_eff, v) ** 1.5


def hertz_max_strain_energy(m: float, r_eff: float, e_eff: float, v: float) -> float:
    """(2/5) K_HZ δ_max^{5/2} (= ½ m v² for the elastic law)."""
    return 0.4 * hertz_stiffness(r_eff, e_eff) * hertz_max_overlap(m, r_eff, e_eff, v) ** 2.5


def stiffness_scale(m: float, r_eff: float, e_eff: float, v: float) -> float:
    """(v R̄ Ē² √m̄)^{2/5}, the factor every Hertz-equivalent linear stiffness carries."""
    return (v * r_eff * e_eff * e_eff * math.sqrt(m)) ** 0.4


# ----------------------------------------------------------------------------- LSDn


def _beta_of(e: float) -> float:
    """β = π / ln ε (negative for ε < 1)."""
    return math.pi / math.log(e)


def lsd_eta_from_restitution(m: float, k: float, e: float) -> float:
    """η_n = −2 ln ε √(m K) / √(ln²ε + π²) (0 for ε = 1)."""
    if e >= 1.0:
        return 0.0
    le = math.log(e)
    return -2.0 * le * math.sqrt(m * k) / math.sqrt(le * le + math.pi**2)


def lsd_frequencies(m: float, k: float, eta: float) -> tuple[float, float]:
    """(Ψ, W): Ψ = η/2m, W = √(K/m − Ψ²). Requires underdamping (W > 0)."""
    psi = eta / (2.0 * m)
    w2 = k / m - psi * psi
    if w2 <= 0:
        raise ValueError("LSD contact is overdamped (η² ≥ 4 m K): it has no rebound")
    return psi, math.sqrt(w2)


def lsd_duration(m: float, k: float, eta: float) -> float:
    """T_c = π / √(K/m − η²/4m²) = π √(m/K (1 + 1/β²)) — the root covers the bracket (seed 000 p. 'LSDn'
    prints the bracket outside it)."""
    return math.pi / lsd_frequencies(m, k, eta)[1]


def lsd_restitution(m: float, k: float, eta: float) -> float:
    """ε = exp(−Ψ T_c)."""
    psi, w = lsd_frequencies(m, k, eta)
    return math.exp(-psi * math.pi / w)


def lsd_max_overlap(m: float, k: float, eta: float, v: float) -> float:
    """δ_max = v √(m/K) exp(−tan⁻¹(β)/β) with Ψ/W = −1/β, i.e. (v/Φ) exp(−(Ψ/W) tan⁻¹(W/Ψ))."""
    psi, w = lsd_frequencies(m, k, eta)
    phi = math.sqrt(k / m)
    if psi == 0.0:
        return v / phi
    return v / phi * math.exp(-(psi / w) * math.atan2(w, psi))


def _lsd_state(m, k, eta, v, t):
    psi, w = lsd_frequencies(m, k, eta)
    decay = math.exp(-psi * t)
    delta = v / w * decay * math.sin(w * t)
    rate = v / w * decay * (w * math.cos(w * t) - psi * math.sin(w * t))
    return delta, rate


def lsd_force_end_time(m: float, k: float, eta: float) -> float:
    """Time at which K δ + η δ̇ first returns to 0: tan(W t) = −ηW/(K − ηΨ) on (π/2W, π/W]."""
    psi, w = lsd_frequencies(m, k, eta)
    if eta == 0.0:
        return math.pi / w
    return (math.pi - math.atan2(eta * w, k - eta * psi)) / w


def lsd_peak_force(m: float, k: float, eta: float, v: float) -> float:
    """max_t (Kδ + ηδ̇): at t = 0⁺ (ηv) when η² ≥ K m, else where dF/dt = 0."""
    psi, w = lsd_frequencies(m, k, eta)
    # F ∝ e^{−Ψt}[(K − ηΨ) sin Wt + ηW cos Wt]; dF/dt = 0 ⇔ tan Wt = (W A − Ψ B)/(Ψ A + W B), A = K − ηΨ, B = ηW
    a_, b_ = k - eta * psi, eta * w
    t_star = math.atan2(w * a_ - psi * b_, psi * a_ + w * b_) / w
    candidates = [eta * v]
    if 0.0 < t_star < math.pi / w:
        delta, rate = _lsd_state(m, k, eta, v, t_star)
        candidates.append(k * delta + eta * rate)
    return max(candidates)


def lsd_restitution_limited(m: float, k: float, eta: float) -> float:
    """Restitution with the collision-time reduction (F ≥ 0): the bodies leave at the force-end time with
    the rate there, and fly free until δ = 0."""
    t_f = lsd_force_end_time(m, k, eta)
    _, rate = _lsd_state(m, k, eta, 1.0, t_f)
    return -rate


# ----------------------------------------------------------------------------- stiffness calibration


STIFFNESS_METHODS = ("duration", "overlap", "energy")


def lsd_stiffness(method: str, m: float, r_eff: float, e_eff: float, v: float, e: float,
                  duration_constant: float = HERTZ_DURATION_CONSTANT) -> float:
    """K_n of the LSDn model that matches an elastic Hertz contact at impact speed v:

    * duration: π²(m/K)(1+1/β²) = T_Hz² ⇒ K = (π/C)² (1 + 1/β²) X,  (π/2.870)² = 1.198 (notes)
    * overlap:  δ_max,LSD = δ_max,Hz ⇒ K = (16/15)^{4/5} exp(−2 tan⁻¹β/β) X
    * energy:   ½ K δ_max,Hz² = (2/5) K_HZ δ_max,Hz^{5/2} ⇒ K = (16/15)^{4/5} X = 1.053 X
    with X = (v R̄ Ē² √m̄)^{2/5}.
    """
    x = stiffness_scale(m, r_eff, e_eff, v)
    if method == "duration":
        inv_b2 = 0.0 if e >= 1.0 else 1.0 / _beta_of(e) ** 2
        return (math.pi / duration_constant) ** 2 * (1.0 + inv_b2) * x
    if method == "energy":
        return (16.0 / 15.0) ** 0.8 * x
    if method == "overlap":
        if e >= 1.0:
            return (16.0 / 15.0) ** 0.8 * x
        b = _beta_of(e)
        return (16.0 / 15.0) ** 0.8 * math.exp(-2.0 * math.atan(b) / b) * x
    raise ValueError(f"unknown stiffness method {method!r}")


# ----------------------------------------------------------------------------- HLS


def hls_max_overlap(m: float, kl: float, v: float) -> float:
    return v * math.sqrt(m / kl)


def hls_peak_force(m: float, kl: float, v: float) -> float:
    return kl * hls_max_overlap(m, kl, v)


def hls_restitution(m: float, kl: float, v: float, *, e: float | None = None, s: float | None = None) -> float:
    """ε = √(K_L/K_U); variable unloading: ε = [1 + S v √(m/K_L)]^{-1/2}."""
    if s is not None:
        return 1.0 / math.sqrt(1.0 + s * v * math.sqrt(m / kl))
    return e


def hls_residual_overlap(m: float, kl: float, v: float, *, e: float | None = None, s: float | None = None) -> float:
    """δ_res = δ_max (1 − K_L/K_U) = δ_max (1 − ε²)."""
    eps = hls_restitution(m, kl, v, e=e, s=s)
    return hls_max_overlap(m, kl, v) * (1.0 - eps * eps)


def hls_duration(m: float, kl: float, v: float, *, e: float | None = None, s: float | None = None) -> float:
    """Duration of the force: (π/2)√(m/K_L)(1 + ε). The overlap lasts δ_res/(εv) longer."""
    eps = hls_restitution(m, kl, v, e=e, s=s)
    return 0.5 * math.pi * math.sqrt(m / kl) * (1.0 + eps)


def hls_overlap_duration(m: float, kl: float, v: float, *, e: float | None = None, s: float | None = None) -> float:
    eps = hls_restitution(m, kl, v, e=e, s=s)
    return hls_duration(m, kl, v, e=e, s=s) + hls_residual_overlap(m, kl, v, e=e, s=s) / (eps * v)


def hls_stiffness(method: str, m: float, r_eff: float, e_eff: float, v: float, *,
                  e: float | None = None, s: float | None = None,
                  duration_constant: float = HERTZ_DURATION_CONSTANT) -> float:
    """K_L of the HLS model that matches an elastic Hertz contact at impact speed v.

    * duration: (π/2)√(m/K_L)(1+ε) = T_Hz ⇒ K_L = (π/2C)² (1+ε)² X (0.2996 with C = 2.870). With variable
      unloading ε depends on K_L; the equation is solved for K_L.
    * overlap and energy: v√(m/K_L) = δ_max,Hz ⇒ K_L = (16/15)^{4/5} X (both 1.053 X).
    """
    x = stiffness_scale(m, r_eff, e_eff, v)
    if method in ("overlap", "energy"):
        return (16.0 / 15.0) ** 0.8 * x
    if method != "duration":
        raise ValueError(f"unknown stiffness method {method!r}")
    c0 = (math.pi / (2.0 * duration_constant)) ** 2 * x
    if s is None:
        return c0 * (1.0 + e) ** 2

    def residual(kl):
        return kl - c0 * (1.0 + hls_restitution(m, kl, v, s=s)) ** 2

    return brentq(residual, c0 * 0.999, 4.0 * c0 * 1.001, xtol=1e-300, rtol=1e-15)


# ----------------------------------------------------------------------------- TTIn


def tti_eta_from_restitution(m: float, k_hz: float, e: float) -> float:
    """Norouzi et al. (2016): η_n = −2.2664 ln ε √(m K_HZ) / √(ln²ε + 10.1354)."""
    if e >= 1.0:
        return 0.0
    le = math.log(e)
    return -2.2664 * le * math.sqrt(m * k_hz) / math.sqrt(le * le + 10.1354)
