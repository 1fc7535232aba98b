"""LIGGGHTS's contact vocabulary read back from a user's deck (``demcheck audit``): ``pair_style gran model …
tangential … [rolling_friction …] [flags]``, the ``fix property/global`` material properties, ``fix wall/gran
model … primitive type T``, ``hard_particles`` / ``soft_particles`` and ``fix particletemplate/sphere``. Every
type pair and wall × type becomes a Native that computes what LIGGGHTS-PUBLIC 3.8.0 computes for it."""

from __future__ import annotations

import math
from pathlib import Path

from ...inputs.script import (NEVER_RUN, Body, Command, note_unread, Finding, PairSetting, ScriptError,
                              Setup, _num, body, finish, read_common, to_number)
from ..base import Native
from . import read as ENGINE_READ  # the deck's set-up evaluated in LIGGGHTS itself (a worker process)

MODELS = ("hertz", "hooke", "hooke/stiffness", "hertz/stiffness")  # the probed ones (they have a twin)
OTHER_MODELS = ("luding", "edinburgh", "thornton_ning", "hooke/hysteresis", "hertz/stiffness/ttt")
TANGENTIAL = ("off", "no_history", "history")
OWN_MODULI = True  # the deck writer writes each type's own Young's modulus and Poisson's ratio

QUIET_FIXES = frozenset({"nve/sphere", "gravity", "particledistribution/discrete", "check/timestep/gran",
                         "enforce2d", "balance", "freeze"})
READ_FIXES = ("property/global", "wall/gran", "particletemplate/sphere", "particledistribution/discrete",
              "insert/pack", "insert/stream", "insert/rate/region", "mesh/surface", "mesh/surface/stress", "gravity")



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


# the range of each property a law reads: (rule, test); a value outside it is refused with its own name
RANGES = {"youngsModulus": ("must be > 0", lambda x: x > 0),
          "poissonsRatio": ("must be in [0, 0.5] (LIGGGHTS 3.8.0 stops on a negative one)", lambda x: 0.0 <= x <= 0.5),
          "coefficientRestitution": ("must be in (0, 1]", lambda x: 0.0 < x <= 1.0),
          "coefficientFriction": ("must be >= 0", lambda x: x >= 0.0),
          "characteristicVelocity": ("must be > 0", lambda x: x > 0),
          "kn": ("must be > 0", lambda x: x > 0), "kt": ("must be > 0", lambda x: x > 0),
          "gamman": ("must be >= 0", lambda x: x >= 0.0), "gammat": ("must be >= 0", lambda x: x >= 0.0)}
STIFFNESS = ("kn", "kt", "gamman", "gammat")  # what the */stiffness models read (LIGGGHTS stops without them)


class RangeError(ScriptError):
    """A property outside its range (RANGES), with its LIGGGHTS name, value and rule."""

    def __init__(self, where: str, name: str, value: float, rule: str, types: str = ""):
        super().__init__(f"{where}: {name}={value:g}{types}: {rule}")
        self.name, self.value, self.rule = name, value, rule


