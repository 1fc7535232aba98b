"""Yade collision scripts: a fixed template with only numbers substituted (written with repr(), so they
round-trip), and the guard that proves a script is one of them (:func:`check_script`).

The script builds the two bodies (spheres, or a sphere and an axis-aligned ``Wall``), one material per body,
the engines (``NewtonIntegrator(damping=0, gravity=…)``: Yade's default Cundall damping is 0.2 in many
examples), then steps one step at a time. Yade's NewtonIntegrator is a leap-frog: a step computes the forces
F_k at the positions x_k with the velocities v_{k−½}, then v_{k+½} = v_{k−½} + dt F_k/m and x_{k+1} = x_k +
dt v_{k+½}. The state table's row of step k (``dump.txt``: a header of the record's columns, a row per body
per step; :func:`read_states`) holds x_k, F_k (the weight included, as the LAMMPS-family engines write a
body's force) and the full-step velocity v_k = v_{k−½} + ½dt F_k/m: exactly the rows velocity Verlet writes,
whose force at step k reads the same x_k and v_{k−½}. The script starts from v_{−½} = v_0 − ½dt g (no contact
at the start, so the weight is F_0), so that its first row's velocity is the case's.
"""

from __future__ import annotations

import ast
import math

from ...case import Case
from ...errors import DemcheckError, UnsupportedByEngine
from ...inputs import common
from ..base import Engine
from ..output import STATE_HEAD, STATE_ROW
from ..mapping import contact_mapping
from .mapping import CUNDALL, LUDING, MINDLIN, VISCEL

VERSION_NOTE = "written for Yade 2023.02a (yade -x -n)"
# a ViscElPhys Native whose props name CUNDALL (mapping.py) runs as FrictMat + FrictPhys + CundallStrack: a linear
# spring and an incremental shear force capped at μFn, without dashpots (cn = cs = 0), as Yade's FrictPhys computes
# the states' table (:func:`read_states`): a header line of the record's column names, then a row per body per step
HEAD, ROW = STATE_HEAD, STATE_ROW  # engines/output.py's layout, read by its read_state_table
STRINGS = frozenset({HEAD, ROW, common.DUMP_FILE, "w"})
NAMES = frozenset({
    "O", "Vector3", "utils", "FrictMat", "ViscElMat", "ForceResetter", "InsertionSortCollider", "Bo1_Sphere_Aabb",
    "Bo1_Wall_Aabb", "InteractionLoop", "Ig2_Sphere_Sphere_ScGeom", "Ig2_Wall_Sphere_ScGeom",
    "Ip2_FrictMat_FrictMat_MindlinPhys", "Law2_ScGeom_MindlinPhys_Mindlin", "Ip2_ViscElMat_ViscElMat_ViscElPhys",
    "Ip2_FrictMat_FrictMat_FrictPhys", "Law2_ScGeom_FrictPhys_CundallStrack",
    "Law2_ScGeom_ViscElPhys_Basic", "NewtonIntegrator", "open", "range", "len",
    "LudingMat", "Ip2_LudingMat_LudingMat_LudingPhys", "Law2_ScGeom_LudingPhys_Basic",
    # the template's own variables
    "DT", "STEPS", "G", "ids", "mass", "inertia", "radius", "out", "k", "n", "i", "s", "x", "v", "w", "f", "t", "a",
    "b", "b0", "b1"})
# keyword arguments of the template's calls (Yade's own constructor keywords)
KEYWORDS = frozenset({"axis", "betan", "betas", "cn", "cs", "damping", "density", "en", "et", "frictionAngle",
                      "gravity", "kn", "ks", "material", "poisson", "sense", "tc", "young", "dt",
                      "k1", "kp", "kc", "PhiF", "G0"})
ATTRIBUTES = frozenset({"materials", "bodies", "append", "sphere", "wall", "state", "mass", "inertia", "pos", "vel",
                        "angVel", "engines", "dt", "step", "forces", "f", "t", "write", "close"})
NODES = (ast.Module, ast.Expr, ast.Assign, ast.Call, ast.Name, ast.Load, ast.Store, ast.Attribute, ast.Constant,
         ast.Tuple, ast.List, ast.keyword, ast.For, ast.BinOp, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Mod,
         ast.UnaryOp, ast.USub, ast.Subscript, ast.ImportFrom, ast.alias, ast.ListComp, ast.comprehension)
