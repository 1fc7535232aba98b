"""Kratos DEM decks: a runner script from one fixed template, and the files Kratos reads.

A run is one subprocess, ``python in.deck`` in the work directory (the Python that has KratosMultiphysics and
KratosDEMApplication installed). The deck is :data:`TEMPLATE` with its one data line ``CASE = {...}`` (numbers
only, written with repr) and the files beside it: ``ProjectParameters.json`` (Velocity_Verlet, the case's
gravity, no global damping, no rolling friction unless a scenario sets a model, a neighbour search every step),
``MaterialsDEM.json`` (one material a particle, the rigid face's material, one relation a pair with the law, the
mapping's friction — none without a tangential law — and FRICTION_DECAY) and ``caseDEM.mdpa`` /
``caseDEM_FEM_boundary.mdpa`` (the spheres; the wall as one rigid triangle in the wall's plane covering the whole
scene). The runner sets each pair's DAMPING_GAMMA after Kratos has initialised, the bodies' velocities and spins,
and writes every step's states to ``dump.txt`` as
a state table (engines/output.py: a header of the record's columns, a row per body per step, %.17g), which
:func:`read_states` reads for the collisions and the scenarios.

:func:`check` is the last guard before Kratos runs: the script must be the template line for line (comment
lines before it allowed), its CASE a literal of known keys and numbers; the JSON files only known keys with
numbers, booleans or known strings; the .mdpa files only the lines demcheck writes. The scenarios' decks
(engines/kratos/scenario.py) are this deck with their layout's bodies and length, a cohesive law with the
relation's PARTICLE_COHESION, and for a pull :data:`PULL_TEMPLATE` (the template with body velocities Kratos holds
fixed, from the CASE line's ``fixed``).
"""

from __future__ import annotations

import ast
import json
import math
import re

from ...case import Case
from ...errors import UnsupportedByEngine
from ...inputs import common
from ..base import Engine
from ..mapping import contact_mapping, pair_mapping
from ..output import STATE_HEAD, STATE_ROW
from .mapping import CUSTOM, LAWS, particle_young

VERSION_NOTE = "written for Kratos DEM 10.4.4 (KratosMultiphysics + KratosDEMApplication from PyPI)"
SCHEME = "Velocity_Verlet"  # x += v dt + ½a dt², v += ½a dt; forces; v += ½a dt: LAMMPS's nve/sphere, the twin's
RIGID_FACE_MODULUS = 1e30  # E* = E/(1 − ν²) of the particle to round-off
PROBLEM = "case"
FILES = ("ProjectParameters.json", "MaterialsDEM.json", f"{PROBLEM}DEM.mdpa", f"{PROBLEM}DEM_FEM_boundary.mdpa")
CASE_LINE = "CASE = None"
CASE_KEYS = {"steps": int, "bodies": list, "gamma": list}
PULL_KEYS = {**CASE_KEYS, "fixed": list}

