"""Validation against published benchmarks, run by ``demcheck validate [NAME]``.

``verify`` asks whether an engine computes the seed model; ``validate`` asks whether a model, as each source
runs it, reproduces the standard published benchmarks: Chung & Ooi (2011)'s eight tests and Thornton,
Cummins & Cleary's oblique impacts (2011 elastic, 2013 inelastic). The case files are ``cases/benchmarks/``;
they run through the verification suite (comparisons/suite.py: the reference and every registered engine that
can express the model, with the run cache), and every source's curve over a file's variants is then judged
against two independent kinds of expected values:

* exact limits — the elastic Hertz closed forms (Tests 1, 2), the restitution a law is given (Test 3),
  gross sliding (Coulomb's tangential impulse is μ times the normal impulse's magnitude, μ ∫|F_n| dt, read off
  each source's own force history: e_t = 1 − μJ/tan θ and a rebound spin of 2.5 μ J v_n / R in the rolling
  sense with J = 1 + e for a rigid body; Thornton's Ψ2 = Ψ1 − 7 and |Ω| = 5), and Test 7's unchanged spin (no
  slip at the contact, no tangential force);
* the papers' digitised curves (data/benchmarks/*.dat, each file naming its source): the largest deviation
  of the source's curve from the paper's points, in the quantity's own units, against a tolerance that says
  what it stands for — judged apart past the gross-sliding threshold (the rigid body) and below it (the
  papers' codes' tangential elastic response).

A source that misses a published curve is a finding (the report says which models meet the paper); the
reference missing an exact limit, or a run that failed, fails the command (exit 1) — except a miss that is the
law's own (a force pushing along the slip at contact onset where the law does so by design: reported, not failed).

Heap benchmarks (``kind = "heap"`` in the catalogue: Ai, Chen, Rotter & Ooi 2011's 2D sandpile, one per rolling
model) are bulk runs, not collisions: one case file of cases/optin/ each, run by the reference's sandpile solver
(``demcheck.reference.sandpile.height_curve(case) → (times, heights)``), judged by the heap height's largest
relative deviation from the paper's digitised curve over the curve's time range (:func:`judge_heap`). They are
opt-in (``opt_in``): never in ``validate --quick`` nor in a run that names no benchmark — a run is ~7.4e9
particle-steps —, only when named. A run that failed, is not finite, or does not span the curve's time range fails
the command; a finite run off the curve is a finding, as for the collisions' curves.
"""

from __future__ import annotations

import contextlib
import functools
import math
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .. import resources
from .records import CaseResult, Check, Summary, Validation

DATA = resources.data_dir() / "benchmarks"
LINK = "latest-validate"  # <report>/latest is verify's
MEETS, MISSES, NO_DATA = "meets", "misses", "no data"


# ----------------------------------------------------------------------------- what a case is


@dataclass(frozen=True)
class Impact:
    """The initial conditions of a benchmark case that its quantities are normalised by."""

    material: str  # particle 0's material: the paper's curve for it
    radius: float  # particle 0's radius (m)
    e: float  # the restitution the case gives (nominal): the resolved pair's (contact.restitution, else the materials' mixed)
    mu: float  # the friction coefficient of a slipping contact: the resolved pair's kinetic μ (else its static μ)
    vn: float  # normal approach speed (m/s)
    vt: float  # tangential speed of the centres (m/s)
    spin: float  # |ω0| of particle 0 (rad/s)
    angle: float  # incidence from the normal (degrees)
    normal: str = ""  # the case's normal law (its id in laws/normal.py): which exact limit applies
    tangential: str = ""  # the case's tangential law (its id in laws/tangential.py)
    # the share of μ∫|F_n|dt by which the law itself holds its force below the Coulomb cap in this case (viscous
    # sliding where η_t|v_t| < μ|F_n|: law_shortfall, on the reference's adaptive run); a contact short of it by more
    # than SHORTFALL_MAX does not slide, whatever a source's run does
    law_short: float = 0.0
    # the law's force may push along the slip at contact onset (TangentialLaw.pushes_at_onset): the reference,
    # solving the law, does too
    pushes_at_onset: bool = False
    pair: Any = field(default=None, compare=False, repr=False)  # the case's resolved Pair (Hertz's m̄, R̄, Ē, v)

    @property
    def key(self) -> str:
        """The paper's curve label for this case: its material, or for Thornton its restitution."""
        return f"e{round(self.e * 100):03d}" if self.material == "sphere" else self.material


def impact_of(case) -> Impact:
    """The case's Impact; its e and μ are the resolved pair's (``contact.restitution``, the kinetic friction
    ``contact.friction_kinetic``, ``contact.friction``, else the materials' mixed): the e the laws are
    calibrated to and the μ the force history measures the Coulomb cap with."""
    from ..case import incidence
    from ..laws.model import models_of, resolve

    p0 = case.particles[0]
    vn, vt = incidence(case)
    model = resolve(case)
    pair, tl = model.pair, model.tangential_law
    return Impact(material=p0.material, radius=p0.radius, e=float(pair.restitution if pair.restitution is not None
                                                                 else 1.0),
                  mu=_coulomb_mu(pair), vn=abs(vn), vt=vt,
                  spin=float(np.linalg.norm(p0.angular_velocity)), angle=math.degrees(math.atan2(vt, abs(vn))),
                  normal=str(case.contact.normal), tangential=models_of(case)[1].id,
                  pushes_at_onset=tl.pushes_at_onset, pair=pair)


def _coulomb_mu(pair) -> float:
    """The friction coefficient of a slipping contact (kinetic, else static)."""
    return float(pair.friction_kinetic if pair.friction_kinetic is not None else pair.friction or 0.0)


# ----------------------------------------------------------------------------- a source's own force history
# Coulomb's gross sliding gives a tangential impulse of μ ∫|F_n| dt, and the seed's dissipative laws pull at the
# end of contact (F_n < 0: the dashpot outlasts the spring), so ∫|F_n| dt exceeds the normal impulse
# ∫F_n dt = m̄ v_n (1 + e′). Numbers off each source's own contact table say what its law gives:
# * pull — ∫_{F_n<0} |F_n| dt in units of m̄ v_n, from the normal velocity the pull takes back (m̄ dδ̇/dt = −F_n,
#   so the pull's impulse is m̄ times the separation speed lost while it acts: exact at the adaptive method's
#   events, interpolated between an engine's steps); the normal impulse's magnitude is m̄ v_n (1 + e′ + 2 pull);
# * stick — how far the tangential force stays below its Coulomb cap, ∫(μ|F_n| − |F_t|)₊ dt as a share of
#   μ ∫|F_n| dt, from contact start until the force first reaches the cap (|F_t| ≥ (1 − REACH) μ|F_n| > 0, by
#   the normal force's peak): a spring law sticks at first, its force building up from zero behind the normal
#   force's jump at contact start.
#   That force opposes the slip and gives a tangential impulse of (1 − stick) μ ∫|F_n| dt: the limit allows it.
#   A force below the cap after it has reached it, or one that never reaches it (a cap below μ|F_n|), is no
#   allowance: it is what the limit is there to catch (below_cap: its share, the rest of ∫(μ|F_n| − |F_t|)₊ dt);
#   so is a force above the cap or along the slip (above_cap: ∫(|F_t| − μ|F_n|)₊ dt, along_slip: ∫|F_t| dt where
#   F_t·v_t > 0). The check names the shares of its worst variant.
# Whether a contact slides at all is the law's answer, not a source's run: law_shortfall (below) is the share by
# which the law itself holds its force below the cap, on the reference's adaptive run of the same variant.

