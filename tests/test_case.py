"""Case files: loading, overrides, effective properties and bad input."""

import math

import pytest

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.laws.contact import pair_of

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
    (["run.verlet_rtol=0"], "run.verlet_rtol", "in (0, 1]"),
    (["run.verlet_rtol=\"tight\""], "run.verlet_rtol", "finite number"),
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


# ----------------------------------------------------------------------------- names and free text


@pytest.mark.parametrize("value", [5, 1.5, True, ["a"], {"a": 1}, "", "a\nb", "a#b", "a$b", "a&", "a'b", 'a"b',
                                   "a\\b", "a\tb", "x" * 1000])
def test_name_is_a_one_line_string_of_plain_characters(value):
    raw = C.tomllib.loads(BASE)
    raw["name"] = value
    with pytest.raises(ConfigError) as info:
        C.from_dict(raw)
    assert info.value.key == "name" and "\n" not in str(info.value) and info.value.exit_code == 2


def test_description_is_a_string():
    with pytest.raises(ConfigError) as info:
        C.loads('description = 5\n' + BASE)
    assert info.value.key == "description"
    assert C.loads('description = """Two spheres.\nHead on."""\n' + BASE).name == "case"


# ----------------------------------------------------------------------------- keys accepted and ignored


PACKING = """
name = "p"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.3
[packing]
layout = "poured"
count = 20
material = "glass"
radius = 1e-3
box = [0.01, 0.01]
duration = 0.01
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
normal = "lsd"
kn = 500.0
[run]
gravity = [0.0, 0.0, -9.81]
"""


@pytest.mark.parametrize("value", ["0.05", '"tall"', "[1, 2]"])
def test_packing_height_is_a_table_not_a_value(value):
    """[packing.height] is a heap's height measure (axis, offset, every, start: tests/test_sandpile.py); a number,
    a word or a list there is refused in one line."""
    with pytest.raises(ConfigError) as info:
        C.loads(PACKING.replace("duration = 0.01", f"duration = 0.01\nheight = {value}"))
    assert info.value.key == "packing.height" and "must be a table" in info.value.rule
    assert "\n" not in str(info.value)


def test_a_misspelt_packing_key_gets_a_suggestion():
    with pytest.raises(ConfigError) as info:
        C.loads(PACKING.replace("duration = 0.01", "duraton = 0.01"))
    assert info.value.key == "packing.duraton" and "did you mean 'duration'" in info.value.rule


# ----------------------------------------------------------------------------- bad values, one line each


