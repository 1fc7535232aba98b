"""A Kratos DEM project read back for ``demcheck audit``: ProjectParametersDEM.json with its materials file
(``solver_settings.material_import_settings.materials_filename``, default MaterialsDEM.json beside it) and the
project's .mdpa files (``<problem_name>DEM.mdpa``, ``…DEM_FEM_boundary.mdpa``, ``…DEM_Inlet.mdpa``), read as
data (JSON, and mdpa.py's bounded line reader): nothing in them is executed.

Each material relation between particle materials, and between a particle material and a wall material (one
assigned to the RigidFacePart of a boundary with conditions), becomes a Native that computes what Kratos DEM
10.4.4 computes for it: the discontinuum law, E* from both materials' E and ν as Kratos combines them, and the
DAMPING_GAMMA Kratos itself derives from the relation's COEFFICIENT_OF_RESTITUTION (restitution.py: Kratos
initialises the relation and the value is read back). Only the head-on probe runs: Kratos' tangential law has a
twin (reference/twins_kratos.py) but no oblique probe is wired here yet, and a head-on impact has no tangential
force.

Beyond sliding (``ps.beyond``, probed by comparisons/audit_beyond.py in engines/kratos/scenario.py's scenarios): a
relation on the cohesive laws ``DEM_D_Hertz_viscous_Coulomb_JKR`` / ``…_DMT`` with its PARTICLE_COHESION w (J/m²)
gets the pull-off probe (and, for JKR, the adhesive impact); a wall relation's rolling friction model
(``DEM_ROLLING_FRICTION_MODEL_NAME`` ConstantTorque / ViscousTorque, ``ROLLING_FRICTION_WITH_WALLS``, which Kratos
defaults to ROLLING_FRICTION) with RollingFrictionOption on gets the sphere rolling on a level wall.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

from ...inputs.script import Body, Finding, PairSetting, ScriptError, Setup
from ..base import Native
from . import mdpa as M
from .mapping import AUDITED, HERTZ, LAWS, LINEAR, PARENT
from .scenario import DMT_LAW, JKR_LAW, ROLLING_MODELS

SCHEME = "Velocity_Verlet"  # the scheme of the probes' runs and of the twin
DEFAULTS = {"TranslationalIntegrationScheme": "Symplectic_Euler", "MaxTimeStep": 5e-5, "Dimension": 3,
            "GlobalDamping": 0.0}  # Kratos DEM 10.4.4's dem_default_input_parameters for what a project omits
MAX_JSON_BYTES = 20_000_000
SPHERES = ("SphericParticle3D", "SphericContinuumParticle3D")
OWN_MODULI = False  # the deck writer writes the pair's E* (a rigid face for a wall), not each material's own
# the audit's probe of each sub-model beyond sliding (comparisons/audit_beyond.py MAKERS): the cohesive laws' pull-off
# (and JKR's adhesive impact), a wall relation's rolling friction model on a sphere rolling on a level wall
BEYOND_PROBES = {"adhesion": "pull_off_kratos", "rolling": "rolling_kratos"}
COHESIVE = {JKR_LAW: "jkr", DMT_LAW: "dmt"}
BOUNDED = "DEMRollingFrictionModelBounded"  # Kratos 10.4.4's default model name for a relation that names none


def claims(script) -> bool:
    return False  # a LAMMPS-language deck is never a Kratos project


def claims_file(path: Path) -> bool:
    """A Kratos project is its ProjectParameters JSON."""
    return path.suffix.lower() == ".json"


def _bad(where: str, key: str, value, rule: str) -> ScriptError:
    return ScriptError(f"{where}: {key} = {str(value)[:60]!r}: {rule}")


def _load(path: Path) -> dict:
    try:
        if path.stat().st_size > MAX_JSON_BYTES:
            raise ScriptError(f"{path.name}: larger than {MAX_JSON_BYTES:,} bytes")
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScriptError(f"{path.name}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
    try:
        value = json.loads(text, parse_constant=lambda c: (_ for _ in ()).throw(
            _bad(path.name, "a number", c, "is not a finite number")))
    except json.JSONDecodeError as exc:
        raise ScriptError(f"{path.name}:{exc.lineno}: not JSON ({exc.msg})") from None
    if not isinstance(value, dict):
        raise ScriptError(f"{path.name}: not a JSON object")
    return value


def _number(d: dict, key: str, where: str, default=None, rule=("must be > 0", lambda x: x > 0)):
    v = d.get(key, default)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise _bad(where, key, v, "must be a finite number")
    if not rule[1](v):
        raise _bad(where, key, v, rule[0])
    return float(v)


def _text(d: dict, key: str, where: str, default: str) -> str:
    v = d.get(key, default)
    if not isinstance(v, str):
        raise _bad(where, key, v, "must be a string")
    return v


def read_file(path: Path) -> Setup:
    path = Path(path)
    project = _load(path)
    root = path.resolve().parent
    where = path.name
    setup = Setup("kratos", units="si", units_where="Kratos DEM: SI units")
    setup.dt = _number(project, "MaxTimeStep", where, DEFAULTS["MaxTimeStep"])
    setup.dt_where = f"{where}: MaxTimeStep" if "MaxTimeStep" in project else "Kratos' default MaxTimeStep 5e-5"
    _settings(project, setup, where)
    mats_name = (project.get("solver_settings") or {}).get("material_import_settings", {}).get(
        "materials_filename", "MaterialsDEM.json") if isinstance(project.get("solver_settings"), dict) else \
        "MaterialsDEM.json"
    if not isinstance(mats_name, str):
        raise _bad(where, "materials_filename", mats_name, "must be a file name")
    mats_path = (root / mats_name).resolve()
    if root not in mats_path.parents:
        raise _bad(where, "materials_filename", mats_name, "must be a file in the project's folder")
    if not mats_path.is_file():
        raise _bad(where, "materials_filename", mats_name, "no such file beside the project (Kratos 10.4.4 reads "
                   "its materials from it; materials in an .mdpa's Properties are a layout it no longer reads)")
    problem = _text(project, "problem_name", where, "")
    meshes = {kind: _mesh(root, problem, kind) for kind in ("", "_FEM_boundary", "_Inlet", "_Clusters")}
    materials = _load(mats_path)
    _materials(materials, mats_path.name, meshes, setup, project, where)
    if not setup.pairs:
        setup.not_audited.append((mats_path.name, "material_relations", "no relation between materials that "
                                  "are given spheres or walls in the project's .mdpa files"))
    return setup


def _mesh(root: Path, problem: str, kind: str):
    p = root / f"{problem}DEM{kind}.mdpa"
    return M.read(p) if problem and p.is_file() else None


def _settings(project: dict, setup: Setup, where: str) -> None:
    """The project's scheme, gravity, damping and options: what the probes take, and what they do not."""
    scheme = _text(project, "TranslationalIntegrationScheme", where, DEFAULTS["TranslationalIntegrationScheme"])
    if scheme != SCHEME:
        setup.not_audited.append((where, f"TranslationalIntegrationScheme {scheme}",
                                  f"the probes integrate with {SCHEME} (the twin's scheme); the project's "
                                  f"{scheme} errs differently at the same step (its time-step error is not audited)"))
    if project.get("AutomaticTimestep") is True:
        setup.not_audited.append((where, "AutomaticTimestep true", "Kratos picks the step at run time (at most "
                                  "MaxTimeStep): probed at MaxTimeStep"))
    dim = project.get("Dimension", DEFAULTS["Dimension"])
    if dim != 3:
        setup.dimension = 2
    g = [_number(project, f"Gravity{c}", where, 0.0, ("", lambda x: True)) for c in "XYZ"]
    mag = math.sqrt(sum(x * x for x in g))
    if mag > 0:
        setup.gravity = (mag, max(range(3), key=lambda k: abs(g[k])), f"{where}: GravityX/Y/Z")
    damping = _number(project, "GlobalDamping", where, 0.0, ("must be >= 0", lambda x: x >= 0))
    if damping > 0:
        setup.findings.append(Finding("note", "global-damping", f"GlobalDamping = {damping:g}: Kratos damps every "
                                      "particle's motion on top of the contact law; the probes run without it (its "
                                      "effect on the restitution is not measured)", where))
    procs = project.get("processes") if isinstance(project.get("processes"), dict) else {}
    for plist in procs.values():
        for proc in plist if isinstance(plist, list) else []:
            par = proc.get("Parameters", {}) if isinstance(proc, dict) else {}
            v = (par.get("velocity_constraints_settings") or {}).get("value") if isinstance(par, dict) else None
            if isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                          and math.isfinite(x) for x in v) and any(v):
                setup.speeds.append((math.sqrt(sum(x * x for x in v)), f"{where}: the velocity imposed on "
                                     f"{str(par.get('model_part_name'))[:40]}"))
    if project.get("PeriodicDomainOption") is True:
        setup.not_audited.append((where, "PeriodicDomainOption true", "periodic images are not probed"))