def _checked(props: dict, name: str, value: float, types: str) -> float:
    rule, ok = RANGES[name]
    if not (math.isfinite(value) and ok(value)):
        where = props[name][2] if name in props else "models"
        kind = props[name][0] if name in props else "scalar"
        raise RangeError(where, name, value, rule, f" ({types})" if kind != "scalar" and where != "models" else "")
    return value


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
    setup.regions = script.regions
    setup.populated |= script.engine_types  # the types LIGGGHTS's own read of the set-up gave atoms
    props: dict = {}  # name → (kind, values, where)
    style = None
    walls = []
    meshes: dict = {}  # mesh fix id → its wall type
    templates: dict = {}  # template id → (type, radius, density)
    distributions: dict = {}  # distribution id → [(template id, mass fraction)]
    hard = soft = False
    for cmd in script.commands:
        w, name = cmd.words, cmd.name
        if name in NEVER_RUN and name != "quit":
            setup.not_audited.append((cmd.where(), cmd.text, "not audited (never run by demcheck)"))
            continue
        if cmd.problem and (name in ("pair_style", "pair_coeff", "set", "timestep", "create_box")
                            or (name == "fix" and len(w) > 3 and w[3] in READ_FIXES)):
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
        style_name = w[3] if name == "fix" and len(w) > 3 else ""
        if style_name == "property/global":
            pname, kind, values = _prop(cmd, w)
            props[pname] = (kind, values, cmd.where())
        elif style_name in ("mesh/surface", "mesh/surface/stress") and "type" in w:
            meshes[w[1]] = int(_num(cmd, w.index("type") + 1, "mesh type"))
        elif style_name == "wall/gran":
            _wall(cmd, w, setup, walls, meshes)
        elif style_name == "particletemplate/sphere":
            _template(cmd, w, setup, templates)
        elif style_name == "particletemplate/multisphere":
            _clump(cmd, w, setup, templates, root)
        elif style_name == "particledistribution/discrete":
            _distribution(cmd, w, distributions)
        elif style_name.startswith("insert"):
            _insert(cmd, w, setup, templates, distributions)
        else:
            _other(cmd, setup, style_name)
    if style is None:
        raise ScriptError("the deck has no pair_style gran: nothing defines its contacts")
    finish(setup, "the default")
    if "characteristicVelocity" in props:
        setup.speeds.append((props["characteristicVelocity"][1][0], props["characteristicVelocity"][2]))
    wall_types = {t for _, t, _, _, _ in walls}
    # a wall's type is a particle type too where the deck gives it bodies (LIGGGHTS's tutorials declare their
    # primitive walls on the particles' own type: that type is both)
    types = sorted(setup.populated) or [t for t in sorted(setup.bodies) if t not in wall_types]
    _poisson_half(setup, props)
    _moduli(setup, props, hard, soft)
    spec, where = style
    for a in types:
        for b in types:
            if b >= a:
                setup.pairs.append(_pair(setup, spec, where, props, a, b, f"{a}-{b}"))
    _heat(setup, props)  # on the particle pairs
    for wspec, t_wall, fix_id, wwhere, what in walls:
        for t in types:
            ps = _pair(setup, wspec, wwhere, props, t, t_wall, f"wall {fix_id} × {t}")
            ps.j = None
            ps.wall = {"youngs_modulus": _per_type(props, "youngsModulus", t_wall),
                       "poisson_ratio": _per_type(props, "poissonsRatio", t_wall)}
            if what.startswith("mesh"):
                ps.notes.append(f"{what}: probed as a flat wall of its material (type {t_wall}); the mesh's "
                                "curvature and edges are not probed")
            setup.pairs.append(ps)
    return setup


def _other(cmd, setup, style_name: str) -> None:
    """A command the contact reading does not take: fix heat/gran[/conduction] (the heat probe's), else listed."""
    if style_name in ("heat/gran", "heat/gran/conduction"):
        setup.heat.update(fix=style_name, where=cmd.where())
    else:
        note_unread(setup, cmd, QUIET_FIXES)


def _wall(cmd, w, setup, walls, meshes) -> None:
    spec, k = parse_style(cmd, w, 4)
    if w[k:k + 1] == ["primitive"] and w[k + 1:k + 2] == ["type"]:
        t = int(_num(cmd, k + 2, "wall type"))
        shape = w[k + 3] if len(w) > k + 3 else ""
        walls.append((spec, t, w[1], cmd.where(), shape))
        if shape in ("xplane", "yplane", "zplane") and len(w) > k + 4 and to_number(w[k + 4]) is not None:
            setup.floors.append(("xyz".index(shape[0]), float(w[k + 4])))
    elif w[k:k + 1] == ["mesh"] and "meshes" in w:
        n = int(_num(cmd, w.index("n_meshes") + 1, "n_meshes")) if "n_meshes" in w else 1
        for mesh in w[w.index("meshes") + 1:w.index("meshes") + 1 + n]:
            if mesh not in meshes:
                setup.not_audited.append((cmd.where(), cmd.text, f"mesh {mesh}: its fix mesh/surface (and wall type) "
                                                                  "is not read"))
                continue
            walls.append((spec, meshes[mesh], f"{w[1]}:{mesh}", cmd.where(), f"mesh {mesh}"))
    else:
        setup.not_audited.append((cmd.where(), cmd.text, "fix wall/gran: neither a primitive nor a mesh wall"))


