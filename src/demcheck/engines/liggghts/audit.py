"""LIGGGHTS's contact vocabulary read back from a user's deck (``demcheck audit``): ``pair_style gran model …
tangential … [rolling_friction …] [flags]``, the ``fix property/global`` material properties, ``fix wall/gran
model … primitive type T``, ``hard_particles`` / ``soft_particles`` and ``fix particletemplate/sphere``. Every
type pair and wall × type becomes a Native that computes what LIGGGHTS-PUBLIC 3.8.0 computes for it."""

from __future__ import annotations

import math
from pathlib import Path

from ...inputs.script import (NEVER_RUN, NO_CONTACT_EFFECT, Body, Command, Finding, PairSetting, ScriptError,
                              Setup, _num, body, read_common)
from ..base import Native

MODELS = ("hertz", "hooke", "hooke/stiffness", "hertz/stiffness")  # the probed ones (they have a twin)
OTHER_MODELS = ("luding", "edinburgh", "thornton_ning", "hooke/hysteresis", "hertz/stiffness/ttt")
TANGENTIAL = ("off", "no_history", "history")
OWN_MODULI = True  # the deck writer writes each type's own Young's modulus and Poisson's ratio


def claims(script) -> bool:
    """LIGGGHTS's own vocabulary: pair_style gran model …, fix property/global, communicate, hard_particles."""
    for c in script.commands:
        w = c.words
        if ((c.name == "pair_style" and w[1:3] == ["gran", "model"]) or c.name in ("communicate", "hard_particles")
                or (c.name == "fix" and len(w) > 3 and w[3] == "property/global")):
            return True
    return False


PER_PAIR = {"coefficientRestitution": "restitution", "coefficientFriction": "friction", "kn": "kn", "kt": "kt",
            "gamman": "gamman", "gammat": "gammat"}


def _bad(cmd: Command, why: str):
    return ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {why}")


def parse_style(cmd: Command, w: list[str], k: int) -> tuple[dict, int]:
    """``model M tangential T [rolling_friction R] [cohesion C] [surface S] [flag on|off]…`` from w[k]."""
    spec = {"model": None, "tangential": "off", "rolling": "off", "cohesion": "off", "flags": {}}
    while k < len(w):
        key = w[k]
        if key in ("model", "tangential", "rolling_friction", "cohesion", "surface"):
            if k + 1 >= len(w):
                raise _bad(cmd, f"{key} needs a value")
            spec[{"rolling_friction": "rolling"}.get(key, key)] = w[k + 1]
            k += 2
        elif k + 1 < len(w) and w[k + 1] in ("on", "off", "yes", "no"):
            spec["flags"][key] = w[k + 1] in ("on", "yes")
            k += 2
        else:
            break
    if spec["model"] is None:
        raise _bad(cmd, "a gran style needs 'model M'")
    if spec["model"] not in MODELS + OTHER_MODELS:
        raise _bad(cmd, f"model {spec['model']}: not a LIGGGHTS 3.8.0 normal model ({', '.join(MODELS + OTHER_MODELS)})")
    if spec["tangential"] not in TANGENTIAL + ("tan_luding",):
        raise _bad(cmd, f"tangential {spec['tangential']}: not a LIGGGHTS 3.8.0 tangential model")
    return spec, k


def _prop(cmd: Command, w: list[str]) -> tuple[str, str, list[float]]:
    """``fix ID group property/global NAME peratomtype|peratomtypepair N|scalar v…``."""
    if len(w) < 7:
        raise _bad(cmd, "property/global needs a name, a kind and values")
    name, kind = w[4], w[5]
    start = 7 if kind == "peratomtypepair" else 6
    values = [_num(cmd, i, name) for i in range(start, len(w))]
    if kind == "peratomtypepair":
        n = int(_num(cmd, 6, "matrix size"))
        if len(values) != n * n:
            raise _bad(cmd, f"{name} peratomtypepair {n} needs {n * n} values, got {len(values)}")
    return name, kind, values