TEMPLATE = r'''
import json

import KratosMultiphysics as K
import KratosMultiphysics.DEMApplication as D
from KratosMultiphysics.DEMApplication.DEM_analysis_stage import DEMAnalysisStage

CASE = None


class DemcheckRun(DEMAnalysisStage):

    def Initialize(self):
        super().Initialize()
        for props in self.spheres_model_part.Properties:
            for pair in CASE["gamma"]:
                if props.Id == pair[0] and props.HasSubProperties(pair[1]):
                    props.GetSubProperties(pair[1]).SetValue(D.DAMPING_GAMMA, pair[2])
        for node in self.spheres_model_part.Nodes:
            body = CASE["bodies"][node.Id - 1]
            node.SetSolutionStepValue(K.VELOCITY_X, body[1][0])
            node.SetSolutionStepValue(K.VELOCITY_Y, body[1][1])
            node.SetSolutionStepValue(K.VELOCITY_Z, body[1][2])
            node.SetSolutionStepValue(K.ANGULAR_VELOCITY_X, body[2][0])
            node.SetSolutionStepValue(K.ANGULAR_VELOCITY_Y, body[2][1])
            node.SetSolutionStepValue(K.ANGULAR_VELOCITY_Z, body[2][2])
        self.demcheck_step = 0
        self.demcheck_dump = open("dump.txt", "w")
        self.demcheck_dump.write(STATE_HEAD)
        self.demcheck_write()

    def KeepAdvancingSolutionLoop(self):
        return self.demcheck_step < CASE["steps"]

    def FinalizeSolutionStep(self):
        super().FinalizeSolutionStep()
        self.demcheck_step += 1
        self.demcheck_write()

    def PrintResultsForGid(self, time):
        pass

    def Finalize(self):
        self.demcheck_dump.close()
        super().Finalize()

    def demcheck_write(self):
        for node in sorted(self.spheres_model_part.Nodes, key=lambda node: node.Id):
            v = node.GetSolutionStepValue(K.VELOCITY)
            w = node.GetSolutionStepValue(K.ANGULAR_VELOCITY)
            f = node.GetSolutionStepValue(K.TOTAL_FORCES)
            t = node.GetSolutionStepValue(D.PARTICLE_MOMENT)
            values = [node.GetSolutionStepValue(K.RADIUS), node.GetSolutionStepValue(K.NODAL_MASS),
                      node.X, node.Y, node.Z, v[0], v[1], v[2], w[0], w[1], w[2], f[0], f[1], f[2], t[0], t[1], t[2]]
            self.demcheck_dump.write(STATE_ROW % tuple([self.demcheck_step, node.Id, node.Id] + values))


K.Logger.GetDefaultOutput().SetSeverity(K.Logger.Severity.WARNING)
with open("ProjectParameters.json") as stream:
    parameters = K.Parameters(json.dumps(json.load(stream)))
DemcheckRun(K.Model(), parameters).Run()
'''.replace("STATE_HEAD", repr(STATE_HEAD)).replace("STATE_ROW", repr(STATE_ROW))


# the pull's runner (scenario pull_off): the template with each ``fixed`` body's velocity held by Kratos (its
# velocity degrees of freedom fixed at the given values after the bodies are set)
PULL_LINES = """        for body in CASE["fixed"]:
            node = self.spheres_model_part.GetNode(body[0])
            for var, value in zip((K.VELOCITY_X, K.VELOCITY_Y, K.VELOCITY_Z), body[1]):
                node.Fix(var)
                node.SetSolutionStepValue(var, value)
"""
PULL_TEMPLATE = TEMPLATE.replace("        self.demcheck_step = 0\n", PULL_LINES + "        self.demcheck_step = 0\n", 1)
COHESIVE = ("DEM_D_Hertz_viscous_Coulomb_JKR", "DEM_D_Hertz_viscous_Coulomb_DMT")  # the scenarios' adhesive laws
# the rolling scenarios' torque models (engines/kratos/scenario.py); Bounded is the relation's default name, unused
# while RollingFrictionOption is off
ROLLING_MODELS = ("DEMRollingFrictionModelConstantTorque", "DEMRollingFrictionModelViscousTorque")

def _case_literal(steps: int, bodies: list, gamma: list, fixed: list | None = None) -> str:
    """The runner's data line: numbers only, each written with repr (float → shortest exact text); ``fixed``
    (the pull's template only): [node id, [vx, vy, vz]] of each body whose velocity Kratos holds."""
    def num(x):
        x = float(x)
        if not math.isfinite(x):
            raise UnsupportedByEngine(f"a non-finite number ({x!r}) cannot go into a Kratos deck")
        return repr(x)

    b = ", ".join(f"[{num(r)}, [{', '.join(num(c) for c in v)}], [{', '.join(num(c) for c in w)}]]"
                  for r, v, w in bodies)
    g = ", ".join(f"[{int(i)}, {int(j)}, {num(x)}]" for i, j, x in gamma)
    if fixed is None:
        return f"CASE = {{'steps': {int(steps)}, 'bodies': [{b}], 'gamma': [{g}]}}"
    h = ", ".join(f"[{int(i)}, [{', '.join(num(c) for c in v)}]]" for i, v in fixed)
    return f"CASE = {{'steps': {int(steps)}, 'bodies': [{b}], 'gamma': [{g}], 'fixed': [{h}]}}"