def _template(cmd, w, setup, templates):
    """fix ID group particletemplate/sphere seed atom_type T density constant ρ radius constant r | gaussian|
    lognormal [number|mass] μ σ …: the type's body (a distribution's mean radius for a random one)."""
    if "atom_type" not in w:
        return
    t = int(_num(cmd, w.index("atom_type") + 1, "atom_type"))
    b = body(setup, t)
    values = {}
    for key in ("density", "radius"):
        if key in w:
            i = w.index(key)
            kind = w[i + 1] if i + 1 < len(w) else ""
            if kind not in ("constant", "gaussian", "lognormal", "uniform"):
                raise _bad(cmd, f"{key} {kind}: not a LIGGGHTS template distribution")
            j = i + 2 + (w[i + 2:i + 3] in (["number"], ["mass"]))  # gaussian number μ σ: LIGGGHTS 3.8's form
            x = _num(cmd, j, key)
            if kind == "uniform":
                x = 0.5 * (x + _num(cmd, j + 1, key))
            if not x > 0:
                raise _bad(cmd, f"{key} = {x:g}: must be > 0")
            values[key] = x
            if kind != "constant":
                b.size_from = f"template {w[1]} ({kind} {key}: its mean probed)"
    b.density = values.get("density", b.density)
    b.radius = values.get("radius", b.radius)
    templates[w[1]] = (t, b.radius, b.density)


POISSON_HALF = 0.5 - 1e-9  # the probes' ν for LIGGGHTS's ν = 0.5 (the case's materials take ν < 0.5)


def _poisson_half(setup, props) -> None:
    """LIGGGHTS takes ν = 0.5 (incompressible); the probes' materials take ν < 0.5: probed at 0.5 − 1e-9 (E*
    changes by 4e-9 relative), said in a note."""
    if "poissonsRatio" not in props:
        return
    kind, values, where = props["poissonsRatio"]
    if any(v == 0.5 for v in values):
        props["poissonsRatio"] = (kind, [POISSON_HALF if v == 0.5 else v for v in values], where)
        setup.findings.append(Finding("note", "poisson-half", "poissonsRatio 0.5 is probed as 0.5 − 1e-9 (demcheck's "
                                      "materials take ν < 0.5; E* changes by 4e-9 relative)", where))


def _clump(cmd, w, setup, templates, root):
    """fix ID group particletemplate/multisphere … atom_type T density constant ρ … spheres file F scale s: a
    clump of spheres; its spheres' contacts are probed as single spheres of the file's radii (× scale)."""
    if "atom_type" not in w or "file" not in w:
        return
    t = int(_num(cmd, w.index("atom_type") + 1, "atom_type"))
    scale = _num(cmd, w.index("scale") + 1, "scale") if "scale" in w else 1.0
    path = (root / w[w.index("file") + 1]).resolve()
    if not path.is_relative_to(root) or not path.is_file():
        raise _bad(cmd, f"spheres file {w[w.index('file') + 1]!r}: no such file in the deck's directory")
    radii = []
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines()[:10_000]:
        nums = [to_number(x) for x in line.split("#", 1)[0].split()]
        if len(nums) >= 4 and None not in nums[:4] and nums[3] > 0:
            radii.append(nums[3] * scale)
    if not radii:
        raise _bad(cmd, "the spheres file gives no sphere (x y z r per line)")
    b = body(setup, t)
    if "density" in w and w[w.index("density") + 1:w.index("density") + 2] == ["constant"]:
        b.density = _num(cmd, w.index("density") + 2, "density")
    b.radius = max(radii)
    templates[w[1]] = (t, b.radius, b.density)
    b.sizes = [(r, r ** 3) for r in radii] if len(set(radii)) > 1 else []
    b.size_from = f"multisphere template {w[1]} (its spheres probed as single spheres; the clump's rigidity is not)"