COOKIE = "coding"


def check_script(text: str, files: dict | None = None) -> None:
    """The final guard before Yade runs a script: it parses, and holds only the template's names, attributes,
    calls and constants (numbers, and the template's own strings); its first two lines name no encoding; it
    reads no other file. Raises DemcheckError otherwise."""
    guard(text, files, NAMES, ATTRIBUTES, KEYWORDS, STRINGS, NODES)


def guard(text: str, files, names, attributes, keywords, strings, nodes, flags=False) -> None:
    """:func:`check_script` with a template's allow-lists (names, attributes, keywords, strings, ast node
    types; ``flags``: the constant True is allowed too): the collision template's here, the packing template's
    in :mod:`.packing`."""
    def refuse(why: str):
        raise DemcheckError(f"refusing to run a Yade script: {why}")

    if files:
        refuse(f"it comes with files ({', '.join(files)}); demcheck's Yade scripts read none")
    if not text.isascii():
        refuse("it has a character that is not ASCII")
    for n, line in enumerate(text.split("\n")[:2], 1):
        if COOKIE in line:
            refuse(f"line {n} could declare the source encoding: {line[:80]!r}")
    if any(not line.isprintable() for line in text.split("\n")):
        refuse("a line has a character that is not printable")
    try:
        tree = ast.parse(text)
    except SyntaxError as exc:
        refuse(f"it does not parse (line {exc.lineno}: {exc.msg})")
    for node in ast.walk(tree):
        if not isinstance(node, nodes):
            refuse(f"line {getattr(node, 'lineno', '?')}: {type(node).__name__} is not in the template")
        if isinstance(node, ast.Name) and node.id not in names:
            refuse(f"line {node.lineno}: name {node.id!r} is not in the template")
        if isinstance(node, ast.Attribute) and node.attr not in attributes:
            refuse(f"line {node.lineno}: attribute {node.attr!r} is not in the template")
        if isinstance(node, ast.keyword) and node.arg is None:
            refuse(f"line {node.lineno}: ** arguments are not in the template")
        if isinstance(node, ast.keyword) and node.arg not in keywords:
            refuse(f"line {node.lineno}: keyword {node.arg!r} is not in the template")
        if isinstance(node, ast.ImportFrom) and (node.module != "yade" or [a.name for a in node.names] != ["utils"]
                                                 or node.names[0].asname or node.level != 0):
            refuse(f"line {node.lineno}: only 'from yade import utils' is imported")
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, str):
                if v not in strings:
                    refuse(f"line {node.lineno}: string {v[:40]!r} is not one of the template's")
            elif v is True and flags:
                continue
            elif isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                refuse(f"line {node.lineno}: constant {v!r} is not a finite number")


def ascii_comment(line: str) -> str:
    """A comment line (inputs.common.comment's) with every character outside ASCII escaped: Yade reads a
    script in the locale's encoding when it is run by hand."""
    return line.encode("ascii", "backslashreplace").decode("ascii")


_num = common.float_literal


def _vec(xs) -> str:
    return f"Vector3({', '.join(_num(x) for x in xs)})"


