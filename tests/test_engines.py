"""The engines, run for real: every configuration demcheck writes is reproduced by its reference twin.

The twin runs the engine's own scheme (velocity Verlet of fix nve/sphere, history rules, lever arms) at the
engine's dt; both contact tables are read off the bodies' states the same way (engines/states.py). The
issue's bar is 1e-9 relative on peak force, restitution and contact time; the measured agreement is
~1e-13 (round-off), recorded in docs/models.md.
"""

import math

import pytest

from demcheck.engines import discovery
from demcheck.engines.collide import collide, twin_states
from demcheck.engines import mapping, registry
from demcheck.engines.mapping import Native

from .helpers import glass_case, oblique_case

TOL = 1e-9
NORMAL_KEYS = ("peak_force", "restitution", "contact_time")
OBLIQUE_KEYS = NORMAL_KEYS + ("tangential_restitution", "rebound_angular_velocity")

NORMAL_CASES = [("lsd", {"stiffness_method": "energy"}), ("lsd", {"kn": 3e6, "eta_n": 0.5}),
                ("lsd", {"stiffness_method": "duration", "limit_force": True}), ("hertz", {}),
                ("bshp", {"dissipative_constant": 1e-7}), ("kk", {"eta_n": 20.0}), ("tti", {}),
                ("tti", {"limit_force": True}), ("hls", {"stiffness_method": "overlap"}),
                ("hls", {"stiffness_method": "overlap", "unloading": "variable", "S": 1e4})]
OBLIQUE_CASES = [("lsd", None, "spring_sliding", None),
                 ("lsd", None, "lsd_sliding", {"truncation": "overlap", "tangential_restitution": 0.5}),
                 ("lsd", None, "lsd_sliding", {"truncation": "spring", "tangential_restitution": 0.5}),
                 ("lsd", None, "viscous", {"eta_t": 2.0}), ("lsd", None, "viscous_sliding", {"eta_t": 2.0}),
                 ("lsd", None, "sliding", {}), ("hertz", {}, "ddt", {}),
                 ("tti", {}, "tti", {"truncation": "overlap"}), ("tti", {}, "tti", {})]


def _agree(engine_result, twin_result, keys):
    a, b = engine_result.metrics(), twin_result.metrics()
    for k in keys:
        assert math.isfinite(a[k]) and math.isfinite(b[k]), k
        assert a[k] == pytest.approx(b[k], rel=TOL, abs=TOL * 1e-3), (k, a[k], b[k])
    return a


def _run(case, engine):
    mp = mapping.contact_mapping(case, engine)
    res = collide(case, engine)
    assert res.engine_version == discovery.find(engine).version
    assert res.meta["fidelity"] == mp.fidelity
    # the health rules (reference/health.py) pass every healthy configuration: they do not misfire
    assert res.status == "ok", res.message
    twin = twin_states(case, engine, res.dt)
    assert twin.status == "ok", twin.message
    return res, twin


def _normal_case(i, wall):
    normal, params = NORMAL_CASES[i]
    return glass_case(normal, params, wall=wall, restitution=0.8)


def _oblique_case(i, wall):
    normal, nparams, tangential, tparams = OBLIQUE_CASES[i]
    return oblique_case(tangential, tparams, normal=normal, normal_params=nparams, wall=wall, angle=30.0,
                        spin=500.0)


def _expressible(make, n):
    """(index, wall, engine) for every case an engine can express: only those have a twin to meet (the
    others are test_mapping.py's 'none' rows); engine tests are never skipped."""
    out = []
    for i in range(n):
        for wall in (False, True):
            for e in registry.names():
                if mapping.contact_mapping(make(i, wall), e).native is not None:
                    out.append(pytest.param(i, wall, e, marks=pytest.mark.engine(e),
                                            id=f"{i}-{'wall' if wall else 'pair'}-{e}"))
    return out


@pytest.mark.parametrize("i,wall,engine", _expressible(_normal_case, len(NORMAL_CASES)))
def test_normal_impact_matches_the_twin(i, wall, engine):
    res, twin = _run(_normal_case(i, wall), engine)
    m = _agree(res, twin, NORMAL_KEYS)
    assert m["peak_force"] > 0 and 0 < m["restitution"] <= 1.001