def _distribution(cmd, w, distributions):
    """fix ID group particledistribution/discrete seed N template1 fraction1 …: mass fractions (LIGGGHTS's)."""
    n = int(_num(cmd, 5, "number of templates"))
    distributions[w[1]] = [(w[6 + 2 * i], _num(cmd, 7 + 2 * i, "fraction")) for i in range(n)]


def _insert(cmd, w, setup, templates, distributions):
    """fix ID group insert/pack|stream|rate/region … distributiontemplate D … vel constant vx vy vz region R: the
    types it inserts (with every size of its distribution), their initial velocity, the insertion region."""
    vel = [0.0, 0.0, 0.0]
    if "vel" in w and w[w.index("vel") + 1:w.index("vel") + 2] == ["constant"]:
        i = w.index("vel") + 2
        vel = [_num(cmd, i + d, "vel") for d in range(3)]
        setup.speeds.append((math.sqrt(sum(x * x for x in vel)), cmd.where()))
    region = w[w.index("region") + 1] if "region" in w and w.index("region") + 1 < len(w) else None
    dist = w[w.index("distributiontemplate") + 1] if "distributiontemplate" in w else None
    types = []
    for template, fraction in distributions.get(dist, []):
        if template not in templates:
            continue
        t, r, rho = templates[template]
        types.append(t)
        setup.populated.add(t)
        b = body(setup, t)
        if "multisphere" not in b.size_from:
            b.sizes.append((r, fraction))
            b.size_from = f"distribution {dist} ({cmd.where()})"
    setup.insertions.append((region, [abs(vel[0]), abs(vel[1]), abs(vel[2])], types, cmd.where()))


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
    pair = f"types {a} {b}"
    for pname, key in PER_PAIR.items():
        v = _pair_value(props, pname, a, b)
        if v is not None:
            p[key] = v
    if model in ("hertz", "hooke"):
        ea, eb = _per_type(props, "youngsModulus", a), _per_type(props, "youngsModulus", b)
        na, nb = _per_type(props, "poissonsRatio", a), _per_type(props, "poissonsRatio", b)
        if None in (ea, eb, na, nb):
            raise ScriptError(f"{where}: model {model} needs youngsModulus and poissonsRatio for types {a} and {b}")
        for name, t, v in (("youngsModulus", a, ea), ("youngsModulus", b, eb), ("poissonsRatio", a, na),
                           ("poissonsRatio", b, nb)):
            _checked(props, name, v, f"type {t}")
        p["youngs_eff"] = 1.0 / ((1 - na * na) / ea + (1 - nb * nb) / eb)
        p["shear_eff"] = 1.0 / (2 * (2 - na) * (1 + na) / ea + 2 * (2 - nb) * (1 + nb) / eb)
        if "restitution" not in p:
            raise ScriptError(f"{where}: model {model} needs coefficientRestitution")
        asked["restitution"] = _checked(props, "coefficientRestitution", p["restitution"], pair)
        if model == "hooke":
            if "characteristicVelocity" not in props:
                raise ScriptError(f"{where}: model hooke needs characteristicVelocity")
            p["characteristic_velocity"] = _checked(props, "characteristicVelocity",
                                                    props["characteristicVelocity"][1][0], pair)
            notes.append("model hooke: kn is set by characteristicVelocity, m̄ and R̄ (not directly), kt = kn")
    elif model in ("hooke/stiffness", "hertz/stiffness"):
        missing = [n for n in STIFFNESS if n not in p]
        if missing:
            raise ScriptError(f"{where}: model {model} needs {', '.join(missing)} (LIGGGHTS stops without them)")
        for name in STIFFNESS:
            _checked(props, name, p[name], pair)
    if tang != "off":
        if "friction" not in p:
            raise ScriptError(f"{where}: tangential {tang} needs coefficientFriction")
        asked["friction"] = _checked(props, "coefficientFriction", p["friction"], pair)
    else:
        notes.append("tangential off (LIGGGHTS's default): no friction at all")
    for key in STIFFNESS:  # read by the */stiffness models only
        p.setdefault(key, 0.0)
    nat = Native("liggghts", model, limit=limit, tangential=tang, props=p,
                 tangential_damping=flags.get("tangential_damping", True))
    ps = PairSetting(label, a, b, nat, where, asked, notes=notes, findings=findings)
    if model not in MODELS or tang == "tan_luding":
        ps.probe = False
        notes.append(f"model {model} / tangential {tang}: listed, not probed (no twin of it in demcheck)")
    ps.beyond = _beyond(spec, props, a, b)
    for key, word, prop in (("rolling", "rolling_friction", "coefficientRollingFriction"),
                            ("cohesion", "cohesion", "cohesionEnergyDensity")):
        if spec[key] == "off" and prop in props:
            notes.append(f"{prop} is set ({props[prop][2]}) but the style has no {word} model: LIGGGHTS applies "
                         "none, and none is probed")
        if spec[key] != "off":
            notes.append(f"{word} {spec[key]}: the collision probes run without it; its own probe is audit's "
                         "beyond-sliding probe (comparisons/audit_beyond.py)")
    if not flags.get("tangential_damping", True) and tang != "off":
        notes.append("tangential_damping off: no tangential dashpot (the seed's TTIt has one); the probes run "
                     "without it")
    if limit and "restitution" in asked and model in ("hertz", "hooke"):
        findings.append(Finding("trap", "limit", "limitForce on: the normal force is held ≥ 0, which raises the "
                                "restitution above coefficientRestitution", where))
    return ps


