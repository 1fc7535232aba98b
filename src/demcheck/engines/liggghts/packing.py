"""LIGGGHTS decks for packing cases, from the layout every engine shares (inputs/packing_decks)."""

from __future__ import annotations

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common, packing_decks as PD
from ...inputs.common import fmt
from .. import family_deck as FD, family_packing as FP
from ..base import Engine
from ..mapping import pair_mapping
from .deck import RIGID_WALL_MODULUS, VERSION_NOTE, model_setup, property_matrices


def deck(engine: Engine, case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    lay = PD.layout(case, duration, dt)
    rep, ns = lay.rep, len(lay.table)
    natives = {}
    for a in range(ns):
        for b in range(a, ns):
            natives[(a, b)] = pair_mapping(case, engine, rep[a], rep[b])
        if case.walls:
            natives[(a, ns)] = pair_mapping(case, engine, rep[a], None)
    for mp in natives.values():
        if mp.native is None:
            raise UnsupportedByEngine(f"liggghts cannot express this model: {'; '.join(mp.reasons)}")
    nat = natives[(0, 0)].native
    if nat.normal == "luding":
        raise UnsupportedByEngine("luding (HLS with variable unloading) lowers δ_max once the unloading force "
                                  "reaches 0, so a contact that reloads before it separates reloads from its "
                                  "lowest overlap, not along the reference's unloading line (Walton & Braun): "
                                  "exact for one load–unload cycle (collisions), not in a packing")
    if nat.normal == "edinburgh" or any(mp.native.normal != nat.normal for mp in natives.values()):
        raise UnsupportedByEngine("this packing's species map to different LIGGGHTS models (or to edinburgh, whose "
                                  "moduli are set per contact): not expressible in one pair style")
    ntypes = ns + (1 if case.walls else 0)

    def native_of_types(a, b):
        mp = natives.get((min(a, b), max(a, b)))
        return mp.native if mp else None

    matrices = property_matrices(nat, ntypes, native_of_types)
    moduli, ratios = [], []
    if nat.normal in ("hertz", "hooke"):
        for i in rep:
            m = case.materials[case.particles[i].material]
            moduli.append(m.youngs_modulus)
            ratios.append(m.poisson_ratio)
        if case.walls:
            moduli.append(RIGID_WALL_MODULUS)
            ratios.append(ratios[0])
    model_lines, style, flags = model_setup(nat, matrices, moduli, ratios)
    lines = FP.head(case, "liggghts", VERSION_NOTE, "liggghts -in", lay, list(natives.values()), "granular",
                    "communicate single vel yes")
    walls = f", {ntypes} the walls" if case.walls else ""
    lines += ["", common.comment("neighbour lists: a skin of half the largest radius, checked every step"),
              f"neighbor {fmt(0.5 * float(lay.rad.max()))} bin", "neigh_modify delay 0",
              "", common.comment(f"the contact law: per atom-type pair (types 1 to {ns} the species{walls}), the "
                                 "property/global values below (docs/liggghts-users.md reads each setting)")]
    lines += PD.law_comments([(f"species {a + 1} with " + ("the walls" if b == ns else f"{b + 1}"), mp)
                              for (a, b), mp in natives.items()])
    lines += [*model_lines, f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *"]
    for k, w in enumerate(case.walls):
        ax, _ = common.wall_axis(w, k)
        lines += [common.comment(f"{PD.wall_comment(w, k)}; a primitive of atom type {ntypes}"),
                  f"fix wall{k} all wall/gran {style} primitive type {ntypes} {'xyz'[ax]}plane "
                  f"{fmt(w.point[ax])} {' '.join(flags)}"]
    lines += FP.gravity(case)
    fmt_line = " ".join(["%d", "%d"] + ["%.17g"] * (len(PD.FINAL_COLUMNS) - 2))
    local_fmt = " ".join(["%.17g"] * 10)  # compute values are doubles, the ids too
    lines += ["", common.comment("per contact: the two ids, a periodic flag, the force on the first and its normal "
                                 "part, the overlap"),
              common.comment("(defined before the first run, as LIGGGHTS requires; dumped at the final state only)"),
              "compute pairs all pair/gran/local id force force_normal delta"]
    lines += FP.integration(lay)
    lines += ["", common.comment("the final state: every particle and every contact at full precision (%.17g), "
                                 "written by a run of no steps"),
              f"dump final all custom 1 {PD.FINAL_DUMP} {' '.join(PD.FINAL_COLUMNS)}",
              f'dump_modify final format "{fmt_line}" sort id',
              f"dump contacts all local 1 {PD.CONTACT_DUMP} " + " ".join(f"c_pairs[{k}]" for k in range(1, 11)),
              f'dump_modify contacts format "{local_fmt}"', "run 0", ""]
    return common.Deck("liggghts", "\n".join(lines), {FP.DATA_FILE: FP.data_file(case, lay, ntypes)}, dt=lay.dt,
                       check=FD.check_deck)