@pytest.mark.parametrize("i,wall,engine", _expressible(_oblique_case, len(OBLIQUE_CASES)))
def test_oblique_spinning_impact_matches_the_twin(i, wall, engine):
    """Approximate mappings too: the engine still computes its twin exactly (only the twin differs from
    the seed model, as test_mapping.py shows)."""
    res, twin = _run(_oblique_case(i, wall), engine)
    m = _agree(res, twin, OBLIQUE_KEYS)
    # friction acted: the test could fail
    assert abs(m["tangential_restitution"] - 1.0) > 1e-3


def test_every_expressible_case_is_covered():
    """The exact mappings the first two engines were built for all have an engine test, pair and wall (LIGGGHTS
    alone expresses HLS); every registered engine at least runs Hertz, pair and wall."""
    ids = {p.id for p in _expressible(_normal_case, len(NORMAL_CASES))}
    for i, (normal, _) in enumerate(NORMAL_CASES):
        engines = ("liggghts",) if normal == "hls" else ("lammps", "liggghts")
        if normal == "hertz":
            engines = registry.names()
        for e in engines:
            assert f"{i}-pair-{e}" in ids and f"{i}-wall-{e}" in ids, (normal, e)


# ----------------------------------------------------------------------------- the engines' traps


@pytest.mark.engine("lammps")
def test_lammps_tsuji_misses_the_input_restitution():
    """docs/lammps-users.md (trap tsuji): damping tsuji (Marshall's α(e), no √2) gives e = 0.616 for an input of 0.5
    in a head-on Hertz collision; coeff_restitution gives back 0.5 (to the scheme's O(dt))."""
    case = glass_case("hertz", {}, restitution=0.5)
    k = 4.0 / 3.0 * 71e9 / (2.0 * (1.0 - 0.22**2))
    tsuji = Native("lammps", "hertz", (k,), damping="tsuji", damping_coeff=0.5, tangential="linear_nohistory",
                   tangential_args=(0.0, 0.0))
    res = collide(case, "lammps", native=tsuji)
    m = _agree(res, twin_states(case, "lammps", res.dt, native=tsuji), NORMAL_KEYS)
    assert m["restitution"] == pytest.approx(0.616, abs=2e-3)
    exact = Native("lammps", "hertz", (k,), damping="coeff_restitution", damping_coeff=0.5,
                   tangential="linear_nohistory", tangential_args=(0.0, 0.0))
    assert collide(case, "lammps", native=exact).metrics()["restitution"] == pytest.approx(0.5, abs=2e-3)


@pytest.mark.engine("liggghts")
def test_liggghts_limit_force_raises_the_restitution():
    """docs/liggghts-users.md: LIGGGHTS hertz gives its input e with limitForce off, 0.550 for 0.5 with it on
    (a rigid wall: E* = E/(1−ν²), G* = E/(2(1+ν)(2−ν)))."""
    case = glass_case("hertz", {}, wall=True, restitution=0.5)
    for limit, expected in ((False, 0.5), (True, 0.550)):
        nat = Native("liggghts", "hertz", limit=limit, tangential="off",
                     props={"restitution": 0.5, "youngs_eff": 71e9 / (1 - 0.22**2),
                            "shear_eff": 71e9 / (2 * 1.22 * 1.78)})
        res = collide(case, "liggghts", native=nat)
        m = _agree(res, twin_states(case, "liggghts", res.dt, native=nat), NORMAL_KEYS)
        assert m["restitution"] == pytest.approx(expected, abs=2e-3)


