"""The scenarios beyond sliding in LIGGGHTS-PUBLIC 3.8.0: the conduction scenario through ``fix heat/gran/conduction``
(its lens conductance, LensHeat: exact for ``heat = "lens"``, the named variant of Batchelor & O'Brien's
``radius``), the held pair written without an integrator (the bodies stay where the data file puts them). The
others are not expressible, each with its reason: LIGGGHTS has no twisting model and no JKR or DMT normal model,
and no deck is written yet for its rolling models on a wall (their twins step pairs only: verlet_pair).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ...case import Case
from ...inputs import common
from ...inputs.common import fmt
from ...laws.heat import LensHeat
from ...laws.model import resolve
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused
from .deck import VERSION_NOTE, model_setup, property_matrices
from .mapping import map_model

WHY_NOT = {
    "twist": "LIGGGHTS-PUBLIC 3.8.0 has no twisting torque model",
    "pull_off": "LIGGGHTS-PUBLIC 3.8.0 has no JKR or DMT normal model (its cohesion sjkr/sjkr2 adds a force "
                "proportional to the contact area to the normal law)",
    "adhesive_impact": "LIGGGHTS-PUBLIC 3.8.0 has no JKR normal model (its cohesion sjkr/sjkr2 adds a force "
                       "proportional to the contact area to the normal law)",
    "rolling": "no LIGGGHTS deck is written for a sphere rolling on a wall yet (its hertz tangential spring is "
               "kt = 8G*√(R̄δ), not the case's constant kt, and the twins of its rolling models step pairs only)",
    "incline": "no LIGGGHTS deck is written for a sphere rolling on a wall yet (epsd/epsd2/epsd3 derive kr from "
               "the normal or tangential stiffness, δ-dependent under hertz; the case's kr is a constant)",
}


def mapping(case: Case) -> Mapping:
    s = case.run.scenario
    if s in WHY_NOT:
        return refused("liggghts", WHY_NOT[s])
    model = resolve(case)
    rec = model.slot("heat")
    if rec.id == "area":
        return refused("liggghts", "LIGGGHTS fix heat/gran/conduction has no conductance per contact area")
    base = map_model(model, case.contact.params)
    if base.native is None:
        return base
    r0, r1 = (p.radius for p in case.particles)
    nat = base.native
    twin_rec = LensHeat(rec.k, r0, r1)
    nat.props = {**nat.props}
    nat.comments = [*nat.comments, f"fix heat/gran/conduction, thermalConductivity {rec.k:g} W/(m·K): 2ks√A over "
                                   "the spheres' intersection circle"]
    reasons = []
    if rec.id == "radius":
        reasons = ["LIGGGHTS fix heat/gran/conduction conducts through the spheres' intersection circle, "
                   "H = 2ks√A (√(2π) × Batchelor & O'Brien's 2ks√(R̄δ) between like spheres at small overlap)"]
    mp = Mapping("liggghts", APPROXIMATE if reasons else EXACT, [*base.reasons, *reasons], nat,
                 {**base.keywords, **{r: "fix heat/gran/conduction" for r in reasons}})
    mp.native.props["slots"] = {"heat": twin_rec}
    return mp


def twin_laws(case: Case, nat: Native) -> dict:
    return {"heat": nat.props["slots"]["heat"]}


def deck(case: Case, nat: Native, lay) -> common.Deck:
    """The held pair: a data file at the layout's positions, the contact's properties, no integrator, the heat fix
    started at body 0's temperature and body 1's set after a ``run 0``."""
    n = len(case.particles)
    props = {k: v for k, v in nat.props.items() if k != "slots"}
    matrices = property_matrices(replace(nat, props=props), n, lambda a, b: replace(nat, props=props))
    mats = [case.materials[p.material] for p in case.particles]
    model_lines, style, flags = model_setup(nat, matrices, [m.youngs_modulus for m in mats],
                                            [m.poisson_ratio for m in mats])
    k = nat.props["slots"]["heat"].k
    t0, t1 = (float(x) for x in case.run.temperatures)
    lines = [f"# demcheck scenario {case.run.scenario} ({case.name}); {VERSION_NOTE}",
             *(f"# {c}" for c in nat.comments),
             "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
             "communicate single vel yes", "read_data data.lmp",
             *(f"set atom {i + 1} mass {fmt(case.mass(i))}" for i in range(n)),
             f"neighbor {fmt(max(p.radius for p in case.particles))} bin", "neigh_modify delay 0", *model_lines,
             f"fix m_k all property/global thermalConductivity peratomtype {' '.join([fmt(k)] * n)}",
             f"fix m_c all property/global thermalCapacity peratomtype {' '.join(fmt(m.specific_heat) for m in mats)}",
             f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *", f"timestep {fmt(lay.dt)}",
             f"fix heat all heat/gran/conduction initial_temperature {fmt(t0)}", "run 0",
             f"set atom 2 property/atom Temp {fmt(t1)}",
             f"dump state all custom {lay.every} {common.DUMP_FILE} id f_Temp",
             'dump_modify state format "%d %.17g" sort id', f"run {lay.steps}", ""]
    box = (np.array(lay.positions).min(axis=0) - 4 * max(p.radius for p in case.particles),
           np.array(lay.positions).max(axis=0) + 4 * max(p.radius for p in case.particles))
    held = replace(case, particles=[replace(p, position=tuple(lay.positions[i]), velocity=(0.0, 0.0, 0.0),
                                            angular_velocity=(0.0, 0.0, 0.0)) for i, p in enumerate(case.particles)])
    data = common.data_file(held, n, box, f"demcheck: scenario {case.run.scenario} of {case.name}")
    return common.Deck("liggghts", "\n".join(lines), {"data.lmp": data}, dt=lay.dt)


def read(case: Case, lay, workdir) -> dict:
    """The held pair's temperatures, sampled from step 0 (the dump after ``run 0`` starts at the run's step 0)."""
    from ..dumps import read_dump

    table = read_dump(Path(workdir) / common.DUMP_FILE, columns=("id", "f_Temp")).sort_values(["step", "id"])
    steps = table["step"].to_numpy()[::2]
    temps = table["f_Temp"].to_numpy()
    return {"t": (steps - steps[0]) * lay.dt, "dT": temps[1::2] - temps[0::2]}