SHORTFALL_MAX = 0.05  # a law short of its Coulomb cap by more than this share does not slide: no sliding limit
REACH = 1e-3  # a force within this share of μ|F_n| has reached its cap (an engine's output, its round-off)


def _window(c: dict, events) -> tuple[int, int]:
    """Rows of the contact: from its start (the adaptive method's event row, else the last step before the
    overlap) to its end (event row, else the first step after), as metrics.py reads them."""
    t, d = np.asarray(c["t"], float), np.asarray(c["delta"], float)
    if events and len(events["event"]):
        names = list(np.asarray(events["event"]))
        if "contact_start" in names and "contact_end" in names:
            ts, te = (float(events["t"][names.index(n)]) for n in ("contact_start", "contact_end"))
            return int(np.argmin(np.abs(t - ts))), int(np.argmin(np.abs(t - te)))
    inside = np.flatnonzero(d > 0)
    if not inside.size:
        raise ValueError("no contact")
    ks = int(inside[0])
    after = np.flatnonzero(d[ks:] <= 0)
    if not after.size:
        raise ValueError("the contact does not end")
    return max(ks - 1, 0), ks + int(after[0])


def _integral(t, y) -> float:
    """Trapezoid over a contact's rows."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def _norm3(contact: dict, prefix: str, rows: slice) -> np.ndarray:
    return np.sqrt(sum(np.asarray(contact[prefix + k], float)[rows] ** 2 for k in "xyz"))


def force_history(contact: dict, events, mu: float) -> dict:
    """``pull``, ``stick``, ``below_cap``, ``above_cap`` and ``along_slip`` (above) of a contact table
    (Result.table("contact"): t, delta, delta_dot, fn, ft*, vt*) with friction coefficient ``mu``."""
    k0, k1 = _window(contact, events)
    rows = slice(k0, k1 + 1)
    t = np.asarray(contact["t"], float)[rows]
    fn = np.asarray(contact["fn"], float)[rows]
    rate = np.asarray(contact["delta_dot"], float)[rows]
    ft = _norm3(contact, "ft", rows)
    v_in = rate[0]
    # the pull: each run of rows with F_n < 0, from the sign change that opens it (linear in t between the two
    # rows) to the one that closes it, or the contact's end; the separation speed it takes back
    pull, opened = 0.0, (rate[0] if fn[0] < 0 else None)
    for k in range(1, len(fn)):
        if (fn[k] < 0) != (fn[k - 1] < 0):
            x = fn[k - 1] / (fn[k - 1] - fn[k])
            r = rate[k - 1] + x * (rate[k] - rate[k - 1])
            if fn[k] < 0:
                opened = r
            else:
                pull, opened = pull + abs(r - opened), None
    if opened is not None:
        pull += abs(rate[-1] - opened)
    cap = mu * np.abs(fn)
    total = _integral(t, cap)
    share = (lambda y: _integral(t, y) / total) if total > 0 else (lambda y: math.nan)
    short = np.maximum(cap - ft, 0.0)
    # the first stick: until the first row at the cap, while the cap still rises (none: the force never reaches it
    # before the normal force's peak — a force that meets the cap only as the cap falls away at the end of contact
    # was below it all along — and nothing is allowed)
    reached = np.flatnonzero((cap > 0) & (ft >= (1 - REACH) * cap))
    k = int(reached[0]) + 1 if reached.size and reached[0] <= int(np.argmax(cap)) else 0
    stick = share(np.where(np.arange(len(t)) < k, short, 0.0))
    along = sum(np.asarray(contact[f], float)[rows] * np.asarray(contact[v], float)[rows]
                for f, v in (("ftx", "vtx"), ("fty", "vty"), ("ftz", "vtz"))) > 0 if "vtx" in contact else 0.0
    return {"pull": float(pull / v_in), "stick": stick, "below_cap": share(short) - stick,
            "above_cap": share(np.maximum(ft - cap, 0.0)), "along_slip": share(ft * along)}


def law_shortfall(model, contact: dict, events) -> float:
    """The share of μ∫|F_n|dt by which the case's tangential law itself holds its force below the Coulomb cap,
    from the law's parameters on a run's kinematics (the reference's adaptive run of the variant: F_n, δ and the
    slip velocity; never its tangential force): viscous damping with sliding friction gives min(η_t|v_t|, μ|F_n|),
    short of the cap where η_t|v_t| < μ|F_n|. Every other Coulomb law's force reaches the cap under a sustained
    slip (0: its first stick is the stick a source's force history measures). ``model``: the case's
    ResolvedModel."""
    from ..laws.tangential_force import eta_of
    from ..laws.tangential import ViscousSlidingTangential

    law = model.tangential_law
    if not isinstance(law.slot(), ViscousSlidingTangential):
        return 0.0
    k0, k1 = _window(contact, events)
    rows = slice(k0, k1 + 1)
    t = np.asarray(contact["t"], float)[rows]
    cap = law.mu_k * np.abs(np.asarray(contact["fn"], float)[rows])
    tl, nl = law.array(), model.normal_law.array()
    eta = np.array([eta_of(tl, nl, float(d)) for d in np.asarray(contact["delta"], float)[rows]])
    total = _integral(t, cap)
    return _integral(t, np.maximum(cap - eta * _norm3(contact, "vt", rows), 0.0)) / total if total > 0 else math.nan


# ----------------------------------------------------------------------------- quantities
# Each a function of a source's metrics (metrics.py: tangential_restitution et along the incoming tangential
# velocity, rebound_angular_velocity ω' positive in the rolling sense, restitution e') and the case's Impact.


def _slip_out(m: dict, c: Impact) -> float:
    """Tangential velocity of the contact point after impact, along the incoming tangential direction."""
    return m["tangential_restitution"] * c.vt - c.radius * m["rebound_angular_velocity"]


def _beta(m: dict, c: Impact) -> float:
    """Tests 6 and 8: the contact point's tangential restitution −v'_c/v_c for a spinning sphere with no
    tangential velocity. The centre's tangential velocity after impact follows from the spin by the sphere's
    momentum balance (Δv_t = −(2/5) R Δω), so β = 0.4 + 1.4 ω'/ω0 (ω0 reads −ω0 in the rolling sense of the
    slip it drives)."""
    return 0.4 + 1.4 * m["rebound_angular_velocity"] / c.spin


QUANTITIES: dict[str, tuple[str, Callable[[dict, Impact], float]]] = {
    "restitution": ("restitution e'", lambda m, c: m["restitution"]),
    "contact_time": ("contact time (s)", lambda m, c: m["contact_time"]),
    "max_overlap": ("max overlap (m)", lambda m, c: m["max_overlap"]),
    "peak_force": ("peak force (N)", lambda m, c: m["peak_force"]),
    "et": ("tangential restitution e_t", lambda m, c: m["tangential_restitution"]),
    "spin_paper": ("rebound spin ω' (rad/s, paper's sign)", lambda m, c: -m["rebound_angular_velocity"]),
    "contact_angle": ("rebound angle of the contact point (°)",
                      lambda m, c: math.degrees(math.atan2(_slip_out(m, c), m["restitution"] * c.vn))),
    "t5_angle": ("v'_c/(μ v'_n)", lambda m, c: _slip_out(m, c) / (c.mu * m["restitution"] * c.vn)),
    "t5_spin": ("R ω'/(μ v_n) (paper's sign)", lambda m, c: -c.radius * m["rebound_angular_velocity"] / (c.mu * c.vn)),
    "beta": ("β = −v'_c/v_c", _beta),
    "psi2": ("Ψ2", lambda m, c: 2 * _slip_out(m, c) / (c.mu * (1 + c.e) * c.vn)),
    "omega": ("Ω (paper's sign)", lambda m, c: -2 * c.radius * m["rebound_angular_velocity"] / (c.mu * (1 + c.e) * c.vn)),
    "spin_ratio": ("ω'/ω0", lambda m, c: m["spin_ratio"]),
}

X_AXES: dict[str, tuple[str, Callable[[Impact], float]]] = {
    "none": ("", lambda c: 0.0),
    "e": ("given restitution e", lambda c: c.e),
    "angle": ("incidence angle θ (°)", lambda c: c.angle),
    "psi": ("v_t/(μ v_n)", lambda c: c.vt / (c.mu * c.vn)),
    "beta1": ("3.5 μ (1 + e) v_n/(R ω0)", lambda c: 3.5 * c.mu * (1 + c.e) * c.vn / (c.radius * c.spin)),
    "psi1": ("Ψ1 = 2 v_t/(μ (1 + e) v_n)", lambda c: 2 * c.vt / (c.mu * (1 + c.e) * c.vn)),
    "spin": ("ω0 (rad/s)", lambda c: c.spin),
}


# ----------------------------------------------------------------------------- expected values


@dataclass(frozen=True)
class Curve:
    """A paper's digitised curve of ``quantity``: file (data/benchmarks), the block per Impact.key."""

    quantity: str
    file: str
    tolerance: float  # in the quantity's units
    why: str
    key: str = ""  # a block of the file that names no material (the paper's FEM): judged for every case file