# the audit's probe of each sub-model beyond sliding (comparisons/audit_beyond.py MAKERS)
BEYOND_PROBES = {"rolling": "rolling_cdt_epsd3", "adhesion": "pull_off_sjkr", "heat": "held_pair"}
ROLLING_PROPS = ("coefficientRollingFriction", "rollingStiffness", "coefficientRollingViscousDamping")


def _beyond(spec: dict, props: dict, a: int, b: int) -> dict:
    """The sub-models beyond sliding of a pair (or wall) style: rolling_friction with its property/global values
    (coefficientRollingFriction, rollingStiffness, coefficientRollingViscousDamping: None where the deck has none),
    cohesion sjkr/sjkr2 with cohesionEnergyDensity (comparisons/audit_beyond.py probes them)."""
    out = {}
    if spec["rolling"] != "off":
        args = tuple(_pair_value(props, n, a, b) for n in ROLLING_PROPS)
        out["rolling"] = {"law": spec["rolling"], "args": args,
                          "words": f"rolling_friction {spec['rolling']} (" + ", ".join(
                              f"{n} {v:g}" for n, v in zip(ROLLING_PROPS, args) if v is not None) + ")"}
    if spec["cohesion"] != "off":
        kc = _pair_value(props, "cohesionEnergyDensity", a, b)
        out["adhesion"] = {"law": spec["cohesion"], "args": (kc,),
                           "words": f"cohesion {spec['cohesion']} (cohesionEnergyDensity "
                                    + ("not set" if kc is None else f"{kc:g}") + ")"}
    return out


def _heat(setup: Setup, props: dict) -> None:
    """fix heat/gran[/conduction]: the conductivities and capacities per type it reads (property/global
    thermalConductivity, thermalCapacity), kept for the heat probe of each pair."""
    if not setup.heat:
        return
    for name, key in (("thermalConductivity", "k"), ("thermalCapacity", "cp")):
        if name in props:
            kind, values, _ = props[name]
            setup.heat[key] = {t: v for t, v in enumerate(values, 1)} if kind == "peratomtype" else {}
            if kind == "scalar":
                setup.heat[f"{key}_all"] = values[0]
    for ps in setup.pairs:  # the particle pairs (a wall conducts only with its own temperature set)
        ps.beyond["heat"] = {"law": "lens", "args": (), "words": f"fix {setup.heat['fix']} "
                             f"({setup.heat['where']}; thermalConductivity and thermalCapacity per type)"}


# ----------------------------------------------------------------------------- reverse lookup

REVERSE_PROPERTIES = ("youngsModulus", "poissonsRatio", "coefficientRestitution", "coefficientFriction",
                      "characteristicVelocity", "kn", "kt", "gamman", "gammat")
