"""Result: what any source (the reference, LAMMPS, LIGGGHTS) returns for a case.

Tidy pandas tables in SI units plus metadata:

* ``contact``: one row per output time of the contact of interest:
  t, delta (overlap, > 0 in contact), delta_dot (approach rate of the contact points along the normal),
  fn (normal force on the pair, + repulsive); 3-D runs add tangential columns.
* ``particles``: t, id, x, y, z, vx, vy, vz, wx, wy, wz (and fx.. when the source has them).
* ``events``: exact event points of the adaptive method (t, event, delta, delta_dot, fn), else empty.

``status`` (with the reason in ``message``; only "ok" is trusted):

* ``ok``;
* ``failed``: NaN or infinite values in the state or in an engine's output (never cached);
* ``unresolved``: the time step does not resolve the contact (too few steps inside it); the message names
  dt and the steps per elastic contact time;
* ``unstable``: a time-stepped run created energy (the scheme is unstable at its step);
* ``out-of-range``: the overlap passed half the smaller radius, in any method: the contact law left its
  range of small overlaps (too fast an impact, too soft a material);
* ``no-contact``: the bodies never touched; ``no-separation``: the contact did not end within the run;
* ``tolerance``: the adaptive method could not meet its tolerance; ``too-many-steps``: the solver ran out
  of room for output points.

The rules are reference/health.py's, the same for the reference's verlet method and every engine.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pandas as pd


@dataclass
class Result:
    source: str  # reference | lammps | liggghts
    method: str  # adaptive | verlet | engine
    case_name: str
    case_hash: str
    model: dict
    params: dict
    contact: pd.DataFrame
    particles: pd.DataFrame | None = None
    events: pd.DataFrame | None = None
    dt: float | None = None
    rtol: float | None = None
    wall_time: float = 0.0
    engine_version: str | None = None
    status: str = "ok"  # see the module docstring
    message: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def metrics(self) -> dict:
        """The metrics (computed once per contact table: a pure function of it)."""
        from .metrics import compute

        memo = self.__dict__.get("_metrics_memo")
        if memo is None or memo[0] is not self.contact or memo[1] is not self.events:
            memo = (self.contact, self.events, compute(self))
            self.__dict__["_metrics_memo"] = memo
        return dict(memo[2])

    def summary(self) -> dict:
        """JSON-ready: metrics under their DESIGN names, the model, the resolved parameters, method, dt."""
        return {
            "source": self.source,
            "method": self.method,
            "case": self.case_name,
            "case_hash": self.case_hash,
            "model": self.model,
            "params": self.params,
            "dt": self.dt,
            "rtol": self.rtol,
            "engine_version": self.engine_version,
            "status": self.status,
            "message": self.message,
            "wall_time": self.wall_time,
            "metrics": self.metrics(),
            "final": self.final_state(),
        }

    def final_state(self) -> list[dict]:
        """Every body's velocity and angular velocity (vectors, SI) at the end of the run, whatever solved it
        (a law that was skipped — no tangential force can act — passes the initial spins through)."""
        p = self.particles
        if p is None or p.empty or not {"vx", "wx"} <= set(p.columns):
            return []
        out = []
        for pid, rows in p.groupby("id", sort=True):
            last = rows.sort_values("t").iloc[-1]
            out.append({"id": int(pid), "t": float(last["t"]),
                        "velocity": [float(last[c]) for c in ("vx", "vy", "vz")],
                        "angular_velocity": [float(last[c]) for c in ("wx", "wy", "wz")]})
        return out