def _materials(doc: dict, name: str, meshes: dict, setup: Setup, project: dict, where: str) -> None:
    mats = {}
    for k, m in enumerate(doc.get("materials") or []):
        w = f"{name}: materials[{k}]"
        if not isinstance(m, dict) or not isinstance(m.get("Variables", {}), dict):
            raise ScriptError(f"{w}: not an object with Variables")
        if "Variables" not in m and "properties" in m:
            raise _bad(w, "properties", "{…}", "Kratos DEM 10.4.4 reads a material's values from 'Variables'")
        mid = m.get("material_id")
        if isinstance(mid, bool) or not isinstance(mid, int) or not 0 <= mid < 10**9:
            raise _bad(w, "material_id", mid, "must be a whole number ≥ 0")
        v = m.get("Variables", {})
        mats[mid] = {"name": _text(m, "material_name", w, str(mid)), "id": mid,
                     "E": _number(v, "YOUNG_MODULUS", w), "nu": _number(v, "POISSON_RATIO", w, None,
                                                                         ("must be in (-1, 0.5)", lambda x: -1 < x < 0.5)),
                     "rho": _number(v, "PARTICLE_DENSITY", w)}
    by_name = {m["name"]: m for m in mats.values()}
    table = doc.get("material_assignation_table") or []
    spheres, walls, inlets = {}, {}, {}
    for k, row in enumerate(table):
        if not (isinstance(row, list) and len(row) == 2 and all(isinstance(x, str) for x in row)):
            raise _bad(f"{name}: material_assignation_table[{k}]", "row", row, "must be [model part, material name]")
        part, mname = row
        if mname not in by_name:
            raise _bad(f"{name}: material_assignation_table[{k}]", "material", mname, "is not a material's name")
        head = part.split(".", 1)
        kind = {"SpheresPart": spheres, "RigidFacePart": walls, "DEMInletPart": inlets}.get(head[0])
        if kind is None:
            setup.not_audited.append((name, f"{part} → {mname}", "a model part the audit does not read (clusters, "
                                      "continuum or FEM coupling parts)"))
            continue
        kind[head[1] if len(head) > 1 else ""] = by_name[mname]["id"]
    _bodies(meshes, spheres, inlets, mats, setup)
    wall_mats = _walls(meshes.get("_FEM_boundary"), walls)
    for pname, key, why in getattr(meshes.get("_FEM_boundary"), "notes", []):
        setup.not_audited.append((f"FEM boundary {pname[:40]}", key, f"{why}: the probes' wall is fixed and "
                                  "not sticky"))
    rolling_on = project.get("RollingFrictionOption") is True and project.get("RotationOption", True) is True
    _relations(doc, name, mats, setup, wall_mats, rolling_on)