@dataclass(frozen=True)
class Limit:
    """An exact value of ``quantity`` for a case where ``applies`` (a function of the Impact), judged relative to
    ``scale`` (a function of the Impact and the value), with the reference's tolerance and the engines' (their time
    step and lever-arm rules). ``value(impact, metrics, s=0)``: the source's metrics (its restitution e′, its
    force history); a gross-sliding value at (1 − s) J, where the source's force forgoes a share s of Coulomb's
    impulse by law (the judging's allowance; 0: the value itself)."""

    quantity: str
    name: str
    value: Callable[..., float]
    applies: Callable[[Impact], bool]
    scale: Callable[[Impact, float], float]
    tol_reference: float
    tol_engine: float
    why: str
    # the size of the limit's spin part in its scale's units (0: no spin in it): the seed's torque arm R − δ/2
    # departs from the rigid body's R, which moves a spin by up to δ_max/(2R) of it (0.39 δ_max/R measured)
    arm: Callable[[Impact, dict], float] | None = None
    # gross sliding: the limit reads the source's force history (pull, stick) and applies where the law slides
    sliding: bool = False


def _hertz(metric: str):
    from ..laws import analytic

    def value(c: Impact, m: dict, s: float = 0.0) -> float:
        p = c.pair  # the case's resolved pair
        args = (p.m_eff, p.r_eff, p.e_eff, p.impact_speed)
        return {"contact_time": analytic.hertz_duration, "max_overlap": analytic.hertz_max_overlap,
                "peak_force": analytic.hertz_peak_force}[metric](*args)

    return Limit(metric, "Hertz closed form", value, lambda c: True, lambda c, v: abs(v), 1e-6, 2e-3,
                 "elastic Hertz: exact (reference 1e-6: the adaptive solver's events; engines 2e-3: their time "
                 "step at 200 steps per contact)")


# laws without Coulomb's cap μ|F_n|, to which no gross-sliding limit applies: frictionless, and simple viscous
# damping (F_t = −η_t v_t, no μ: its force is whatever the slip makes it, above or below μ|F_n|)
NO_COULOMB = ("none", "viscous")


def _sliding(c: Impact) -> bool:
    """Gross sliding throughout with margin: the rigid-body threshold is v_t = 3.5 μ (1 + e) v_n (a law with
    Coulomb friction)."""
    return c.tangential not in NO_COULOMB and c.vt > 1.2 * 3.5 * c.mu * (1 + c.e) * c.vn


# Gross sliding: Coulomb's law gives a tangential impulse of μ times the normal impulse's magnitude, μ m̄ v_n J with
# J = ∫|F_n| dt/(m̄ v_n) = 1 + e′ + 2 pull from the source's own force history (e′ its own restitution; pull the
# attractive end's impulse, force_history above): the rigid-body values with 1 + e′ in place of 1 + e where no
# force pulls, and the law's own where one does; at (1 − s) J with s the share a force short of its cap forgoes.
def _J(m: dict, s: float = 0.0) -> float:
    return (1 + m["restitution"] + 2 * m["pull"]) * (1 - s)


def _WHOLE(c, m) -> float:
    return 1.0


_SLIDE_WHY = ("gross sliding: a tangential impulse of μ∫|F_n|dt = μ m̄ v_n J, J = 1 + e' + 2·pull from the source's "
              "own force history (its restitution e', and the impulse of its attractive end, on which friction "
              "μ|F_n| acts too); reference 1e-4, engines 1e-2 (their time step); spins also δ_max/R of their "
              "part (torque arm R − δ/2, not R); also the value at (1 − s) J on that side, s the share of "
              "μ∫|F_n|dt the force forgoes by law: its first stick until it reaches the Coulomb cap μ|F_n| (a "
              "spring builds up from zero), at most "
              f"{SHORTFALL_MAX:g}, and what the law holds below the cap (viscous sliding, η_t|v_t| < μ|F_n|, on "
              "the reference's run) — a force below the cap after reaching it, or never reaching it, is not "
              f"allowed; where the law falls short by more than {SHORTFALL_MAX:g} the contact does not slide and "
              "the limit does not apply")
SLIDE_ET = Limit("et", "gross sliding e_t = 1 − μJ/tanθ", lambda c, m, s=0.0: 1 - c.mu * _J(m, s) * c.vn / c.vt,
                 _sliding, lambda c, v: 1.0, 1e-4, 1e-2, _SLIDE_WHY, sliding=True)
SLIDE_SPIN = Limit("spin_paper", "gross sliding ω' = −2.5 μJ v_n/R",
                   lambda c, m, s=0.0: -2.5 * c.mu * _J(m, s) * c.vn / c.radius, _sliding,
                   lambda c, v: abs(v), 1e-4, 1e-2, _SLIDE_WHY, arm=_WHOLE, sliding=True)
T5_ANGLE = Limit("t5_angle", "gross sliding v'_c/(μ v'_n) = (ψ − 3.5J)/e'",
                 lambda c, m, s=0.0: (c.vt / (c.mu * c.vn) - 3.5 * _J(m, s)) / m["restitution"], _sliding,
                 lambda c, v: 1.0, 1e-4, 1e-2, _SLIDE_WHY + "; the contact point's velocity carries R ω'",
                 arm=lambda c, m: 2.5 * _J(m) / m["restitution"], sliding=True)
