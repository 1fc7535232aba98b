"""What both collision solvers (1-D and 3-D) share: the statuses of a run and their messages, the bound on a
verlet record, the free-flight time, dt = auto, and the health judgement of a finished run."""

from __future__ import annotations

import numpy as np

from ..case import Case, free_flight
from ..errors import ConfigError
from ..result import Result
from . import health, kernels
from ..laws.model import ResolvedModel, characteristic_time, resolve

STATUS = {
    kernels.ST_OK: "ok",
    kernels.ST_TOLERANCE: "tolerance",
    kernels.ST_STEPS: "too-many-steps",
    kernels.ST_NO_CONTACT: "no-contact",
    kernels.ST_NO_SEPARATION: "no-separation",
    kernels.ST_UNRESOLVED: "unresolved",
}
MESSAGES = {
    "tolerance": "the adaptive method could not meet its tolerance (step size underflow)",
    "too-many-steps": "the solver ran out of room for output points",
    "no-contact": "the bodies never touched",
    "no-separation": "the contact did not end within the time limit",
    "unresolved": "the time step does not resolve the contact: the state became NaN or infinite",
}
# A verlet run records every step; the record, the tables built from it and the metrics take this many bytes
# a step at most (peak resident memory over recorded steps, measured for a pair: 536 B in 1-D, 810 B in
# 3-D; a wall takes less), and a run may take RECORD_BUDGET.
RECORD_BUDGET = 1 << 30
ROW_BYTES_1D, ROW_BYTES_3D = 600, 900


def time_to_contact(case: Case) -> float:
    """The free flight until the surfaces first touch (for bodies that never touch, until their closest
    approach): case.free_flight's time."""
    return free_flight(case)[0]


def verlet_capacity(case: Case, dt: float, dt_given: bool, t_free: float, t_c: float, t_max: float,
                    row_bytes: int) -> int:
    """Rows to give a verlet run: the whole run's steps, bounded by RECORD_BUDGET. A run that cannot record
    its free flight and one contact time within the budget is refused before anything is allocated, naming
    the speed (a long free flight) or the step: --dt when ``dt_given`` (an argument), else run.dt or, for
    the auto dt, run.steps_per_contact."""
    limit = RECORD_BUDGET // row_bytes
    free, contact = t_free / dt, t_c / dt
    if free + contact > limit:
        cap = (f"a verlet run records every step, at most {limit:.3g} ({RECORD_BUDGET / 2**30:g} GiB)")
        if free >= contact:
            raise ConfigError("impact.speed", case_speed(case),
                              f"the free flight to contact takes {free:.3g} time steps of {dt:.3g} s; {cap}: "
                              "raise the speed, shorten impact.gap, or use the adaptive method")
        if dt_given or case.run.dt:
            raise ConfigError("--dt" if dt_given else "run.dt", dt, f"{contact:.3g} steps per elastic contact time "
                              f"of {t_c:.3g} s; {cap}: use a larger time step, or the adaptive method")
        raise ConfigError("run.steps_per_contact", case.run.steps_per_contact, f"{cap}: use fewer steps per "
                          "contact, or the adaptive method")
    return int(min(t_max / dt + 4, limit))


def case_speed(case: Case) -> float:
    """The bodies' relative speed at the start (``impact.speed`` of an impact case)."""
    v = np.asarray(case.particles[0].velocity, float)
    if not case.walls:
        v = v - np.asarray(case.particles[1].velocity, float)
    return float(np.linalg.norm(v))


def auto_dt(case: Case, model: ResolvedModel | None = None, t_c: float | None = None) -> float:
    """dt = contact time / steps_per_contact (the elastic contact time of the law at the impact speed; ``t_c``:
    that time, when the caller has it)."""
    if t_c is None:
        t_c = characteristic_time(model or resolve(case))
    return t_c / case.run.steps_per_contact


def judge(result: Result, case: Case, model: ResolvedModel) -> Result:
    """The reference's status from its run and the shared rules (reference/health.py): a verlet run goes
    through every rule (the run's own status stands where the rules find nothing, and when the record ran
    out); the adaptive method's converged answer through the overlap rule."""
    if result.method == "verlet":
        if result.status != "too-many-steps":
            health.apply(result, case, model)
    elif result.status in ("ok", "no-separation"):
        out = health.overlap_rule(float(np.max(result.table("contact")["delta"])), health.smallest_radius(case))
        if out is not None:
            result.status, result.message = out
    return result