def _parts_nodes(mesh, sub: str) -> list:
    if mesh is None:
        return []
    if sub == "":
        return [n for (etype, _, nodes) in mesh.elements.values() if etype in SPHERES for n in nodes[:1]]
    nodes = []
    for pname, part in mesh.parts.items():
        if pname == sub or pname.startswith(sub + "."):  # its nodes, and its elements' (a part may list either)
            nodes += part.nodes + [n for e in part.elements if e in mesh.elements
                                   and mesh.elements[e][0] in SPHERES for n in mesh.elements[e][2][:1]]
    return list(dict.fromkeys(nodes))


def _bodies(meshes: dict, spheres: dict, inlets: dict, mats: dict, setup: Setup) -> None:
    """Each particle material's sizes (the radii of its spheres, or its inlets' RADIUS), its bodies' positions
    and velocities, and its inlets' velocities."""
    mesh = meshes.get("")
    radius = mesh.nodal.get("RADIUS", {}) if mesh else {}
    vel = {c: (mesh.nodal.get(f"VELOCITY_{c}", {}) if mesh else {}) for c in "XYZ"}
    for sub, mid in spheres.items():
        m = mats[mid]
        nodes = _parts_nodes(mesh, sub)
        if not any(radius.get(n, 0) > 0 for n in nodes):
            setup.not_audited.append((f"SpheresPart{'.' + sub if sub else ''}", m["name"], "no sphere with a RADIUS "
                                      "in the project's DEM .mdpa" + ("" if mesh else " (the file is not there)")))
            continue
        b = setup.bodies.setdefault(mid, Body(mid, density=m["rho"]))
        for n in nodes:
            r = radius.get(n)
            if r is None or not r > 0:
                continue
            b.sizes.append((r, r ** 3))
            v = [vel[c].get(n, 0.0) for c in "XYZ"]
            if len(setup.atoms) < 100_000:
                setup.atoms[n] = [mid, list(mesh.nodes.get(n, (0.0, 0.0, 0.0))), v]
            s = math.sqrt(sum(x * x for x in v))
            if s > 0:
                setup.speeds.append((s, f"{mesh.path.name}: node {n}'s VELOCITY"))
        b.size_from = f"{mesh.path.name if mesh else 'the .mdpa'}'s RADIUS"
    for pname, part in (mesh.parts.items() if mesh else []):  # initial velocities given per sub-model part
        v = [part.data.get(f"INITIAL_VELOCITY_{c}_VALUE", "0") for c in "XYZ"]
        try:
            v = [float(x) for x in v]
        except ValueError:
            continue
        if any(v) and all(math.isfinite(x) for x in v):
            setup.speeds.append((math.sqrt(sum(x * x for x in v)), f"{mesh.path.name}: {pname}'s INITIAL_VELOCITY"))
    inlet = meshes.get("_Inlet")
    for sub, mid in inlets.items():
        for pname, part in (inlet.parts.items() if inlet else []):
            if sub and not (pname == sub or pname.startswith(sub + ".")):
                continue
            d = part.data
            m = mats[mid]
            try:
                r = float(d.get("RADIUS", "nan"))
            except ValueError:
                r = math.nan
            if math.isfinite(r) and r > 0:
                b = setup.bodies.setdefault(mid, Body(mid, density=m["rho"]))
                b.sizes.append((r, r ** 3))
                b.size_from = (b.size_from + ", " if b.size_from else "") + f"inlet {pname}'s RADIUS"
                if str(d.get("STANDARD_DEVIATION", "0")).strip() not in ("0", "0.0"):
                    setup.not_audited.append((inlet.path.name, f"{pname}: STANDARD_DEVIATION "
                                              f"{d.get('STANDARD_DEVIATION')}", "the inlet's size distribution is "
                                              "probed at its mean RADIUS"))
            v = d.get("VELOCITY")
            if isinstance(v, tuple):
                s = math.sqrt(sum(x * x for x in v))
                if s > 0:
                    setup.speeds.append((s, f"{inlet.path.name}: inlet {pname}'s VELOCITY"))
            setup.populated.add(mid)
    for b in setup.bodies.values():
        radii = sorted({r for r, _ in b.sizes})
        if len(radii) == 1:
            b.radius, b.sizes = radii[0], []
        elif radii:
            total = sum(w for _, w in b.sizes)
            b.radius = sum(r * w for r, w in b.sizes) / total