def _check_options(options: dict) -> None:
    """``copies`` (1 only); a scenario's ``steps``, ``fixed``, ``rolling`` and ``mapping``
    (engines/kratos/scenario.py)."""
    if options.get("copies", 1) != 1:
        raise UnsupportedByEngine("Kratos decks are written for one copy of a collision")
    known = {"copies", "steps", "fixed", "rolling", "mapping"}
    if set(options) - known:
        raise TypeError(f"unknown deck options {sorted(set(options) - known)}")
    rolling = options.get("rolling")
    if rolling is not None and (rolling[0] not in ROLLING_MODELS or not math.isfinite(float(rolling[1]))
                                or float(rolling[1]) < 0.0):
        raise UnsupportedByEngine(f"no Kratos rolling friction model {rolling!r} is written here")


def deck(engine: Engine, case: Case, dt: float | None = None, length: float = 1.0, native=None,
         **options) -> common.Deck:
    """The deck of a collision case, written with ``engine``'s mapping (the Engine that runs it; ``native``: one
    configuration for every pair instead of the mapped model). One copy of the collision only (no batched copies). A
    scenario's (engines/kratos/scenario.py): ``steps`` its layout's length (the bodies where its case puts them),
    ``fixed`` the pull's held velocities (PULL_TEMPLATE), ``rolling`` (model name, ROLLING_FRICTION) the relation's
    rolling friction model with RollingFrictionOption on, ``mapping`` the scenario mapping (its fidelity and reasons
    go into the header, not the contact's alone)."""
    _check_options(options)
    fixed = options.get("fixed")
    sc = common.scene(case, dt, length) if options.get("steps") is None else _scenario_scene(case, dt, options["steps"])
    mp = contact_mapping(case, engine, native)
    nat = mp.require()
    n = len(case.particles)
    if n > 2:
        raise UnsupportedByEngine("Kratos decks are written for two bodies")
    natives = {}
    for i, j in common.type_pairs(case):
        pm = pair_mapping(case, engine, i, j, native)
        if pm.native is None:
            raise UnsupportedByEngine(f"pair {i + 1} {j + 1 if j is not None else 'wall'}: {'; '.join(pm.reasons)}")
        if pm.native.normal != nat.normal:
            raise UnsupportedByEngine("Kratos decks here take one law for every pair: the pairs map differently")
        natives[(i, j)] = pm.native
    # the particles' moduli: Kratos' E* of the contact of interest is the mapped one (a wall face is rigid)
    e_star = nat.normal_args[0]
    mats = [case.materials[p.material] for p in case.particles]
    # a frictional law's Poisson's ratio is the mapping's (it sets Kt/Kn = 2(1 − ν)/(2 − ν)); else the materials'
    nu = nat.props.get("poisson")
    nus = [m.poisson_ratio if nu is None else float(nu) for m in mats]
    youngs = [particle_young(e_star, nus, bool(case.walls))] * n
    wall_id = n + 1
    gamma = []
    for (i, j), pn in natives.items():
        a, b = i + 1, (wall_id if j is None else j + 1)
        gamma += [(a, b, pn.damping_coeff)] + ([(b, a, pn.damping_coeff)] if a != b and j is not None else [])
    bodies = [(p.radius, p.velocity, p.angular_velocity) for p in case.particles]
    lines = common.header("kratos", sc, options.get("mapping") or mp, VERSION_NOTE, "python")
    lines += common.notes(nat.comments)
    lines.append(common.comment(f"time scheme {SCHEME}; files read: {', '.join(FILES)}"))
    data = _case_literal(sc.steps, bodies, gamma, fixed)
    text = "\n".join(lines) + "\n" + (TEMPLATE if fixed is None else PULL_TEMPLATE).replace(CASE_LINE, data, 1)
    g = list(case.run.gravity)
    params = {
        "Dimension": 3, "PeriodicDomainOption": False, "BoundingBoxOption": False, "dem_inlet_option": False,
        "GravityX": float(g[0]), "GravityY": float(g[1]), "GravityZ": float(g[2]),
        "RotationOption": True, "CleanIndentationsOption": False,
        "solver_settings": {"RemoveBallsInitiallyTouchingWalls": False, "strategy": "sphere_strategy",
                            "material_import_settings": {"materials_filename": "MaterialsDEM.json"}},
        "VirtualMassCoefficient": 1.0, "RollingFrictionOption": False, "GlobalDamping": 0.0,
        "ContactMeshOption": False, "OutputFileType": "Ascii", "Multifile": "single_file",
        "ElementType": "SphericPartDEMElement3D", "TranslationalIntegrationScheme": SCHEME,
        "RotationalIntegrationScheme": "Direct_Integration", "AutomaticTimestep": False,
        "DeltaTimeSafetyFactor": 1.0, "MaxTimeStep": float(sc.dt), "FinalTime": float(sc.dt) * (sc.steps + 10),
        "NeighbourSearchFrequency": 1, "GraphExportFreq": 1e30, "VelTrapGraphExportFreq": 1e30,
        "OutputTimeStep": 1e30, "PostVelocity": False, "problem_name": PROBLEM}
    relation = _relation(nat, options.get("rolling"))
    params["RollingFrictionOption"] = options.get("rolling") is not None
    materials = [{"material_name": f"particle{k + 1}", "material_id": k + 1,
                  "Variables": {"PARTICLE_DENSITY": float(mats[k].density), "YOUNG_MODULUS": float(youngs[k]),
                                "POISSON_RATIO": float(nus[k])}} for k in range(n)]
    relations = [{"material_names_list": [f"particle{i + 1}", f"particle{j + 1}"],
                  "material_ids_list": [i + 1, j + 1], "Variables": relation} for (i, j) in natives if j is not None]
    table = [[f"SpheresPart.Body{k + 1}", f"particle{k + 1}"] for k in range(n)]
    if case.walls:
        materials.append({"material_name": "wall", "material_id": wall_id,
                          "Variables": {"YOUNG_MODULUS": RIGID_FACE_MODULUS, "POISSON_RATIO": float(nus[0])}})
        relations += [{"material_names_list": [f"particle{i + 1}", "wall"], "material_ids_list": [i + 1, wall_id],
                       "Variables": relation} for (i, j) in natives if j is None]
        table.append(["RigidFacePart.Wall", "wall"])
    files = {"ProjectParameters.json": json.dumps(params, indent=1),
             "MaterialsDEM.json": json.dumps({"materials": materials, "material_relations": relations,
                                              "material_assignation_table": table}, indent=1),
             f"{PROBLEM}DEM.mdpa": _spheres_mdpa(case),
             f"{PROBLEM}DEM_FEM_boundary.mdpa": _wall_mdpa(sc, wall_id) if case.walls else _empty_mdpa()}
    return common.Deck("kratos", text, files, dt=sc.dt, check=check)


