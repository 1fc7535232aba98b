"""Marshall's twisting (J. Comput. Phys. 228 (2009) 1541-1561; LAMMPS ``twisting marshall``): the sds law with
its coefficients from the tangential law and the contact radius a: ktw = ½ kt a², γtw = ½ γt a², μtw = ⅔ a μt."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .sds import SdsTwisting
from .slot import KERNELS, TwistingSubModel, _sds


@dataclass(frozen=True)
class MarshallTwisting(TwistingSubModel):
    id: ClassVar[str] = "marshall"
    title: ClassVar[str] = "Marshall's twisting (coefficients from the tangential law and the contact radius)"
    scenarios: ClassVar[tuple] = ("twist",)
    from_contact_radius: ClassVar[bool] = True
    keys: ClassVar[tuple] = (
        Key("kt", "the tangential stiffness the twist is built from (N/m)", "must be > 0", positive),
        Key("gamma_t", "the tangential damping (N·s/m)", default=0.0),
        Key("mu_t", "the tangential friction coefficient (default the pair's friction)", from_pair=True))
    formula: ClassVar[str] = "sds with ktw = kt a²/2, γtw = γt a²/2, μtw = 2aμt/3 (a the contact radius)"
    source: ClassVar[str] = "Marshall 2009; LAMMPS twisting marshall"
    example: ClassVar[dict] = {"kt": 1e5}
    kt: float = 0.0  # the tangential law's stiffness (N/m)
    gamma_t: float = 0.0  # its damping (N·s/m)
    mu_t: float = 0.0  # its friction coefficient

    def at(self, a: float) -> SdsTwisting:
        """The sds law it is at contact radius a."""
        return SdsTwisting(0.5 * self.kt * a * a, 0.5 * self.gamma_t * a * a, 2.0 / 3.0 * a * self.mu_t)


@njit(cache=KERNEL_CACHE)
def marshall_twisting_force(c, w, n, fn_abs, a, dt, phi):
    return _sds(0.5 * c[0] * a * a, 0.5 * c[1] * a * a, 2.0 / 3.0 * a * c[2], w, n, fn_abs, dt, phi)


KERNELS.register(MarshallTwisting, marshall_twisting_force)