@pytest.mark.engine("lammps")
def test_lammps_auto_mixed_mindlin_null_is_wrong_between_types():
    """docs/lammps-users.md, Mixing: with only I I coefficients, LAMMPS mixes mindlin NULL wrongly for I ≠ J; the explicit
    pair_coeff demcheck writes is right (it matches the twin with k_t = 8G*)."""
    case = oblique_case("ddt", {}, normal="hertz", normal_params={}, wall=False, angle=30.0)
    nat = Native("lammps", "hertz/material", (71e9, 0.22), damping="velocity", damping_coeff=0.0,
                 tangential="mindlin", tangential_args=(None, 0.0, 0.3))
    explicit = collide(case, "lammps", native=nat)
    m = _agree(explicit, twin_states(case, "lammps", explicit.dt, native=nat), OBLIQUE_KEYS)
    mixed = collide(case, "lammps", native=nat, explicit_pairs=False).metrics()
    assert abs(mixed["tangential_restitution"] - m["tangential_restitution"]) > 0.05


@pytest.mark.engine("lammps")
def test_lammps_wall_moduli_are_pair_values():
    """docs/lammps-users.md, Walls: fix wall/gran granular hertz/material E ν uses E* = E/(2(1−ν²)), the pair value, not
    the rigid wall's E/(1−ν²): the peak force is (1/2)^{2/5} of the rigid wall's."""
    case = glass_case("hertz", {}, wall=True)
    nat = Native("lammps", "hertz/material", (71e9, 0.22), damping="velocity", damping_coeff=0.0,
                 tangential="linear_nohistory", tangential_args=(0.0, 0.0))
    res = collide(case, "lammps", native=nat)
    m = _agree(res, twin_states(case, "lammps", res.dt, native=nat), NORMAL_KEYS)
    rigid = collide(case, "lammps").metrics()  # demcheck's deck: hertz k = (4/3)Ē of the rigid wall
    # Hertz: F_max ∝ E*^{2/5} at equal m, R, v
    assert m["peak_force"] / rigid["peak_force"] == pytest.approx(0.5**0.4, rel=1e-3)


# ----------------------------------------------------------------------------- HLS with variable unloading: luding


def _plastic_case(wall, speed=1.0):
    """HLS with variable unloading, strongly plastic: S·δ_max ≈ 3 (e ≈ 0.5), so the mapping raises δ_lim
    above the floor 1/S (r > 2) to stay above the impact's overlap."""
    return glass_case("hls", {"stiffness_method": "overlap", "unloading": "variable", "S": 1e6}, wall=wall,
                      speed=speed)


@pytest.mark.engine("liggghts")
@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
def test_liggghts_luding_is_hls_with_variable_unloading(wall):
    """luding (δ_max < δ_lim, r free) computes HLS's K_U = K_L + S·F_max: the engine meets the seed law (its
    twin is the seed law itself) at equal dt to the bar, the maximum overlap included, and the closed forms
    δ_max = v√(m̄/K_L), F_max = K_L δ_max, ε = [1 + S v √(m̄/K_L)]^{-½} to the scheme's O(dt)."""
    from demcheck.laws.model import resolve

    case = _plastic_case(wall)
    nat = mapping.contact_mapping(case, "liggghts").require()
    assert nat.normal == "luding" and nat.props["unloading"] > 2.0
    res, twin = _run(case, "liggghts")
    m = _agree(res, twin, NORMAL_KEYS + ("max_overlap", "force_contact_time"))
    law, pair = resolve(case).normal_law, resolve(case).pair
    d_max = pair.impact_speed * math.sqrt(pair.m_eff / law.kl)
    e = (1.0 + law.s * d_max) ** -0.5
    assert 0.4 < e < 0.6  # the unloading stiffness is far from the loading one: the test can fail
    # sampled maxima and the rebound carry the scheme's O(dt): measured 1e-5 … 3e-5 at the default dt
    assert m["max_overlap"] == pytest.approx(d_max, rel=1e-4)
    assert m["peak_force"] == pytest.approx(law.kl * d_max, rel=1e-4)
    assert m["restitution"] == pytest.approx(e, rel=1e-4)


