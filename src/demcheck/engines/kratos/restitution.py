"""Kratos' own COEFFICIENT_OF_RESTITUTION → DAMPING_GAMMA, read from Kratos (``demcheck audit`` of a project).

Kratos turns a material relation's restitution into its damping ratio γ in Python when it reads the materials
(``ExplicitStrategy.ModifySubProperties``: a bisection for 'Linear' laws, Thornton's fit for 'Hertz' laws). The
audit does not re-implement either: it lets Kratos initialise a relation with the user's law and restitution
in a process of the Python that has Kratos (the engine discovery found) and reads back DAMPING_GAMMA. The
process runs :data:`PROGRAM`, a fixed text; its input is a JSON list of [law, restitution] on stdin, each law
one of the twinned laws' names (checked here before anything starts) and each restitution a finite number.
"""

from __future__ import annotations

import functools
import json
import math
import subprocess

from ...errors import DemcheckError
from .mapping import LAWS

# Kratos' ModifySubProperties on a fresh Properties holding the relation's law and restitution (its strategy
# object is made without __init__, which needs a model: the method uses only the strategy's own methods, and a
# warning printer for properties it fills with defaults)
PROGRAM = r'''
import json, sys, types
import KratosMultiphysics as K
import KratosMultiphysics.DEMApplication as D
from KratosMultiphysics.DEMApplication.sphere_strategy import ExplicitStrategy
K.Logger.GetDefaultOutput().SetSeverity(K.Logger.Severity.WARNING)
strategy = ExplicitStrategy.__new__(ExplicitStrategy)
strategy.Procedures = types.SimpleNamespace(KratosPrintWarning=lambda *a: None, KratosPrintInfo=lambda *a: None)
out = []
for k, (law, e) in enumerate(json.load(sys.stdin)):
    p = K.Properties(k + 2)
    p.SetValue(D.DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME, law)
    p.SetValue(D.COEFFICIENT_OF_RESTITUTION, e)
    p.SetValue(D.ROLLING_FRICTION, 0.0)
    p.SetValue(D.DEM_ROLLING_FRICTION_MODEL_NAME, "DEMRollingFrictionModelBounded")
    strategy.ModifySubProperties(p, 1)
    out.append(p.GetValue(D.DAMPING_GAMMA))
print("DEMCHECK-GAMMA " + json.dumps(out))
'''
TIMEOUT = 300.0


def gammas(relations: list[tuple[str, float]]) -> list[float]:
    """Kratos' DAMPING_GAMMA for each (law, restitution). Raises DemcheckError when Kratos is not installed or
    its process fails (the message keeps its last lines)."""
    for law, e in relations:
        if law not in LAWS or not (isinstance(e, float) and math.isfinite(e)):
            raise ValueError(f"no γ read for {law!r} with restitution {e!r}")
    return list(_gammas(tuple(relations)))


@functools.lru_cache(maxsize=64)
def _gammas(relations: tuple) -> tuple:
    from .. import discovery

    info = discovery.find("kratos")
    if info is None:
        raise DemcheckError(f"Kratos' γ for the restitution cannot be read: {discovery.missing('kratos')}")
    try:
        run = subprocess.run([info.executable, "-c", PROGRAM], input=json.dumps([list(r) for r in relations]),
                             capture_output=True, text=True, timeout=TIMEOUT)
    except (OSError, subprocess.SubprocessError) as exc:
        raise DemcheckError(f"Kratos' γ for the restitution: the process did not run ({exc})") from None
    line = next((ln for ln in run.stdout.splitlines() if ln.startswith("DEMCHECK-GAMMA ")), None)
    if run.returncode != 0 or line is None:
        tail = " | ".join((run.stderr or run.stdout).strip().splitlines()[-4:])
        raise DemcheckError(f"Kratos' γ for the restitution: exit {run.returncode}: {tail[-400:]}")
    values = json.loads(line.split(" ", 1)[1])
    if len(values) != len(relations) or not all(isinstance(g, float) and math.isfinite(g) and g >= 0 for g in values):
        raise DemcheckError(f"Kratos' γ for the restitution: not a γ ≥ 0 for each relation: {values!r}")
    return tuple(values)