def read(script, root: Path) -> Setup:
    setup = Setup("liggghts")
    props: dict = {}  # name → (kind, values, where)
    style = None
    walls = []
    hard = soft = False
    for cmd in script.commands:
        w, name = cmd.words, cmd.name
        if name in NEVER_RUN and name != "quit":
            setup.not_audited.append((cmd.where(), cmd.text, "not audited (never run by demcheck)"))
            continue
        if cmd.problem and name in ("pair_style", "pair_coeff", "fix", "set", "timestep", "create_box"):
            raise _bad(cmd, cmd.problem)
        if read_common(cmd, setup, root):
            continue
        if name in ("hard_particles", "soft_particles"):
            on = w[1:2] in (["yes"], ["on"])
            hard, soft = (on, soft) if name == "hard_particles" else (hard, on)
            continue
        if name == "pair_style":
            if w[1:2] != ["gran"]:
                raise _bad(cmd, "audit reads LIGGGHTS's pair_style gran model …")
            spec, k = parse_style(cmd, w, 2)
            if k != len(w):
                raise _bad(cmd, f"{w[k]!r} is not a keyword of pair_style gran")
            style = (spec, cmd.where())
            continue
        if name == "fix" and len(w) > 3 and w[3] == "property/global":
            pname, kind, values = _prop(cmd, w)
            props[pname] = (kind, values, cmd.where())
            continue
        if name == "fix" and len(w) > 3 and w[3] == "wall/gran":
            spec, k = parse_style(cmd, w, 4)
            if w[k:k + 1] == ["primitive"] and w[k + 1:k + 2] == ["type"]:
                t = int(_num(cmd, k + 2, "wall type"))
                walls.append((spec, t, w[1], cmd.where(), w[k + 3] if len(w) > k + 3 else ""))
            else:
                setup.not_audited.append((cmd.where(), cmd.text, "fix wall/gran with a mesh: not probed (audit "
                                                                 "probes primitive walls)"))
            continue
        if name == "fix" and len(w) > 3 and w[3] == "particletemplate/sphere":
            _template(cmd, w, setup)
            continue
        if name == "fix" and len(w) > 3 and w[3].startswith("insert"):
            if "vel" in w and w[w.index("vel") + 1:w.index("vel") + 2] == ["constant"]:
                i = w.index("vel") + 2
                v = [_num(cmd, i + d, "vel") for d in range(3)]
                setup.speeds.append((math.sqrt(sum(x * x for x in v)), cmd.where()))
            continue
        if name == "fix":
            if len(w) > 3 and w[3] in ("nve/sphere", "gravity", "particledistribution/discrete",
                                       "check/timestep/gran"):
                continue
            setup.not_audited.append((cmd.where(), cmd.text, f"fix {w[3] if len(w) > 3 else ''}: not read by the "
                                                             "audit"))
            continue
        if name in NO_CONTACT_EFFECT:
            continue
        setup.not_audited.append((cmd.where(), cmd.text, "not audited: not a command the audit reads"))
    if style is None:
        raise ScriptError("the deck has no pair_style gran: nothing defines its contacts")
    if setup.dt is None:
        setup.dt, setup.dt_where = 1e-8, "the default for units si (no timestep command)"
    if "characteristicVelocity" in props:
        setup.speeds.append((props["characteristicVelocity"][1][0], props["characteristicVelocity"][2]))
    wall_types = {t for _, t, _, _, _ in walls}
    types = [t for t in sorted(setup.bodies) if t not in wall_types]
    _moduli(setup, props, hard, soft)
    spec, where = style
    for a in types:
        for b in types:
            if b >= a:
                setup.pairs.append(_pair(setup, spec, where, props, a, b, f"{a}-{b}"))
    for wspec, t_wall, fix_id, wwhere, _ in walls:
        for t in types:
            ps = _pair(setup, wspec, wwhere, props, t, t_wall, f"wall {fix_id} × {t}")
            ps.j = None
            ps.wall = {"youngs_modulus": _per_type(props, "youngsModulus", t_wall),
                       "poisson_ratio": _per_type(props, "poissonsRatio", t_wall)}
            setup.pairs.append(ps)
    return setup


def _template(cmd, w, setup):
    if "atom_type" not in w:
        return
    t = int(_num(cmd, w.index("atom_type") + 1, "atom_type"))
    b = body(setup, t)
    for key, attr, factor in (("density", "density", 1.0), ("radius", "radius", 1.0)):
        if key in w and w[w.index(key) + 1:w.index(key) + 2] == ["constant"]:
            setattr(b, attr, _num(cmd, w.index(key) + 2, key) * factor)


def _per_type(props, name, t):
    if name not in props:
        return None
    kind, values, _ = props[name]
    return values[t - 1] if kind == "peratomtype" and t - 1 < len(values) else (values[0] if kind == "scalar"
                                                                                 else None)