def _walls(boundary, walls: dict) -> set:
    """The wall materials of rigid faces that exist (a boundary sub-model part with conditions)."""
    if boundary is None or not boundary.conditions:
        return set()
    out = set()
    for pname, part in boundary.parts.items():
        for key, why in (("IS_STICKY", "particles stick to this wall"), ("RIGID_BODY_MOTION", "the wall moves")):
            if str(part.data.get(key, "0")).strip() not in ("0", ""):
                boundary.notes = getattr(boundary, "notes", []) + [(pname, key, why)]
    for sub, mid in walls.items():
        if sub == "" or any((p == sub or p.startswith(sub + ".")) and part.conditions
                            for p, part in boundary.parts.items()):
            out.add(mid)
    return out


def _relation_ids(rel: dict, w: str, mats: dict) -> tuple[int, int]:
    ids = rel.get("material_ids_list")
    if ids is None and isinstance(rel.get("material_names_list"), list):
        by_name = {m["name"]: k for k, m in mats.items()}
        ids = [by_name.get(n) for n in rel["material_names_list"]]
    if not (isinstance(ids, list) and len(ids) == 2 and all(isinstance(i, int) and not isinstance(i, bool)
                                                             and i in mats for i in ids)):
        raise _bad(w, "material_ids_list", ids, "must name two of the materials")
    return ids[0], ids[1]


