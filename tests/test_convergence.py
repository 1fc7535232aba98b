"""Order of convergence of the verlet method (the engines' scheme) to the converged answer.

Measured on contact_time, which the series resolve smoothly (restitution and sampled maxima carry a
bounded, phase-dependent O(dt) term from where the contact starts inside a step). Elastic Hertz and the
hysteretic spring (no velocity dependence) converge at order 2. Every law with a dashpot converges at
order 1: the force is evaluated with the half-step velocity, an O(dt) lag of the damping force; LSD adds
a force jump at contact start and end, which is O(dt) too. See docs/models.md ("Convergence of the
engines' scheme") and benchmarks/.
"""

import numpy as np
import pytest

from demcheck.reference.collision import auto_dt, collide

from .helpers import glass_case

CASES = [
    ("hertz", {}, 0.97, 2.0),
    ("hls", {"stiffness_method": "overlap"}, 0.5, 2.0),
    ("lsd", {"stiffness_method": "energy"}, 0.5, 1.0),
    ("tti", {}, 0.5, 1.0),
    ("kk", {"eta_n": 300.0}, 0.5, 1.0),
    ("bshp", {"dissipative_constant": 3e-7}, 0.5, 1.0),
]


@pytest.mark.parametrize("model_id,params,e,order", CASES)
def test_verlet_order(model_id, params, e, order):
    case = glass_case(model_id, params, restitution=e)
    exact = collide(case).metrics()["contact_time"]
    t_c = auto_dt(case) * case.run.steps_per_contact
    spcs = np.array([400, 800, 1600, 3200])
    errors = [abs(collide(case, "verlet", dt=t_c / s).metrics()["contact_time"] / exact - 1) for s in spcs]
    fitted = -np.polyfit(np.log(spcs), np.log(errors), 1)[0]
    assert fitted == pytest.approx(order, abs=0.15), errors
