"""Ai, Chen, Rotter & Ooi (2011)'s model C, the elastic–plastic spring–dashpot, parametrised as the paper and the
codes that follow it do (LIGGGHTS ``rolling_friction epsd``/``epsd3``, Lethe's ``epsd_resistance``): the rolling
stiffness from the normal one, kr = ε kn μr² Rr² (ε = 2.25 for spheres in 3D, "following Ai" in LIGGGHTS's words;
Lethe takes 3 for its 2D runs and 2.25 in 3D), the dashpot Cr = ηr·2√(Ir kr) (ηr the ratio to the critical
damping, 1/Ir = 1/(I0 + m0R0²) + 1/(I1 + m1R1²)), and at full mobilisation the dashpot scaled by f (0 ≤ f ≤ 1):

  Mk ← Mk − kr w_t dt; |Mk| ≤ Mm = μr Rr |Fn| (Mk scaled back onto it);
  M = Mk − Cr w_t below the limit, Mk − f Cr w_t at it.

With f = 0 it is demcheck's ``epsd`` (``cap`` = spring) at kr and Cr computed as above — that law takes kr and Cr
as given numbers; this one ties them to kn, as Ai does, and adds f. A Hertz contact's kn follows its overlap: a
solver that has it per contact and step writes it into the record's coefficient array at :data:`K_N` (and Ir at
:data:`I_R`) before calling the force — the record's traits ``kn_column`` and ``ir_column`` name those places. The
packing loop does (reference/packing.py: kn the normal spring's secant stiffness F_spring/δ each step, as Lethe's
(4/3)E*√(R̄δ) for Hertz; packing_rolling.rolling_laws: Ir per species pair from the masses and radii), so a packing
case sets neither k_n nor i_r; the scenarios' sphere at rest on a wall has a fixed kn, the case's k_n (required
there: a missing one is a ConfigError, never a silent 0)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, MU_R, R_ROLL, RollingSubModel, _rolling_part

K_N, I_R = 2, 5  # the record's array: mu_r, r_roll, k_n, k_ratio, eta_r, i_r, f


def _fraction(v) -> bool:
    return 0.0 <= v <= 1.0


@dataclass(frozen=True)
class AiEpsdRolling(RollingSubModel):
    id: ClassVar[str] = "ai_epsd"
    history_size: ClassVar[int] = 3  # the spring torque Mk
    title: ClassVar[str] = "elastic-plastic spring-dashpot as Ai et al. 2011 model C (kr from kn)"
    spring: ClassVar[bool] = True
    kn_column: ClassVar[int] = K_N  # the packing loop writes the contact's kn here each step
    ir_column: ClassVar[int] = I_R  # and the pair's Ir here (its table)
    keys: ClassVar[tuple] = (
        MU_R, R_ROLL,
        Key("k_n", "the normal stiffness kr derives from (N/m; a Hertz contact's kn at its overlap; a packing's loop "
            "supplies it per contact, a packing case does not set it)", "must be > 0", positive),
        Key("k_ratio", "ε in kr = ε kn μr² Rr² (2.25: Ai's 3D value; Lethe's 2D runs 3)", "must be > 0", positive,
            default=2.25),
        Key("eta_r", "ηr: the dashpot's ratio to critical damping, Cr = ηr·2√(Ir kr)", default=0.0),
        Key("i_r", "Ai's equivalent inertia Ir (kg·m²; 1.4 m R² for a sphere on a wall; a packing's loop supplies it "
            "per pair)", default=0.0),
        Key("f", "the dashpot's share at full mobilisation (Ai's f; 0: off)", "must be in [0, 1]", _fraction,
            default=0.0))
    formula: ClassVar[str] = ("Mk ← Mk − kr wt dt, |Mk| ≤ μr Rr |Fn|, kr = ε kn μr² Rr²; M = Mk − Cr wt "
                              "(− f Cr wt at the limit), Cr = ηr·2√(Ir kr)")
    source: ClassVar[str] = ("Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269, model C, as LIGGGHTS epsd and "
                             "Lethe implement it")
    example: ClassVar[dict] = {"mu_r": 0.1, "k_n": 1e6}
    mu_r: float = 0.0
    r_roll: float = 0.0
    k_n: float = 0.0  # N/m
    k_ratio: float = 2.25
    eta_r: float = 0.0
    i_r: float = 0.0  # kg·m²
    f: float = 0.0

    def __post_init__(self):
        if self.eta_r > 0.0 and not self.i_r > 0.0:  # a dashpot needs its inertia: never a silent Cr = 0
            from ...errors import ConfigError

            raise ConfigError("contact.i_r", self.i_r, "must be > 0 with eta_r > 0 (Cr = ηr·2√(Ir kr))")

    @property
    def k_r(self) -> float:
        """kr = ε kn μr² Rr² (N·m/rad)."""
        return self.k_ratio * self.k_n * (self.mu_r * self.r_roll) ** 2

    @property
    def c_r(self) -> float:
        """Cr = ηr·2√(Ir kr) (N·m·s/rad)."""
        return self.eta_r * 2.0 * math.sqrt(self.i_r * self.k_r)


@njit(cache=KERNEL_CACHE)
def ai_epsd_rolling_force(c, w, n, fn_abs, dt, history):
    mu_r, r_roll, k_n, k_ratio, eta_r, i_r, f = c[0], c[1], c[2], c[3], c[4], c[5], c[6]
    wt = _rolling_part(w, n)
    k_r = k_ratio * k_n * (mu_r * r_roll) ** 2
    c_r = eta_r * 2.0 * math.sqrt(i_r * k_r)
    cap = mu_r * r_roll * fn_abs
    spring = history - (k_r * dt) * wt
    mag = math.sqrt(spring[0] ** 2 + spring[1] ** 2 + spring[2] ** 2)
    if mag > cap:  # full mobilisation: the spring held at the limit, the dashpot scaled by f
        spring = spring * (cap / mag)
        return spring - (f * c_r) * wt, spring
    return spring - c_r * wt, spring


KERNELS.register(AiEpsdRolling, ai_epsd_rolling_force)
