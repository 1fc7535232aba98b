"""The engine contract, held for every registered law × every registered engine.

Each engine's vocabulary makes a claim about every seed model (engines.base.Mapping): ``exact`` — its twin
computes the seed model's force law, so the two run to round-off at equal dt (the same scheme and the same
kinematic rules: only the laws differ); ``approximate`` — the twin is a named variant and the reasons say how
it differs (whether it differs in this one geometry is tests/test_mapping.py's question); ``none`` — no deck,
with a reason. A new law or a new engine
is tested here without new test code: the cases are the mapping table's (one row per normal law with no
friction, one per tangential law with its natural partner, and the parameter variants whose mapping
differs)."""

from __future__ import annotations

import copy
import dataclasses
import math

import pytest

from demcheck import case as C
from demcheck.engines import mapping, registry
from demcheck.engines.base import APPROXIMATE, EXACT, FIDELITIES, NONE_
from demcheck.reference import collision3d
from demcheck.laws import normal
from demcheck.laws.model import resolve

METRICS = ("restitution", "contact_time", "max_overlap", "peak_force", "tangential_restitution",
           "rebound_angular_velocity")


def _rows():
    out = []
    combos = ([(n, "none", {}) for n in normal.REGISTRY] + [
        (mapping._PARTNER.get(t, "lsd"), t, {}) for t in _tangential_ids() if t != "none"] + mapping._VARIANTS)
    for engine in registry.names():
        for n, t, extra in combos:
            out.append(pytest.param(engine, n, t, extra, id=f"{engine}-{n}-{t}" + ("-" + "-".join(
                f"{k}={v}" for k, v in extra.items()) if extra else "")))
    return out


def _tangential_ids():
    from demcheck.laws import tangential

    return list(tangential.REGISTRY)


def _case(normal_id: str, tangential_id: str, extra: dict, oblique: bool) -> C.Case:
    """The mapping table's glass pair with the model set; an oblique impact at 30° with spin where a
    tangential law acts (so that the tangential claim is exercised), head-on otherwise."""
    import tomllib

    from demcheck.laws.tangential import REGISTRY as T

    base = tomllib.loads(mapping._TABLE_CASE)
    params = {**normal.REGISTRY[normal_id].example, **T[tangential_id].example, **extra}
    params.pop("friction", None)
    base["contact"] = {"normal": normal_id, "tangential": tangential_id, **params}
    if oblique:
        base.pop("particles")
        base["particles"] = [{"material": "glass", "radius": 1.59e-3}, {"material": "glass", "radius": 1.59e-3}]
        base["impact"] = {"speed": 1.0, "angle": 30.0, "spin": 200.0}
    return C.from_dict(copy.deepcopy(base))


def _metrics(case, model, rules, dt):
    res = collision3d.collide(case, model, "verlet", dt=dt, rules=rules)
    assert res.ok, f"{res.status}: {res.message}"
    return res.metrics()


def _differences(case: C.Case, engine: str) -> tuple[str, list[str], dict]:
    """(fidelity, reasons, {metric: |twin − seed| in the metric's own relative scale}) at equal dt, with the
    engine's rules for both."""
    mp = mapping.contact_mapping(case, engine)
    if mp.native is None:
        return mp.fidelity, mp.reasons, {}
    seed = resolve(case)
    twin = mapping.twin_model(seed, mp.native)
    rules = registry.get(engine).rules
    from demcheck.reference.collision import auto_dt

    dt = auto_dt(case, seed)
    a, b = _metrics(case, seed, rules, dt), _metrics(case, twin, rules, dt)
    diffs = {}
    for k in METRICS:
        x, y = a.get(k), b.get(k)
        if x is None or y is None or not (math.isfinite(x) and math.isfinite(y)):
            assert (x is None or not math.isfinite(x)) == (y is None or not math.isfinite(y)), k
            continue
        diffs[k] = abs(x - y) / max(abs(x), 1e-300)
    return mp.fidelity, mp.reasons, diffs


@pytest.mark.parametrize("engine,normal_id,tangential_id,extra", _rows())
def test_every_mapping_claim_holds(engine, normal_id, tangential_id, extra):
    case = _case(normal_id, tangential_id, extra, oblique=tangential_id != "none")
    fidelity, reasons, diffs = _differences(case, engine)
    assert fidelity in FIDELITIES
    if fidelity == NONE_:
        assert reasons and all(r.strip() for r in reasons), "a refusal says why"
        return
    worst = max(diffs.values())
    if fidelity == EXACT:
        # the twin is the seed law: the same scheme and rules at equal dt agree to round-off
        assert worst <= 1e-9, f"claimed exact, twin differs by {worst:.3g}: {diffs}"
    else:
        assert fidelity == APPROXIMATE and reasons, "an approximate mapping says how it differs"


def test_the_contract_catches_a_linear_law_mapped_as_hertz(monkeypatch):
    """Registering a linear normal law (exponent 1) under a new id must not be mapped to a Hertz model: the
    vocabulary reads the law's shape, not its id (a mapping that picked the stiffness by ``id == "lsd"`` once
    claimed such a law exact while its twin ran with exponent 1.5)."""
    lsd = normal.REGISTRY["lsd"]
    twin_law = dataclasses.replace(lsd, id="linear2", seed_name="LIN2", aliases=())
    monkeypatch.setitem(normal.REGISTRY, "linear2", twin_law)
    case = _case("linear2", "none", {"restitution": 1.0}, oblique=False)  # elastic: once claimed exact as hertz
    assert resolve(case).normal_law.a == 1.0
    for engine in registry.names():
        fidelity, reasons, diffs = _differences(case, engine)
        if fidelity == EXACT:
            assert max(diffs.values()) <= 1e-9, (engine, diffs)


def test_every_engine_fulfils_the_contract():
    for e in registry.all_engines():
        assert e.name == e.name.lower() and e.title and e.release and e.how_to_install
        assert {"slip_arm", "torque_arm", "wall_torque_arm", "rotation"} <= set(e.rules) <= {
            "slip_arm", "torque_arm", "wall_torque_arm", "rotation", "wall_slip_arm"}
        from demcheck.reference.collision3d import rules_array

        assert len(rules_array(e.rules)) == 5  # every rule has a kernel meaning
        assert e.style.colour and e.style.marker
    styles = [(e.style.colour, e.style.marker) for e in registry.all_engines()]
    assert len(set(styles)) == len(styles), "every engine is drawn in a colour and marker of its own"