T5_SPIN = Limit("t5_spin", "gross sliding R ω'/(μ v_n) = −2.5J", lambda c, m, s=0.0: -2.5 * _J(m, s),
                _sliding, lambda c, v: 2.5 * (1 + c.e), 1e-4, 1e-2, _SLIDE_WHY,
                arm=lambda c, m: _J(m) / (1 + c.e), sliding=True)
PSI2 = Limit("psi2", "Ψ2 = Ψ1 − 7J/(1+e)",
             lambda c, m, s=0.0: 2 * c.vt / (c.mu * (1 + c.e) * c.vn) - 7 * _J(m, s) / (1 + c.e),
             _sliding, lambda c, v: 1.0, 1e-4, 1e-2, _SLIDE_WHY + "; Ψ2 = Ψ1 − 7 when J = 1 + e; Ψ2 carries Ω",
             arm=lambda c, m: 5 * _J(m) / (1 + c.e), sliding=True)
OMEGA = Limit("omega", "Ω = −5J/(1+e)", lambda c, m, s=0.0: -5 * _J(m, s) / (1 + c.e), _sliding,
              lambda c, v: 5.0, 1e-4, 1e-2, _SLIDE_WHY + "; |Ω| = 5 when J = 1 + e",
              arm=lambda c, m: _J(m) / (1 + c.e), sliding=True)


def _spin_slide(c: Impact) -> bool:
    """Tests 6 and 8: the contact slides throughout when 3.5 μ (1 + e) v_n < R ω0 (β1 < 1), with margin."""
    return c.tangential not in NO_COULOMB and 3.5 * c.mu * (1 + c.e) * c.vn < 0.6 * c.radius * c.spin


BETA = Limit("beta", "gross sliding β = 3.5μJ v_n/(Rω0) − 1",
             lambda c, m, s=0.0: 3.5 * c.mu * _J(m, s) * c.vn / (c.radius * c.spin) - 1, _spin_slide,
             lambda c, v: 1.0, 1e-4, 1e-2, _SLIDE_WHY + "; β carries 1.4 ω'/ω0",
             arm=lambda c, m: 1.4 * abs(m["rebound_angular_velocity"]) / c.spin, sliding=True)
GIVEN_E = Limit("restitution", "e' = the given e", lambda c, m: c.e, lambda c: c.normal != "tti", lambda c, v: 1.0,
                1e-6, 1e-2, "a law calibrated to the restitution it is given returns it: exact for LSDn and HLS "
                "(reference 1e-6: its events); engines 1e-2 (their time step)")


@functools.lru_cache(maxsize=None)
def tti_restitution(e: float) -> float:
    """The restitution TTIn returns when its ηn is Norouzi's correlation for ``e`` — a fit, so not ``e`` itself:
    with x = δ/δ_0 and time in units of √(m̄/(K_HZ δ_0^{1/2})) (δ_0 = v T) the law reads
    x″ = −x^{3/2} − c x^{1/4} x′ with c = ηn/√(m̄ K_HZ) = −2.2664 ln e/√(ln² e + 10.1354), whatever the mass,
    stiffness and speed; solved here by scipy (DOP853, rtol 1e-12) from x = 0, x′ = 1 to x = 0 (the seed's end
    of contact, the attractive force uncapped): an independent path from the reference's solver. It gives
    0.19881 at e = 0.2, 0.79995 at 0.8."""
    from scipy.integrate import solve_ivp

    L = math.log(e)
    c = -2.2664 * L / math.sqrt(L * L + 10.1354)

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -x**1.5 - c * x**0.25 * y[1]]

    def out(t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 100.0), [0.0, 1.0], method="DOP853", events=out, rtol=1e-12, atol=1e-14)
    return float(-sol.y_events[0][0][1])


TTI_E = Limit("restitution", "TTIn's e' with Norouzi's ηn (its ODE solved by scipy)",
              lambda c, m: tti_restitution(c.e), lambda c: c.normal == "tti", lambda c, v: 1.0, 1e-6, 1e-2,
              "TTIn's ηn comes from Norouzi's correlation, a fit that returns 0.19881 for e = 0.2 (1.2e-3 low) and "
              "0.79995 for 0.8: the exact value is the law's own ODE, solved independently; reference 1e-6 (its "
              "events), engines 1e-2 (their time step)")
SPIN_KEPT = Limit("spin_ratio", "ω' = ω0", lambda c, m: 1.0, lambda c: True, lambda c, v: 1.0, 1e-9, 1e-6,
                  "no slip at the contact: no tangential force, the spin is kept exactly (reference 1e-9; engines "
                  "1e-6: round-off in their output)")

# the exact limits a benchmark of the catalogue (data/benchmarks.toml) names
LIMITS: dict[str, Limit] = {
    **{f"hertz:{k}": _hertz(k) for k in ("contact_time", "max_overlap", "peak_force")},
    "given_e": GIVEN_E, "tti_e": TTI_E, "slide_et": SLIDE_ET, "slide_spin": SLIDE_SPIN, "t5_angle": T5_ANGLE,
    "t5_spin": T5_SPIN, "beta": BETA, "spin_kept": SPIN_KEPT, "psi2": PSI2, "omega": OMEGA,
}


@dataclass(frozen=True)
class Benchmark:
    name: str
    title: str
    prefix: str  # case files cases/benchmarks/<prefix>*.toml
    x: str  # X_AXES key
    quantities: tuple[str, ...]
    curves: tuple[Curve, ...] = ()
    limits: tuple[Limit, ...] = ()
    final_spin: bool = False  # needs particle 0's final spin (Test 7): read from each source's own Result
    quick: str = ""  # the case file (its stem) of the quick subset (validate's quick run): one per benchmark
    kind: str = "collision"  # or "heap": a bulk run judged by judge_heap (HEAP)
    case: str = ""  # a heap benchmark's case file, relative to the shipped cases/ without .toml (optin/…)
    opt_in: bool = False  # run only when named: not in --quick, not in a run that names no benchmark


CATALOGUE = resources.data_dir() / "benchmarks.toml"


def catalogue(path: Path = CATALOGUE, data: Path = DATA, cases: Path | None = None) -> tuple[Benchmark, ...]:
    """The benchmarks of the catalogue ``path`` (data/benchmarks.toml), checked as they are read: each limit one
    of LIMITS, each x one of X_AXES, each curve's file in ``data`` with a tolerance > 0, each quick file in
    ``cases`` (default the shipped cases/benchmarks/); else ConfigError naming the catalogue's key."""
    import tomllib

    from ..errors import ConfigError

    cases = cases or resources.cases_dir() / "benchmarks"
    raw = tomllib.loads(path.read_text())
    notes = raw.get("notes", {})
    out = []
    for i, b in enumerate(raw.get("benchmark", [])):
        where = f"{path.name}: benchmark.{i}"
        if b.get("kind", "collision") != "collision":
            out.append(_heap_benchmark(b, notes, data, where))
            continue
        try:
            limits = tuple(LIMITS[n] for n in b.get("limits", ()))
            curves = tuple(_curve(c, notes, data, f"{where}.curves.{k}") for k, c in enumerate(b.get("curves", ())))
            bench = Benchmark(b["name"], b["title"], b["prefix"], b["x"], tuple(b["quantities"]), curves, limits,
                              bool(b.get("final_spin", False)), b["quick"])
        except KeyError as exc:
            raise ConfigError(where, b.get("name"), f"names {exc} — not a limit ({', '.join(LIMITS)}) nor a key it "
                                                   "may leave out") from None
        if bench.x not in X_AXES:
            raise ConfigError(f"{where}.x", bench.x, f"must be one of {', '.join(X_AXES)}")
        if not (cases / f"{bench.quick}.toml").is_file() or not bench.quick.startswith(bench.prefix):
            raise ConfigError(f"{where}.quick", bench.quick, f"must name a case file {bench.prefix}*.toml in {cases}")
        out.append(bench)
    return tuple(out)


