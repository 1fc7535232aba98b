"""Case files: loading, overrides, effective properties and bad input."""

import math

import pytest

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference.contact import pair_of

BASE = """
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = 0.97

[[particles]]
material = "glass"
radius = 1e-3
position = [0.0, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]

[[particles]]
material = "glass"
radius = 2e-3
position = [3.5e-3, 0.0, 0.0]

[contact]
normal = "hertz"
"""


def test_effective_pair_properties_match_definitions():
    case = C.loads(BASE)
    p = pair_of(case)
    m1 = 2500 * 4 / 3 * math.pi * 1e-9
    m2 = 2500 * 4 / 3 * math.pi * 8e-9
    assert p.r_eff == pytest.approx(2e-3 / 3, rel=1e-15)
    assert p.m_eff == pytest.approx(m1 * m2 / (m1 + m2), rel=1e-15)
    assert p.e_eff == pytest.approx(71e9 / (2 * (1 - 0.22**2)), rel=1e-15)
    g = 71e9 / (2 * 1.22)
    assert p.g_eff == pytest.approx(g / (2 * (2 - 0.22)), rel=1e-15)  # Mindlin's (2 − ν), not (2 − ν²)
    assert p.impact_speed == pytest.approx(1.0, rel=1e-15)


def test_rigid_wall_has_infinite_partner():
    case = C.loads(BASE.replace("""[[particles]]
material = "glass"
radius = 2e-3
position = [3.5e-3, 0.0, 0.0]
""", """[[walls]]
point = [0.0, 0.0, -2e-3]
normal = [0.0, 0.0, 1.0]
"""))
    p = pair_of(case)
    assert p.wall and p.r_eff == 1e-3 and p.m_eff == pytest.approx(case.mass(0), rel=1e-15)
    assert p.e_eff == pytest.approx(71e9 / (1 - 0.22**2), rel=1e-15)


def test_impact_table_places_bodies_at_speed_and_angle():
    text = BASE.replace("[contact]", "[impact]\nspeed = 2.0\nangle = 30.0\n\n[contact]")
    case = C.loads(text)
    p = pair_of(case)
    assert p.impact_speed == pytest.approx(2.0 * math.cos(math.radians(30)), rel=1e-12)


def test_set_overrides_with_dotted_keys_and_indices():
    case = C.loads(BASE, ["contact.normal=lsd", "contact.kn=1e6", "particles.0.velocity=[2, 0, 0]",
                          "materials.glass.restitution=0.5"])
    assert case.contact.normal == "lsd" and case.contact.params["kn"] == 1e6
    assert case.particles[0].velocity == (2.0, 0.0, 0.0)
    assert case.materials["glass"].restitution == 0.5


def test_case_hash_changes_with_content_only():
    assert C.loads(BASE).hash == C.loads(BASE).hash
    assert C.loads(BASE).hash != C.loads(BASE, ["particles.0.velocity=[2,0,0]"]).hash


BAD = [
    (["materials.glass.restitution=1.5"], "materials.glass.restitution", "(0, 1]"),
    (["materials.glass.restitution=0"], "materials.glass.restitution", "(0, 1]"),
    (["materials.glass.poisson_ratio=0.5"], "materials.glass.poisson_ratio", "(-1, 0.5)"),
    (["materials.glass.poisson_ratio=-1"], "materials.glass.poisson_ratio", "(-1, 0.5)"),
    (["particles.0.radius=-1e-3"], "particles.0.radius", "> 0"),
    (["particles.0.radius=0"], "particles.0.radius", "> 0"),
    (["materials.glass.density=0"], "materials.glass.density", "> 0"),
    (["materials.glass.youngs_modulus=-5"], "materials.glass.youngs_modulus", "> 0"),
    (["particles.1.position=[2.5e-3, 0, 0]"], "particles.1.position", "overlap"),
    (["contact.normal=herz"], "contact.normal", "did you mean 'hertz'"),
    (["contact.normal=lsd"], "contact.stiffness_method", "duration, overlap, energy"),
    (["contact.normal=kk"], "contact.eta_n", "missing"),
    (["contact.normal=hls", "contact.kl=1e6", "contact.unloading=variable"], "contact.S", "missing"),
    (["contact.kn=1e6"], "contact.kn", "not a parameter"),
    (["particles.0.materal=glass"], "particles.0.materal", "did you mean 'material'"),
    (["run.dt=-1"], "run.dt", "> 0"),
    (["particles.0.velocity=[1, 0]"], "particles.0.velocity", "3 finite numbers"),
]


@pytest.mark.parametrize("overrides,key,rule", BAD)
def test_bad_input_names_key_value_and_rule(overrides, key, rule):
    with pytest.raises(ConfigError) as info:
        C.loads(BASE, overrides)
    assert info.value.key == key
    assert rule in str(info.value)
    assert "\n" not in str(info.value)
    assert info.value.exit_code == 2


def test_bad_override_syntax():
    with pytest.raises(ConfigError, match="KEY=VALUE"):
        C.loads(BASE, ["contact.normal"])