def _relation(nat, rolling) -> dict:
    """A relation's Variables: the law, the mapping's friction, the law's own numbers (Custom_Constants' Kn and Kt,
    a cohesive law's PARTICLE_COHESION), and ``rolling`` (model name, ROLLING_FRICTION) or no rolling friction."""
    friction = [float(nat.props.get(k, 0.0)) for k in ("mu_s", "mu_d", "decay")]
    relation = {"STATIC_FRICTION": friction[0], "DYNAMIC_FRICTION": friction[1], "FRICTION_DECAY": friction[2],
                "ROLLING_FRICTION": 0.0,
                "ROLLING_FRICTION_WITH_WALLS": 0.0, "COEFFICIENT_OF_RESTITUTION": 1.0,
                "DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": nat.normal,
                "DEM_ROLLING_FRICTION_MODEL_NAME": "DEMRollingFrictionModelBounded"}
    if nat.normal == CUSTOM:  # its Kn, Kt are the contact's (the relation's) K_NORMAL, K_TANGENTIAL
        relation.update(K_NORMAL=float(nat.props["k_normal"]), K_TANGENTIAL=float(nat.props["k_tangential"]))
    if nat.normal in COHESIVE:  # the cohesive laws read the relation's PARTICLE_COHESION (w, J/m²)
        relation["PARTICLE_COHESION"] = float(nat.props["cohesion"])
    if rolling is not None:  # the relation's model and coefficient (a wall's contact reads them too)
        name, mu = rolling
        relation.update(ROLLING_FRICTION=float(mu), ROLLING_FRICTION_WITH_WALLS=float(mu),
                        DEM_ROLLING_FRICTION_MODEL_NAME=name)
    return relation


_f = common.float_literal


