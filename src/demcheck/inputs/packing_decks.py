"""Decks for packing cases: the same initial state as the reference (a LAMMPS data file, one atom type per
particle species), the species pairs' coefficients from the mapping, plane walls, gravity, periodic x and
y where the packing has a box, a final dump of every particle in full precision, and a final dump of every
particle-particle contact (the engine's own per-contact output: LAMMPS ``compute pair/local`` with
``property/local``, LIGGGHTS ``compute pair/gran/local``) for the contact-force distribution."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..case import Case
from ..errors import UnsupportedByEngine
from ..reference import packing as P
from . import common, lammps as L
from .common import fmt

FINAL_DUMP = "final.txt"
CONTACT_DUMP = "contacts.txt"
# the contact table every source yields: particle indices (0-based), overlap, normal force, |tangential force|
CONTACT_COLUMNS = ("i", "j", "overlap", "fn", "ft")
CONTACT_READER = 2  # in the engine-run cache key: cached contact tables are parsed ones (2: LIGGGHTS Fn signed)
FINAL_COLUMNS = ("id", "type", "radius", "mass", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
                 "fx", "fy", "fz")


def _data_file(case: Case, species, lo, hi, n_types: int | None = None) -> str:
    n_types = n_types or int(species.max()) + 1
    lines = [common.comment(f"demcheck packing: case {case.name} (hash {case.hash})"), "",
             f"{len(case.particles)} atoms", f"{n_types} atom types", "", f"{fmt(lo[0])} {fmt(hi[0])} xlo xhi",
             f"{fmt(lo[1])} {fmt(hi[1])} ylo yhi", f"{fmt(lo[2])} {fmt(hi[2])} zlo zhi", "", "Atoms", ""]
    for k, p in enumerate(case.particles):
        rho = case.materials[p.material].density
        lines.append(f"{k + 1} {species[k] + 1} {fmt(2 * p.radius)} {fmt(rho)} {' '.join(fmt(x) for x in p.position)}")
    lines += ["", "Velocities", ""]
    for k, p in enumerate(case.particles):
        lines.append(f"{k + 1} {' '.join(fmt(x) for x in p.velocity)} {' '.join(fmt(x) for x in p.angular_velocity)}")
    return "\n".join(lines) + "\n"


def _head(case: Case, engine: str, note: str, n_species: int, dt: float, steps: int, periodic, setup: list[str]):
    """Header comments, units, the engine's atom setup (BOUNDS: the boundary line), the data file and the
    exact masses."""
    bounds = "boundary " + " ".join("p" if periodic[k] else "f" for k in range(2)) + " f"
    lines = [common.comment(f"demcheck packing deck for {engine} ({note})"),
             common.comment(f"case: {case.name} (hash {case.hash})"),
             common.comment(f"model: normal = {case.contact.normal}, tangential = {case.contact.tangential}"),
             common.comment(f"{len(case.particles)} particles of {n_species} species, dt = {fmt(dt)} s, {steps} "
                            f"steps; final state: {FINAL_DUMP}"), "", "units si",
             *[bounds if x == "BOUNDS" else x for x in setup],
             "read_data data.lmp"]
    for k in range(len(case.particles)):
        lines.append(f"set atom {k + 1} mass {fmt(case.mass(k))}")
    return lines


def _layout(case: Case, duration, dt):
    """What both decks take from the case: species and their representatives, radii, the box (lo, hi,
    periodic), dt and the number of steps."""
    if case.kind != "packing":
        raise UnsupportedByEngine(f"case '{case.name}' is not a packing")
    species, rep = P.species_of(case)
    x = np.array([p.position for p in case.particles], float)
    rad = np.array([p.radius for p in case.particles], float)
    lo, hi, periodic = P.box_of(case, x, rad)
    dt = dt or P.packing_dt(case)
    duration = duration or (case.raw.get("packing") or {}).get("duration")
    return species, rep, rad, lo, hi, periodic, dt, int(np.ceil(duration / dt))


def lammps_deck(case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    species, rep, rad, lo, hi, periodic, dt, steps = _layout(case, duration, dt)
    g = np.asarray(case.run.gravity, float)
    gn = float(np.linalg.norm(g))
    lines = _head(case, "lammps", L.VERSION_NOTE, len(rep), dt, steps, periodic,
                  ["atom_style sphere", "atom_modify map array", "BOUNDS", "newton off", "comm_modify vel yes"])
    rmax = float(rad.max())
    lines += ["", f"neighbor {fmt(0.5 * rmax)} bin", "neigh_modify delay 0 every 1 check yes", "pair_style granular"]
    for a in range(len(rep)):
        for b in range(a, len(rep)):
            mp = common.pair_mapping(case, "lammps", rep[a], rep[b])
            if mp.native is None:
                raise UnsupportedByEngine(f"lammps cannot express this model: {'; '.join(mp.reasons)}")
            lines.append(f"pair_coeff {a + 1} {b + 1} {L.coeff_args(mp.native)}")
    for k, w in enumerate(case.walls):
        ax, side = common.wall_axis(w, k)
        where = f"{fmt(w.point[ax])} NULL" if side == "lo" else f"NULL {fmt(w.point[ax])}"
        for s_ in range(len(rep)):
            mp = common.pair_mapping(case, "lammps", rep[s_], None)
            if s_ > 0 and mp.native != common.pair_mapping(case, "lammps", rep[0], None).native:
                raise UnsupportedByEngine("fix wall/gran takes one set of coefficients for every species: species "
                                          "whose wall contacts differ are not expressible")
        lines.append(f"fix wall{k} all wall/gran granular {L.coeff_args(mp.require())} {'xyz'[ax]}plane {where}")
    if gn > 0:
        lines.append(f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(c / gn) for c in g)}")
    every = max(1, steps // 50)
    lines += ["fix integrate all nve/sphere", f"timestep {fmt(dt)}", "thermo_style custom step ke atoms",
              "thermo_modify norm no", f"thermo {every}", f"run {steps}",
              "# every pair within the cutoff: the two ids, centre distance, normal force (repulsive > 0) and the",
              "# tangential force's magnitude (pair granular's 4th single() quantity), re-evaluated at the final state",
              "compute pairs all pair/local dist force p4", "compute ids all property/local patom1 patom2",
              f"dump contacts all local 1 {CONTACT_DUMP} c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3]",
              "dump_modify contacts format float %.17g", "run 0", "undump contacts",
              f"write_dump all custom {FINAL_DUMP} {' '.join(FINAL_COLUMNS)} modify format float %.17g sort id", ""]
    return common.Deck("lammps", "\n".join(lines), {"data.lmp": _data_file(case, species, lo, hi)})


def liggghts_deck(case: Case, duration: float | None = None, dt: float | None = None) -> common.Deck:
    from . import liggghts as G

    species, rep, rad, lo, hi, periodic, dt, steps = _layout(case, duration, dt)
    ns = len(rep)
    natives = {}
    for a in range(ns):
        for b in range(a, ns):
            natives[(a, b)] = common.pair_mapping(case, "liggghts", rep[a], rep[b])
        if case.walls:
            natives[(a, ns)] = common.pair_mapping(case, "liggghts", rep[a], None)
    for mp in natives.values():
        if mp.native is None:
            raise UnsupportedByEngine(f"liggghts cannot express this model: {'; '.join(mp.reasons)}")
    nat = natives[(0, 0)].native
    if nat.normal == "edinburgh" or any(mp.native.normal != nat.normal for mp in natives.values()):
        raise UnsupportedByEngine("this packing's species map to different LIGGGHTS models (or to edinburgh, whose "
                                  "moduli are set per contact): not expressible in one pair style")
    ntypes = ns + (1 if case.walls else 0)

    def native_of_types(a, b):
        mp = natives.get((min(a, b), max(a, b)))
        return mp.native if mp else None

    matrices = G.property_matrices(nat, ntypes, native_of_types)
    moduli, ratios = [], []
    if nat.normal in ("hertz", "hooke"):
        for i in rep:
            m = case.materials[case.particles[i].material]
            moduli.append(m.youngs_modulus)
            ratios.append(m.poisson_ratio)
        if case.walls:
            moduli.append(G.RIGID_WALL_MODULUS)
            ratios.append(ratios[0])
    model_lines, style, flags = G.model_setup(nat, matrices, moduli, ratios)
    lines = _head(case, "liggghts", G.VERSION_NOTE, ns, dt, steps, periodic,
                  ["atom_style granular", "atom_modify map array", "BOUNDS", "newton off",
                   "communicate single vel yes"])
    lines += ["", f"neighbor {fmt(0.5 * float(rad.max()))} bin", "neigh_modify delay 0", *model_lines,
              f"pair_style gran {style} {' '.join(flags)}", "pair_coeff * *"]
    for k, w in enumerate(case.walls):
        ax, _ = common.wall_axis(w, k)
        lines.append(f"fix wall{k} all wall/gran {style} primitive type {ntypes} {'xyz'[ax]}plane "
                     f"{fmt(w.point[ax])} {' '.join(flags)}")
    g = np.asarray(case.run.gravity, float)
    gn = float(np.linalg.norm(g))
    if gn > 0:
        lines.append(f"fix gravity all gravity {fmt(gn)} vector {' '.join(fmt(c / gn) for c in g)}")
    every = max(1, steps // 50)
    fmt_line = " ".join(["%d", "%d"] + ["%.17g"] * (len(FINAL_COLUMNS) - 2))
    local_fmt = " ".join(["%.17g"] * 10)  # compute values are doubles, the ids too
    lines += ["# per contact: the two ids, a periodic flag, the force on the first and its normal part, the overlap",
              "# (defined before the first run, as LIGGGHTS requires; dumped at the final state only)",
              "compute pairs all pair/gran/local id force force_normal delta",
              "fix integrate all nve/sphere", f"timestep {fmt(dt)}", "thermo_style custom step ke atoms",
              "thermo_modify norm no", f"thermo {every}", f"run {steps}",
              f"dump final all custom 1 {FINAL_DUMP} {' '.join(FINAL_COLUMNS)}",
              f'dump_modify final format "{fmt_line}" sort id',
              f"dump contacts all local 1 {CONTACT_DUMP} " + " ".join(f"c_pairs[{k}]" for k in range(1, 11)),
              f'dump_modify contacts format "{local_fmt}"', "run 0", ""]
    return common.Deck("liggghts", "\n".join(lines), {"data.lmp": _data_file(case, species, lo, hi, ntypes)})


@dataclass
class PackingRun:
    """An engine's settled packing: the final per-particle table (FINAL_COLUMNS), its particle-particle
    contacts (CONTACT_COLUMNS), the kinetic energy series [(step, ke)] and the engine's version."""

    table: pd.DataFrame
    contacts: pd.DataFrame
    ke: list
    version: str