def _e_star(a: dict, b: dict, w: str) -> float:
    for m in (a, b):
        for key, k in (("YOUNG_MODULUS", "E"), ("POISSON_RATIO", "nu")):
            if m[k] is None:
                raise _bad(w, f"{m['name']}.{key}", None, "is needed by the relation's contact law")
    return a["E"] * b["E"] / (a["E"] * (1.0 - b["nu"] ** 2) + b["E"] * (1.0 - a["nu"] ** 2))


def _relations(doc: dict, name: str, mats: dict, setup: Setup, wall_mats: set, rolling_on: bool = False) -> None:
    pending = []
    for k, rel in enumerate(doc.get("material_relations") or []):
        w = f"{name}: material_relations[{k}]"
        if not isinstance(rel, dict) or not isinstance(rel.get("Variables", {}), dict):
            raise ScriptError(f"{w}: not an object with Variables")
        i, j = _relation_ids(rel, w, mats)
        bi, bj = setup.bodies.get(i), setup.bodies.get(j)
        if bi is None and bj is not None:
            i, j, bi, bj = j, i, bj, bi
        if bi is None or (bj is None and j not in wall_mats):
            setup.not_audited.append((w, f"{mats[i]['name']} – {mats[j]['name']}", "no sphere or wall of these "
                                      "materials in the project's .mdpa files"))
            continue
        v = rel.get("Variables", {})
        law = _text(v, "DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME", w, "")
        cor = _number(v, "COEFFICIENT_OF_RESTITUTION", w, None, ("must be in [0, 1]", lambda x: 0 <= x <= 1))
        e_star = _e_star(mats[i], mats[j], w)
        wall = bj is None
        label = f"wall {_word(mats[j])} × {_word(mats[i])}" if wall else f"{_word(mats[i])}-{_word(mats[j])}"
        nat = Native("kratos", normal=law or "(none)", normal_args=(e_star,), damping="gamma", damping_coeff=0.0,
                     tangential="none", limit=True, props={"young_eff": e_star, "gamma": 0.0, "wall": wall})
        ps = PairSetting(label, i, None if wall else j, nat, w, {} if cor is None else {"restitution": cor})
        if setup.dimension == 3:  # a 2-D project's cylinders are not the probes' spheres
            _beyond(ps, v, w, law, (mats[i], mats[j]), e_star, rolling_on)
        ps.notes.append(_friction_note(v, w, setup, "rolling" in ps.beyond and not ps.beyond["rolling"].get("refused")))
        if setup.dimension != 3:
            ps.probe = False
            ps.notes.append("listed, not probed: a 2-D project's particles are Kratos' cylinders (its 2-D laws act "
                            "per unit length); the probes are spheres")
        elif law in COHESIVE:
            ps.probe = False
            ps.notes.append(f"listed, not probed by the head-on impact: {law}'s collision is not twinned; its "
                            "cohesion is the pull-off probe's (beyond sliding)")
        elif law in LAWS and law not in AUDITED:
            ps.probe = False
            ps.notes.append(f"listed, not probed: {law} is twinned but its stiffness is not read by the audit yet "
                            "(Simple_Coulomb's from the first material's E and ν, Custom_Constants' from the "
                            "relation's K_NORMAL and K_TANGENTIAL)")
        elif law not in LAWS:
            ps.probe = False
            ps.notes.append(f"listed, not probed: demcheck has no twin of Kratos' {law or 'missing'} law (twins: "
                            f"{', '.join(LAWS)})")
        elif cor is None:
            ps.probe = False
            ps.notes.append("listed, not probed: the relation has no COEFFICIENT_OF_RESTITUTION (Kratos reads 0)")
        else:
            pending.append(ps)
        setup.pairs.append(ps)
    _kratos_gamma(pending)