@pytest.mark.engine("liggghts")
def test_liggghts_luding_departs_from_hls_when_delta_max_passes_delta_lim():
    """The condition is real: with δ_lim below the impact's δ_max luding loads along r·K_L beyond δ_lim, and
    the engine leaves the HLS law (what the twin computes from the same numbers) far above the bar."""
    case = _plastic_case(wall=True)
    mapped = mapping.contact_mapping(case, "liggghts").require()
    res = collide(case, "liggghts")
    d_max = res.metrics()["max_overlap"]
    # the same S = (r − 1)/δ_lim, with δ_lim at half the overlap: phiF = δ_lim (r − 1)/(2R̄r)
    d_lim = 0.5 * d_max
    r = 1.0 + 1e6 * d_lim
    nat = Native("liggghts", "luding", tangential="off",
                 props={**mapped.props, "unloading": r, "plasticity_depth": d_lim * (r - 1.0) / (2 * 1.59e-3 * r)})
    broken = collide(case, "liggghts", native=nat)
    twin = twin_states(case, "liggghts", broken.dt, native=nat).metrics()
    assert abs(broken.metrics()["peak_force"] / twin["peak_force"] - 1.0) > 1e-2


# ----------------------------------------------------------------------------- results carry the engine


@pytest.mark.engine("liggghts")
def test_liggghts_warnings_are_parsed_from_its_log():
    res = collide(glass_case("hertz", {}), "liggghts")
    assert any("whitelist" in w for w in res.meta["warnings"])
    assert res.summary()["engine_version"].startswith("LIGGGHTS-PUBLIC 3.8.0")


@pytest.mark.engine("lammps")
def test_lammps_result_records_version_deck_and_work_directory(tmp_path):
    res = collide(glass_case("hertz", {}), "lammps", workdir=tmp_path / "run")
    assert "22 Jul 2025" in res.engine_version
    assert (tmp_path / "run" / "in.deck").read_text() == res.meta["deck"]
    assert (tmp_path / "run" / "dump.txt").exists()


# ----------------------------------------------------------------------------- twins no seed model maps to


@pytest.mark.engine("lammps")
@pytest.mark.parametrize("style", ["mindlin/force", "mindlin_rescale", "mindlin_rescale/force"])
@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
def test_lammps_mindlin_variants_match_their_twins(style, wall):
    """Thornton et al.'s incremental-force and rescaled histories, with a dashpot (x_t = 1 on TTIn's
    damping): they differ from plain mindlin, and the twin reproduces each."""
    case = oblique_case("tti", {"truncation": "overlap"}, normal="tti", normal_params={}, wall=wall, angle=30.0,
                        spin=500.0)
    base = mapping.contact_mapping(case, "lammps").native
    nat = Native("lammps", base.normal, base.normal_args, damping=base.damping, damping_coeff=base.damping_coeff,
                 tangential=style, tangential_args=base.tangential_args)
    res = collide(case, "lammps", native=nat)
    m = _agree(res, twin_states(case, "lammps", res.dt, native=nat), OBLIQUE_KEYS)
    plain = collide(case, "lammps").metrics()
    assert abs(m["tangential_restitution"] - plain["tangential_restitution"]) > 1e-6


@pytest.mark.engine("liggghts")
@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
def test_liggghts_hooke_with_characteristic_velocity_matches_its_twin(wall):
    """LIGGGHTS hooke: Kn from Hertz's energy at characteristicVelocity — the notes' equal-energy
    calibration of LSD (1.053 = (16/15)^{4/5}) — with Kt = Kn and γt = γn."""
    from demcheck.laws.model import resolve

    case = oblique_case("spring_sliding", None, normal="lsd", wall=wall, angle=30.0, spin=500.0)
    model = resolve(case)
    nat = Native("liggghts", "hooke", tangential="history",
                 props={"restitution": 0.9, "youngs_eff": model.pair.e_eff, "friction": 0.3,
                        "characteristic_velocity": model.pair.impact_speed})
    nl, tl = registry.get(nat.engine).twin(nat, model.pair.m_eff, model.pair.r_eff)
    assert nl.k == pytest.approx(model.normal_law.k, rel=1e-13)  # the seed's energy calibration (example)
    assert tl.kt == nl.k and tl.eta == nl.eta
    res = collide(case, "liggghts", native=nat)
    _agree(res, twin_states(case, "liggghts", res.dt, native=nat), OBLIQUE_KEYS)


# ----------------------------------------------------------------------------- a collision under gravity