def test_a_case_file_that_is_not_utf8_is_one_line(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes(("# Gl\u00e4ser\n" + BASE).encode("latin-1"))
    with pytest.raises(ConfigError) as info:
        C.load(path)
    assert str(path) in str(info.value) and "UTF-8" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("box", ["[nan, 0.01]", "[0.01, inf]", "[-inf, 0.01]", "[true, 0.01]", "[0.01]",
                                 '["a", 0.01]'])
def test_packing_box_must_be_two_finite_lengths(box):
    with pytest.raises(ConfigError) as info:
        C.loads(PACKING.replace("box = [0.01, 0.01]", f"box = {box}"))
    assert info.value.key == "packing.box" and "\n" not in str(info.value)


@pytest.mark.parametrize("overrides,key", [
    (["materials.glass.density=1e-300"], "materials.glass.density"),
    (["materials.glass.density=1e-200"], "materials.glass.density"),
    (["materials.glass.density=1e300"], "materials.glass.density"),
    (["particles.0.radius=1e-120", "particles.0.position=[-1e-3, 0, 0]"], "particles.0.radius"),
])
def test_a_mass_outside_the_representable_range_is_refused(overrides, key):
    """m̄ = m₁m₂/(m₁+m₂) underflows to 0 for masses below ~1e-154 kg (density 1e-300 gave a division by zero
    in the solver): such a case is refused up front, naming the key that made the mass."""
    with pytest.raises(ConfigError) as info:
        C.loads(BASE, overrides)
    assert info.value.key == key and "\n" not in str(info.value) and "mass" in info.value.rule


def test_small_real_particles_are_accepted():
    """A 1 µm sphere of an aerogel (density 1 kg/m³): 4e-18 kg."""
    case = C.loads(BASE, ["materials.glass.density=1.0", "particles.0.radius=1e-6", "particles.1.radius=1e-6",
                          "particles.1.position=[3e-6, 0, 0]"])
    assert case.mass(0) == pytest.approx(4 / 3 * math.pi * 1e-18, rel=1e-12)


def test_a_density_of_1e_300_is_refused_by_the_command_line(tmp_path):
    import subprocess
    import sys

    from .conftest import CASES

    for args in (["collide"], ["collide", "--method", "verlet"], ["deck", "--engine", "lammps"]):
        p = subprocess.run([sys.executable, "-m", "demcheck", args[0], str(CASES / "glass-pair.toml"), *args[1:],
                            "--set", "materials.glass.density=1e-300"], capture_output=True, text=True, timeout=120)
        assert p.returncode == 2, p.stderr[-1000:]
        assert p.stderr.count("\n") == 1 and "materials.glass.density" in p.stderr


def test_a_packing_count_the_machine_cannot_hold_is_refused_before_allocating():
    import time
    import tracemalloc

    tracemalloc.start()
    started = time.perf_counter()
    with pytest.raises(ConfigError) as info:
        C.loads(PACKING.replace("count = 20", "count = 1_000_000_000_000"))
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert info.value.key == "packing.count" and "memory" in info.value.rule
    assert peak < 50e6 and time.perf_counter() - started < 5.0
    assert len(C.loads(PACKING.replace("count = 20", "count = 2000")).particles) == 2000


# ----------------------------------------------------------------------------- free flight and run length


def _hertz_duration(case):
    """Hertz's elastic contact duration 2.868 (m̄²/(R̄ Ē² v))^(1/5) of the pair, from the case's own
    numbers (Ē: the pair's plane-strain modulus)."""
    p = pair_of(case)
    return 2.868 * (p.m_eff**2 / (p.r_eff * p.e_eff**2 * p.impact_speed)) ** 0.2


def _time_to_contact(case):
    """First touch of the bodies in free flight without gravity, solved here from the positions."""
    import numpy as np

    p0 = case.particles[0]
    x, v = np.asarray(p0.position), np.asarray(p0.velocity)
    if case.walls:
        w = case.walls[0]
        n = np.asarray(w.normal)
        return ((x - np.asarray(w.point)) @ n - p0.radius) / -(v @ n)
    p1 = case.particles[1]
    d, u = np.asarray(p1.position) - x, np.asarray(p1.velocity) - v
    a, b, c = u @ u, 2 * d @ u, d @ d - (p0.radius + p1.radius) ** 2
    return (-b - math.sqrt(b * b - 4 * a * c)) / (2 * a)


@pytest.mark.parametrize("wall", [False, True])
@pytest.mark.parametrize("normal", ["hertz", "lsd"])
def test_a_tiny_impact_speed_starts_the_bodies_near_contact(wall, normal):
    """At 1e-9 m/s the default gap (1e-3 R) took 1.6e3 s to cross: 265 million steps of free flight in the
    LAMMPS deck. Without gravity the motion is linear, so the bodies start where they are a few contact
    times before touching."""
    from .helpers import glass_case

    case = glass_case(normal, {"stiffness_method": "energy"} if normal == "lsd" else None, wall=wall, speed=1e-9)
    assert pair_of(case).impact_speed == pytest.approx(1e-9, rel=1e-6)
    flight = _time_to_contact(case)
    assert 0 < flight <= 50 * _hertz_duration(case)
    from demcheck.engines import registry

    for writer in (registry.get("lammps").collision_deck, registry.get("liggghts").collision_deck):
        steps = int(next(line.split()[1] for line in writer(case).text.splitlines() if line.startswith("run ")))
        assert steps <= 100 * case.run.steps_per_contact


def test_moving_the_bodies_along_their_velocities_changes_nothing():
    """A pair started 1 m apart at 1 m/s collides as the same pair started 1e-3 R apart."""
    from demcheck.reference.collision import collide

    from .conftest import CASES

    near = C.load(CASES / "glass-pair.toml")
    far = C.load(CASES / "glass-pair.toml", ["impact.gap=1.0"])
    assert _time_to_contact(far) <= 50 * _hertz_duration(far)
    a, b = collide(near).metrics(), collide(far).metrics()
    for k in ("restitution", "peak_force", "contact_time", "max_overlap"):
        assert b[k] == pytest.approx(a[k], rel=1e-9), k


def test_with_gravity_the_bodies_start_where_the_impact_puts_them():
    from .helpers import glass_case

    case = glass_case("hertz", wall=True, speed=1e-3, overrides=["run.gravity=[0, 0, -9.81]"])
    p, w = case.particles[0], case.walls[0]
    gap = p.position[2] - w.point[2] - p.radius
    assert gap == pytest.approx(1e-3 * p.radius, rel=1e-9)


@pytest.mark.parametrize("overrides,key", [(["run.dt=1e-16"], "run.dt"),
                                           (["run.steps_per_contact=100000000"], "run.steps_per_contact"),
                                           (["impact.gap=10.0", "run.gravity=[0, 0, -9.81]"], "impact.gap")])
def test_a_run_too_long_to_write_is_refused(overrides, key):
    from .helpers import glass_case

    with pytest.raises(ConfigError) as info:
        glass_case("hertz", wall=True, overrides=overrides)
    assert info.value.key == key and "steps" in info.value.rule and "\n" not in str(info.value)


def test_a_deck_dt_too_small_for_the_run_is_refused():
    from demcheck.engines import registry

    from .helpers import glass_case

    with pytest.raises(ConfigError) as info:
        registry.get("lammps").collision_deck(glass_case("hertz"), dt=1e-16)
    assert info.value.key == "--dt" and "steps" in info.value.rule


# ----------------------------------------------------------------------------- tilted walls


TILTED = """
name = "tilted"
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = 0.9
[[particles]]
material = "glass"
radius = 1.59e-3
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.6, 0.8]
[impact]
speed = 1.0
[contact]
normal = "hertz"
"""


@pytest.mark.parametrize("engine", ["lammps", "liggghts"])
def test_a_tilted_wall_is_not_expressible_in_an_engine(engine):
    from demcheck.engines import mapping

    mp = mapping.contact_mapping(C.loads(TILTED), engine)
    assert mp.native is None and mp.fidelity == "none"
    assert any("walls.0.normal" in r and "axis" in r for r in mp.reasons)


def test_verify_reports_a_tilted_wall_as_not_expressible(tmp_path):
    import json
    import subprocess
    import sys

    path = tmp_path / "tilted.toml"
    path.write_text(TILTED)
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(path), "--engines", "lammps,liggghts",
                        "--report", str(tmp_path / "reports"), "--json"], capture_output=True, text=True,
                       cwd=tmp_path, timeout=600)
    out = json.loads(p.stdout)
    sources = out["cases"][0]["sources"]
    for engine in ("lammps", "liggghts"):
        assert sources[engine]["status"] == "not expressible", sources[engine]
        assert "walls.0.normal" in sources[engine]["message"]
    assert p.returncode == 0, p.stderr[-2000:]


