"""LIGGGHTS decks (`pair_style gran`, `fix wall/gran … primitive`), for LIGGGHTS-PUBLIC 3.8.0.

Per-pair coefficients go into ``fix property/global … peratomtypepair`` matrices, one atom type per
particle and, for a wall, one more type for the wall primitive. LIGGGHTS checks Young's moduli against
5e6 ≤ E ≤ 1e9 Pa; ``hard_particles yes`` (or ``soft_particles yes``) is written when a modulus is outside.
A rigid wall is a wall type of modulus 1e30 Pa: E* then equals the particle's E/(1−ν²) to round-off.
"""

from __future__ import annotations

import numpy as np

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common
from ...inputs.common import fmt
from .. import family_deck as FD
from ..base import Engine
from ..family import DUMP_COLUMNS
from ..mapping import contact_mapping, pair_mapping

VERSION_NOTE = "written for LIGGGHTS-PUBLIC 3.8.0 (pair_style gran)"
RIGID_WALL_MODULUS = 1e30


NAMES = {"kn": "kn", "kt": "kt", "gamman": "gamman", "gammat": "gammat", "friction": "coefficientFriction",
         "restitution": "coefficientRestitution", "unloading": "UnloadingStiffness",
         "adhesion": "coefficientAdhesionStiffness", "pulloff": "pullOffForce", "surface_energy": "surfaceEnergy",
         "loading": "LoadingStiffness", "plasticity_depth": "coefficientPlasticityDepth"}


def property_matrices(nat, ntypes: int, native_of_types) -> dict:
    """The peratomtypepair matrices of every per-pair property, from each type pair's configuration
    (``native_of_types(a, b)``, None for pairs that never meet: they take ``nat``'s value, since LIGGGHTS
    checks every entry against its sanity limits)."""
    keys = set()
    for a in range(ntypes):
        for b in range(ntypes):
            v = native_of_types(a, b)
            if v is not None:
                keys |= set(v.props)
    keys -= {"youngs_eff", "shear_eff", "kl", "characteristic_velocity"}
    matrices = {}
    for key in sorted(keys):
        mat = np.full((ntypes, ntypes), nat.props.get(key, 0.0))
        for a in range(ntypes):
            for b in range(ntypes):
                v = native_of_types(a, b)
                if v is not None:
                    mat[a, b] = v.props.get(key, 0.0)
        matrices[NAMES[key]] = mat
    if nat.tangential != "off" and "coefficientFriction" not in matrices:
        matrices["coefficientFriction"] = np.zeros((ntypes, ntypes))
    return matrices


def model_setup(nat, matrices: dict, moduli: list, ratios: list) -> tuple[list[str], str, list[str]]:
    """The property fixes and sanity switches, the gran style and its flags (pair_style and wall/gran)."""
    lines = []
    if moduli:
        lines.append(f"fix m_E all property/global youngsModulus peratomtype {' '.join(fmt(x) for x in moduli)}")
        lines.append(f"fix m_nu all property/global poissonsRatio peratomtype {' '.join(fmt(x) for x in ratios)}")
    for name, mat in matrices.items():
        lines.append(_matrix(name, mat))
    if nat.normal == "hooke":
        lines.append(f"fix m_vc all property/global characteristicVelocity scalar "
                     f"{fmt(nat.props['characteristic_velocity'])}")
    if nat.normal == "edinburgh":
        lines += ["fix m_cex all property/global adhesionExponent scalar 1",
                  "fix m_dex all property/global overlapExponent scalar 1"]
    style = f"model {nat.normal} tangential {'off' if nat.tangential == 'off' else nat.tangential}"
    flags = ["fixKc on"] if nat.normal == "edinburgh" else []
    if nat.tangential == "history" and not nat.tangential_damping:
        flags.append("tangential_damping off")
    flags.append(f"limitForce {'on' if nat.limit else 'off'}")
    if moduli and max(moduli) > 1e9:
        lines += ["# a Young's modulus above LIGGGHTS's 1e9 Pa sanity limit", "hard_particles yes"]
    if moduli and min(moduli) < 5e6:
        lines += ["# a Young's modulus below LIGGGHTS's 5e6 Pa sanity limit", "soft_particles yes"]
    return lines, style, flags


def _matrix(name: str, values: np.ndarray) -> str:
    n = values.shape[0]
    return (f"fix m_{name} all property/global {name} peratomtypepair {n} "
            + " ".join(fmt(x) for x in values.ravel()))