def materials(nat, case: Case, sc) -> tuple[str, str]:
    """(particle material, wall material) as Yade constructor calls, from the native configuration."""
    p = nat.props
    phi = math.atan(p.get("mu", 0.0))
    if nat.normal == VISCEL and p.get("law2") == CUNDALL:
        # Ip2_FrictMat_FrictMat_FrictPhys: kn = 2EaRa·EbRb/(EaRa + EbRb), ks = kn·poisson for equal materials —
        # E R̄·2 for a pair, E·R on a Wall (Ig2_Wall_Sphere_ScGeom gives the wall the sphere's radius)
        radii = [q.radius for q in case.particles]
        r = radii[0] if case.walls else 2.0 * radii[0] * radii[1] / (radii[0] + radii[1])
        body = (f"FrictMat(young={_num(p['kn'] / r)}, poisson={_num(p['ks'] / p['kn'])}, frictionAngle={_num(phi)}, "
                "density=1.0)")
        return body, body
    if nat.normal == VISCEL:
        if p.get("tc") is not None:  # Yade's own calibration input (never mapped: docs/yade.md's trap)
            body = (f"ViscElMat(tc={_num(p['tc'])}, en={_num(p['en'])}, et={_num(p.get('et', 1.0))}, "
                    f"frictionAngle={_num(phi)}, density=1.0)")
            return body, body
        # in series: 1/(1/a + 1/b) = a/2 for equal values; a wall's material takes the same values
        body = (f"ViscElMat(kn={_num(2.0 * p['kn'])}, cn={_num(2.0 * p['cn'])}, ks={_num(2.0 * p['ks'])}, "
                f"cs={_num(2.0 * p['cs'])}, frictionAngle={_num(phi)}, density=1.0)")
        return body, body
    if nat.normal == LUDING:
        # Ip2_LudingMat_LudingMat_LudingPhys: 2/(1/a + 1/b), the value itself for equal materials
        body = (f"LudingMat(k1={_num(p['k1'])}, kp={_num(p['kp'])}, kc=0.0, ks=0.0, PhiF={_num(p['phi_f'])}, "
                f"G0=0.0, frictionAngle=0.0, density=1.0)")
        return body, body
    if nat.normal == MINDLIN:
        r_y = (case.particles[0].radius / 2.0) if case.walls else p["r_eff"]  # Yade's R̄ (a wall: R/2)
        nu = 0.0
        if p["kso"] > 0.0:  # kso/kno = 3(1 − ν)/(2 − ν) for two equal materials
            rho = p["kso"] / p["kno"]
            nu = (3.0 - 2.0 * rho) / (3.0 - rho)
            if not -1.0 < nu < 0.5:
                raise UnsupportedByEngine(f"Yade Mindlin: kso/kno = {rho:.4g} needs Poisson's ratio {nu:.4g}, "
                                          "outside (−1, 0.5)")
        e_star = p["kno"] / (4.0 / 3.0 * math.sqrt(r_y))
        young = 2.0 * (1.0 - nu * nu) * e_star  # two equal materials: E* = E/(2(1 − ν²))
        body = f"FrictMat(young={_num(young)}, poisson={_num(nu)}, frictionAngle={_num(phi)}, density=1.0)"
        return body, body
    raise UnsupportedByEngine(f"no Yade deck for {nat.normal}")