def _gravity_case(gravity):
    """cases/hertz-wall.toml at 0.5 m/s under gravity (the wall's normal is +z: gravity's z part points into it),
    or an oblique spring-dashpot impact with friction under a tilted gravity."""
    from demcheck import case as C

    from .conftest import CASES

    if gravity[0] == 0.0:
        return C.load(CASES / "hertz-wall.toml", ["impact.speed=0.5", f"run.gravity={list(gravity)}"])
    return C.load(CASES / "oblique-lsd-wall.toml", ["impact.speed=0.5", f"run.gravity={list(gravity)}"])


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ("lammps", "liggghts")])
@pytest.mark.parametrize("gravity", [(0.0, 0.0, -9.81), (3.0, -4.0, -9.81)], ids=["normal", "tilted"])
def test_an_impact_under_gravity_matches_the_twin(engine, gravity):
    """The engine's dump holds each body's whole force, its weight m·g included; the contact is read without
    it (once m·g/F_peak = 5.07e-05 on the peak force: "the engine does not compute its own formula")."""
    case = _gravity_case(gravity)
    res, twin = _run(case, engine)
    keys = NORMAL_KEYS + ("max_overlap", "force_contact_time")
    m = _agree(res, twin, keys + (OBLIQUE_KEYS[3:] if gravity[0] else ()))
    mg = case.mass(0) * 9.81
    assert mg / m["peak_force"] > 1e3 * TOL, "the weight's share of the peak force is far above the bar"


@pytest.fixture(scope="module")
def gravity_verify(tmp_path_factory):
    """`demcheck verify` of the probe's case (cases/hertz-wall.toml at 0.5 m/s under gravity [0, 0, -9.81]) with
    the installed engines: (process, engines)."""
    import os
    import subprocess
    import sys

    from .conftest import CASES

    engines = [e for e in ("lammps", "liggghts") if discovery.find(e) is not None]
    if not engines:
        pytest.skip("no engine installed")
    tmp_path = tmp_path_factory.mktemp("gravity-verify")
    path = tmp_path / "hertz-wall-gravity.toml"
    text = (CASES / "hertz-wall.toml").read_text().replace("speed = 1.0", "speed = 0.5")
    path.write_text(text.replace('name = "hertz-wall"', 'name = "hertz-wall-gravity"')
                    + "\n[run]\ngravity = [0.0, 0.0, -9.81]\n")
    env = {**os.environ, "DEMCHECK_CACHE": str(tmp_path / "cache")}
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(path), "--engines", ",".join(engines),
                        "--report", str(tmp_path / "reports"), "--json"], capture_output=True, text=True,
                       cwd=tmp_path, timeout=600, env=env)
    return p, engines


def test_verify_under_gravity_passes_with_the_engines_on_their_twins(gravity_verify):
    """Exit 0, each engine within 1e-9 of its twin, and no closed form judged (they are the gravity-free
    model's)."""
    import json

    p, engines = gravity_verify
    assert p.returncode == 0, p.stderr[-3000:]
    (entry,) = json.loads(p.stdout)["cases"]
    assert entry["status"] == "ok", [c for c in entry["comparisons"] if c["verdict"] != "agree"]
    assert not [c for c in entry["comparisons"] if c["source"] == "closed-form"]
    for engine in engines:
        comps = [c for c in entry["comparisons"] if c["source"] == engine]
        assert comps and all(c["parts"]["implementation"] <= TOL for c in comps
                             if math.isfinite(c["parts"]["implementation"])), comps


def test_verify_under_gravity_reads_the_seed_verlet_run_as_the_engines(gravity_verify):
    """The seed law's verlet run at the engine's dt (the time step's own error) is read off its states as the
    engine and the twin are: Hertz maps exactly, so the twin is the seed law and both agree to round-off."""
    import json

    p, engines = gravity_verify
    (entry,) = json.loads(p.stdout)["cases"]
    for engine in engines:
        src = entry["sources"][engine]
        for k in NORMAL_KEYS:
            assert src["seed_verlet_metrics"][k] == pytest.approx(src["twin_metrics"][k], rel=TOL), (engine, k)