def read_contacts(engine: str, path, radius: np.ndarray, x: np.ndarray | None = None, box=None) -> pd.DataFrame:
    """The engine's per-contact dump as CONTACT_COLUMNS: touching pairs only (overlap > 0), each once
    (with newton off a pair across a periodic or processor boundary may be listed from both sides).
    ``radius`` (and ``x``): per particle, indexed by id − 1 (LAMMPS lists centre distances, not overlaps).
    Fn is signed, repulsive > 0: LAMMPS's as it writes it; LIGGGHTS's normal force vector projected on the
    contact normal from the positions ``x`` (minimum image in the periodic ``box`` [lx, ly]), its magnitude
    when no positions are given."""
    from ..engines import dumps

    raw = dumps.read_dump(path)
    raw = raw[raw["step"] == raw["step"].max()] if len(raw) else raw
    v = raw.drop(columns="step").to_numpy(float)
    i, j = v[:, 0].astype(np.int64) - 1, v[:, 1].astype(np.int64) - 1
    if engine == "lammps":
        overlap, fn, ft = radius[i] + radius[j] - v[:, 2], v[:, 3], v[:, 4]
    else:  # id1 id2 periodic-flag, force (3), its normal part (3), delta
        overlap = v[:, 9]
        fn = np.linalg.norm(v[:, 6:9], axis=1)
        if x is not None and len(v):
            d = x[j] - x[i]
            for k in range(2 if box is not None else 0):
                d[:, k] -= box[k] * np.floor(d[:, k] / box[k] + 0.5)
            # the force on i pushes it away from j when repulsive: −F_n·n̂(i→j) > 0
            fn = -np.einsum("ij,ij->i", v[:, 6:9], d) / np.linalg.norm(d, axis=1)
        ft = np.linalg.norm(v[:, 3:6] - v[:, 6:9], axis=1)
    out = pd.DataFrame({"i": np.minimum(i, j), "j": np.maximum(i, j), "overlap": overlap, "fn": fn, "ft": ft})
    out = out[out["overlap"] > 0].drop_duplicates(subset=["i", "j"]).sort_values(["i", "j"])
    return out.reset_index(drop=True)


