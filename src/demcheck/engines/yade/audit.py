"""A Yade script read back for ``demcheck audit``, from its syntax tree (pyread.py): never executed or imported.

Read: the materials appended to ``O.materials`` (FrictMat, ViscElMat, … with their literal or arithmetically
evaluable keywords, ``**dict`` included, and simple name bindings), the spheres and walls appended to
``O.bodies`` (``sphere(center, radius, material=…)``, ``wall``, ``facet``, ``box``) with their ``state.vel``,
``O.engines``' InteractionLoop (its Ip2 and Law2 functors with their keywords) and NewtonIntegrator (damping —
0.2 when not given, Yade's default — and gravity), and ``O.dt`` (a number, or a factor of ``PWaveTimeStep()``,
which Yade computes at run time as min r/√(E/ρ) over the spheres: evaluated here from the spheres read, and
said so). Everything else the contact probes would need and the script computes at run time is listed as not
read. Each pair of the spheres' materials, and each wall's material with each sphere material, becomes a Native
of Yade 2023.02a where a twin exists: ViscElPhys (kn, cn, ks, cs given) and MindlinPhys (its normal law, with
betan); the others are listed, not probed, with the reason.
"""

from __future__ import annotations

import ast
import math
import re
from pathlib import Path

from ...inputs.script import Body, Finding, PairSetting, ScriptError, Setup
from ..base import Native
from .mapping import MINDLIN, VISCEL
from .deck import CUNDALL
from .pyread import Call, Evaluator, Unknown, _dotted, _number, parse

OWN_MODULI = False
# Yade 2023.02a's defaults for what a script does not give (Material.density, ElastMat.young/poisson,
# FrictMat.frictionAngle; utils.defaultMaterial() when no material exists; NewtonIntegrator.damping)
DEFAULT_MATERIAL = {"density": 1000.0, "young": 1e9, "poisson": 0.25, "frictionAngle": 0.5}
UTILS_DEFAULT = Call("FrictMat", [], {"density": 1e3, "young": 1e7, "poisson": 0.3, "frictionAngle": 0.5,
                                     "label": "defaultMat"}, 0)
NEWTON_DAMPING = 0.2
DEFAULT_DT = 1e-8
WALLS = ("wall", "facet", "box", "facetBox", "facetCylinder")
MATERIAL_KEYS = frozenset({"young", "poisson", "density", "frictionAngle", "kn", "cn", "ks", "cs", "tc", "en", "et",
                           "label", "material"})  # what the probes read from a material
PACKS = ("regularHexa", "regularOrtho")  # pack.regular*(predicate, radius=…, gap=…, material=…)
FRICT_FAMILY = ("FrictMat", "ViscElMat", "CohFrictMat", "FrictViscoMat", "ViscElCapMat", "MortarMat")
# the audit's probe of each sub-model beyond sliding (comparisons/audit_beyond.py MAKERS): Mindlin's DMT
# (Ip2_FrictMat_FrictMat_MindlinPhys gamma + includeAdhesion) and ThermalEngine's conduction (engines/yade/pair.py)
BEYOND_PROBES = {"adhesion": "pull_off", "heat": "held_pair"}
THERMAL_DEFAULTS = {"particleK": 3.0, "particleCp": 750.0, "particleDensity": 0.0}  # ThermalEngine's, 2023.02a


def claims(script) -> bool:
    return False  # a LAMMPS-language deck is never a Yade script


def claims_file(path: Path) -> bool:
    return path.suffix.lower() == ".py"


class _State:
    def __init__(self, name: str):
        self.name = name
        self.ev = Evaluator()
        self.materials: list = []  # Call records in O.materials order
        self.bodies: list = []  # Call records in O.bodies order (None: bodies the script makes at run time)
        self.engines = None
        self.dt = None  # the O.dt expression node
        self.dt_line = 0
        self.unread: list = []  # (where, text, why)
        self.omega = {"O"}


def read_file(path: Path) -> Setup:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise ScriptError(f"{path.name}: cannot be read ({exc.strerror})") from None
    tree = parse(text, path.name)
    st = _State(path.name)
    _walk(tree.body, st, "")
    setup = Setup("yade", units="si", units_where="Yade: SI units")
    setup.not_audited += st.unread
    laws = _engines(st, setup)
    types = _bodies(st, setup)
    _dt(st, setup, types)
    _pairs(st, setup, types, laws)
    return setup


# ----------------------------------------------------------------------------- the walk

def _walk(stmts, st: _State, why: str) -> None:
    """``why``: "" at top level; else why a name bound here is not known (a loop, a condition)."""
    for s in stmts:
        try:
            _statement(s, st, why)
        except RecursionError:
            st.unread.append((f"{st.name}:{getattr(s, 'lineno', '?')}", "", "nested too deep to read"))