def _word(m: dict) -> str:
    """A material's name in labels (probe case names): the name when it is a plain word, else its id."""
    return m["name"] if re.fullmatch(r"[A-Za-z0-9_.+-]{1,40}", m["name"]) else f"material{m['id']}"


def _beyond(ps: PairSetting, v: dict, w: str, law: str, pair: tuple, e_star: float, rolling_on: bool) -> None:
    """The relation's sub-models beyond sliding: a cohesive law's w, a wall relation's rolling friction model
    (``rolling_on``: the project's RollingFrictionOption and RotationOption)."""
    if law in COHESIVE:
        cohesion = _number(v, "PARTICLE_COHESION", w, 0.0, ("must be >= 0", lambda x: x >= 0))
        if cohesion > 0:
            ps.beyond["adhesion"] = {"law": COHESIVE[law], "args": (e_star, pair[0]["nu"], cohesion),
                                     "words": f"{law}, PARTICLE_COHESION {cohesion:g}"}
        elif cohesion == 0:
            ps.notes.append(f"{law} with PARTICLE_COHESION 0 (Kratos' default): no cohesion acts")
    wall = ps.j is None
    roll = _number(v, "ROLLING_FRICTION", w, 0.0, ("must be >= 0", lambda x: x >= 0))
    key = "ROLLING_FRICTION_WITH_WALLS" if wall and "ROLLING_FRICTION_WITH_WALLS" in v else "ROLLING_FRICTION"
    coef = _number(v, key, w, 0.0, ("must be >= 0", lambda x: x >= 0))
    if not coef > 0:
        return
    if not rolling_on:
        ps.findings.append(Finding("note", "rolling-friction-off", f"{key} = {coef:g} while the project's "
                                   "RollingFrictionOption (with RotationOption) is off: Kratos applies no rolling "
                                   "friction", w, {"rolling_friction": coef}))
        return
    model = _text(v, "DEM_ROLLING_FRICTION_MODEL_NAME", w, BOUNDED)
    ids = {name: k for k, name in ROLLING_MODELS.items()}
    words = f"{model}{'' if 'DEM_ROLLING_FRICTION_MODEL_NAME' in v else ' (Kratos default)'}, {key} {coef:g}"
    sub = {"law": ids.get(model, model), "args": (coef, _number(v, "STATIC_FRICTION", w, 0.0, ("", lambda x: True)),
                                                  _kt_ratio(pair, e_star)), "words": words}
    sub["refused"] = _rolling_refused(ps, model, law, sub["args"][1], roll)
    ps.beyond["rolling"] = sub


