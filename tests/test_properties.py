"""Properties of the normal laws, with hypothesis."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from demcheck.laws import normal
from demcheck.reference.collision import collide

from .helpers import glass_case

restitutions = st.floats(0.1, 0.95)
speeds = st.floats(0.05, 20.0)


@pytest.mark.parametrize("model_id", ["lsd", "tti", "kk", "bshp"])
@given(e=restitutions, v=speeds)
@settings(max_examples=15)
def test_limit_force_never_lowers_restitution(model_id, e, v):
    params = {"lsd": {"kn": 2e6}, "tti": {}, "kk": {"eta_n": 50.0}, "bshp": {"dissipative_constant": 3e-7}}[model_id]
    free = collide(glass_case(model_id, params, speed=v, restitution=e)).metrics()["restitution"]
    limited = collide(glass_case(model_id, {**params, "limit_force": True}, speed=v, restitution=e)).metrics()
    assert limited["restitution"] >= free - 1e-9


# the laws' own capability flags choose who must do what (a new law is tested without new test code); HLS
# with variable unloading is velocity-dependent through its parameters, not as a model
VELOCITY_DEPENDENT = [(m.id, m.example) for m in normal.REGISTRY.values() if m.velocity_dependent_restitution] + [
    ("hls", {"kl": 2e6, "unloading": "variable", "S": 500.0})]
SPEED_INDEPENDENT = [(m.id, m.example) for m in normal.REGISTRY.values()
                     if m.dissipative and not m.velocity_dependent_restitution]


@pytest.mark.parametrize("model_id,params", VELOCITY_DEPENDENT)
@given(v1=speeds, ratio=st.floats(1.5, 10.0))
@settings(max_examples=15)
def test_restitution_falls_as_impact_speed_rises(model_id, params, v1, ratio):
    e1 = collide(glass_case(model_id, params, speed=v1)).metrics()["restitution"]
    e2 = collide(glass_case(model_id, params, speed=min(v1 * ratio, 100.0))).metrics()["restitution"]
    assert e2 < e1


@pytest.mark.parametrize("model_id,params", SPEED_INDEPENDENT)
@given(e=restitutions, v1=speeds, v2=speeds)
@settings(max_examples=15)
def test_restitution_does_not_depend_on_speed(model_id, params, e, v1, v2):
    """LSD and constant-unloading HLS by construction; TTI because δ^{1/4}δ̇ scales exactly like Hertz.
    Restitution is a ratio of rates whose error the solver bounds relative to the impact rate, so it is
    held to 1e-9 absolute (a 1e-10 error is 1e-9 relative at ε = 0.1)."""
    r1 = collide(glass_case(model_id, params, speed=v1, restitution=e)).metrics()["restitution"]
    r2 = collide(glass_case(model_id, params, speed=v2, restitution=e)).metrics()["restitution"]
    assert r1 == pytest.approx(r2, abs=1e-9)


@given(e=restitutions, v=speeds)
@settings(max_examples=15)
def test_lsd_restitution_is_the_input(e, v):
    assert collide(glass_case("lsd", {"stiffness_method": "energy"}, speed=v, restitution=e)).metrics()[
        "restitution"] == pytest.approx(e, abs=1e-9)
