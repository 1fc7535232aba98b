"""A packing in an engine: its deck (the engine's package writes it from the shared layout of
inputs/packing_decks), the run, and the engine's record of it (engines.output.PackingOutput: the final state, the
contacts, the kinetic energy, read by the engine itself), as the tables every source yields."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..case import Case
from ..inputs.packing_decks import CONTACT_READER, FINAL_DUMP
from . import dumps, registry
from .cache import ke_series, text
from .output import CONTACT_COLUMNS, FINAL_COLUMNS

__all__ = ["PackingRun", "run_engine", "universe", "CONTACT_COLUMNS"]


@dataclass
class PackingRun:
    """An engine's settled packing: the final per-particle table (FINAL_COLUMNS), its particle-particle
    contacts (CONTACT_COLUMNS), the kinetic energy series [(step, ke)] and the engine's version; ``cached``: read
    from the run cache, not run."""

    table: pd.DataFrame
    contacts: pd.DataFrame
    ke: list
    version: str
    cached: bool = False


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
            return PackingRun(table, contacts, [tuple(x) for x in meta["ke"]], meta["version"], cached=True)
    out = runner.run(engine, dk.text, files=dk.files, timeout=timeout, mpi=mpi, workdir=workdir)
    record = registry.get(engine).read_packing(out.workdir, out.log, case.packing.box if case.packing else None)
    table, contacts, ke = record.final, record.contacts, record.ke
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