HEAP = "heap"
HEAP_QUANTITY = "heap_height"  # the height of the heap (m) against time (s)
QUANTITIES_HEAP = {HEAP_QUANTITY: ("heap height (m)", "time (s)")}


def _heap_benchmark(b: dict, notes: dict, data: Path, where: str) -> Benchmark:
    """A heap benchmark of the catalogue, checked: kind "heap", its case a path under the shipped cases/ (checked
    when it runs: :func:`heap_case_path`), exactly one curve of quantity heap_height, its file in ``data`` and its
    tolerance a relative deviation in (0, 1)."""
    from ..errors import ConfigError

    if b.get("kind") != HEAP:
        raise ConfigError(f"{where}.kind", b.get("kind"), f"must be collision or {HEAP}")
    for key in ("name", "title", "case", "curves"):
        if key not in b:
            raise ConfigError(f"{where}.{key}", None, f"a {HEAP} benchmark names its {key}")
    case = b["case"]
    if (not isinstance(case, str) or not case or case.startswith("/") or ".." in case.split("/")
            or case.endswith(".toml")):
        raise ConfigError(f"{where}.case", case, "must be a case file's path under the shipped cases/, without .toml")
    if len(b["curves"]) != 1 or b["curves"][0].get("quantity") != HEAP_QUANTITY:
        raise ConfigError(f"{where}.curves", b["curves"], f"a {HEAP} benchmark has one curve of {HEAP_QUANTITY}")
    cur = _curve(b["curves"][0], notes, data, f"{where}.curves.0")
    if not cur.tolerance < 1.0:
        raise ConfigError(f"{where}.curves.0.tolerance", cur.tolerance, "must be < 1 (a relative deviation)")
    blocks = {ln.split(":", 1)[1].strip() for ln in (data / cur.file).read_text().splitlines()
              if ln.strip().startswith("# block:")}
    if cur.key not in blocks:
        raise ConfigError(f"{where}.curves.0.key", cur.key, f"must name a block of {cur.file}")
    if b.get("limits") or b.get("quick"):
        raise ConfigError(f"{where}.quick", b.get("quick") or b.get("limits"), f"a {HEAP} benchmark has no quick "
                                                                              "file and no exact limits")
    return Benchmark(b["name"], b["title"], "", "time", (HEAP_QUANTITY,), (cur,), (), False, "", HEAP, case,
                     bool(b.get("opt_in", True)))


def _curve(c: dict, notes: dict, data: Path, where: str) -> Curve:
    """One curve of the catalogue, checked: its file in ``data``, its tolerance a number > 0."""
    from ..errors import ConfigError

    tol = c.get("tolerance")
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not math.isfinite(tol) or tol <= 0:
        raise ConfigError(f"{where}.tolerance", tol, "must be a number > 0 (in the quantity's units)")
    if not (data / c["file"]).is_file():
        raise ConfigError(f"{where}.file", c["file"], f"is not a data file of {data}")
    return Curve(c["quantity"], c["file"], float(tol), c["why"].format(**notes), c.get("key", ""))


CATALOGUED: tuple[Benchmark, ...] = catalogue()
# the collision benchmarks (case files in cases/benchmarks/, each with its quick file) and the opt-in heap benchmarks
BENCHMARKS: tuple[Benchmark, ...] = tuple(b for b in CATALOGUED if b.kind != HEAP)
HEAPS: tuple[Benchmark, ...] = tuple(b for b in CATALOGUED if b.kind == HEAP)


# The quick subset (``run(..., quick=True)``): one case file per benchmark, 68 cases of the 614 — every test's
# exact limits and its paper's curve in one material, with laws every engine that can run the test expresses
# (spring-sliding where Yade has no TTIt; not Test 5's and Thornton's TTIt at e 1, which stop LIGGGHTS).
QUICK = tuple(b.quick for b in BENCHMARKS if b.quick)


def by_name(name: str | None) -> list[Benchmark]:
    """The benchmark NAME, or without one every benchmark that is not opt-in."""
    from ..errors import ConfigError

    if name is None:
        return [b for b in BENCHMARKS + HEAPS if not b.opt_in]
    hits = [b for b in BENCHMARKS + HEAPS if b.name == name]
    if not hits:
        raise ConfigError("NAME", name, f"must be one of {', '.join(b.name for b in BENCHMARKS + HEAPS)}")
    return hits


def files_of(bench: Benchmark, root: Path, quick: bool = False) -> list[Path]:
    """The benchmark's case files under ``root``; ``quick``: its quick subset's one file (QUICK). A heap
    benchmark's one case file (:func:`heap_case_path`); none in a quick run."""
    if bench.kind == HEAP:
        return [] if quick else [heap_case_path(bench)]
    if quick:
        return [root / f"{bench.quick}.toml"]
    return sorted(root.glob(f"{bench.prefix}*.toml"))


def read_curve(file: str, key: str, root: Path = DATA) -> np.ndarray | None:
    """The (x, y) points of a data file's block ``key`` (``# block: key`` lines), or None without one."""
    blocks: dict[str, list] = {}
    current = None
    for line in (root / file).read_text().splitlines():
        line = line.strip()
        if line.startswith("# block:"):
            current = blocks.setdefault(line.split(":", 1)[1].strip(), [])
        elif line and not line.startswith("#") and current is not None:
            current.append([float(v) for v in line.replace(",", " ").split()[:2]])
    pts = blocks.get(key)
    return np.asarray(pts, float) if pts else None


# ----------------------------------------------------------------------------- judging


def deviation(xs, ys, paper: np.ndarray) -> tuple[float, float, int] | None:
    """Largest |source − paper| over the paper's points inside the source's x range, where (its x), and how many
    paper points were compared: the source at a paper point is its sample within 2% of it (of its x, and of the
    x range: a digitised point off the variant it was drawn from), else linear interpolation. (2% of the range
    alone was too coarse on an axis of a hundredfold span: Test 6's β1 runs 0.2–24, and the source's β at 0.42
    stood for the paper's at 0.55, 0.11 off on a line of slope 1.)"""
    pts = [(x, y) for x, y in zip(xs, ys) if y is not None and math.isfinite(y)]
    if len(pts) < 1:
        return None
    pts.sort()
    sx = np.array([p[0] for p in pts])
    sy = np.array([p[1] for p in pts])
    span = max(sx[-1] - sx[0], 1e-300)
    worst, used = None, 0
    for px, py in paper:
        k = int(np.argmin(np.abs(sx - px)))
        if abs(sx[k] - px) <= 0.02 * min(span, abs(px)):
            y = sy[k]
        elif sx[0] <= px <= sx[-1]:
            y = float(np.interp(px, sx, sy))
        else:
            continue
        used += 1
        d = abs(y - py)
        if worst is None or d > worst[0]:
            worst = (d, float(px))
    return None if worst is None else (*worst, used)


