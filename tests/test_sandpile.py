"""An inserted packing (case.py's layout = "inserted", [packing.insertion], [packing.height]) and the heap's height
curve (reference/sandpile.height_curve): the batches' lattice and shares, their times, the height measure against
free fall's closed form, the shipped sandpile cases, and bad input."""

import math
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.errors import ConfigError
from demcheck.reference import packing as P
from demcheck.reference import sandpile as S

DROP = """
name = "drops"
kind = "packing"
[materials.grain]
density = 1000.0
youngs_modulus = 1e7
poisson_ratio = 0.3
restitution = 0.5
friction = 0.5
[packing]
layout = "inserted"
count = {count}
material = "grain"
radii = [2e-3]
seed = 4
duration = {duration}
[packing.insertion]
every = {every}
batch = {batch}
batches = {batches}
region = {region}
spacing = 1.5
offset = {offset}
[packing.height]
axis = [0.0, 1.0, 0.0]
offset = 0.25
every = 0.01
start = 0.0
[[walls]]
point = [0.0, -1.0, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
normal = "hertz"
tangential = "none"
[run]
dt = 1e-5
gravity = [0.0, -9.81, 0.0]
"""


def _drops(**kw):
    values = dict(count=2, batch=1, batches=2, every=0.05, duration=0.1, offset=0.0,
                  region="[[0.0, 0.5, 0.0], [0.0, 0.5, 0.0]]")
    values.update(kw)
    return C.loads(DROP.format(**values))


def test_the_height_follows_free_fall_and_jumps_when_a_batch_comes_in():
    """One sphere at rest at y = 0.5 m, a second at the same place 0.05 s later, the floor far below: the height (the
    highest centre's y + 0.25 m, every 0.01 s from 0) is 0.75 − g t²/2 until the second comes in, then 0.75 −
    g (t − 0.05)²/2 — velocity Verlet integrates free fall exactly (to round-off: 1e-13 m)."""
    case = _drops()
    times, heights = S.height_curve(case)
    assert np.allclose(times, np.arange(11) * 0.01, rtol=0.0, atol=1e-15)
    since = np.where(times < 0.05 - 1e-12, times, times - 0.05)
    assert np.allclose(heights, 0.75 - 0.5 * 9.81 * since ** 2, rtol=0.0, atol=1e-13)


def test_an_inserted_packing_holds_its_first_batch_and_takes_the_others_at_their_times():
    case = _drops(count=6, batch=2, batches=3, every=0.04, duration=0.1,
                  region="[[-0.05, 0.5, 0.0], [0.05, 0.5, 0.0]]")
    assert len(case.particles) == 2
    seen = []
    P.simulate(case, observe=(range(0, 10001, 1000), lambda s: seen.append((s.steps, len(s.x)))))
    assert seen == [(0, 2), (1000, 2), (2000, 2), (3000, 2), (4000, 4), (5000, 4), (6000, 4), (7000, 4), (8000, 6),
                    (9000, 6), (10000, 6)]


def test_the_batches_lie_on_the_regions_lattice_in_its_plane_with_the_volume_shares():
    """Sites from the region's lo corner, half a pitch in (at lo along an axis of no extent), x fastest; moved by at
    most offset largest diameters in the region's plane only (z stays 0); radii drawn with number shares
    φ_i/r_i³ (normalised): 2000 draws within 4 standard deviations; each batch its own seed, the same on every load."""
    spec = C.packing_spec({"layout": "inserted", "count": 4000, "material": "g", "radii": [1e-3, 2e-3],
                           "volume_fractions": [0.5, 0.5], "seed": 7, "insertion": {
                               "every": 0.1, "batch": 2000, "batches": 2, "region": [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
                               "spacing": 1.5, "offset": 0.1}}, {"g": None})
    batches = C.insertion_batches(spec)
    assert [len(b) for b in batches] == [2000, 2000]
    x = np.array([p["position"] for p in batches[0]])
    pitch = 1.5 * 4e-3
    site = np.array([(k % 166 + 0.5) * pitch for k in range(2000)])
    assert 1.0 // pitch == 166
    assert np.abs(x[:, 0] - site).max() <= 0.1 * 4e-3 and not x[:, 2].any()
    share = 0.5 / 1e-9 / (0.5 / 1e-9 + 0.5 / 8e-9)
    small = sum(p["radius"] == 1e-3 for p in batches[0])
    assert abs(small - 2000 * share) <= 4 * math.sqrt(2000 * share * (1 - share))
    again = C.insertion_batches(spec)
    assert again == batches and batches[0] != batches[1]


@pytest.mark.parametrize("change, key, words", [
    ({"batches": 3}, "packing.insertion.batches", "packing.count"),
    ({"region": [[0.0, 0.0, 0.0], [0.004, 0.0, 0.0]]}, "packing.insertion.region", "lattice sites"),
    ({"region": [[0.0, 0.0], [1.0, 0.0]]}, "packing.insertion.region", "two opposite corners"),
    ({"offset": 0.3}, "packing.insertion.offset", "spacing - 2 offset"),
    ({"every": 1.0}, "packing.insertion.every", "before the end"),
    ({"spacing": 0.5}, "packing.insertion.spacing", ">= 1"),
    ({"color": 1}, "packing.insertion.color", "unknown key"),
])
def test_bad_insertion_keys_are_one_line_naming_the_key(change, key, words):
    ins = {"every": 0.1, "batch": 2, "batches": 2, "region": [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]], **change}
    with pytest.raises(ConfigError) as err:
        C.packing_spec({"layout": "inserted", "count": 4, "material": "g", "radius": 1e-3, "duration": 1.0,
                        "insertion": ins}, {"g": None})
    assert err.value.key == key and words in err.value.rule
    assert "\n" not in str(err.value) and err.value.exit_code == 2