def _statement(s, st: _State, why: str) -> None:
    where = f"{st.name}:{s.lineno}"
    if isinstance(s, ast.Assign):
        value = _effect(s.value, st)
        for t in s.targets:
            _assign(t, value, st, why, where, s.value)
    elif isinstance(s, (ast.AugAssign, ast.AnnAssign)):
        if isinstance(s.target, ast.Name):
            st.ev.names[s.target.id] = Unknown(f"{where}: {s.target.id} changes as the script runs")
        elif _dotted(s.target) in {f"{o}.engines" for o in st.omega} and isinstance(s.op, ast.Add):
            add = st.ev(s.value)
            st.engines = st.engines + add if isinstance(st.engines, tuple) and isinstance(add, tuple) and not why \
                else Unknown(f"{where}: O.engines extended at run time")
            for o in st.omega:
                st.ev.attrs[f"{o}.engines"] = st.engines
        elif _dotted(s.target) in {f"{o}.dt" for o in st.omega}:
            st.dt, st.dt_line = None, s.lineno
            st.unread.append((where, "O.dt", "changed as the script runs"))
    elif isinstance(s, ast.Expr):
        _effect(s.value, st)
    elif isinstance(s, (ast.For, ast.AsyncFor, ast.While)):
        for n in ast.walk(s.target) if isinstance(s, (ast.For, ast.AsyncFor)) else []:
            if isinstance(n, ast.Name):
                st.ev.names[n.id] = Unknown(f"{where}: {n.id} is a loop variable")
        _walk(s.body, st, why or f"{where}: bound inside a loop")
        _walk(s.orelse, st, why or f"{where}: bound inside a loop")
    elif isinstance(s, ast.If):
        _walk(s.body, st, why or f"{where}: bound under a condition")
        _walk(s.orelse, st, why or f"{where}: bound under a condition")
    elif isinstance(s, (ast.With, ast.AsyncWith)):
        _walk(s.body, st, why)
    elif isinstance(s, ast.Try):
        for block in (s.body, s.orelse, s.finalbody):
            _walk(block, st, why)
    elif isinstance(s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        st.ev.names[s.name] = Unknown(f"{where}: {s.name} is a function of the script")


def _assign(t, value, st: _State, why: str, where: str, node=None) -> None:
    if isinstance(t, ast.Name):
        if isinstance(value, Call) and value.name == "Omega":
            st.omega.add(t.id)
        st.ev.names[t.id] = Unknown(why) if why and not isinstance(value, Call) else value
        return
    if isinstance(t, (ast.Tuple, ast.List)):
        for k, e in enumerate(t.elts):
            v = value[k] if isinstance(value, tuple) and len(value) == len(t.elts) else Unknown(f"{where}: unpacked")
            _assign(e, v, st, why, where)
        return
    dotted = _dotted(t) or ""
    omega = {o for o in st.omega}
    if dotted in {f"{o}.engines" for o in omega}:
        st.engines = Unknown(f"{where}: O.engines set {why}") if why else value
        for o in omega:
            st.ev.attrs[f"{o}.engines"] = st.engines
    elif dotted in {f"{o}.dt" for o in omega}:
        st.dt, st.dt_line = (None if why else node), int(where.rsplit(":", 1)[1])
        if why:
            st.unread.append((where, "O.dt", f"set inside a loop or under a condition ({why})"))
    elif isinstance(t, ast.Attribute) and t.attr in ("vel", "angVel"):
        body = _body_of(t.value, st)
        if body is not None:
            body.attrs[t.attr] = value
        else:
            st.unread.append((where, f"{dotted or '…'} = …", "the body is chosen at run time"))


def _body_of(node, st: _State):
    """The Call record of the body ``node.state`` names: ``O.bodies[k]`` (k literal or bound to an id), or a
    name bound to a sphere call or an id."""
    if not (isinstance(node, ast.Attribute) and node.attr == "state"):
        return None
    b = node.value
    if isinstance(b, ast.Subscript) and _dotted(b.value) in {f"{o}.bodies" for o in st.omega}:
        k = st.ev(b.slice)
    else:
        k = st.ev(b)
    if isinstance(k, Call):
        return k
    if isinstance(k, int) and not isinstance(k, bool) and -len(st.bodies) <= k < len(st.bodies):
        return st.bodies[k]
    return None


def _effect(node, st: _State):
    """The value of an expression, with the side effects the audit reads: O.materials.append, O.bodies.append
    (their ids are the values)."""
    if isinstance(node, ast.Call):
        name = _dotted(node.func) or ""
        owner, _, method = name.rpartition(".")
        if owner in {f"{o}.materials" for o in st.omega} and method == "append" and node.args:
            mat = st.ev(node.args[0])
            if isinstance(mat, Call):
                st.materials.append(mat)
                return len(st.materials) - 1
            st.unread.append((f"{st.name}:{node.lineno}", "O.materials.append(…)", "a material made at run time"))
            st.materials.append(None)
            return Unknown("a material made at run time")
        if owner in {f"{o}.bodies" for o in st.omega} and method in ("append", "appendClumped") and node.args:
            return _append_bodies(st.ev(node.args[0]), st, node.lineno)
    value = st.ev(node)
    if isinstance(value, Call) and value.name == "makeCloud":
        st.cloud = value
    elif isinstance(value, Call) and value.name == "toSimulation":
        cloud = getattr(st, "cloud", None)
        r = None
        if cloud is not None:
            r = cloud.kw.get("rMean", cloud.args[2] if len(cloud.args) > 2 else None)
        kw = {"__material_at__": len(st.materials) - 1, "__from__": "makeCloud(rMean)"}
        if "material" in value.kw:
            kw["material"] = value.kw["material"]
        st.bodies.append(Call("sphere", [None, r], kw, value.line))
    return value


def _append_bodies(value, st: _State, line: int):
    items = value if isinstance(value, tuple) else (value,)
    ids = []
    for v in items:
        if isinstance(v, Call) and v.name in PACKS and _number(v.kw.get("radius")):  # a pack of equal spheres
            v = Call("sphere", [None, v.kw["radius"]], dict(v.kw), v.line)
        if isinstance(v, Call) and (v.name == "sphere" or v.name in WALLS):
            v.kw.setdefault("__material_at__", len(st.materials) - 1)
            st.bodies.append(v)
            ids.append(len(st.bodies) - 1)
        else:
            st.unread.append((f"{st.name}:{line}", "O.bodies.append(…)", "bodies the script computes at run time "
                              "(a pack, an import, a loop's result): their sizes and materials are not read"))
            st.bodies.append(None)
            ids.append(Unknown("a body made at run time"))
    return ids[0] if not isinstance(value, tuple) else tuple(ids)


# ----------------------------------------------------------------------------- what was read

def _calls(value) -> list:
    if isinstance(value, Call):
        return [value]
    if isinstance(value, tuple):
        return [c for v in value for c in _calls(v)]
    return []


def _engines(st: _State, setup: Setup) -> dict:
    """{"ip2": [Call], "law2": [Call]} of O.engines' InteractionLoop; NewtonIntegrator's damping and gravity."""
    out = {"ip2": [], "law2": [], "thermal": None}
    where = f"{st.name}: O.engines"
    if st.engines is None or not isinstance(st.engines, tuple):
        setup.not_audited.append((where, "O.engines", "not given literally at the top level: the contact laws "
                                  "are not read"))
        return out
    engines = [e for e in st.engines if isinstance(e, Call)]
    for e in st.engines:
        if not isinstance(e, Call):
            setup.not_audited.append((where, "an engine", f"computed at run time ({getattr(e, 'why', e)})"))
    for e in engines:
        if e.name == "InteractionLoop":
            lists = list(e.args) + [e.kw.get(k) for k in ("geomDispatcher", "physDispatcher", "lawDispatcher")
                                    if k in e.kw]
            out["ip2"] = [c for c in _calls(tuple(lists[1:2])) if c.name.startswith("Ip2_")]
            out["law2"] = [c for c in _calls(tuple(lists[2:3])) if c.name.startswith("Law2_")]
        elif e.name == "NewtonIntegrator":
            _newton(e, setup, f"{st.name}:{e.line}")
        elif e.name == "ThermalEngine" and e.kw.get("dead") in (None, False, 0):
            out["thermal"] = e  # the heat probe's (_thermal)
        elif e.name in ("GlobalStiffnessTimeStepper", "TimeStepper"):
            setup.not_audited.append((f"{st.name}:{e.line}", e.name, "changes O.dt at run time: the probes take "
                                      "the script's O.dt"))
        elif e.name not in ("ForceResetter", "InsertionSortCollider", "PyRunner", "VTKRecorder", "qtRecorder"):
            setup.not_audited.append((f"{st.name}:{e.line}", e.name, "an engine the contact probes do not include"))
    return out


def _newton(e: Call, setup: Setup, where: str) -> None:
    damping = e.kw.get("damping", NEWTON_DAMPING)
    g = e.kw.get("gravity", (0.0, 0.0, 0.0))
    if isinstance(g, tuple) and len(g) == 3 and all(_number(x) for x in g):
        mag = math.sqrt(sum(x * x for x in g))
        if mag > 0:
            setup.gravity = (mag, max(range(3), key=lambda k: abs(g[k])), f"{where}: NewtonIntegrator gravity")
    elif "gravity" in e.kw:
        setup.not_audited.append((where, "NewtonIntegrator gravity", "computed at run time"))
    if not _number(damping):
        setup.not_audited.append((where, "NewtonIntegrator damping", "computed at run time"))
    elif damping > 0:
        setup.newton_damping = (float(damping), where, "damping" not in e.kw)
        setup.findings.append(Finding(
            "note", "newton-damping",
            f"NewtonIntegrator damping = {damping:g}" + (" (Yade's default: the script does not set it)"
                                                          if "damping" not in e.kw else "")
            + ": Cundall's non-viscous damping scales every body's force by 1 ∓ damping (against or along its "
            "velocity) on top of the contact law; it lowers the rebound (measured, docs/findings.md: a Mindlin wall "
            "impact with en = 0.7 realises 0.5721 with damping 0.2, 0.6996 without). The probes run without it; with "
            "engine runs each head-on probe is run again with it and the effect is a trap of its pair", where,
            {"damping": damping}))


def _material(body: Call, st: _State):
    """The material Call of a body: material=k (index), a label, a material object, or the last one appended
    before the body (Yade's material=-1), else utils.defaultMaterial()."""
    m = body.kw.get("material", -1)
    at = body.kw.get("__material_at__", len(st.materials) - 1)
    if isinstance(m, Call):
        return m, f"{m.name} (line {m.line})"
    if isinstance(m, str):
        for k, c in enumerate(st.materials):
            if isinstance(c, Call) and c.kw.get("label") == m:
                return c, k
        return None, f"label {m!r} not found"
    if isinstance(m, int) and not isinstance(m, bool):
        k = m if m >= 0 else at + 1 + m
        if m < 0 and at < 0:
            return UTILS_DEFAULT, "defaultMat"
        if 0 <= k < len(st.materials):
            c = st.materials[k]
            return (c, k) if c is not None else (None, f"material {k} is made at run time")
        return None, f"material {m} does not exist when the body is made"
    return None, f"material {getattr(m, 'why', m)}"


def _bodies(st: _State, setup: Setup) -> dict:
    """{material key: (type, Call)}; each sphere material's Body (its mass-weighted radius: sizes are probed at
    one radius, said so), placed spheres' positions and velocities, and the walls' materials."""
    types, radii = {}, {}
    setup.walls_yade = []
    for k, b in enumerate(st.bodies):
        if b is None:
            continue
        mat, key = _material(b, st)
        where = f"{st.name}:{b.line}"
        if mat is None:
            setup.not_audited.append((where, f"{b.name}(…)", f"its material is not read ({key})"))
            continue
        t = types.setdefault(id(mat), (len(types) + 1, mat, key))[0]
        if b.name in WALLS:
            setup.walls_yade.append((t, b.name, where))
            continue
        r = b.kw.get("radius", b.args[1] if len(b.args) > 1 else None)
        if not (_number(r) and r > 0):
            setup.not_audited.append((where, "sphere(…)", f"its radius is not read ({getattr(r, 'why', r)})"))
            continue
        radii.setdefault(t, []).append(r)
        center = b.kw.get("center", b.args[0] if b.args else None)
        vel = b.attrs.get("vel", (0.0, 0.0, 0.0))
        if isinstance(vel, tuple) and len(vel) == 3 and all(_number(x) for x in vel):
            s = math.sqrt(sum(x * x for x in vel))
            if s > 0:
                setup.speeds.append((s, f"{where}: body {k}'s state.vel"))
        else:
            setup.not_audited.append((where, "state.vel", f"computed at run time ({getattr(vel, 'why', vel)})"))
            vel = None
        if isinstance(center, tuple) and len(center) == 3 and all(_number(x) for x in center) \
                and len(setup.atoms) < 100_000:
            setup.atoms[k] = [t, list(center), list(vel) if vel else None]
    for t, rs in radii.items():
        mat = next(m for (tt, m, _) in types.values() if tt == t)
        rho = _get(mat, "density")
        body = setup.bodies.setdefault(t, Body(t, density=rho))
        body.radius = sum(r ** 4 for r in rs) / sum(r ** 3 for r in rs)
        if len(set(rs)) > 1:
            setup.not_audited.append((st.name, f"material {t}: radii {min(rs):g} … {max(rs):g}",
                                      "probed at the mass-weighted radius only"))
    return types


def _get(mat: Call, key: str):
    v = mat.kw.get(key, UTILS_DEFAULT.kw[key] if mat is UTILS_DEFAULT else DEFAULT_MATERIAL.get(key))
    return float(v) if _number(v) else None


def _dt(st: _State, setup: Setup, types: dict) -> None:
    where = f"{st.name}:{st.dt_line}"
    if st.dt is None:
        if st.dt_line:
            raise ScriptError(f"{where}: O.dt: computed at run time — the audit needs the script's time step")
        setup.dt, setup.dt_where = DEFAULT_DT, f"Yade's default O.dt {DEFAULT_DT:g} (the script does not set it)"
        return
    calls = [n for n in ast.walk(st.dt) if isinstance(n, ast.Call) and (_dotted(n.func) or "").endswith(
        "PWaveTimeStep")]
    if not calls:
        v = st.ev(st.dt)
        if not (_number(v) and v > 0 and math.isfinite(v)):
            raise ScriptError(f"{where}: O.dt = {ast.unparse(st.dt)[:60]}: {getattr(v, 'why', 'not > 0')} — the "
                              "audit needs the script's time step")
        setup.dt, setup.dt_where = float(v), f"{where}: O.dt"
        return
    factors = []
    for probe in (1.0, 2.0):
        st.ev.names["__pwave__"] = probe
        tree = _Replace().visit(ast.parse(ast.unparse(st.dt), mode="eval"))
        factors.append(st.ev(tree.body))
    st.ev.names.pop("__pwave__", None)
    dts = []
    for t, mat, _ in types.values():
        b = setup.bodies.get(t)
        e, rho = _get(mat, "young"), _get(mat, "density")
        if b is not None and b.radius and e and rho:
            dts.append(b.radius / math.sqrt(e / rho))
    if not (all(_number(f) for f in factors) and abs(factors[1] - 2 * factors[0]) <= 1e-12 * abs(factors[1])
            and factors[0] > 0 and dts):
        raise ScriptError(f"{where}: O.dt = {ast.unparse(st.dt)[:60]}: PWaveTimeStep() is computed at run time "
                          "and the spheres it reads are not all given literally — the audit needs the step")
    setup.dt = factors[0] * min(dts)
    setup.dt_where = (f"{where}: O.dt = {ast.unparse(st.dt)[:40]} — PWaveTimeStep() is Yade's run-time min r/√(E/ρ) "
                      f"over the spheres, evaluated here from the spheres read: {min(dts):.4g} s")


class _Replace(ast.NodeTransformer):
    def visit_Call(self, node):
        if (_dotted(node.func) or "").endswith("PWaveTimeStep"):
            return ast.copy_location(ast.Name("__pwave__", ast.Load()), node)
        return self.generic_visit(node)


def _label(key, mat: Call) -> str:
    """A material's name in labels (probe case names): its label when it is a plain word, else class and index."""
    lab = mat.kw.get("label")
    return lab if isinstance(lab, str) and re.fullmatch(r"[A-Za-z0-9_.+-]{1,40}", lab) else \
        f"{mat.name}{key if isinstance(key, int) else ''}"


def _functors(m1: Call, m2: Call, laws: dict):
    """(Ip2, Law2) Yade dispatches for two materials: the Ip2 naming both classes (a FrictMat functor takes
    FrictMat's subclasses where none names them), and the Law2 of its physics."""
    names = {m1.name, m2.name}
    exact = [c for c in laws["ip2"] if set(c.name.split("_")[1:3]) == names]
    generic = [c for c in laws["ip2"] if c.name.split("_")[1:3] == ["FrictMat", "FrictMat"]
               and names <= set(FRICT_FAMILY)]
    ip2 = (exact or generic or [None])[0]
    if ip2 is None:
        return None, None
    phys = ip2.name.split("_")[-1]
    law2 = next((c for c in laws["law2"] if c.name.split("_")[2:3] == [phys]), None)
    return ip2, law2


def _pairs(st: _State, setup: Setup, types: dict, laws: dict) -> None:
    spheres = sorted(t for (t, _, _) in types.values() if t in setup.bodies)
    mats = {t: (mat, key) for (t, mat, key) in types.values()}
    walls = {}
    for w, kind, where in setup.walls_yade:
        walls.setdefault(w, (kind, where))
    combos = [(a, b, False) for k, a in enumerate(spheres) for b in spheres[k:]]
    combos += [(t, w, True) for w in sorted(walls) for t in spheres]
    for a, b, wall in combos:
        (ma, ka), (mb, kb) = mats[a], mats[b]
        label = (f"wall {_label(kb, mb)} × {_label(ka, ma)}" if wall else f"{_label(ka, ma)}-{_label(kb, mb)}")
        ip2, law2 = _functors(ma, mb, laws)
        nat, asked, why = _native(ma, mb, ip2, law2, setup, a, None if wall else b)
        ps = PairSetting(label, a, None if wall else b, nat, f"{st.name}:{ip2.line if ip2 else '?'}", asked)
        if not wall and nat.tangential == "spring" and ps.probe:
            ps.asked = {}
            ps.notes.append("head-on only: Yade turns a sphere pair's shear history with ScGeom's first-order "
                            "rotation, which the twin does not have yet (oblique pair probes differ by ~5e-8); "
                            "its friction is probed on the walls")
        if nat.props.get("law2") == CUNDALL:
            ps.notes.append(f"{CUNDALL}: its normal law probed head-on; its shear (μ = {_mu(ma, mb):.4g}, ks = "
                            f"{nat.props['ks']:.4g}) is not — no twin of its shear force matches a Yade run yet "
                            "(the ViscElPhys spring differs by 3.8e-3 at 30° on a wall)")
        extra = sorted({k for m in (ma, mb) for k in m.kw if k not in MATERIAL_KEYS and not k.startswith("_")})
        if extra and ps.probe:
            setup.not_audited.append((ps.where, f"{label}: {', '.join(extra)}", "material keywords the probes do not "
                                      "include (rolling resistance, cohesion, capillarity, …)"))
        if wall and walls[b][0] != "wall":
            ps.notes.append(f"a {walls[b][0]} ({walls[b][1]}) probed as a flat Wall")
        if why:
            ps.probe = False
            ps.notes.append(f"listed, not probed: {why}")
        _beyond(ps, ma, mb, ip2, law2, laws, setup, wall)
        setup.pairs.append(ps)


def _beyond(ps: PairSetting, ma: Call, mb: Call, ip2, law2, laws: dict, setup: Setup, wall: bool) -> None:
    """The pair's sub-models beyond sliding (``ps.beyond``): Mindlin's DMT adhesion (a trap where ``gamma`` is
    set without the Law2's ``includeAdhesion``) and, between spheres, ThermalEngine's conduction."""
    if ip2 is not None and ip2.name == "Ip2_FrictMat_FrictMat_MindlinPhys" and "gamma" in ip2.kw:
        _dmt(ps, ma, mb, ip2, law2)
    if laws.get("thermal") is not None and not wall:
        _thermal(ps, laws["thermal"], setup)


def _dmt(ps: PairSetting, ma: Call, mb: Call, ip2: Call, law2) -> None:
    gamma = ip2.kw["gamma"]
    if not _number(gamma):
        ps.notes.append(f"MindlinPhys gamma is computed at run time ({getattr(gamma, 'why', gamma)}): its adhesion "
                        "is not probed")
        return
    if not gamma > 0:
        return
    if law2 is None or law2.kw.get("includeAdhesion") in (None, False, 0):
        ps.findings.append(Finding(
            "trap", "yade-adhesion-off", f"Ip2_FrictMat_FrictMat_MindlinPhys(gamma = {gamma:g}) without "
            "Law2_ScGeom_MindlinPhys_Mindlin(includeAdhesion=True): the DMT adhesion 4πR̄γ is computed and never "
            "applied (measured: a DMT pull never pulls, docs/findings.md)", ps.where, {"gamma": gamma}))
        return
    e, nu = _get(ma, "young"), _get(ma, "poisson")
    if not (_number(e) and _number(nu)):
        return
    ps.beyond["adhesion"] = {"law": "dmt", "args": (e, 0.0, nu, gamma),
                             "words": f"Mindlin DMT gamma {gamma:g} (w = 2 gamma), includeAdhesion"}
    ps.notes.append("the collision probes run Mindlin without its adhesion; the adhesion is the pull-off probe's"
                    + ("" if (e, nu) == (_get(mb, "young"), _get(mb, "poisson")) else
                       f" (of two spheres of {_label(None, ma)}'s E and ν)"))


def _thermal(ps: PairSetting, th: Call, setup: Setup) -> None:
    """ThermalEngine's conduction between the pair's spheres, asked as Batchelor & O'Brien's 2ks a with ks its
    ``particleK``; capacities from ``particleCp`` (the first call sets every body's k and Cp to these)."""
    vals = {k: th.kw.get(k, d) for k, d in THERMAL_DEFAULTS.items()}
    sub = {"law": "radius", "args": (vals["particleK"],),
           "words": f"ThermalEngine(particleK = {vals['particleK']}, particleCp = {vals['particleCp']})"}
    flags = [f for f in ("useKernMethod", "useHertzMethod") if th.kw.get(f) not in (None, False, 0)]
    if not all(_number(v) for v in vals.values()):
        sub["refused"] = "ThermalEngine's particleK, particleCp or particleDensity is computed at run time"
    elif flags:
        sub["refused"] = (f"ThermalEngine({flags[0]}=True) is not mapped (measured on a steel pair: useKernMethod "
                          "32× below Batchelor & O'Brien's conductance, useHertzMethod 217× above: docs/findings.md)")
    elif vals["particleDensity"] > 0:
        sub["refused"] = "ThermalEngine(particleDensity > 0) replaces the materials' density in the capacities"
    else:
        setup.heat = {"cp_all": float(vals["particleCp"]), "where": f"ThermalEngine (line {th.line})"}
    ps.beyond["heat"] = sub


def _series(x: float, y: float) -> float:
    """Yade's ViscElPhys combination: 1/(1/x + 1/y) over the nonzero values (a 0 leaves the other's)."""
    inv = [1.0 / v for v in (x, y) if v]
    return 1.0 / sum(inv) if inv else 0.0


def _mu(ma: Call, mb: Call) -> float | None:
    phis = [_get(m, "frictionAngle") for m in (ma, mb)]
    return None if None in phis else math.tan(min(phis))


def _native(ma: Call, mb: Call, ip2, law2, setup: Setup, a: int, b: int | None):
    """(Native, asked, why not probed or "") of a material pair under the dispatched functors."""
    names = f"{ip2.name if ip2 else 'no Ip2'} + {law2.name if law2 else 'no Law2'}"
    listed = Native("yade", normal=names, tangential="(not read)")
    if ip2 is None or law2 is None:
        return listed, {}, (f"O.engines has no Ip2 and Law2 functor for {ma.name} with {mb.name} "
                            "(or they are not read)")
    phys = ip2.name.split("_")[-1]
    mu = _mu(ma, mb)
    if mu is None:
        return listed, {}, "a frictionAngle is computed at run time"
    if any(m.kw.get("SPHmode") not in (None, False, 0) for m in (ma, mb)):
        return listed, {}, "ViscElMat(SPHmode=…): smoothed-particle forces, not a contact law"
    if phys == VISCEL and law2.name == "Law2_ScGeom_ViscElPhys_Basic":
        if all(k in m.kw for m in (ma, mb) for k in ("tc", "en")) and not any("kn" in m.kw for m in (ma, mb)):
            return _viscel_tc(ma, mb, setup, a, b, listed)
        return _viscel(ma, mb, mu, listed)
    if phys == MINDLIN and law2.name == "Law2_ScGeom_MindlinPhys_Mindlin":
        return _mindlin(ma, mb, ip2, setup, a, b, listed)
    if phys == "FrictPhys" and law2.name == CUNDALL and ip2.name == "Ip2_FrictMat_FrictMat_FrictPhys":
        return _cundall(ma, mb, mu, setup, a, b, listed)
    return listed, {}, f"demcheck has no twin of {ip2.name} + {law2.name}"


def _viscel(ma: Call, mb: Call, mu: float, listed: Native):
    vals = {}
    for key in ("kn", "cn", "ks", "cs"):
        xs = [m.kw.get(key) for m in (ma, mb)]
        if any(x is None for x in xs) and "kn" in ma.kw and "kn" in mb.kw:
            return listed, {}, f"ViscElMat without {key}: Yade's default is NaN"
        if not all(_number(x) for x in xs):
            given = [k for k in ("tc", "en", "et", "young") if k in ma.kw or k in mb.kw]
            return listed, {}, ("ViscElMat without kn given literally" + (
                f" ({', '.join(given)}: Yade calibrates kn, cn from the bodies' masses at run time — on a wall "
                "with half the mass, docs/yade.md)" if given else ""))
        if any(x < 0 for x in xs):
            raise ScriptError(f"ViscElMat (line {ma.line}): {key} = {min(xs):g}: must be >= 0")
        vals[key] = _series(*xs)
    if not vals["kn"] > 0:
        raise ScriptError(f"ViscElMat (line {ma.line}): kn: must be > 0")
    tangential = "none"
    if mu > 0 and vals["ks"] > 0:
        tangential = "spring"
    elif mu > 0 and vals["cs"] > 0:
        tangential = "viscous"
    nat = Native("yade", normal=VISCEL, tangential=tangential, limit=True,
                 props={**vals, "mu": mu if tangential != "none" else 0.0})
    return nat, ({"friction": mu} if tangential != "none" else {}), ""


def _mindlin(ma: Call, mb: Call, ip2: Call, setup: Setup, a: int, b: int | None, listed: Native):
    e = [_get(m, "young") for m in (ma, mb)]
    nu = [_get(m, "poisson") for m in (ma, mb)]
    if None in e or None in nu:
        return listed, {}, "a material's young or poisson is computed at run time"
    for x, n in zip(e, nu):
        if not (x > 0 and -1 < n < 0.5):
            raise ScriptError(f"FrictMat (line {ma.line}): young {x:g}, poisson {n:g}: need young > 0 and poisson "
                              "in (-1, 0.5)")
    if "en" in ip2.kw or "es" in ip2.kw:
        return listed, {"restitution": ip2.kw["en"]} if _number(ip2.kw.get("en")) else {}, (
            "Ip2_FrictMat_FrictMat_MindlinPhys(en=…): Yade's damping for en is not twinned here (measured: it "
            "realises the law's e without its ≥ 0 hold, docs/findings.md)")
    betan = ip2.kw.get("betan", 0.0)
    if not (_number(betan) and 0 <= betan):
        return listed, {}, f"betan is not read ({getattr(betan, 'why', betan)})"
    e_star = e[0] * e[1] / ((1.0 - nu[0] ** 2) * e[1] + (1.0 - nu[1] ** 2) * e[0])
    ra = setup.bodies[a].radius
    rb = setup.bodies[b].radius if b is not None else None
    r_y = ra / 2.0 if b is None else ra * rb / (ra + rb)  # Ig2_Wall_Sphere_ScGeom gives a wall the sphere's radius
    r_eff = ra if b is None else r_y
    kno = 4.0 / 3.0 * e_star * math.sqrt(r_y)
    nat = Native("yade", normal=MINDLIN, tangential="none", limit=betan > 0,
                 props={"kno": kno, "betan": float(betan), "betas": 0.0, "kso": 0.0, "mu": 0.0, "r_eff": r_eff})
    nat.comments = [f"MindlinPhys kno = (4/3)E*√R̄_Y = {kno:.10g} (E* {e_star:.6g} Pa, R̄_Y {r_y:.6g} m)"]
    return nat, {}, ""


def _viscel_tc(ma: Call, mb: Call, setup: Setup, a: int, b: int | None, listed: Native):
    """ViscElMat(tc, en, …): Yade calibrates each contact's kn, cn from the bodies' masses when it forms —
    each material 2m̄(π² + ln²en)/tc² and −4m̄ ln en/tc, in series, with m̄ = m₁m₂/(m₁ + m₂) and a wall's mass
    taken as the sphere's (docs/yade.md; a twin given these runs as Yade to round-off). Probed head-on (the
    shear calibration from et is not twinned here), asking for en: the trap is the wall's half mass."""
    vals = [(m.kw.get("tc"), m.kw.get("en")) for m in (ma, mb)]
    if not all(_number(t) and t > 0 and _number(e) and 0 < e <= 1 for t, e in vals):
        return listed, {}, "ViscElMat tc or en is computed at run time (or out of range)"
    if vals[0] != vals[1]:
        return listed, {}, "ViscElMat tc/en differ between the two materials (the probe's script takes one)"
    tc, en = vals[0]
    rho = setup.bodies[a].density
    m1 = rho * 4.0 / 3.0 * math.pi * setup.bodies[a].radius ** 3
    m2 = m1 if b is None else setup.bodies[b].density * 4.0 / 3.0 * math.pi * setup.bodies[b].radius ** 3
    m_bar = m1 * m2 / (m1 + m2)  # a wall's mass is the sphere's
    ln = math.log(en)
    kn = m_bar * (math.pi ** 2 + ln * ln) / tc ** 2  # two equal per-material values in series
    cn = -2.0 * m_bar * ln / tc
    nat = Native("yade", normal=VISCEL, tangential="none", limit=True,
                 props={"tc": tc, "en": en, "et": 1.0, "kn": kn, "cn": cn, "ks": 0.0, "cs": 0.0, "mu": 0.0})
    nat.comments = [f"ViscElMat tc = {tc:g}, en = {en:g}: Yade's kn = {kn:.10g}, cn = {cn:.10g} for m̄ = {m_bar:.6g} kg"]
    return nat, {"restitution": float(en)}, ""


def measure(setup: Setup, ps: PairSetting, entry: dict, rerun) -> list:
    """NewtonIntegrator's damping, measured: the head-on probe run again in Yade with the script's damping
    (``rerun(native)`` → the engine's metrics); its restitution against the undamped probe's is the trap's size."""
    damping, where, default = getattr(setup, "newton_damping", (0.0, "", False))
    head = entry["probes"][0]
    if not damping or head.get("failure") or head["angle"] != 0.0 or head["engine"].get("status") != "ok":
        return []
    import copy

    nat = copy.deepcopy(ps.native)
    nat.props["newton_damping"] = damping
    got = rerun(nat)
    e0, e1 = head["engine"]["restitution"], got.get("restitution", math.nan)
    if got.get("status") != "ok" or not (math.isfinite(e0) and math.isfinite(e1)):
        return [Finding("note", "newton-damping", f"NewtonIntegrator damping = {damping:g}: its effect could not be "
                        f"measured ({got.get('status')}: {str(got.get('message', ''))[:120]})", where)]
    return [Finding("trap", "newton-damping", f"NewtonIntegrator damping = {damping:g}"
                    + (" (Yade's default: the script does not set it)" if default else "")
                    + f" lowers this contact's head-on restitution from {e0:.4f} to {e1:.4f} (measured in Yade: "
                    "Cundall's non-viscous damping scales the contact force by 1 ∓ damping on top of the law)",
                    where, {"damping": damping, "restitution": e0, "with_damping": e1, "difference": e1 - e0})]


def _cundall(ma: Call, mb: Call, mu: float, setup: Setup, a: int, b: int | None, listed: Native):
    """Ip2_FrictMat_FrictMat_FrictPhys + Law2_ScGeom_FrictPhys_CundallStrack: kn = 2EaRa·EbRb/(EaRa + EbRb),
    ks = 2EaRaνa·EbRbνb/(EaRaνa + EbRbνb) (Ra, Rb the spheres' radii; a Wall takes the sphere's), a linear
    spring with an incremental shear spring capped at μFn — ViscElPhys's twin with cn = cs = 0."""
    e = [_get(m, "young") for m in (ma, mb)]
    nu = [_get(m, "poisson") for m in (ma, mb)]
    if None in e or None in nu:
        return listed, {}, "a material's young or poisson is computed at run time"
    if e[0] != e[1] or nu[0] != nu[1]:
        return listed, {}, "FrictMat young/poisson differ between the two materials (the probe's script takes one)"
    if not (e[0] > 0 and nu[0] >= 0):
        raise ScriptError(f"FrictMat (line {ma.line}): young {e[0]:g}, poisson {nu[0]:g}: need young > 0 and "
                          "poisson (FrictPhys's ks/kn) >= 0")
    ra = setup.bodies[a].radius
    rb = ra if b is None else setup.bodies[b].radius
    kn = 2.0 * e[0] * ra * e[1] * rb / (e[0] * ra + e[1] * rb)
    ks = kn * nu[0]
    # its normal law only (the probe is head-on): the shear has a twin now (mapping.twin with law2, ≤ 3e-12 of
    # Yade runs, tests/test_yade.py), not yet probed by the audit
    nat = Native("yade", normal=VISCEL, tangential="none", limit=True,
                 props={"kn": kn, "cn": 0.0, "ks": ks, "cs": 0.0, "mu": 0.0, "law2": CUNDALL})
    nat.comments = [f"FrictPhys kn = {kn:.10g} N/m, ks = {ks:.10g} N/m (Law2_ScGeom_FrictPhys_CundallStrack), "
                    f"frictionAngle tan = {mu:.6g} not probed (head-on only)"]
    return nat, {}, ""