_NOT_A_SOURCE = ("not expressible", "engine missing")  # comparisons/verdicts.py's statuses of a source left out


def _source_metrics(entry: CaseResult, source: str) -> dict | None:
    s = entry.sources.get(source)
    if s is None or not s.ok or "metrics" not in s.keys:
        return None
    return dict(s.metrics)


def judge(bench: Benchmark, groups: dict[str, list[tuple[Impact, dict]]], root: Path = DATA) -> tuple[list, list]:
    """The verdicts and the plot series of one benchmark. ``groups``: case file → [(Impact, {source: metrics
    or None})] over its variants. Returns (checks, series)."""
    checks, series = [], []
    for file, rows in groups.items():
        sources = sorted({s for _, ms in rows for s in ms}, key=lambda s: (s != "reference", s))
        key = rows[0][0].key
        for q in bench.quantities:
            label, fn = QUANTITIES[q]
            xfn = X_AXES[bench.x][1]
            line = {"benchmark": bench.name, "file": file, "quantity": q, "label": label,
                    "x_label": X_AXES[bench.x][0], "key": key, "sources": {}, "paper": None}
            for src in sources:
                xs, ys = [], []
                for imp, ms in rows:
                    m = ms.get(src)
                    xs.append(xfn(imp))
                    ys.append(_value(fn, m, imp))
                line["sources"][src] = {"x": xs, "y": ys}
                for lim in bench.limits:
                    if lim.quantity == q:
                        checks.append(_judge_limit(bench, file, src, lim, rows))
                for cur in bench.curves:
                    if cur.quantity == q:
                        ckey = cur.key or key
                        paper = read_curve(cur.file, ckey, root)
                        if paper is not None and not cur.key:
                            line["paper"] = paper.tolist()
                        for regime, points in regimes(bench, paper, rows[0][0]):
                            checks.append(_judge_curve(bench, file, src, cur, ckey, points, xs, ys, regime))
            series.append(line)
    return checks, series


def _value(fn, m, imp):
    if m is None:
        return None
    try:
        v = fn(m, imp)
    except (KeyError, ZeroDivisionError, TypeError):
        return None
    return v if v is not None and math.isfinite(v) else None


def _allowance(imp: Impact, m: dict) -> float:
    """The share s of μ∫|F_n|dt a source's tangential force forgoes by law: its first stick (force_history's stick,
    at most SHORTFALL_MAX) and what the law itself holds below the cap (Impact.law_short)."""
    law = imp.law_short if math.isfinite(imp.law_short) else 0.0
    return min(max(m["stick"], 0.0), SHORTFALL_MAX) + law


_BREACHES = ("below_cap", "above_cap", "along_slip")  # shares of a force off its cap that no law excuses


def _judge_limit(bench, file, src, lim: Limit, rows) -> Check:
    fn = QUANTITIES[lim.quantity][1]
    tol = lim.tol_reference if src == "reference" else lim.tol_engine
    worst, at, n, tol_at, stuck, breach = None, None, 0, tol, 0, {}
    for imp, ms in rows:
        if src not in ms or not lim.applies(imp):
            continue
        if lim.sliding and imp.law_short > SHORTFALL_MAX:
            stuck += 1  # the law holds its force short of the Coulomb cap: the contact does not slide
            continue
        m = ms[src]  # None: the run failed, which never meets a limit
        y = _value(fn, m, imp)
        short_value = None
        try:
            exact = lim.value(imp, m) if m is not None else None
            if lim.sliding and m is not None:
                short_value = lim.value(imp, m, s=_allowance(imp, m))  # the limit's value at (1 − s) J
        except (KeyError, ZeroDivisionError, TypeError, AttributeError):
            exact = None
        n += 1
        if y is None or exact is None or not math.isfinite(exact) or (lim.sliding and not math.isfinite(short_value)):
            worst, at = math.inf, X_AXES[bench.x][1](imp)  # a NaN is never an agreement
            break
        scale = max(lim.scale(imp, exact), 1e-300)
        d = abs(y - exact) / scale
        allowed = tol + (lim.arm(imp, m) * m.get("max_overlap", 0.0) / imp.radius if lim.arm else 0.0)
        if short_value is not None and (y - exact) * (short_value - exact) > 0:
            allowed += abs(short_value - exact) / scale  # on the side a force short of its cap moves it to
        if worst is None or d / allowed > worst / tol_at:
            worst, at, tol_at = d, X_AXES[bench.x][1](imp), allowed
            breach = {k: m.get(k, 0.0) for k in _BREACHES} if lim.sliding else {}
    verdict = NO_DATA if n == 0 else (MEETS if worst <= tol_at else MISSES)
    why = lim.why
    said = [f"{k.replace('_', ' ')} {v:.2g}" for k, v in breach.items() if v > 1e-3]
    if said:  # where the worst variant's tangential force fell below or broke Coulomb's cap, or pushed along the slip
        why += f" (its tangential force, as shares of μ∫|F_n|dt: {', '.join(said)})"
    # the law's own miss: the reference solves the law, and a law whose force pushes along the slip at contact
    # onset (Impact.pushes_at_onset) does not slide as the rigid body's limit assumes — a finding about the model
    # (reported as a miss), not a failure of the reference
    law_miss = (verdict == MISSES and breach.get("along_slip", 0.0) > 1e-3
                and all(imp.pushes_at_onset for imp, _ in rows))
    if law_miss:
        why += ("; the law's own miss: its force pushes along the slip at contact onset (Maw's truncation under "
                "a Kt that vanishes there, docs/models.md finding 9), as the reference, computing the law as it is, "
                "shows too — not a failure of the reference")
    if stuck:
        why += (f" ({stuck} variant{'s' if stuck > 1 else ''} past the rigid-body threshold where the law holds its "
                f"force short of the cap by more than {SHORTFALL_MAX:g}: not judged)")
    return Check(bench.name, file, src, "limit", lim.quantity, lim.name, worst, at, tol_at, why, verdict, n,
                 law=law_miss)


# A paper's curve is two things. Where the rigid body slides throughout (past the gross-sliding threshold with
# the limits' 20% margin) it is Coulomb's rigid-body value, J = 1 + e: every law with Coulomb friction that holds
# F_n ≥ 0 lands on it, and one that pulls at the end of contact sits off it by its pull (the limits judge the
# law's own J). Below the threshold it is the paper's codes' tangential elastic response — their tangential
# stiffness, damping and history rule, micro-slip —, a property of their law and not of the rigid body. The two
# are judged apart.
SLIDING_REGIME, PARTIAL_REGIME = "gross sliding", "partial slip"
_SLIDES_AT: dict[str, Callable[[float, Impact], bool]] = {
    "angle": lambda x, c: math.tan(math.radians(x)) > 1.2 * 3.5 * c.mu * (1 + c.e),
    "psi": lambda x, c: x > 1.2 * 3.5 * (1 + c.e),
    "beta1": lambda x, c: x < 0.6,
    "psi1": lambda x, c: x > 1.2 * 7,
}
_REGIME_WHY = {
    SLIDING_REGIME: "; past the gross-sliding threshold (20% margin) the paper's curve is the rigid body's Coulomb "
                    "value with J = 1 + e: a law that pulls at the end of contact sits off it by its pull",
    PARTIAL_REGIME: "; below the gross-sliding threshold the curve is the paper's codes' tangential elastic "
                    "response (tangential stiffness, damping, history rule), not a property of the rigid body",
}