def _scenario_scene(case: Case, dt: float, steps: int):
    """A scenario's scene (engines/kratos/scenario.py): its layout's step and length, the bodies where the layout
    put them (they need not meet: a pull, a sphere resting on its wall), a box 40 radii around them."""
    import numpy as np

    from ...laws.model import resolve

    pos = np.array([p.position for p in case.particles], dtype=float)
    reach = 40.0 * max(p.radius for p in case.particles)
    lo, hi = pos.min(axis=0) - reach, pos.max(axis=0) + reach
    axis = side = wpos = None
    if case.walls:
        if len(case.walls) > 1:
            raise UnsupportedByEngine("Kratos scenario decks are written for one wall")
        axis, side = common.wall_axis(case.walls[0], 0)
        wpos = float(case.walls[0].point[axis])
    return common.Scene(case, resolve(case), float(dt), int(steps), (lo, hi), axis, side, wpos)


def _spheres_mdpa(case: Case) -> str:
    n = len(case.particles)
    lines = ["Begin ModelPartData", "End ModelPartData"]
    for k in range(n):
        lines += [f"Begin Properties {k + 1}", "End Properties"]
    lines += ["Begin Nodes"] + [f"{k + 1} {' '.join(_f(c) for c in p.position)}"
                                for k, p in enumerate(case.particles)] + ["End Nodes"]
    for k in range(n):
        lines += ["Begin Elements SphericParticle3D", f"{k + 1} {k + 1} {k + 1}", "End Elements"]
    lines += ["Begin NodalData RADIUS"] + [f"{k + 1} 0 {_f(p.radius)}" for k, p in enumerate(case.particles)]
    lines += ["End NodalData"]
    for k in range(n):
        lines += [f"Begin SubModelPart Body{k + 1}", "Begin SubModelPartNodes", str(k + 1), "End SubModelPartNodes",
                  "Begin SubModelPartElements", str(k + 1), "End SubModelPartElements", "End SubModelPart"]
    return "\n".join(lines) + "\n"


def _empty_mdpa() -> str:
    return "Begin ModelPartData\nEnd ModelPartData\n"


def _wall_mdpa(sc, wall_id: int) -> str:
    """One triangle in the wall's plane whose inside holds the whole scene box's shadow (a face's edges and
    corners are contacts of their own in Kratos; the bodies never come near them)."""
    lo, hi = sc.box
    ax = sc.wall_axis
    u, v = [k for k in range(3) if k != ax]
    span = max(hi[u] - lo[u], hi[v] - lo[v])
    a0, b0 = lo[u] - span, lo[v] - span
    corners = [(a0, b0), (a0 + 5 * span, b0), (a0, b0 + 5 * span)]
    if sc.wall_side == "hi":  # the face's normal towards the particle (counter-clockwise seen from it)
        corners = [corners[0], corners[2], corners[1]]
    nodes = []
    for a, b in corners:
        p = [0.0, 0.0, 0.0]
        p[ax], p[u], p[v] = sc.wall_position, a, b
        nodes.append(p)
    ids = [wall_id + k for k in range(3)]
    lines = ["Begin ModelPartData", "End ModelPartData", f"Begin Properties {wall_id}", "End Properties",
             "Begin Nodes"] + [f"{i} {' '.join(_f(c) for c in p)}" for i, p in zip(ids, nodes)] + [
        "End Nodes", "Begin Conditions RigidFace3D3N", f"1 {wall_id} {ids[0]} {ids[1]} {ids[2]}", "End Conditions",
        "Begin SubModelPart Wall", "Begin SubModelPartData", "RIGID_BODY_MOTION 0", "IDENTIFIER wall",
        "End SubModelPartData", "Begin SubModelPartNodes"] + [str(i) for i in ids] + [
        "End SubModelPartNodes", "Begin SubModelPartConditions", "1", "End SubModelPartConditions", "End SubModelPart"]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- the guard

def _refuse(what: str, why: str):
    raise UnsupportedByEngine(f"refusing to run a Kratos deck: {what} {why}")