REVERSE_SWITCHES = ("hard_particles", "soft_particles")
# what LIGGGHTS 3.8.0 stops without, per model (its property/global lookups), and per tangential model
NEEDS = {"hertz": ("youngsModulus", "poissonsRatio", "coefficientRestitution"),
         "hooke": ("youngsModulus", "poissonsRatio", "coefficientRestitution", "characteristicVelocity"),
         "hooke/stiffness": ("kn", "kt", "gamman", "gammat"), "hertz/stiffness": ("kn", "kt", "gamman", "gammat")}
REVERSE_SYNTAX = ("the pair_style gran arguments, then the property/global values of a like pair as NAME=VALUE: "
                  "\"model hertz tangential history coefficientRestitution=0.6 coefficientFriction=0.5 "
                  "youngsModulus=63e9 poissonsRatio=0.24 hard_particles=yes\"")


def reverse(line: str, setup: Setup | None = None) -> PairSetting:
    """``[pair_style] [gran] model M tangential T [flag on|off …] NAME=VALUE …`` — the ``pair_style gran``
    arguments, then the ``fix property/global`` values of a like pair (one number each: youngsModulus,
    poissonsRatio, coefficientRestitution, coefficientFriction, characteristicVelocity, kn, kt, gamman,
    gammat) and ``hard_particles=yes|no``, ``soft_particles=yes|no`` — as the pair setting of two bodies of
    one type, with its static traps (``demcheck models --engine liggghts "…"``). ``setup`` receives the type's
    moduli and the deck-wide findings (hard-particles). What LIGGGHTS would stop without is one ScriptError."""
    setup = setup if setup is not None else Setup("liggghts")
    words = line.split()
    words = words[1:] if words[:1] == ["pair_style"] else words
    words = words[1:] if words[:1] == ["gran"] else words
    style = [w for w in words if "=" not in w]
    cmd = Command(["pair_style", "gran", *style], "models", 1, line)
    spec, k = parse_style(cmd, cmd.words, 2)
    if k != len(cmd.words):
        raise _bad(cmd, f"{cmd.words[k]!r} is not a keyword of pair_style gran (a property is NAME=VALUE)")
    props: dict = {}
    unread = []
    switches = {"hard_particles": False, "soft_particles": False}
    for w in words:
        if "=" not in w:
            continue
        name, _, text = w.partition("=")
        if name in REVERSE_SWITCHES:
            if text not in ("yes", "no", "on", "off"):
                raise _bad(cmd, f"{name}={text}: takes yes or no")
            switches[name] = text in ("yes", "on")
            continue
        if name not in REVERSE_PROPERTIES:  # a property of a sub-model the twin has none of: noted, not failed
            if not name.isidentifier() or to_number(text) is None:  # a property/global value is a number
                raise _bad(cmd, f"{name[:40]}: not a property read here ({', '.join(REVERSE_PROPERTIES)}), and "
                                f"{text[:40]!r} is not a property/global number")
            unread.append(f"{name}={text[:40]}: not read by the lookup (the twin has no {name}; "
                          f"it reads {', '.join(REVERSE_PROPERTIES)})")
            continue
        if name in props:
            raise _bad(cmd, f"{name} is given twice")
        c = Command(["fix", "p", "all", "property/global", name, "scalar", text], "models", 1, w)
        value = _num(c, 6, name)
        if not math.isfinite(value):
            raise _bad(cmd, f"{name}={text}: must be a finite number")
        props[name] = ("scalar", [value], "models")
    if spec["model"] in MODELS:
        missing = [n for n in NEEDS[spec["model"]] if n not in props]
        if spec["tangential"] != "off" and "coefficientFriction" not in props:
            missing.append("coefficientFriction")
        if missing:
            raise _bad(cmd, f"model {spec['model']} tangential {spec['tangential']} needs "
                            + ", ".join(f"{n}=…" for n in missing) + " (LIGGGHTS stops without them)")
    for name in ("youngsModulus", "poissonsRatio"):  # one type: per-type values
        if name in props:
            props[name] = ("peratomtype", props[name][1], "models")
    if "poissonsRatio" in props and not 0.0 <= props["poissonsRatio"][1][0] <= 0.5:
        raise _bad(cmd, f"poissonsRatio={props['poissonsRatio'][1][0]:g}: must be in [0, 0.5] (LIGGGHTS 3.8.0 stops "
                        "on a negative one)")
    for name in ("youngsModulus", "characteristicVelocity"):
        if name in props and not props[name][1][0] > 0:
            raise _bad(cmd, f"{name}={props[name][1][0]:g}: must be > 0")
    if "coefficientRestitution" in props and not 0.0 < props["coefficientRestitution"][1][0] <= 1.0:
        raise _bad(cmd, f"coefficientRestitution={props['coefficientRestitution'][1][0]:g}: must be in (0, 1]")
    setup.bodies.setdefault(1, Body(1))
    _moduli(setup, props, switches["hard_particles"], switches["soft_particles"])
    for f in setup.findings:
        f.where = "models"
    try:
        ps = _pair(setup, spec, "models", props, 1, 1, "1-1")  # its notes name rolling friction and cohesion
    except ScriptError as exc:
        raise _bad(cmd, str(exc).removeprefix("models: ")) from None
    for flag in spec["flags"]:
        if flag not in CASE_FLAGS:
            ps.notes.append(f"{flag}: not part of the lookup (the twin reads {', '.join(CASE_FLAGS)})")
    ps.notes += unread
    return ps