def regimes(bench: Benchmark, paper: np.ndarray | None, imp: Impact) -> list[tuple[str, np.ndarray | None]]:
    """The paper's points split by where the rigid body slides throughout: [(regime, points)] with the empty
    regimes left out; [("", paper)] for an axis without the split (or no paper)."""
    slides = _SLIDES_AT.get(bench.x)
    if paper is None or slides is None:
        return [("", paper)]
    mask = np.array([slides(float(x), imp) for x in paper[:, 0]], bool)
    return [(r, paper[k]) for r, k in ((SLIDING_REGIME, mask), (PARTIAL_REGIME, ~mask)) if k.any()]


def _judge_curve(bench, file, src, cur: Curve, key, paper, xs, ys, regime: str = "") -> Check:
    why = cur.why + _REGIME_WHY.get(regime, "")
    out = Check(bench.name, file, src, "curve", cur.quantity, f"{cur.file} [{key}]" + (f", {regime}" if regime else ""),
                tolerance=cur.tolerance, why=why, verdict=NO_DATA, regime=regime)
    if paper is None:
        return out
    if any(y is None for y in ys):
        out.deviation, out.verdict, out.why = math.inf, MISSES, why + " (a variant gave no value)"
        return out
    d = deviation(xs, ys, paper)
    if d is None:
        return out
    # the points compared are those inside the source's range: a source that covers part of a curve says so
    out.deviation, out.at, out.points = d
    out.verdict = MEETS if d[0] <= cur.tolerance else MISSES
    if d[2] < len(paper):
        out.why = why + f" ({d[2]} of the paper's {len(paper)} points here lie in the source's range)"
    return out


# ----------------------------------------------------------------------------- heap benchmarks


def heap_case_path(bench: Benchmark, cases: Path | None = None) -> Path:
    """A heap benchmark's case file (cases/<case>.toml); ConfigError naming the catalogue's key when it is not
    shipped."""
    from ..errors import ConfigError

    path = (cases or resources.cases_dir()) / f"{bench.case}.toml"
    if not path.is_file():
        raise ConfigError(f"benchmarks.toml: {bench.name}.case", bench.case, f"must name a case file of {path.parent}")
    return path


def judge_heap(bench: Benchmark, file: str, times, heights, source: str = "reference",
               error: str | None = None, root: Path = DATA) -> tuple[Check, dict]:
    """The verdict of a heap run against its benchmark's curve, and its plot series. The run's heights are
    interpolated (linearly) at the curve's times; the deviation is the largest |h_run − h_paper|/h_paper over the
    curve's points (``at``: its time). The run must have finished (``error`` None), be finite and span the curve's
    whole time range — else the verdict is a miss with an infinite deviation and ``failed`` in the Check's extra
    (the run did not compute what the curve needs: never an agreement)."""
    cur = bench.curves[0]
    paper = read_curve(cur.file, cur.key, root)
    label, x_label = QUANTITIES_HEAP[HEAP_QUANTITY]
    out = Check(bench.name, file, source, "curve", HEAP_QUANTITY, f"{cur.file} [{cur.key}], relative",
                tolerance=cur.tolerance, why=cur.why, verdict=NO_DATA)
    t = np.asarray(times if times is not None else [], float).ravel()
    h = np.asarray(heights if heights is not None else [], float).ravel()
    series = {"benchmark": bench.name, "file": file, "quantity": HEAP_QUANTITY, "label": label, "x_label": x_label,
              "key": cur.key, "sources": {}, "paper": paper.tolist() if paper is not None else None}

    def failed(reason: str):
        out.deviation, out.verdict = math.inf, MISSES
        out.why = f"{cur.why} (the run failed: {reason})"
        out.extra["failed"] = reason
        out.keys = Check.CURVE + ("failed",)
        return out, series

    if error is not None:
        return failed(error)
    if t.size < 2 or t.size != h.size:
        return failed(f"{t.size} times and {h.size} heights: no height curve")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(h))):
        return failed("a time or height is not finite")
    if np.any(np.diff(t) <= 0):
        return failed("the times do not increase")
    series["sources"][source] = {"x": t.tolist(), "y": h.tolist()}
    if paper is None:
        return out, series
    lo, hi = float(paper[0, 0]), float(paper[-1, 0])
    if t[0] > lo or t[-1] < hi:
        return failed(f"it spans t = {t[0]:.6g}–{t[-1]:.6g} s, not the curve's {lo:.6g}–{hi:.6g} s")
    at_paper = np.interp(paper[:, 0], t, h)
    rel = np.abs(at_paper - paper[:, 1]) / np.abs(paper[:, 1])
    k = int(np.argmax(rel))
    out.deviation, out.at, out.points = float(rel[k]), float(paper[k, 0]), int(len(paper))
    out.verdict = MEETS if rel[k] <= cur.tolerance else MISSES
    out.extra["mean_deviation"] = float(np.mean(at_paper / paper[:, 1] - 1.0))  # signed: below the curve < 0
    out.keys = Check.CURVE + ("mean_deviation",)
    return out, series


def _load_case(path: Path):
    from ..case import load

    return load(path)


class HeapInterrupted(KeyboardInterrupt):
    """An interrupt during a heap run, carrying the run's verdict so far (a failure: "interrupted at t = … s") and
    its heights up to then, so that the report keeps them."""

    def __init__(self, check: Check, series: dict):
        super().__init__(check.extra.get("failed", "interrupted"))
        self.check, self.series = check, series


def run_heap(bench: Benchmark, cases: Path | None = None, progress=None) -> tuple[Check, dict]:
    """Run a heap benchmark's case in the reference's sandpile solver (demcheck.reference.sandpile, imported
    here) and judge it. A solver that raises, or is not in this build, is a failed run. ``progress(t, height)``
    is called at each measure (the run's log); an interrupt raises HeapInterrupted with the heights so far."""
    import importlib

    path = heap_case_path(bench, cases)
    file = path.stem
    times, heights = [], []

    def look(t, h):
        times.append(t)
        heights.append(h)
        if progress is not None:
            progress(t, h)

    from ..engines.run import interrupt_in

    try:
        sandpile = importlib.import_module("demcheck.reference.sandpile")
        curve = sandpile.height_curve(_load_case(path), progress=look)
    except KeyboardInterrupt as exc:
        stop = exc
    except Exception as exc:  # noqa: BLE001 — any failure of the run is a failed run, reported with its reason
        if interrupt_in(exc) is None:  # (an interrupt in a compiled kernel comes as numba's SystemError)
            return judge_heap(bench, file, None, None, error=f"{type(exc).__name__}: {exc}")
        stop = exc
    else:
        return judge_heap(bench, file, *curve)
    at = f" at t = {times[-1]:.6g} s" if times else " before its first height"
    check, series = judge_heap(bench, file, None, None, error=f"interrupted{at}")
    if times:
        series["sources"]["reference"] = {"x": list(times), "y": list(heights)}
    raise HeapInterrupted(check, series) from stop


def heap_log(name: str, every: float = 1.0, out=None):
    """A progress(t, height) that prints a line every ``every`` simulated seconds (to stderr): a heap run takes
    one to two hours here (model A: 6 510 s on one thread), and says how far it is."""
    import sys
    import time

    start, last = time.monotonic(), [-math.inf]

    def log(t, h):
        if t - last[0] >= every * (1.0 - 1e-9):
            last[0] = t
            print(f"demcheck validate {name}: t = {t:.2f} s, height {h:.4f} m ({time.monotonic() - start:.0f} s)",
                  file=out or sys.stderr, flush=True)

    return log