def _pair_value(props, name, a, b):
    if name not in props:
        return None
    kind, values, _ = props[name]
    if kind == "peratomtypepair":
        n = int(round(math.sqrt(len(values))))
        return values[(a - 1) * n + (b - 1)]
    if kind == "scalar":
        return values[0]
    return None


def _moduli(setup: Setup, props: dict, hard: bool, soft: bool) -> None:
    if "youngsModulus" not in props:
        return
    kind, values, where = props["youngsModulus"]
    nus = props.get("poissonsRatio", (None, [], ""))[1]
    for t, e in enumerate(values, 1):
        b = setup.bodies.get(t) or Body(t)
        b.youngs_modulus, b.poisson_ratio = e, nus[t - 1] if t - 1 < len(nus) else 0.3
    if max(values) > 1e9 and not hard:
        setup.findings.append(Finding("trap", "hard-particles", f"youngsModulus {max(values):g} Pa is above LIGGGHTS's "
                                      "1e9 Pa sanity limit and the deck has no 'hard_particles yes': LIGGGHTS stops "
                                      "with an error (the probes run with it)", where,
                                      {"youngs_modulus": max(values), "limit": 1e9}))
    if min(values) < 5e6 and not soft:
        setup.findings.append(Finding("trap", "soft-particles", f"youngsModulus {min(values):g} Pa is below LIGGGHTS's "
                                      "5e6 Pa sanity limit and the deck has no 'soft_particles yes'", where,
                                      {"youngs_modulus": min(values), "limit": 5e6}))


def _pair(setup, spec, where, props, a, b, label) -> PairSetting:
    flags = spec["flags"]
    model, tang = spec["model"], spec["tangential"]
    limit = flags.get("limitForce", model in ("luding", "edinburgh"))
    p = {}
    notes, findings, asked = [], [], {}
    for pname, key in PER_PAIR.items():
        v = _pair_value(props, pname, a, b)
        if v is not None:
            p[key] = v
    if model in ("hertz", "hooke"):
        ea, eb = _per_type(props, "youngsModulus", a), _per_type(props, "youngsModulus", b)
        na, nb = _per_type(props, "poissonsRatio", a), _per_type(props, "poissonsRatio", b)
        if None in (ea, eb, na, nb):
            raise ScriptError(f"{where}: model {model} needs youngsModulus and poissonsRatio for types {a} and {b}")
        p["youngs_eff"] = 1.0 / ((1 - na * na) / ea + (1 - nb * nb) / eb)
        p["shear_eff"] = 1.0 / (2 * (2 - na) * (1 + na) / ea + 2 * (2 - nb) * (1 + nb) / eb)
        if "restitution" not in p:
            raise ScriptError(f"{where}: model {model} needs coefficientRestitution")
        asked["restitution"] = p["restitution"]
        if model == "hooke":
            if "characteristicVelocity" not in props:
                raise ScriptError(f"{where}: model hooke needs characteristicVelocity")
            p["characteristic_velocity"] = props["characteristicVelocity"][1][0]
            notes.append("model hooke: kn is set by characteristicVelocity, m̄ and R̄ (not directly), kt = kn")
    if tang != "off":
        if "friction" not in p:
            raise ScriptError(f"{where}: tangential {tang} needs coefficientFriction")
        asked["friction"] = p["friction"]
    else:
        notes.append("tangential off (LIGGGHTS's default): no friction at all")
    for key in ("kn", "kt", "gamman", "gammat"):
        p.setdefault(key, 0.0)
    nat = Native("liggghts", model, limit=limit, tangential=tang, props=p,
                 tangential_damping=flags.get("tangential_damping", True))
    ps = PairSetting(label, a, b, nat, where, asked, notes=notes, findings=findings)
    if model not in MODELS or tang == "tan_luding":
        ps.probe = False
        notes.append(f"model {model} / tangential {tang}: listed, not probed (no twin of it in demcheck)")
    if spec["rolling"] != "off":
        notes.append(f"rolling_friction {spec['rolling']}: not part of the probes (the twin has none)")
    if limit and "restitution" in asked and model in ("hertz", "hooke"):
        findings.append(Finding("trap", "limit", "limitForce on: the normal force is held ≥ 0, which raises the "
                                "restitution above coefficientRestitution", where))
    return ps