def test_a_bad_variant_says_which_one(tmp_path):
    from .conftest import CASES

    path = tmp_path / "v.toml"
    path.write_text((CASES / "glass-pair.toml").read_text() + '\n[variants]\n"impact.speed" = [1.0, -2.0]\n'
                    '"impact.angle" = [0.0, 30.0]\n')
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    assert info.value.key == "impact.speed" and info.value.variant == "speed=-2,angle=0"


ZIPPED = """
[variants]
"impact.speed" = [1.0, 2.0]

[variants.spin]
labels = ["low", "high"]
"impact.spin" = [1.0, 10.0]
"particles.1.angular_velocity" = [[0.0, -1.0, 0.0], [0.0, -10.0, 0.0]]
"""


def test_a_group_of_variants_varies_its_keys_together(tmp_path):
    """[variants.GROUP]: its keys' lists zipped — one dimension of the product (2 speeds × 2 spin pairs = 4
    cases, not 2 × 2 × 2), labelled by the group's name and its labels."""
    from .conftest import CASES

    path = tmp_path / "z.toml"
    path.write_text((CASES / "glass-pair.toml").read_text() + ZIPPED)
    cases = C.expand(path)
    assert [c.name.split("[")[1] for c in cases] == ["speed=1,spin=low]", "speed=1,spin=high]", "speed=2,spin=low]",
                                                     "speed=2,spin=high]"]
    spins = [(math.hypot(*c.particles[0].angular_velocity), c.particles[1].angular_velocity[1]) for c in cases]
    assert spins == [(1.0, -1.0), (10.0, -10.0)] * 2
    # without labels the members are numbered
    path.write_text((CASES / "glass-pair.toml").read_text() + ZIPPED.replace('labels = ["low", "high"]\n', ""))
    assert [c.name.rsplit("=", 1)[1] for c in C.expand(path)] == ["1]", "2]", "1]", "2]"]