# ----------------------------------------------------------------------------- native settings in case files

CASE_PROPERTIES = ("coefficientRestitution", "coefficientFriction", "characteristicVelocity", "kn", "kt", "gamman",
                   "gammat")
CASE_FLAGS = ("limitForce", "tangential_damping")
RIGID_WALL_MODULUS = 1e30  # the deck writer's rigid wall type (deck.RIGID_WALL_MODULUS)


def native_from_case(table: dict, case) -> Native:
    """A case's ``[engine.liggghts]`` table as the Native of its contact: ``pair_style`` = ``gran model M
    tangential T [limitForce on|off] [tangential_damping on|off]`` (the leading ``gran`` optional) and the
    scalar properties of ``fix property/global`` (coefficientRestitution, coefficientFriction,
    characteristicVelocity, kn, kt, gamman, gammat) as text; youngsModulus and poissonsRatio are the case's
    materials' (a rigid wall: LIGGGHTS's 1e30 Pa wall type), and restitution and friction default to the
    materials' when the bodies share them. Read by the deck reader's own parsers; the deck is written from the
    parsed numbers."""
    from ...errors import ConfigError

    for key in table:
        if key != "pair_style" and key not in CASE_PROPERTIES:
            raise ConfigError(f"engine.liggghts.{key}", table[key], "is not a setting read here (pair_style, "
                              + ", ".join(CASE_PROPERTIES) + "; youngsModulus and poissonsRatio come from [materials])")
    spec = _case_style(table)
    text = table["pair_style"]
    props = _case_properties(table)
    _material_properties(case, props)
    if spec["model"] in ("hooke/stiffness", "hertz/stiffness"):
        missing = [n for n in STIFFNESS if n not in table]
        if missing:
            raise ConfigError(f"engine.liggghts.{missing[0]}", None, f"model {spec['model']} needs "
                              f"{', '.join(STIFFNESS)} (LIGGGHTS stops without them)")
    try:
        ps = _pair(Setup("liggghts"), spec, "engine.liggghts", props, 1, 2, "contact")
    except RangeError as exc:
        if exc.name in table:
            raise ConfigError(f"engine.liggghts.{exc.name}", table[exc.name], exc.rule) from None
        raise ConfigError(f"engine.liggghts.{exc.name}", None, f"{exc.rule}: {props[exc.name][2]} gives "
                          f"{exc.value:g}; give {exc.name} here") from None
    except ScriptError as exc:
        raise ConfigError("engine.liggghts", sorted(table), str(exc).split(": ", 1)[-1]) from None
    if not ps.probe:
        raise ConfigError("engine.liggghts.pair_style", text, f"model {spec['model']} / tangential "
                          f"{spec['tangential']}: demcheck has no twin of it (it runs {', '.join(MODELS)})")
    from .mapping import twin

    try:
        twin(ps.native, 1.0, 1.0)
    except (ValueError, ArithmeticError) as exc:
        raise ConfigError("engine.liggghts", sorted(table), f"no twin: {exc}") from None
    ps.native.comments.append("the case's own native setting ([engine.liggghts])")
    return ps.native