def _check_case(line: str, keys: dict = CASE_KEYS) -> None:
    if not line.startswith("CASE = "):
        _refuse("its data line", "is not 'CASE = {...}'")
    try:
        tree = ast.parse(line[len("CASE = "):], mode="eval")
    except SyntaxError:
        _refuse("its data line", "is not a Python literal")
    allowed = (ast.Expression, ast.Dict, ast.List, ast.Constant, ast.UnaryOp, ast.USub, ast.Load)
    for node in ast.walk(tree):
        if not isinstance(node, allowed):
            _refuse("its data line", f"holds a {type(node).__name__}, not only numbers")
        if isinstance(node, ast.Constant) and (isinstance(node.value, bool) or not isinstance(
                node.value, (int, float, str))):
            _refuse("its data line", f"holds {node.value!r}")
        if isinstance(node, ast.UnaryOp) and not (isinstance(node.operand, ast.Constant)
                                                  and type(node.operand.value) in (int, float)):
            _refuse("its data line", "negates something other than a number")
    value = ast.literal_eval(tree)
    if not isinstance(value, dict) or set(value) != set(keys):
        _refuse("its data line", f"must have exactly the keys {sorted(keys)}")
    strings = [n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
    if sorted(strings) != sorted(keys):
        _refuse("its data line", "holds a string that is not one of its keys")
    if not isinstance(value["steps"], int) or value["steps"] < 0:
        _refuse("its data line", "has a step count that is not a whole number ≥ 0")

    def num(x):
        return type(x) in (int, float) and math.isfinite(x)

    def vec(v):
        return isinstance(v, list) and len(v) == 3 and all(num(x) for x in v)

    if not (1 <= len(value["bodies"]) <= 2 and all(isinstance(b, list) and len(b) == 3 and num(b[0]) and vec(b[1])
                                                   and vec(b[2]) for b in value["bodies"])):
        _refuse("its data line", "has bodies that are not [radius, [3 numbers], [3 numbers]]")
    if not all(isinstance(g, list) and len(g) == 3 and type(g[0]) is int and type(g[1]) is int and num(g[2])
               for g in value["gamma"]):
        _refuse("its data line", "has damping entries that are not [property id, property id, number]")
    if not all(isinstance(f, list) and len(f) == 2 and type(f[0]) is int and 1 <= f[0] <= len(value["bodies"])
               and vec(f[1]) for f in value.get("fixed", [])):
        _refuse("its data line", "has held velocities that are not [body id, [3 numbers]]")


def check(text: str, files: dict | None = None) -> None:
    """Raise unless ``text`` is the runner template (after whole-line comments) with a numbers-only CASE line
    and ``files`` are the four files demcheck writes, each holding only what demcheck writes."""
    lines = text.split("\n")
    # Python decodes a script by the encoding its first two lines may declare (PEP 263): a comment there that
    # names one would make Python run a different text from the one checked here
    for n, line in enumerate(lines[:2], 1):
        if re.search(r"coding[:=]", line):
            _refuse(f"line {n}", f"could declare the source encoding: {line[:80]!r}")
    if "\\" in "\n".join(x for x in lines if x.startswith("#")):
        _refuse("its comments", "hold a backslash")
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        if any(not ch.isprintable() for ch in lines[k]):
            _refuse(f"line {k + 1}", "is a comment with characters that are not printable")
        k += 1
    body = lines[k:]
    # the collision's template, or the pull's (its line count differs: PULL_LINES)
    pull = len(body) == len(PULL_TEMPLATE.split("\n"))
    template = (PULL_TEMPLATE if pull else TEMPLATE).split("\n")
    if len(body) != len(template):
        _refuse("its script", "is not demcheck's runner template (line count)")
    for no, (got, want) in enumerate(zip(body, template), start=k + 1):
        if want == CASE_LINE:
            _check_case(got, PULL_KEYS if pull else CASE_KEYS)
        elif got != want:
            _refuse(f"line {no}", f"differs from demcheck's runner template: {got[:60]!r}")
    files = files or {}
    if set(files) != set(FILES):
        _refuse("its files", f"are {sorted(files)}, not {sorted(FILES)}")
    _check_json(files["ProjectParameters.json"], "ProjectParameters.json")
    _check_json(files["MaterialsDEM.json"], "MaterialsDEM.json")
    for name in FILES[2:]:
        _check_mdpa(files[name], name)


PARAMETER_KEYS = frozenset({
    "Dimension", "PeriodicDomainOption", "BoundingBoxOption", "dem_inlet_option", "GravityX", "GravityY",
    "GravityZ", "RotationOption", "CleanIndentationsOption", "solver_settings", "RemoveBallsInitiallyTouchingWalls",
    "strategy", "material_import_settings", "materials_filename", "VirtualMassCoefficient", "RollingFrictionOption",
    "GlobalDamping", "ContactMeshOption", "OutputFileType", "Multifile", "ElementType",
    "TranslationalIntegrationScheme", "RotationalIntegrationScheme", "AutomaticTimestep", "DeltaTimeSafetyFactor",
    "MaxTimeStep", "FinalTime", "NeighbourSearchFrequency", "GraphExportFreq", "VelTrapGraphExportFreq",
    "OutputTimeStep", "PostVelocity", "problem_name",
    "materials", "material_relations", "material_assignation_table", "material_name", "material_id", "Variables",
    "material_names_list", "material_ids_list", "PARTICLE_DENSITY", "YOUNG_MODULUS", "POISSON_RATIO",
    "STATIC_FRICTION", "DYNAMIC_FRICTION", "FRICTION_DECAY", "ROLLING_FRICTION", "ROLLING_FRICTION_WITH_WALLS",
    "COEFFICIENT_OF_RESTITUTION", "DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME", "DEM_ROLLING_FRICTION_MODEL_NAME",
    "K_NORMAL", "K_TANGENTIAL", "PARTICLE_COHESION"})
KNOWN_STRINGS = frozenset({"sphere_strategy", "MaterialsDEM.json", "Ascii", "single_file", "SphericPartDEMElement3D",
                           SCHEME, "Direct_Integration", PROBLEM, "DEMRollingFrictionModelBounded", "wall",
                           *LAWS, *COHESIVE, *ROLLING_MODELS})
NAME = re.compile(r"particle[0-9]{1,3}|SpheresPart\.Body[0-9]{1,3}|RigidFacePart\.Wall")


def _check_json(text: str, name: str) -> None:
    try:
        value = json.loads(text, parse_constant=lambda c: _refuse(name, f"holds {c}"))
    except json.JSONDecodeError as exc:
        _refuse(name, f"is not JSON ({exc})")

    def walk(v):
        if isinstance(v, dict):
            for key, item in v.items():
                if key not in PARAMETER_KEYS:
                    _refuse(name, f"has the key {key!r}, which demcheck does not write")
                walk(item)
        elif isinstance(v, list):
            for item in v:
                walk(item)
        elif isinstance(v, str):
            if v not in KNOWN_STRINGS and not NAME.fullmatch(v):
                _refuse(name, f"holds the string {v[:40]!r}, which demcheck does not write")
        elif not isinstance(v, (bool, int, float)):
            _refuse(name, f"holds {v!r}")
    walk(value)


NUMBER = r"-?(?:[0-9]+\.?[0-9]*(?:e[-+]?[0-9]+)?|inf)"
MDPA_LINE = re.compile(
    r"(Begin|End) (ModelPartData|Nodes|SubModelPartNodes|SubModelPartElements|SubModelPartConditions|"
    r"SubModelPartData|SubModelPart|Elements|Conditions|NodalData)"
    r"|Begin (Properties [0-9]+|Elements SphericParticle3D|Conditions RigidFace3D3N|NodalData RADIUS|"
    r"SubModelPart (Body[0-9]{1,3}|Wall))|End Properties|RIGID_BODY_MOTION 0|IDENTIFIER wall"
    rf"|[0-9]+( {NUMBER}){{0,4}}")


def _check_mdpa(text: str, name: str) -> None:
    for no, line in enumerate(text.split("\n"), start=1):
        if line and not MDPA_LINE.fullmatch(line):
            _refuse(f"{name}:{no}", f"is not a line demcheck writes: {line[:60]!r}")


def read_states(workdir):
    """The runner's state table (TEMPLATE's ``demcheck_write``: engines/output.py's STATE_HEAD, then a STATE_ROW per
    body per step) with the record's columns (engines.output.STATE_COLUMNS): the collisions' and the scenarios'."""
    from pathlib import Path

    from ..output import read_state_table

    return read_state_table(Path(workdir) / common.DUMP_FILE, "the Kratos runner")