@pytest.mark.parametrize("group,key,words", [
    ('"particles.0.angular_velocity" = [[0.0, 1.0, 0.0]]\n"particles.1.angular_velocity" = [[0.0, 1.0, 0.0], '
     '[0.0, 2.0, 0.0]]', "variants.spin", "must be of one length"),
    ('labels = ["a"]\n"impact.speed" = [1.0, 2.0]', "variants.spin.labels", "must be a list of 2 labels"),
    ('labels = ["a", "a"]\n"impact.speed" = [1.0, 2.0]', "variants.spin.labels", "must be distinct"),
    ('labels = ["a b;", "c"]\n"impact.speed" = [1.0, 2.0]', "variants.spin.labels", "labels its variant"),
    ('"impact.speed" = []', "variants.spin.impact.speed", "non-empty list"),
    ("", "variants.spin", "at least one dotted key"),
])
def test_a_bad_group_of_variants_is_one_clear_line(tmp_path, group, key, words):
    from .conftest import CASES

    path = tmp_path / "z.toml"
    path.write_text((CASES / "glass-pair.toml").read_text() + "\n[variants.spin]\n" + group + "\n")
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    assert info.value.key == key and words in info.value.rule, (info.value.key, info.value.rule)


@pytest.mark.parametrize("extra,key,words", [
    # the same key in a plain variant and in a group: the last would win under both labels
    ('"impact.spin" = [2.0]\n[variants.spin2]\n"impact.spin" = [1.0, 3.0]', "variants.impact.spin",
     "is varied twice"),
    # a group named as another dimension's label
    ('"impact.speed" = [1.0]\n[variants.speed]\n"impact.angle" = [0.0, 10.0]', "variants", "labels two dimensions"),
    # an unquoted dotted key inside a group
    ('[variants.g]\nimpact.speed = [1.0, 2.0]', "variants.g.impact", '"impact.speed" = ['),
])
def test_variants_that_would_mislabel_a_case_are_refused(tmp_path, extra, key, words):
    from .conftest import CASES

    path = tmp_path / "z.toml"
    path.write_text((CASES / "glass-pair.toml").read_text() + "\n[variants]\n" + extra + "\n")
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    assert info.value.key == key and words in info.value.rule, (info.value.key, info.value.rule)


def test_an_unquoted_dotted_variant_key_is_named_with_the_fix(tmp_path):
    """impact.speed = [...] without quotes is a TOML table: said in one line, not read as a group."""
    from .conftest import CASES

    path = tmp_path / "z.toml"
    path.write_text((CASES / "glass-pair.toml").read_text() + "\n[variants]\nimpact.speed = [1.0, 2.0]\n")
    with pytest.raises(ConfigError) as info:
        C.expand(path)
    assert info.value.key == "variants.impact" and '"impact.speed" = [' in info.value.rule