def _case_style(table: dict) -> dict:
    """The ``pair_style`` of a case's [engine.liggghts] table, parsed by the deck reader; what the deck writer
    does not write is refused by key."""
    from ...errors import ConfigError

    if "pair_style" not in table:
        raise ConfigError("engine.liggghts.pair_style", None, "missing: \"gran model M tangential T\"")
    text = table["pair_style"]
    words = text.split()
    words = words[1:] if words[:1] == ["gran"] else words
    cmd = Command(["pair_style", "gran", *words], "engine.liggghts.pair_style", 1, text)
    try:
        spec, k = parse_style(cmd, cmd.words, 2)
        if k != len(cmd.words):
            raise _bad(cmd, f"{cmd.words[k]!r} is not a keyword of pair_style gran")
    except ScriptError as exc:
        raise ConfigError("engine.liggghts.pair_style", text, str(exc).split(": ", 2)[-1]) from None
    for key in spec["flags"]:
        if key not in CASE_FLAGS:
            raise ConfigError("engine.liggghts.pair_style", text, f"flag {key}: demcheck's deck writes "
                              f"{', '.join(CASE_FLAGS)} only")
    for key in ("rolling", "cohesion"):
        if spec[key] != "off":
            raise ConfigError("engine.liggghts.pair_style", text, f"{key} {spec[key]}: demcheck's twin has none "
                                                                  "(leave it out)")
    if spec.get("surface", "off") not in ("off", "default"):
        raise ConfigError("engine.liggghts.pair_style", text, f"surface {spec['surface']}: not read here")
    return spec


def _case_properties(table: dict) -> dict:
    """The scalar properties of a case's [engine.liggghts] table, each read as its fix property/global line."""
    from ...errors import ConfigError

    props: dict = {}
    for name in CASE_PROPERTIES:
        if name in table:
            c = Command(["fix", "p", "all", "property/global", name, "scalar", *table[name].split()],
                        f"engine.liggghts.{name}", 1, table[name])
            try:
                if len(c.words) != 7:
                    raise _bad(c, "one number")
                props[name] = ("scalar", [_num(c, 6, name)], c.file)
            except ScriptError as exc:
                raise ConfigError(f"engine.liggghts.{name}", table[name], str(exc).split(": ", 2)[-1]) from None
    return props


def _material_properties(case, props: dict) -> None:
    """Restitution and friction from the case's materials where the table leaves them out (the bodies must share
    them), and youngsModulus and poissonsRatio per atom type from the materials (a rigid wall: LIGGGHTS's wall
    modulus)."""
    from ...errors import ConfigError

    mats = [case.materials[p.material] for p in case.particles]
    walls = list(case.walls)
    for name, attr in (("coefficientRestitution", "restitution"), ("coefficientFriction", "friction")):
        if name in props:
            continue
        own = {getattr(m, attr) for m in mats} | ({getattr(case.materials[w.material], attr) for w in walls
                                                   if w.material} - {None})
        if len(own) == 1 and None not in own:
            props[name] = ("scalar", [next(iter(own))], f"materials' {attr}")
        elif len(own) > 1:
            raise ConfigError(f"engine.liggghts.{name}", None, f"the bodies' materials differ in {attr}: give it "
                                                                 "here")
    moduli = [m.youngs_modulus for m in mats]
    ratios = [m.poisson_ratio for m in mats]
    if walls:
        w = walls[0]
        if w.rigid:
            moduli.append(RIGID_WALL_MODULUS)
            ratios.append(ratios[0])
        else:
            moduli.append(case.materials[w.material].youngs_modulus)
            ratios.append(case.materials[w.material].poisson_ratio)
    props["youngsModulus"] = ("peratomtype", moduli, "materials")
    props["poissonsRatio"] = ("peratomtype", ratios, "materials")
