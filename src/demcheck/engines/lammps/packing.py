"""LAMMPS decks for packing cases, from the layout every engine shares (inputs/packing_decks)."""

from __future__ import annotations

import numpy as np

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common, packing_decks
from ...inputs.common import fmt
from ..mapping import pair_mapping
from .deck import VERSION_NOTE, coeff_args


def deck(case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    species, rep, rad, lo, hi, periodic, dt, steps = packing_decks.layout(case, duration, dt)
    g = np.asarray(case.run.gravity, float)
    gn = float(np.linalg.norm(g))
    lines = packing_decks.head(case, "lammps", VERSION_NOTE, len(rep), dt, steps, periodic,
                  ["atom_style sphere", "atom_modify map array", "BOUNDS", "newton off", "comm_modify vel yes"])
    rmax = float(rad.max())
    lines += ["", f"neighbor {fmt(0.5 * rmax)} bin", "neigh_modify delay 0 every 1 check yes", "pair_style granular"]
    for a in range(len(rep)):
        for b in range(a, len(rep)):
            mp = pair_mapping(case, "lammps", rep[a], rep[b])
            if mp.native is None:
                raise UnsupportedByEngine(f"lammps cannot express this model: {'; '.join(mp.reasons)}")
            lines.append(f"pair_coeff {a + 1} {b + 1} {coeff_args(mp.native)}")
    for k, w in enumerate(case.walls):
        ax, side = common.wall_axis(w, k)
        where = f"{fmt(w.point[ax])} NULL" if side == "lo" else f"NULL {fmt(w.point[ax])}"
        for s_ in range(len(rep)):
            mp = pair_mapping(case, "lammps", rep[s_], None)
            if s_ > 0 and mp.native != pair_mapping(case, "lammps", rep[0], None).native:
                raise UnsupportedByEngine("fix wall/gran takes one set of coefficients for every species: species "
                                          "whose wall contacts differ are not expressible")
        lines.append(f"fix wall{k} all wall/gran granular {coeff_args(mp.require())} {'xyz'[ax]}plane {where}")
    if gn > 0:
        lines.append(f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(c / gn) for c in g)}")
    every = max(1, steps // 50)
    lines += ["fix integrate all nve/sphere", f"timestep {fmt(dt)}", "thermo_style custom step ke atoms",
              "thermo_modify norm no", f"thermo {every}", f"run {steps}",
              "# every pair within the cutoff: the two ids, centre distance, normal force (repulsive > 0) and the",
              "# tangential force's magnitude (pair granular's 4th single() quantity), re-evaluated at the final state",
              "compute pairs all pair/local dist force p4", "compute ids all property/local patom1 patom2",
              f"dump contacts all local 1 {packing_decks.CONTACT_DUMP} c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3]",
              "dump_modify contacts format float %.17g", "run 0", "undump contacts",
              f"write_dump all custom {packing_decks.FINAL_DUMP} {' '.join(packing_decks.FINAL_COLUMNS)} modify format float %.17g sort id", ""]
    return common.Deck("lammps", "\n".join(lines), {"data.lmp": packing_decks.data_file(case, species, lo, hi)}, dt=dt)