def run_engine(case: Case, engine: str, duration=None, dt=None, timeout: float = 3600.0, mpi: int = 1,
               cache=None) -> PackingRun:
    """Run the packing in an engine (``mpi`` ranks). ``cache`` (engines.cache.Cache) skips decks already
    run (keyed with the ranks too)."""
    import re

    from ..engines import discovery, dumps, run as runner
    from ..engines.cache import key as cache_key

    dk = (lammps_deck if engine == "lammps" else liggghts_deck)(case, duration, dt)
    k = None
    if cache is not None and discovery.find(engine) is not None:
        k = cache_key(engine, discovery.find(engine).version,
                      dk.text + f"\n# mpi {mpi}\n# contact reader {CONTACT_READER}", dk.files)
        hit = cache.get(k, columns=FINAL_COLUMNS, meta_keys=("version", "ke"))
        hit_contacts = cache.get(k + "-contacts", columns=CONTACT_COLUMNS)
        if hit is not None and hit_contacts is not None:
            table, meta = hit
            contacts = hit_contacts[0].astype({"i": np.int64, "j": np.int64})
            return PackingRun(table, contacts, [tuple(x) for x in meta["ke"]], meta["version"])
    out = runner.run(engine, dk.text, files=dk.files, timeout=timeout, mpi=mpi)
    table = dumps.read_dump(out.workdir / FINAL_DUMP, columns=FINAL_COLUMNS)
    table = table[table["step"] == table["step"].max()]
    ke = [(int(m.group(1)), float(m.group(2))) for m in re.finditer(r"^\s*(\d+)\s+(\S+)\s+\d+\s*$", out.log, re.M)]
    table = table.sort_values("id").reset_index(drop=True)
    # the data file numbers the particles 1…N and the table is sorted by id: row k is particle id k + 1
    contacts = read_contacts(engine, out.workdir / CONTACT_DUMP, table["radius"].to_numpy(),
                             table[["x", "y", "z"]].to_numpy(), (case.raw.get("packing") or {}).get("box"))
    from ..errors import EngineFailed

    bad = dumps.non_finite(table) or dumps.non_finite(contacts)
    if bad or not all(np.isfinite(e) for _, e in ke):
        raise EngineFailed(f"{engine} wrote NaN or infinite values ({bad or 'kinetic energy'}): the packing is not "
                           f"used and not cached; work directory kept: {out.workdir}")
    if k is not None:
        cache.put(k + "-contacts", contacts, {})
        cache.put(k, table, {"version": out.version, "ke": ke})
    return PackingRun(table, contacts, ke, out.version)