def deck(engine: Engine, case: Case, dt: float | None = None, length: float = 1.0, native=None,
         **options) -> common.Deck:
    """The script of a collision case, by ``engine``'s mapping (``native``: a configuration used instead of it)."""
    if options.get("copies", 1) != 1:
        raise UnsupportedByEngine("Yade scripts are written for one copy of a collision")
    sc = common.scene(case, dt, length)
    mp = contact_mapping(case, engine, native)
    nat = mp.require()
    body_mat, wall_mat = materials(nat, case, sc)
    p = nat.props
    g = [float(x) for x in case.run.gravity]
    if nat.normal == VISCEL and p.get("law2") == CUNDALL:
        phys, law = "Ip2_FrictMat_FrictMat_FrictPhys()", "Law2_ScGeom_FrictPhys_CundallStrack()"
    elif nat.normal == VISCEL:
        phys, law = "Ip2_ViscElMat_ViscElMat_ViscElPhys()", "Law2_ScGeom_ViscElPhys_Basic()"
    elif nat.normal == LUDING:
        phys, law = "Ip2_LudingMat_LudingMat_LudingPhys()", "Law2_ScGeom_LudingPhys_Basic()"
    else:
        phys = (f"Ip2_FrictMat_FrictMat_MindlinPhys(betan={_num(p['betan'])}, betas={_num(p['betas'])})"
                if p["betan"] > 0.0 or p["betas"] > 0.0 else "Ip2_FrictMat_FrictMat_MindlinPhys()")
        if p.get("en") is not None:  # Yade's own restitution input (never mapped: docs/findings.md's trap)
            if p["betan"] > 0.0 or p["betas"] > 0.0:
                raise DemcheckError("a Yade MindlinPhys takes en or betan/betas, not both")
            phys = f"Ip2_FrictMat_FrictMat_MindlinPhys(en={_num(p['en'])})"
        law = "Law2_ScGeom_MindlinPhys_Mindlin()"
    head = common.header("yade", sc, mp, VERSION_NOTE, "yade -x -n")
    notes = [ascii_comment(c) for c in head[1:] + common.notes(nat.comments)]
    lines = ["# demcheck: a Yade script (Python), generated from a fixed template",
             "# every value below is a number written by demcheck"] + notes
    lines += ["from yade import utils", "", f"DT = {_num(sc.dt)}", f"STEPS = {int(sc.steps)}", f"G = {_vec(g)}",
              f"O.materials.append({body_mat})"]
    if case.walls:
        lines.append(f"O.materials.append({wall_mat})")
    ids = []
    for i, part in enumerate(case.particles):
        lines.append(f"b{i} = O.bodies.append(utils.sphere({_vec(part.position)}, {_num(part.radius)}, material=0))")
        ids.append(f"b{i}")
    if case.walls:
        sense = 1 if sc.wall_side == "lo" else -1
        lines.append(f"O.bodies.append(utils.wall({_num(sc.wall_position)}, axis={int(sc.wall_axis)}, "
                     f"sense={sense}, material=1))")
    lines.append(f"ids = [{', '.join(ids)}]")
    masses, inertias = [], []
    for i, part in enumerate(case.particles):
        m = case.mass(i)
        inertia = 0.4 * m * part.radius * part.radius
        masses.append(_num(m))
        inertias.append(_num(inertia))
        lines += [f"O.bodies[b{i}].state.mass = {_num(m)}",
                  f"O.bodies[b{i}].state.inertia = {_vec([inertia] * 3)}",
                  # leap-frog starts from v_{-1/2} = v_0 − ½dt F_0/m: no contact at the start, the weight alone
                  f"O.bodies[b{i}].state.vel = {_vec([v - 0.5 * sc.dt * gk for v, gk in zip(part.velocity, g)])}",
                  f"O.bodies[b{i}].state.angVel = {_vec(part.angular_velocity)}"]
    lines += [f"mass = [{', '.join(masses)}]", f"radius = [{', '.join(_num(q.radius) for q in case.particles)}]", f"inertia = [{', '.join(inertias)}]",
              "O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),",
              "              InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],",
              f"                              [{phys}],",
              f"                              [{law}]),",
              # damping 0 (Yade's default is 0.2): a Native's newton_damping only where the audit measures its effect
              f"              NewtonIntegrator(damping={_num(float(p.get('newton_damping', 0.0)))}, gravity=G)]",
              "O.dt = DT",
              f"out = open({common.DUMP_FILE!r}, 'w')",
              f"out.write({HEAD!r})",
              "n = len(ids)",
              # step k: F_k (the weight m g included: NewtonIntegrator adds it, O.forces holds the contacts') at x_k
              # with v_{k-1/2}; the row holds x_k, v_k = v_{k-1/2} + dt F_k/(2m), F_k
              "for k in range(STEPS + 1):",
              "    x = [Vector3(O.bodies[i].state.pos) for i in ids]",
              "    v = [Vector3(O.bodies[i].state.vel) for i in ids]",
              "    w = [Vector3(O.bodies[i].state.angVel) for i in ids]",
              "    O.step()",
              "    for s in range(n):",
              "        f = O.forces.f(ids[s]) + G * mass[s]",
              "        t = O.forces.t(ids[s])",
              "        a = v[s] + f * (0.5 * DT / mass[s])",
              "        b = w[s] + t * (0.5 * DT / inertia[s])",
              f"        out.write({ROW!r} % (k, s + 1, s + 1, radius[s], mass[s], x[s][0], x[s][1], "
              "x[s][2], a[0], a[1], a[2], b[0], b[1], b[2], f[0], f[1], f[2], t[0], t[1], t[2]))",
              "out.close()", ""]
    return common.Deck("yade", "\n".join(lines), {}, dt=sc.dt, check=check_script)


def read_states(workdir):
    """The collision script's state table (HEAD, then ROW: a row per body per step, float64 as ``%.17g``) with the
    record's columns (engines.output.STATE_COLUMNS): ``step``, ``id`` and ``type`` as integers."""
    from pathlib import Path

    from ..output import read_state_table

    return read_state_table(Path(workdir) / common.DUMP_FILE, "the Yade script")