# ----------------------------------------------------------------------------- [contact] pair keys

GLASS_LSD = ["contact.normal=lsd", "contact.stiffness_method=duration"]
OBLIQUE = ["contact.normal=lsd", "contact.stiffness_method=energy", "contact.tangential=lsd_sliding",
           "materials.glass.friction=0.3", "materials.glass.tangential_restitution=0.5",
           "particles.1.velocity=[0.0, 0.5, 0.0]"]
HLS = ["contact.normal=hls", "contact.kl=1e6"]

# (overrides, key, words of the rule): the same rules as a material's values (case._material)
BAD_PAIR = [
    (GLASS_LSD + ['contact.restitution="abc"'], "contact.restitution", "must be a finite number"),
    (GLASS_LSD + ["contact.restitution=nan"], "contact.restitution", "must be a finite number"),
    (GLASS_LSD + ["contact.restitution=inf"], "contact.restitution", "must be a finite number"),
    (GLASS_LSD + ["contact.restitution=true"], "contact.restitution", "must be a finite number"),
    (GLASS_LSD + ["contact.restitution=5"], "contact.restitution", "must be in (0, 1]"),
    (GLASS_LSD + ["contact.restitution=0"], "contact.restitution", "must be in (0, 1]"),
    (GLASS_LSD + ["contact.restitution=-0.5"], "contact.restitution", "must be in (0, 1]"),
    (OBLIQUE + ['contact.friction="x"'], "contact.friction", "must be a finite number"),
    (OBLIQUE + ["contact.friction=-1"], "contact.friction", "must be >= 0"),
    (OBLIQUE + ["contact.friction_kinetic=-0.1"], "contact.friction_kinetic", "must be >= 0"),
    (OBLIQUE + ["contact.friction=0.2", "contact.friction_kinetic=0.25"], "contact.friction_kinetic",
     "must not exceed the static coefficient friction = 0.2"),
    (OBLIQUE + ["contact.tangential_restitution=1.5"], "contact.tangential_restitution", "must be in [0, 1]"),
    (OBLIQUE + ["contact.tangential_restitution=-0.1"], "contact.tangential_restitution", "must be in [0, 1]"),
    (OBLIQUE + ['contact.tangential_restitution="x"'], "contact.tangential_restitution", "must be a finite number"),
    # string-valued parameters: strings of their allowed set (a list is not hashable: once a TypeError)
    (OBLIQUE + ["contact.truncation=[1]"], "contact.truncation", "must be one of force, overlap, spring"),
    (OBLIQUE + ["contact.truncation=1"], "contact.truncation", "must be one of force, overlap, spring"),
    (OBLIQUE + ['contact.truncation={a = 1}'], "contact.truncation", "must be one of force, overlap, spring"),
    (HLS + ["contact.unloading=[1]"], "contact.unloading", "must be one of constant, variable"),
    (GLASS_LSD[:1] + ["contact.stiffness_method=[1]"], "contact.stiffness_method",
     "must be one of duration, overlap, energy"),
    # a string parameter the resolved path does not read (kn given) is still checked
    (GLASS_LSD[:1] + ["contact.kn=1e6", "contact.stiffness_method=[1]"], "contact.stiffness_method",
     "must be one of duration, overlap, energy"),
    # a pair key no model of the case uses is an unknown key, whatever its value
    (['contact.restitution="abc"'], "contact.restitution", "is not a parameter of normal 'hertz'"),
    (["contact.restitution=0.5"], "contact.restitution", "is not a parameter of normal 'hertz'"),
    (["contact.friction=0.3"], "contact.friction", "is not a parameter of normal 'hertz'"),
    (GLASS_LSD + ["contact.tangential_restitution=0.5"], "contact.tangential_restitution",
     "is not a parameter of normal 'lsd'"),
]


@pytest.mark.parametrize("overrides,key,rule", BAD_PAIR)
def test_contact_pair_keys_obey_the_materials_rules(overrides, key, rule):
    with pytest.raises(ConfigError) as info:
        C.loads(BASE, overrides)
    assert info.value.key == key, str(info.value)
    assert rule in info.value.rule, str(info.value)
    assert "\n" not in str(info.value) and info.value.exit_code == 2


