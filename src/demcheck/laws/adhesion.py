"""Adhesion: the slot ``adhesion`` (an attractive normal force at a contact).

* ``jkr`` (Johnson, Kendall & Roberts, Proc. R. Soc. A 324 (1971) 301-313): with the contact radius a,
  δ = a²/R̄ − √(2πwa/E*) and F = 4E*a³/(3R̄) − √(8πwE*a³) (w the work of adhesion, w = 2γ for two like surfaces
  of surface energy γ). It replaces the elastic normal law. Hysteresis: the contact forms at δ = 0 (jumping to
  F = −(8/9)·(3/2)πwR̄) and breaks at δ_f = −3a_f²/R̄ with a_f³ = πwR̄²/(8E*), where F = −(5/6)πwR̄ (pull-off under
  imposed displacement; ``break_at`` = load moves the break to δ_c, as LAMMPS does); under imposed load it
  breaks at F = −(3/2)πwR̄, δ_c = −a_c²/(3R̄), a_c³ = 9πwR̄²/(8E*).
* ``dmt`` (Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53 (1975) 314-326): F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄
  while δ ≥ 0; pull-off 2πwR̄ at δ = 0, no hysteresis. It replaces the elastic normal law.
* ``sjkr`` (simplified JKR cohesion, LIGGGHTS ``cohesion sjkr``/``sjkr2``): an extra force −kc·A on top of the
  normal law while the bodies overlap, kc a cohesion energy density (J/m³) and A a contact area: ``lens`` the
  circle where the two undeformed spheres intersect (π(2Rδ − δ²) on a wall), ``band`` 2πR_x δ with R_x = 2R̄ for a
  pair and R on a wall (what sjkr2 uses).
Thornton & Ning (Powder Technol. 99 (1998) 154-162) give the adhesive impact of elastic JKR spheres: capture below
v_s (the energy of the hysteresis loop) and e = √(1 − (v_s/v)²) above (reference/beyond.py).

Sign: F > 0 repels. ``touching`` (0 or 1) is the contact state kept between steps (JKR's hysteresis). Each law is
one module of ``laws/adhesion_laws/`` (its record with its traits, case keys and docs row, its compiled force
function ``<id>_adhesion_force(c, delta, touching) → (F, touching after)`` and its registration;
adhesion_laws/slot.py the interface): for jkr and dmt the whole elastic normal force (they replace the normal
law: ``replaces_normal``), for sjkr the cohesive force to add to the normal law's. This module is the slot's
face: the records and :func:`adhesive_force`, which calls the one of a record.
"""

from __future__ import annotations

from .adhesion_laws.dmt import DmtAdhesion
from .adhesion_laws.jkr import BREAK_DISPLACEMENT, BREAK_LOAD, JkrAdhesion, jkr_break, jkr_radius
from .adhesion_laws.sjkr import AREA_BAND, AREA_LENS, SjkrAdhesion, lens_area
from .adhesion_laws.slot import KERNELS, AdhesionSubModel

__all__ = ["AREA_BAND", "AREA_LENS", "AdhesionSubModel", "BREAK_DISPLACEMENT", "BREAK_LOAD", "DmtAdhesion",
           "JkrAdhesion", "KERNELS", "SjkrAdhesion", "adhesive_force", "jkr_break", "jkr_radius", "lens_area"]


def adhesive_force(law, delta: float, touching: float = 0.0) -> tuple[float, float]:
    """(F, touching after) of an adhesion record (or None: no force)."""
    force = KERNELS.of(law)
    if force is None:
        return 0.0, 0.0
    return force(law.array(), float(delta), float(touching))
