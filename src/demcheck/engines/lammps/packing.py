"""LAMMPS decks for packing cases: the layout every engine shares (inputs/packing_decks), written in the LAMMPS
family's packing blocks (engines/family_packing.py)."""

from __future__ import annotations

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common, packing_decks as PD
from ...inputs.common import fmt
from .. import family_deck as FD, family_packing as FP
from ..base import Engine
from ..mapping import pair_mapping
from .deck import VERSION_NOTE, coeff_args


def deck(engine: Engine, case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    lay = PD.layout(case, duration, dt)
    rep, ns = lay.rep, len(lay.table)
    pairs = {}
    for a in range(ns):
        for b in range(a, ns):
            mp = pair_mapping(case, engine, rep[a], rep[b])
            if mp.native is None:
                raise UnsupportedByEngine(f"lammps cannot express this model: {'; '.join(mp.reasons)}")
            pairs[(a, b)] = mp
    walls = []
    if case.walls:
        walls = [pair_mapping(case, engine, r, None) for r in rep]
        for mp in walls:
            mp.require()
            if mp.native != walls[0].native:
                raise UnsupportedByEngine("fix wall/gran takes one set of coefficients for every species: species "
                                          "whose wall contacts differ are not expressible")
    lines = FP.head(case, "lammps", VERSION_NOTE, "lmp -in", lay, [*pairs.values(), *walls], "sphere",
                    "comm_modify vel yes")
    lines += ["", common.comment("neighbour lists: a skin of half the largest radius, checked every step"),
              f"neighbor {fmt(0.5 * float(lay.rad.max()))} bin", "neigh_modify delay 0 every 1 check yes",
              "", common.comment("the contact law of every species pair, each given explicitly (no mixing; "
                                 "docs/lammps-users.md reads each setting)"),
              *PD.law_comments([*((f"species {a + 1} with {b + 1}", mp) for (a, b), mp in pairs.items()),
                                *([("every species with the walls", walls[0])] if walls else [])]),
              "pair_style granular"]
    lines += [f"pair_coeff {a + 1} {b + 1} {coeff_args(mp.native)}" for (a, b), mp in pairs.items()]
    for k, w in enumerate(case.walls):
        ax, side = common.wall_axis(w, k)
        where = f"{fmt(w.point[ax])} NULL" if side == "lo" else f"NULL {fmt(w.point[ax])}"
        lines += [common.comment(f"{PD.wall_comment(w, k)}, with the walls' law"),
                  f"fix wall{k} all wall/gran granular {coeff_args(walls[0].native)} {'xyz'[ax]}plane {where}"]
    lines += FP.gravity(case)
    lines += FP.integration(lay)
    lines += ["", common.comment("the final state's contacts, re-evaluated by a run of no steps: for every pair within "
                                 "the cutoff the two ids, the centre distance,"),
              common.comment("the normal force (repulsive > 0) and the tangential force's magnitude (pair granular's "
                             "4th single() quantity), at full precision"),
              "compute pairs all pair/local dist force p4", "compute ids all property/local patom1 patom2",
              f"dump contacts all local 1 {PD.CONTACT_DUMP} c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3]",
              "dump_modify contacts format float %.17g", "run 0", "undump contacts",
              common.comment("the final state: every particle, at full precision (%.17g), sorted by id"),
              f"write_dump all custom {PD.FINAL_DUMP} {' '.join(PD.FINAL_COLUMNS)} modify format float %.17g sort id",
              ""]
    return common.Deck("lammps", "\n".join(lines), {FP.DATA_FILE: FP.data_file(case, lay)}, dt=lay.dt,
                       check=FD.check_deck)
