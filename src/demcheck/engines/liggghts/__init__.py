"""LIGGGHTS-PUBLIC 3.8.0 (Debian's package): ``pair_style gran`` and ``fix wall/gran … primitive``."""

from __future__ import annotations

import math
import os
import re
import shutil
import sys
from pathlib import Path

import numpy as np

from .. import registry
from ..base import Native, Style
from ..family import LammpsFamily


MIN_RESTITUTION = 0.05  # LIGGGHTS refuses a coefficientRestitution e <= 0.05


class Liggghts(LammpsFamily):
    name = "liggghts"
    title = "LIGGGHTS"
    release = "LIGGGHTS 3.8.0"
    how_to_install = "apt-get install liggghts openmpi-bin (Debian), or `make engines` in a clone of demcheck"
    banner = re.compile(r"LIGGGHTS \(Version (LIGGGHTS-PUBLIC [^,)]+)", re.M)
    # slip velocity and torques at the contact point; the history is projected into the new tangent plane
    rules = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact", "rotation": "project"}
    style = Style(colour="#d62728", marker="v", linestyle="-.")

    def executables(self) -> tuple[str, ...]:
        return ("liggghts",)

    def argv(self, executable: str, deck: str) -> list[str]:
        return [*super().argv(executable, deck), "-echo", "none"]

    def worker_argv(self, executable: str) -> list[str] | None:
        """The worker (worker.py) loading the LIGGGHTS library ``executable`` itself loads (Debian's
        ``libliggghts.so.3``); None for a build that loads none (a static build: a process per run)."""
        from . import worker

        path = worker.library(executable)
        return None if path is None else [sys.executable, "-m", worker.MODULE, "--library", path]

    def mpi_launcher(self, executable: str, ranks: int) -> list[str]:
        """Debian's mpirun (Open MPI, which Debian's LIGGGHTS is built with), not the mpich wheel's."""
        from ...errors import EngineNotFound

        launcher = next((c for c in ("/usr/bin/mpirun.openmpi", "/usr/bin/mpirun", shutil.which("orterun"))
                         if c and Path(c).exists()), None)
        if not launcher:
            raise EngineNotFound("no mpirun for LIGGGHTS (Debian: apt-get install openmpi-bin)")
        extra = ["--allow-run-as-root"] if os.geteuid() == 0 else []
        return [launcher, *extra, "--oversubscribe", "-np", str(ranks)]

    def summary(self, native: Native) -> str:
        parts = [f"model {native.normal}", f"tangential {native.tangential}"]
        if native.tangential == "history" and not native.tangential_damping:
            parts.append("tangential_damping off")
        if native.limit:
            parts.append("limitForce on")
        return " ".join(parts)

    def native_from_case(self, table: dict, case) -> Native:
        """``[engine.liggghts]`` of a case file, read by the deck reader (audit.native_from_case)."""
        return self._part("audit").native_from_case(table, case)

    def knob(self, native: Native, metric: str):
        """restitution: coefficientRestitution (hertz, hooke; in (0, 1]) or gamman (the stiffness models)."""
        from dataclasses import replace

        from ..base import Knob

        if metric != "restitution":
            return None
        if native.normal in ("hertz", "hooke"):  # LIGGGHTS takes 0.05 < e <= 1 (native_limits)
            return Knob("coefficientRestitution", math.nextafter(MIN_RESTITUTION, 1.0), 1.0,
                        native.props.get("restitution", 0.5),
                        lambda x: replace(native, props={**native.props, "restitution": x}))
        if native.normal in ("hooke/stiffness", "hertz/stiffness"):
            return Knob("gamman", 0.0, None, native.props.get("gamman") or 1.0,
                        lambda x: replace(native, props={**native.props, "gamman": x}))
        return None

    def native_limits(self, native: Native) -> list[tuple[str, object, str]]:
        """LIGGGHTS stops on a coefficientRestitution outside 0.05 < e <= 1 (global_properties.cpp)."""
        e = native.props.get("restitution")
        if native.normal in ("hertz", "hooke") and e is not None and not MIN_RESTITUTION < e <= 1.0:
            return [("coefficientRestitution", e, f"must be in ({MIN_RESTITUTION:g}, 1]")]
        return []

    def native_lines(self, native: Native) -> list[str]:
        from .deck import NAMES, fmt

        lines = [f"pair_style gran {self.summary(native)}"]
        for key in ("restitution", "friction", "kn", "kt", "gamman", "gammat"):
            if key in native.props and (native.props[key] or key in ("restitution", "friction")):
                lines.append(f"fix m_{key} all property/global {NAMES[key]} peratomtypepair 1 "
                             f"{fmt(native.props[key])}")
        return lines

    def read_contacts(self, v, i, j, radius, x=None, box=None):
        """``compute pair/gran/local id force force_normal delta``: id1 id2 periodic-flag, the force on the
        first (3), its normal part (3), the overlap. Fn is signed from the positions ``x`` (minimum image in
        the periodic ``box``), repulsive > 0 as LAMMPS writes it; its magnitude without positions."""
        overlap = v[:, 9]
        fn = np.linalg.norm(v[:, 6:9], axis=1)
        if x is not None and len(v):
            d = x[j] - x[i]
            for k in range(2 if box is not None else 0):
                d[:, k] -= box[k] * np.floor(d[:, k] / box[k] + 0.5)
            # the force on i pushes it away from j when repulsive: −F_n·n̂(i→j) > 0
            fn = -np.einsum("ij,ij->i", v[:, 6:9], d) / np.linalg.norm(d, axis=1)
        ft = np.linalg.norm(v[:, 3:6] - v[:, 6:9], axis=1)
        return overlap, fn, ft


registry.register(Liggghts())