@pytest.mark.parametrize("overrides,key,rule", [
    (["contact.restitution=5"], "contact.restitution", "must be in (0, 1]"),
    (['contact.restitution="abc"'], "contact.restitution", "must be a finite number"),
    (["contact.friction=0.3"], "contact.friction", "is not a parameter of normal 'lsd'"),
])
def test_a_packing_checks_its_pair_keys_when_loaded(overrides, key, rule):
    """A packing resolves its laws only when it runs: its [contact] values are checked when it is loaded."""
    with pytest.raises(ConfigError) as info:
        C.loads(PACKING, overrides)
    assert info.value.key == key and rule in info.value.rule, str(info.value)


def test_valid_pair_keys_override_the_materials():
    """Each rule's edge is admitted and the pair takes the [contact] value over the materials' (which are
    restitution 0.97, friction 0.3, tangential restitution 0.5)."""
    pair = pair_of(C.loads(BASE, OBLIQUE + ["contact.restitution=1", "contact.friction=0",
                                            "contact.friction_kinetic=0", "contact.tangential_restitution=0"]))
    assert (pair.restitution, pair.friction, pair.friction_kinetic, pair.tangential_restitution) == (1, 0, 0, 0)
    pair = pair_of(C.loads(BASE, OBLIQUE + ["contact.restitution=0.5", "contact.friction_kinetic=0.3",
                                            "contact.tangential_restitution=1"]))
    assert (pair.restitution, pair.friction, pair.friction_kinetic, pair.tangential_restitution) == (0.5, 0.3,
                                                                                                     0.3, 1)


@pytest.mark.parametrize("case,sets,needle", [
    ("glass-pair.toml", ["contact.normal=lsd", "contact.stiffness_method=duration", 'contact.restitution="abc"'],
     "contact.restitution = 'abc': must be a finite number"),
    ("glass-pair.toml", ["contact.normal=lsd", "contact.stiffness_method=duration", "contact.restitution=5"],
     "contact.restitution = 5: must be in (0, 1]"),
    ("oblique-lsd-wall.toml", ["contact.friction=-1"], "contact.friction = -1: must be >= 0"),
    ("oblique-lsd-wall.toml", ["contact.truncation=[1]"],
     "contact.truncation = [1]: must be one of force, overlap, spring"),
    ("glass-pair.toml", ['contact.restitution="abc"'], "contact.restitution = 'abc': is not a parameter"),
])
def test_cli_bad_pair_keys_are_one_line_and_exit_2(tmp_path, case, sets, needle):
    import subprocess
    import sys

    from .conftest import CASES

    args = [a for s in sets for a in ("--set", s)]
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(CASES / case), *args], capture_output=True,
                       text=True, timeout=120, cwd=tmp_path)
    assert p.returncode == 2, p.stderr[-2000:]
    assert p.stdout == "" and p.stderr.count("\n") == 1, p.stderr
    assert p.stderr.startswith(f"demcheck: error: {needle}"), p.stderr
    assert not list(tmp_path.iterdir()), "nothing is written before the case is checked"


def test_plain_copy_is_a_deep_copy_of_toml_data():
    """apply_overrides and from_dict copy a case's raw tables with plain_copy (a sweep copies once per point):
    nothing of the copy is shared with the original, and values that are not TOML's are deep-copied."""
    import datetime

    from demcheck.case import apply_overrides, plain_copy

    raw = {"a": {"b": [1, 2.5, {"c": "x"}], "d": True, "e": None}, "f": datetime.date(2026, 12, 2),
           "g": (1, [2]), "h": {"z": [[0.0]]}}
    copy_ = plain_copy(raw)
    assert copy_ == raw
    copy_["a"]["b"][2]["c"] = "y"
    copy_["a"]["b"].append(3)
    copy_["g"][1].append(4)
    copy_["h"]["z"][0][0] = 1.0
    assert raw == {"a": {"b": [1, 2.5, {"c": "x"}], "d": True, "e": None}, "f": datetime.date(2026, 12, 2),
                   "g": (1, [2]), "h": {"z": [[0.0]]}}
    over = apply_overrides(raw, ["a.b.0=7", "h.z=[[2.0]]"])
    assert (over["a"]["b"][0], over["h"]["z"]) == (7, [[2.0]]) and (raw["a"]["b"][0], raw["h"]["z"]) == (1, [[0.0]])


