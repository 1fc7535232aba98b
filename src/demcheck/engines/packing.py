"""A packing in an engine: its deck (the engine's package writes it from the shared layout of
inputs/packing_decks), the run, the final state and the engine's own per-contact output, read back into the
tables every source yields."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..case import Case
from ..inputs.packing_decks import CONTACT_COLUMNS, CONTACT_DUMP, CONTACT_READER, FINAL_COLUMNS, FINAL_DUMP
from . import dumps, registry
from .cache import ke_series, text

__all__ = ["PackingRun", "read_contacts", "run_engine", "universe", "CONTACT_COLUMNS"]


@dataclass
class PackingRun:
    """An engine's settled packing: the final per-particle table (FINAL_COLUMNS), its particle-particle
    contacts (CONTACT_COLUMNS), the kinetic energy series [(step, ke)] and the engine's version."""

    table: pd.DataFrame
    contacts: pd.DataFrame
    ke: list
    version: str


def read_contacts(engine: str, path, radius: np.ndarray, x: np.ndarray | None = None, box=None) -> pd.DataFrame:
    """The engine's per-contact dump (its last block) as CONTACT_COLUMNS: touching pairs only (overlap > 0),
    each once (with newton off a pair across a periodic or processor boundary may be listed from both
    sides). ``radius`` (and ``x``): per particle, indexed by id − 1; ``box``: the periodic [lx, ly]. The
    engine's package turns its own columns into (i, j, overlap, fn, ft) (:meth:`Engine.read_contacts`)."""
    raw = dumps.read_dump(path)
    raw = raw[raw["step"] == raw["step"].max()] if len(raw) else raw
    v = raw.drop(columns="step").to_numpy(float)
    i, j = v[:, 0].astype(np.int64) - 1, v[:, 1].astype(np.int64) - 1
    overlap, fn, ft = registry.get(engine).read_contacts(v, i, j, radius, x, box)
    out = pd.DataFrame({"i": np.minimum(i, j), "j": np.maximum(i, j), "overlap": overlap, "fn": fn, "ft": ft})
    out = out[out["overlap"] > 0].drop_duplicates(subset=["i", "j"]).sort_values(["i", "j"])
    return out.reset_index(drop=True)


def run_engine(case: Case, engine: str, duration=None, dt=None, timeout: float = 3600.0, mpi: int = 1,
               cache=None, workdir=None) -> PackingRun:
    """Run the packing in an engine (``mpi`` ranks). ``cache`` (engines.cache.Cache) skips decks already
    run (keyed with the ranks too). ``workdir``: run there and keep it (the deck, its data file, the dumps — for
    :func:`universe`); by default a temporary directory, removed once read (kept when the run fails)."""
    from . import discovery, run as runner
    from .cache import key as cache_key

    dk = registry.get(engine).packing_deck(case, duration, dt)
    k = None
    info = discovery.find(engine) if cache is not None else None
    if info is not None:
        k = cache_key(engine, info.version,
                      dk.text + f"\n# mpi {mpi}\n# contact reader {CONTACT_READER}", dk.files)
        hit = cache.get(k, columns=FINAL_COLUMNS, meta_keys={"version": text, "ke": ke_series}, min_rows=1)
        hit_contacts = cache.get(k + "-contacts", columns=CONTACT_COLUMNS)
        if hit is not None and hit_contacts is not None:
            table, meta = hit
            contacts = hit_contacts[0].astype({"i": np.int64, "j": np.int64})
            return PackingRun(table, contacts, [tuple(x) for x in meta["ke"]], meta["version"])
    out = runner.run(engine, dk.text, files=dk.files, timeout=timeout, mpi=mpi, workdir=workdir)
    table, ke = registry.get(engine).read_packing(out.workdir, out.log)
    # the data file numbers the particles 1…N and the table is sorted by id: row k is particle id k + 1
    contacts = read_contacts(engine, out.workdir / CONTACT_DUMP, table["radius"].to_numpy(),
                             table[["x", "y", "z"]].to_numpy(), case.packing.box if case.packing else None)
    from ..errors import EngineFailed

    bad = dumps.non_finite(table) or dumps.non_finite(contacts)
    if bad or not all(np.isfinite(e) for _, e in ke):
        kept = ", ".join(runner.keep_for_diagnosis(out.workdir))  # within its bound, as a failed run's
        raise EngineFailed(f"{engine} wrote NaN or infinite values ({bad or 'kinetic energy'}): the packing is not "
                           f"used and not cached; work directory kept: {out.workdir} ({kept})")
    if k is not None:
        cache.put(k + "-contacts", contacts, {})
        cache.put(k, table, {"version": out.version, "ke": ke})
    if workdir is None and out.workdir.name.startswith(f"demcheck-{engine}-"):
        import shutil

        shutil.rmtree(out.workdir, ignore_errors=True)  # a temporary directory of a run that succeeded, read
    return PackingRun(table, contacts, ke, out.version)