def deck(engine: Engine, case: Case, dt: float | None = None, length: float = 1.0, native=None,
         data_name: str = "data.lmp", copies: int = 1) -> common.Deck:
    """The deck of a collision case, written with ``engine``'s mapping (the Engine that runs it; ``native``: one
    configuration for every type pair instead of the case's mapped model; ``copies``: independent copies of the
    collision in one run, as in lammps.deck)."""
    sc = common.scene(case, dt, length)
    mp = contact_mapping(case, engine, native)
    nat = mp.require()
    n = len(case.particles)
    ntypes = n * copies + (1 if case.walls else 0)
    lo, hi = sc.box
    batch_axis, spacing = 0, 0.0
    if copies > 1:
        batch_axis, spacing, (lo, hi) = FD.batch_layout(sc, copies)
    lines = common.header("liggghts", sc, mp, VERSION_NOTE, "liggghts -in") + common.notes(nat.comments)
    natives = _type_natives(engine, case, native, nat, n)

    def native_of_types(a, b):
        ia = n if (case.walls and a == ntypes - 1) else a % n
        ib = n if (case.walls and b == ntypes - 1) else b % n
        return natives.get((min(ia, ib), max(ia, ib)))

    matrices = property_matrices(nat, ntypes, native_of_types)
    moduli, ratios = _moduli(case, nat, sc.model.pair.r_eff, n, copies)
    lines += ["", "units si", "atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
              "communicate single vel yes",
              f"read_data {data_name}"]
    # read_data sets the angular velocities (3.8.0's set has no omega); masses are then set exactly
    for k in range(1, n * copies + 1):
        lines.append(f"set atom {k} mass {fmt(case.mass((k - 1) % n))}")
    rmax = max(p.radius for p in case.particles)
    lines += ["", f"neighbor {fmt(rmax)} bin", "neigh_modify delay 0", ""]
    model_lines, style, flags = model_setup(nat, matrices, moduli, ratios)
    lines += model_lines
    lines += [f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *"]
    if case.walls:
        axis = "xyz"[sc.wall_axis]
        lines += ["", f"# the wall: primitive of type {ntypes}",
                  f"fix wall all wall/gran {style} primitive type {ntypes} {axis}plane {fmt(sc.wall_position)} "
                  f"{' '.join(flags)}"]
    g = list(case.run.gravity)
    gn = sum(x * x for x in g) ** 0.5
    if gn > 0:
        lines.append(f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(x / gn) for x in g)}")
    fmt_line = " ".join(["%d", "%d"] + ["%.17g"] * (len(DUMP_COLUMNS) - 2))
    lines += ["", "fix integrate all nve/sphere", f"timestep {fmt(sc.dt)}",
              f"dump state all custom 1 {common.DUMP_FILE} {' '.join(DUMP_COLUMNS)}",
              f'dump_modify state format "{fmt_line}" sort id',
              "thermo_style custom step atoms ke", f"thermo {max(sc.steps // 10, 1)}",
              f"run {sc.steps}", ""]
    data = FD.data_file(case, ntypes, (lo, hi), f"demcheck: case {case.name} (hash {case.hash})", copies=copies,
                            axis=batch_axis, spacing=spacing)
    return common.Deck("liggghts", "\n".join(lines), {data_name: data}, dt=sc.dt, check=FD.check_deck)


def _type_natives(engine: Engine, case: Case, native, nat, n: int) -> dict:
    """Every type pair's configuration, keyed (i, j) with the wall as type n (it pairs with each particle); LIGGGHTS
    has one gran model per pair style, so every pair must map to the model of ``nat``."""
    natives = {}
    for i, j in common.type_pairs(case):
        pm = pair_mapping(case, engine, i, j, native)
        if pm.native is None:
            raise UnsupportedByEngine(f"type pair {i + 1} {j + 1 if j is not None else 'wall'}: "
                                      f"{'; '.join(pm.reasons)}")
        if pm.native.normal != nat.normal or pm.native.tangential != nat.tangential:
            raise UnsupportedByEngine("LIGGGHTS has one gran model per pair style: type pairs map differently")
        natives[(i, n if j is None else j)] = pm.native
    return natives


def _moduli(case: Case, nat, r_eff: float, n: int, copies: int) -> tuple[list, list]:
    """youngsModulus and poissonsRatio per atom type (the wall's type last): the materials' (hertz, hooke), or
    those that give edinburgh's K_L = 2E*R̄ of the contact; empty for the stiffness models."""
    moduli, ratios = [], []
    if nat.normal == "edinburgh":
        # K_L = 2E*R̄ of the contact: equal moduli E for the particles give E* = E/(2(1−ν²)); a rigid wall
        # type of modulus 1e30 gives E* = E/(1−ν²)
        nu = case.materials[case.particles[0].material].poisson_ratio
        if case.walls:
            if not case.walls[0].rigid:
                raise UnsupportedByEngine("edinburgh (HLS) decks are written for rigid walls")
            e_part = (1.0 - nu * nu) * nat.props["kl"] / (2.0 * r_eff)
            moduli, ratios = [e_part] * (n * copies) + [RIGID_WALL_MODULUS], [nu] * (n * copies + 1)
        else:
            moduli, ratios = [(1.0 - nu * nu) * nat.props["kl"] / r_eff] * (n * copies), [nu] * (n * copies)
    if nat.normal in ("hertz", "hooke"):
        mats = [case.materials[p.material] for p in case.particles] * copies
        moduli = [m.youngs_modulus for m in mats]
        ratios = [m.poisson_ratio for m in mats]
        if case.walls:
            w = case.walls[0]
            if w.rigid:
                moduli.append(RIGID_WALL_MODULUS)
                ratios.append(ratios[0])
            else:
                wm = case.materials[w.material]
                moduli.append(wm.youngs_modulus)
                ratios.append(wm.poisson_ratio)
    return moduli, ratios