def test_cli_refuses_a_viscous_roll_past_the_no_slip_bound_before_any_run(tmp_path):
    """Rolling type B (rolling = "viscous") above the largest Cr the sphere rolls under without slip, 1.4 μ m g R²/v0
    on the level wall (2.19e-8 N·m·s for the suite's glass sphere at 0.02 m/s, μ 0.3): one line naming contact.c_r, its value
    and the bound with its number, exit 2, nothing written (issue 30: before, the case loaded and its runs failed,
    "the sphere slides"). Just below the bound the same case loads."""
    import subprocess
    import sys

    from demcheck.resources import case_path

    text = case_path("suite/beyond-rolling-viscous.toml").read_text()
    assert "c_r = 1.5e-8" in text
    deck = tmp_path / "rolling.toml"
    deck.write_text(text.replace("c_r = 1.5e-8", "c_r = 2.2e-8"))
    out = tmp_path / "out"
    out.mkdir()
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(deck)], capture_output=True, text=True,
                       timeout=120, cwd=out)
    assert p.returncode == 2, p.stderr[-2000:]
    assert p.stdout == "" and p.stderr.count("\n") == 1, p.stderr
    assert p.stderr.startswith("demcheck: error: contact.c_r = 2.2e-08: must be at most 2.19231e-08 N·m·s"), p.stderr
    assert "Cr ≤ 1.4 μ m g R²/v0 on a level wall" in p.stderr and "the sphere slides" in p.stderr, p.stderr
    assert not list(out.iterdir()), "nothing is written before the case is checked"
    assert C.loads(text.replace("c_r = 1.5e-8", "c_r = 2.19e-8")).contact.params["c_r"] == 2.19e-8
    with pytest.raises(ConfigError) as info:
        C.loads(text.replace("friction = 0.3", "friction = 0.0"))
    # the friction is the material's here (line 13 of the case): the key named is the one the case sets
    assert info.value.key == "materials.*.friction" and "viscous" in info.value.rule


@pytest.mark.parametrize("scenario_file", ["suite/beyond-rolling.toml", "suite/beyond-rolling-viscous.toml",
                                           "suite/beyond-incline.toml"])
@pytest.mark.parametrize("tangential", ["none", "viscous", "viscous_sliding"])
def test_a_roll_without_a_law_that_holds_friction_at_rest_is_refused(scenario_file, tangential):
    """The rolling and incline scenarios roll the sphere without slip (reference/beyond.py assumes it): a tangential
    law with no force at a resting contact point lets the sphere slide, so the case is refused at load, naming
    contact.tangential (before, tangential = "none" loaded and the reference agreed with the no-slip closed form)."""
    from demcheck.resources import case_path

    text = case_path(scenario_file).read_text()
    assert 'tangential = "spring_sliding"\nkt = 1e5' in text
    keys = "" if tangential == "none" else "\neta_t = 1e-3"
    with pytest.raises(ConfigError) as info:
        C.loads(text.replace('tangential = "spring_sliding"\nkt = 1e5', f'tangential = "{tangential}"{keys}'))
    assert info.value.key == "contact.tangential" and info.value.value == tangential
    assert "without slip" in info.value.rule


def test_a_roll_with_coulomb_stick_loads():
    from demcheck.resources import case_path

    text = case_path("suite/beyond-rolling.toml").read_text()
    case = C.loads(text.replace('tangential = "spring_sliding"\nkt = 1e5', 'tangential = "sliding"'))
    assert case.contact.tangential == "sliding"