def universe(path, dt: float = 1.0):
    """An engine's packing as an MDAnalysis Universe, for one's own analysis: ``path`` is a run directory (a
    deck written by ``demcheck deck`` and run by hand, or ``run_engine``'s ``workdir``: its final dump,
    FINAL_DUMP) or a LAMMPS-style ``dump custom`` file with x, y, z (every frame of a trajectory). Positions,
    velocities and forces are MDAnalysis's float32, in the engines' frame (MDAnalysis moves them to the box's
    lower corner; they are moved back); per atom ``radii`` and, where dumped, ``masses``; ``ts.data`` holds the
    radius and mass columns of each frame; a frame's ``time`` is its step × ``dt`` (give the packing's time step
    for seconds: MDAnalysis labels them ps). Float32 keeps a position to |x|·2^-24 (1.8e-9 m at 30 mm), and
    where the box's lower corner lo is not 0 (z), moved there and back, to 2^-24(2|x| + |x − lo| + |lo|):
    enough for the particle tables, profiles, bed height and the fabric of a packing, not for overlaps, which
    are ~1e-3 of the coordinates (docs/packing.md, measured); demcheck's own metrics read the float64 dump.
    The translation is the first frame's lo (the packing decks' boxes do not move)."""
    import warnings

    import MDAnalysis as mda
    from MDAnalysis import transformations

    p = Path(path)
    p = p / FINAL_DUMP if p.is_dir() else p
    lo = _box_lo(p)
    with warnings.catch_warnings():  # its guess of the masses is replaced below, and said when unknown
        warnings.filterwarnings("ignore", message="Guessed all Masses")
        warnings.filterwarnings("ignore", message="Some of the additional columns are not present")
        u = mda.Universe(str(p), format="LAMMPSDUMP", lammps_coordinate_convention="unscaled",
                         additional_columns=["radius", "mass"], dt=dt)
    data = u.trajectory.ts.data
    if "radius" in data:
        u.add_TopologyAttr("radii", np.asarray(data["radius"], float))
    # without a mass column MDAnalysis would guess masses from atom names (1.0 for these): say "unknown" instead
    u.atoms.masses = np.asarray(data["mass"], float) if "mass" in data else np.full(len(u.atoms), np.nan)
    if np.any(lo != 0.0):
        u.trajectory.add_transformations(transformations.translate(lo))
    return u


def _box_lo(path) -> np.ndarray:
    """The lower corner of a dump's box (its first frame's BOX BOUNDS), where MDAnalysis puts the origin."""
    from ..errors import ParseError

    if not Path(path).is_file():
        raise ParseError(f"{path}: no such dump file")
    with dumps._open(Path(path)) as fh:
        for line in fh:
            if line.startswith("ITEM: BOX BOUNDS"):
                try:
                    return np.array([float(next(fh).split()[0]) for _ in range(3)])
                except (StopIteration, ValueError, IndexError):
                    break
    raise ParseError(f"{path}: no ITEM: BOX BOUNDS with three bounds lines")