# ----------------------------------------------------------------------------- running


def _result(case, src: str, opts):
    """The source's own Result: the reference's adaptive run again, or the engine's run from the run cache the
    suite filled (its Source.run, as the suite ran it)."""
    from .sources import ADAPTIVE, Source

    if src == "reference":
        return ADAPTIVE.run(case)
    return Source.parse(src).run(case, cache=opts.cache, timeout=opts.timeout)


def _final_spin_ratio(case, res) -> float | None:
    """ω'·ω0/|ω0|² of particle 0 from a source's Result."""
    if not res.ok:
        return None
    p = res.particles
    last = p[p["id"] == p["id"].min()].iloc[-1]
    w0 = np.asarray(case.particles[0].angular_velocity, float)
    w = np.array([last["wx"], last["wy"], last["wz"]], float)
    return float(w @ w0 / (w0 @ w0))


def _needs_history(bench: Benchmark, imp: Impact) -> bool:
    return any(lim.sliding and lim.applies(imp) for lim in bench.limits)


def _law_short(case, run_of) -> float:
    """law_shortfall of the case's law on the reference's adaptive run (run only for a law that can fall short of
    its cap: viscous sliding); NaN without a run to read."""
    from ..laws.model import resolve
    from ..laws.tangential import ViscousSlidingTangential

    model = resolve(case)
    if not isinstance(model.tangential_law.slot(), ViscousSlidingTangential):
        return 0.0
    res = run_of("reference")
    if not res.ok:
        return math.nan
    try:
        return law_shortfall(model, res.table("contact"), res.table("events"))
    except ValueError:  # no contact, or no end
        return math.nan


def validate(summary: Summary, benches: list[Benchmark], files: dict[str, list[Path]], opts,
             root: Path = DATA) -> Validation:
    """The validation of a finished suite run (its records.Summary: its cases' entries): checks and series per
    benchmark."""
    from ..case import expand

    entries = {c.case: c for c in Summary.of(summary).cases}
    out = Validation()
    for bench in benches:
        groups: dict[str, list] = {}
        for f in files[bench.name]:
            for case in expand(f):
                entry = entries.get(case.name)
                if entry is None:
                    continue
                imp = impact_of(case)
                runs: dict = {}  # each source's own Result, run (or read from the run cache) once per case

                def run_of(src: str, case=case, runs=runs):
                    if src not in runs:
                        runs[src] = _result(case, src, opts)
                    return runs[src]

                needs_history = _needs_history(bench, imp)
                if needs_history:  # whether the law slides: its answer on the reference's adaptive run
                    imp = replace(imp, law_short=_law_short(case, run_of))
                ms = {}
                for src, got in entry.sources.items():
                    if src == "reference-verlet" or got.status in _NOT_A_SOURCE:
                        continue  # an engine that cannot express the model is no source here (a failed run is)
                    m = _source_metrics(entry, src)
                    if m is not None:
                        history = needs_history and not {"pull", "stick"} <= m.keys()
                        if bench.final_spin or history:
                            res = run_of(src)
                            if bench.final_spin:
                                m["spin_ratio"] = _final_spin_ratio(case, res)
                            if history and res.ok:
                                with contextlib.suppress(ValueError):  # no contact, or no end: no history
                                    m.update(force_history(res.table("contact"), res.table("events"), imp.mu))
                    ms[src] = m
                groups.setdefault(Path(f).stem, []).append((imp, ms))
        checks, series = judge(bench, groups, root)
        out.benchmarks.append({"name": bench.name, "title": bench.title, "files": [str(f) for f in files[bench.name]]})
        out.checks += checks
        out.series += series
    out.failed = [c for c in out.checks if c.kind == "limit" and c.source == "reference" and c.verdict == MISSES
                  and not c.law]
    return out


class _Retitled:
    """A console whose tables titled "demcheck verify…" print as ``title``…; everything else passes through."""

    def __init__(self, console, title: str):
        self._console, self._title = console, title

    def print(self, *objects, **kwargs):
        from rich.table import Table

        for o in objects:
            if isinstance(o, Table) and isinstance(o.title, str) and o.title.startswith("demcheck verify"):
                o.title = self._title + o.title[len("demcheck verify"):]
        self._console.print(*objects, **kwargs)

    def __getattr__(self, name):
        return getattr(self._console, name)


@contextlib.contextmanager
def _titled(title: str):
    """The suite's closing summary table titled for this command (suite.run_suite prints it as verify's)."""
    from . import suite

    printer = suite._print
    suite._print = lambda console, summary: printer(_Retitled(console, title), summary)
    try:
        yield
    finally:
        suite._print = printer


def run(names: str | None, root: Path, report_root: Path, opts, quiet=False, junit=None, argv=None,
        quick: bool = False) -> Summary:
    """Run the benchmarks' case files through the suite, judge them, and rewrite the run's report with the
    validation section. ``quick``: each benchmark's quick subset alone (QUICK)."""
    from . import report
    from .suite import run_suite

    benches = by_name(names)
    heaps = [b for b in benches if b.kind == HEAP and not quick]
    benches = [b for b in benches if b.kind != HEAP]
    for b in heaps:
        heap_case_path(b)  # bad input: one line before any work
    files = {b.name: files_of(b, root, quick) for b in benches}
    every = [f for fs in files.values() for f in fs]
    if not every and not heaps:
        from ..errors import ConfigError

        raise ConfigError("NAME", names or "(all)", f"no benchmark case files in {root}")
    if every:
        with _titled("demcheck validate"):
            summary = run_suite(every, report_root, opts, quiet=quiet, junit=junit, argv=argv, link=LINK)
        summary.validation = validate(summary, benches, files, opts)
    else:
        summary = _heap_summary(report_root, argv)
        summary.validation = Validation()
    val = summary.validation
    stopped, started = None, time.perf_counter()
    for b in heaps:
        try:
            check, line = run_heap(b, progress=None if quiet else heap_log(b.name))
        except HeapInterrupted as exc:  # the report keeps the heights so far, then the interrupt goes on
            check, line, stopped = exc.check, exc.series, exc
        val.benchmarks.append({"name": b.name, "title": b.title, "files": [str(heap_case_path(b))]})
        val.checks.append(check)
        val.series.append(line)
        if "failed" in check.extra:
            val.failed.append(check)  # a run that failed fails the command; a finite run off the curve is a finding
        if stopped is not None:
            break
    summary.failed += len(val.failed)
    if not every:
        summary.wall_time = time.perf_counter() - started
        summary.partial = stopped is not None
    report.write_all(summary, Path(summary.report), report_root, junit=junit, link=LINK)
    if stopped is not None:
        raise stopped
    return summary


def _heap_summary(report_root: Path, argv) -> Summary:
    """The run record of a validate run of heap benchmarks alone (no suite run)."""
    import datetime as _dt
    import os
    import sys

    from .. import __version__

    run_id = _dt.datetime.now().strftime("%Y%m%d-%H%M%S") + f"-{os.getpid()}"
    return Summary(__version__, run_id, str(report_root / run_id), True,
                   _dt.datetime.now().isoformat(timespec="seconds"), argv if argv is not None else sys.argv, planned=0)