def _rolling_refused(ps: PairSetting, model: str, law: str, mu: float, roll: float) -> str:
    """Why a relation's rolling friction is listed, not probed ('' where the rolling probe runs)."""
    if model == BOUNDED:
        return (f"{BOUNDED} (Irazábal's bounded model: type A's torque cut, each step, to the one that stops the "
                "spin within the step) has no demcheck law: not mapped (docs/kratos.md)")
    if model not in ROLLING_MODELS.values():
        return f"no Kratos 10.4.4 rolling friction model {model[:60]!r} in demcheck's mapping"
    if ps.j is not None:
        return ("the rolling probe is a sphere on a wall (engines/kratos/scenario.py maps Kratos' rolling friction "
                f"on a wall only); the particle–particle ROLLING_FRICTION {roll:g} is not probed")
    if law != LINEAR:
        return (f"the rolling probe is wired for {LINEAR} only (the law whose rolling run is measured against "
                f"Kratos: docs/kratos.md); {law or 'no law'} on this relation is not probed rolling")
    if not mu > 0:
        return "STATIC_FRICTION 0: the sphere slides on the wall, it does not roll"
    return ""


def _kt_ratio(pair: tuple, e_star: float) -> float:
    """Kratos' Kt/Kn = 4G*/E* of the relation's two materials (G* = 1/((2 − ν₁)/G₁ + (2 − ν₂)/G₂))."""
    return 4.0 / sum((2.0 - m["nu"]) * 2.0 * (1.0 + m["nu"]) / m["E"] for m in pair) / e_star


def _friction_note(v: dict, w: str, setup: Setup, rolled: bool = False) -> str:
    mu_s = _number(v, "STATIC_FRICTION", w, 0.0, ("must be >= 0", lambda x: x >= 0))
    mu_d = _number(v, "DYNAMIC_FRICTION", w, mu_s, ("must be >= 0", lambda x: x >= 0))
    decay = _number(v, "FRICTION_DECAY", w, 500.0, ("must be >= 0", lambda x: x >= 0))
    text = (f"STATIC_FRICTION {mu_s:g}, DYNAMIC_FRICTION {mu_d:g}, FRICTION_DECAY {decay:g}"
            + ("" if "FRICTION_DECAY" in v else " (Kratos' default)")
            + ": not probed — the audit has no oblique probe of "
            "Kratos' tangential law yet (its twin: reference/twins_kratos.py); the head-on probe has no tangential "
            "force, so it measures the normal law whole" + ("; the rolling friction is the rolling probe's (beyond "
                                                            "sliding)" if rolled else ""))
    if mu_s or mu_d:
        setup.not_audited.append((w, f"friction μs {mu_s:g}, μd {mu_d:g}, decay {decay:g}",
                                  "no oblique probe of Kratos' tangential law (head-on probe only)"
                                  + ("; its rolling friction is the rolling probe's" if rolled else "")))
    return text


def _kratos_gamma(pending: list) -> None:
    """DAMPING_GAMMA for each probed relation, as Kratos derives it from the restitution (read from Kratos)."""
    from ...errors import DemcheckError
    from . import restitution

    if not pending:
        return
    try:
        found = restitution.gammas([(ps.native.normal, ps.asked["restitution"]) for ps in pending])
    except DemcheckError as exc:
        for ps in pending:
            ps.probe = False
            ps.notes.append(f"listed, not probed: {exc}")
        return
    for ps, gamma in zip(pending, found):
        ps.native.damping_coeff = gamma
        ps.native.props["gamma"] = gamma
        how = "Thornton's fit" if PARENT.get(ps.native.normal) == HERTZ else "its bisection"
        ps.native.comments = [f"DAMPING_GAMMA {gamma:.10g}: Kratos' own ({how}) for COEFFICIENT_OF_RESTITUTION "
                              f"{ps.asked['restitution']:g}, read back from Kratos"]
        ps.notes.append(ps.native.comments[0])