@pytest.mark.parametrize("packing, key", [
    ({"layout": "inserted"}, "packing.insertion"),
    ({"layout": "poured", "box": [0.1, 0.1], "insertion": {"every": 0.1}}, "packing.insertion"),
    ({"layout": "poured", "box": [0.1, 0.1], "volume_fractions": [1.0]}, "packing.volume_fractions"),
    ({"layout": "inserted", "box": [0.1, 0.1]}, "packing.box"),
    ({"layout": "inserted", "radii": [1e-3, 2e-3], "volume_fractions": [0.5, 0.6]}, "packing.volume_fractions"),
    ({"layout": "inserted", "height": {"axis": [0.0, 0.0, 0.0], "every": 0.1}}, "packing.height.axis"),
    ({"layout": "inserted", "height": {"axis": [0.0, 1.0, 0.0], "every": 0.0}}, "packing.height.every"),
    ({"layout": "inserted", "height": {"axis": [0.0, 1.0, 0.0], "every": 0.1, "start": 2.0}}, "packing.height.start"),
])
def test_bad_inserted_packing_keys(packing, key):
    p = {"count": 4, "material": "g", "radius": 1e-3, "duration": 1.0, **packing}
    if p["layout"] == "inserted" and "insertion" not in packing and key != "packing.insertion":
        p["insertion"] = {"every": 0.1, "batch": 2, "batches": 2, "region": [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]]}
    with pytest.raises(ConfigError) as err:
        C.packing_spec(p, {"g": None})
    assert err.value.key == key and "\n" not in str(err.value)


def test_a_batch_placed_into_a_wall_is_refused_at_load():
    with pytest.raises(ConfigError) as err:
        _drops(region="[[0.0, -0.999, 0.0], [0.0, -0.999, 0.0]]")
    assert err.value.key.startswith("particles.0") or err.value.key == "packing.insertion.region"


def test_height_curve_needs_a_height_table():
    text = DROP.format(count=2, batch=1, batches=2, every=0.05, duration=0.1, offset=0.0,
                       region="[[0.0, 0.5, 0.0], [0.0, 0.5, 0.0]]")
    case = C.loads(text.split("[packing.height]")[0] + "[[walls]]" + text.split("[[walls]]")[1])
    with pytest.raises(ConfigError) as err:
        S.height_curve(case)
    assert err.value.key == "packing.height"


@pytest.mark.parametrize("model", ["constant", "viscous", "epsd"])
def test_the_shipped_sandpile_cases_load_as_lethe_sets_them_up(model):
    """3000 spheres in 12 batches of 250 every 0.2 s, 13 walls (the gate, a plane, removed at 4.5 s), heights from 9 s
    every 0.02 s to 50 s; every centre in z = 0; only the reference runs it (the engines' decks write no segment)."""
    from demcheck.comparisons.packing_suite import engine_blind

    case = C.load(Path(__file__).parents[1] / "cases" / "optin" / f"ai2011-sandpile-{model}.toml")
    full = P.with_batches(case)
    assert len(case.particles) == 250 and len(full.particles) == 3000
    assert not np.array([p.position for p in full.particles])[:, 2].any()
    assert len(case.walls) == 13 and [w.until for w in case.walls if w.until] == [4.5]
    steps = S.measure_steps(case, case.run.dt)
    assert len(steps) == 2051 and steps[0] == 450000 and steps[-1] == 2500000  # 9 s to 50 s: the curves' 9.1-49.5 s
    assert C.packing_run(case)[2] in (2500000, 2500001) and steps[-1] <= C.packing_run(case)[2]
    assert "only the reference" in engine_blind(case)
    assert case.contact.rolling == {"constant": "constant_torque", "viscous": "ai_viscous", "epsd": "ai_epsd"}[model]  # Ai's model C proper: kn per contact


def test_an_inserted_packing_is_not_run_in_the_engines_even_with_plane_walls_and_no_rolling():
    """The engines' packing decks write the case's particles, an inserted packing's first batch only: run there, an
    engine would settle another packing than the reference (review: engine_blind named rolling and walls only)."""
    from demcheck.comparisons.packing_suite import engine_blind

    case = _drops()
    assert case.contact.rolling == "none" and all(w.extent is None and w.until is None for w in case.walls)
    assert "batch insertion" in (engine_blind(case) or "")


def test_the_reference_packings_cache_key_holds_every_batch(tmp_path, monkeypatch):
    """The case's hash holds its first batch only: a change to how the later batches are laid out (case.py's
    insertion_batches, code the case's hash does not see) must not be served the kept packing."""
    from dataclasses import replace

    from demcheck.comparisons import packing_suite as PS
    from demcheck.engines.cache import Cache

    keys = []
    monkeypatch.setattr(P, "simulate", lambda case, rest=0.0: (_ for _ in ()).throw(RuntimeError("solve")))
    cache = Cache(tmp_path)
    real_get = cache.get
    monkeypatch.setattr(cache, "get", lambda k, **kw: keys.append(k) or real_get(k, **kw))
    case = _drops()
    real = P.with_batches
    for shift in (0.0, 1e-4):  # the second batch laid out 0.1 mm further: the same case, the same hash
        monkeypatch.setattr(P, "with_batches", lambda c, s=shift: replace(real(c), particles=tuple(
            replace(p, position=(p.position[0] + (s if k else 0.0), *p.position[1:]))
            for k, p in enumerate(real(c).particles))))
        with pytest.raises(RuntimeError):
            PS.reference_packing(case, cache=cache)
    assert keys[0] != keys[2]
