"""LAMMPS's contact vocabulary read back from a user's deck (``demcheck audit``): ``pair_style granular`` with
``pair_coeff`` per type pair and LAMMPS's own mixing, the classic ``gran/hooke``, ``gran/hooke/history`` and
``gran/hertz/history`` styles, and ``fix wall/gran`` (``/region``). Every type pair and wall × type becomes a
Native that computes what LAMMPS 22Jul2025 computes for it (an auto-mixed pair as its explicit equivalent),
with the static traps of its settings."""

from __future__ import annotations

import math
from pathlib import Path

from ...inputs.script import (NEVER_RUN, Command, note_unread, Finding, PairSetting, ScriptError, Setup,
                              _num, finish, read_common, to_number, type_range)
from ..base import Native
from . import read as ENGINE_READ  # the deck's set-up evaluated in LAMMPS itself (a worker process)

NORMAL_ARGS = {"hooke": 2, "hertz": 2, "hertz/material": 3, "dmt": 4, "jkr": 4, "mdr": 6}
DAMPING = ("velocity", "mass_velocity", "viscoelastic", "tsuji", "coeff_restitution", "mdr", "none")
TANGENTIAL_ARGS = {"linear_nohistory": 2, "linear_history": 3, "mindlin": 3, "mindlin/force": 3,
                   "mindlin_rescale": 3, "mindlin_rescale/force": 3}
ROLLING_ARGS = {"none": 0, "sds": 3}
TWISTING_ARGS = {"none": 0, "marshall": 0, "sds": 3}
HEAT_ARGS = {"none": 0, "radius": 1, "area": 1}
CLASSIC = ("gran/hooke", "gran/hooke/history", "gran/hertz/history")
PROBED_NORMALS = ("hooke", "hertz", "hertz/material")
# the audit's probe of each sub-model beyond sliding (comparisons/audit_beyond.py MAKERS)
BEYOND_PROBES = {"rolling": "incline_sds", "twisting": "twist", "adhesion": "pull_off", "heat": "held_pair"}
DEFAULT = True  # a LAMMPS-family deck that no other reader claims is read as LAMMPS's

QUIET_FIXES = frozenset({"nve/sphere", "gravity", "print", "ave/time", "ave/atom", "enforce2d", "balance",
                         "freeze"})  # fixes without effect on a contact
READ_FIXES = ("wall/gran", "wall/gran/region", "pour", "gravity")  # the fixes whose words the audit reads



def claims(script) -> bool:
    """LAMMPS's own vocabulary: pair_style granular or a classic gran/* style (also under hybrid)."""
    return any(c.name == "pair_style" and c.words[1:2] and (c.words[1] == "granular" or c.words[1] in CLASSIC
                                                            or any(x in CLASSIC for x in c.words[1:3]))
               for c in script.commands)


def _bad(cmd: Command, why: str):
    return ScriptError(f"{cmd.where()}: {cmd.text[:70]!r}: {why}")


def parse_granular(cmd: Command, words: list[str], k: int) -> dict:
    """The sub-models of a ``granular`` argument list from words[k]: {normal, normal_coeffs, damping,
    tangential, tangential_coeffs (None for NULL), rolling, twisting, limit_damping, extras}."""
    out = {"damping": "viscoelastic", "rolling": "none", "twisting": "none", "limit_damping": False, "extras": []}
    if k >= len(words) or words[k] not in NORMAL_ARGS:
        raise _bad(cmd, f"{words[k] if k < len(words) else '(missing)'} is not a normal model of pair granular "
                        f"({', '.join(NORMAL_ARGS)})")
    out["normal"] = words[k]
    n = NORMAL_ARGS[words[k]]
    out["normal_coeffs"] = tuple(_num(cmd, k + 1 + i, f"{words[k]} coefficient {i + 1}") for i in range(n))
    k += 1 + n
    while k < len(words):
        key = words[k]
        if key == "damping":
            if k + 1 >= len(words) or words[k + 1] not in DAMPING:
                raise _bad(cmd, f"damping takes one of {', '.join(DAMPING)}")
            out["damping"] = words[k + 1]
            k += 2
            if out["damping"] == "mdr" and k < len(words) and to_number(words[k]) is not None:
                out["damping_args"] = (_num(cmd, k, "damping mdr type"),)  # damping mdr N: MDR's damping type
                k += 1
        elif key in ("tangential", "rolling", "twisting", "heat"):
            table = {"tangential": TANGENTIAL_ARGS, "rolling": ROLLING_ARGS, "twisting": TWISTING_ARGS,
                     "heat": HEAT_ARGS}[key]
            model = words[k + 1] if k + 1 < len(words) else "(missing)"
            if model not in table:
                raise _bad(cmd, f"{key} {model}: not a {key} model of pair granular ({', '.join(table)})")
            m = table[model]
            coeffs = tuple(None if words[k + 2 + i] == "NULL" else _num(cmd, k + 2 + i, f"{key} coefficient")
                           for i in range(m) if k + 2 + i < len(words))
            if len(coeffs) != m:
                raise _bad(cmd, f"{key} {model} takes {m} coefficients")
            out[key] = model
            out[f"{key}_coeffs"] = coeffs
            k += 2 + m
        elif key == "limit_damping":
            out["limit_damping"] = True
            k += 1
        elif key == "synchronized_verlet":
            out["extras"].append(key)
            k += 1
        elif key == "cutoff":
            _num(cmd, k + 1, "cutoff")
            out["extras"].append(f"cutoff {words[k + 1]}")
            k += 2
        else:
            break
    if k == len(words) and "tangential" not in out:
        raise _bad(cmd, "pair granular needs a tangential model")
    _ranges(cmd, out)
    return {**out, "rest": k}


POSITIVE, NON_NEGATIVE, RESTITUTION = ("must be > 0", lambda x: x > 0), ("must be >= 0", lambda x: x >= 0), \
    ("must be in (0, 1]", lambda x: 0 < x <= 1)
POISSON = ("must be in (-1, 0.5)", lambda x: -1 < x < 0.5)
MATERIAL_NORMALS = ("hertz/material", "dmt", "jkr", "mdr")  # where mindlin's k_t may be NULL (from E and ν)


def _ranges(cmd: Command, spec: dict) -> None:
    """The coefficients of the laws demcheck twins within their ranges, each refused by its LAMMPS name and
    value: k_n, E > 0, ν in (−1, 0.5), the damping coefficient η_n0 ≥ 0 or e in (0, 1] (tsuji,
    coeff_restitution), k_t > 0 (or NULL with a material normal model), x_γ,t ≥ 0, μ_s ≥ 0."""
    def check(what, value, rule):
        text, ok = rule
        if value is not None and not ok(value):
            raise _bad(cmd, f"{what} = {value:g}: {text}")

    normal, c = spec["normal"], spec["normal_coeffs"]
    if normal in PROBED_NORMALS:
        check(f"{normal} {'E' if normal == 'hertz/material' else 'k_n'}", c[0], POSITIVE)
        if spec["damping"] in ("tsuji", "coeff_restitution"):
            check(f"damping {spec['damping']} e (the 2nd {normal} coefficient)", c[1], RESTITUTION)
        else:
            check(f"damping {spec['damping']} η_n0 (the 2nd {normal} coefficient)", c[1], NON_NEGATIVE)
        if normal == "hertz/material":
            check("hertz/material ν", c[2], POISSON)
    tang, tc = spec.get("tangential"), spec.get("tangential_coeffs") or ()
    if tang is None or not tc:
        return
    if tang == "linear_nohistory":
        check(f"tangential {tang} x_γ,t", tc[0], NON_NEGATIVE)
    else:
        if tc[0] is None and tang.startswith("mindlin") and normal not in MATERIAL_NORMALS:
            raise _bad(cmd, f"tangential {tang} NULL: k_t from E and ν needs a material normal model "
                            f"({', '.join(MATERIAL_NORMALS)}), not {normal}")
        if tc[0] is None and not tang.startswith("mindlin"):
            raise _bad(cmd, f"tangential {tang}: k_t must be a number (NULL is mindlin's)")
        check(f"tangential {tang} k_t", tc[0], POSITIVE)
        check(f"tangential {tang} x_γ,t", tc[1], NON_NEGATIVE)
    check(f"tangential {tang} μ_s", tc[-1], NON_NEGATIVE)


def native_of(spec: dict) -> Native:
    """A parsed granular specification as a Native (the deck writer's and the twin's vocabulary)."""
    c = spec["normal_coeffs"]
    if spec["normal"] == "hertz/material":
        normal_args, damp = (c[0], c[2]), c[1]
    else:
        normal_args, damp = (c[0],), c[1]
    tc = spec["tangential_coeffs"]
    damping = spec["damping"]
    if damping == "none":  # no dashpot: newer LAMMPS's `damping none`, written as a velocity dashpot of η 0
        damping, damp = "velocity", 0.0
    return Native("lammps", spec["normal"], normal_args, damping=damping, damping_coeff=damp,
                  tangential=spec["tangential"], tangential_args=tuple(tc), limit=spec["limit_damping"])


def classic(cmd: Command, style: str, words: list[str], k: int) -> tuple[dict, list[str]]:
    """``Kn Kt γn γt μ dampflag [limit_damping]`` of a classic style as its pair granular equivalent."""
    kn = _num(cmd, k, "Kn")
    kt = 2.0 / 7.0 * kn if words[k + 1:k + 2] == ["NULL"] else _num(cmd, k + 1, "Kt")
    gn = _num(cmd, k + 2, "gamma_n")
    gt = 0.5 * gn if words[k + 3:k + 4] == ["NULL"] else _num(cmd, k + 3, "gamma_t")
    mu = _num(cmd, k + 4, "xmu")
    flag = _num(cmd, k + 5, "dampflag")
    for what, value, (text, ok) in (("Kn", kn, POSITIVE), ("Kt", kt, POSITIVE), ("gamma_n", gn, NON_NEGATIVE),
                                    ("gamma_t", gt, NON_NEGATIVE), ("xmu", mu, NON_NEGATIVE)):
        if not ok(value) and (what != "Kt" or style != "gran/hooke"):  # gran/hooke has no spring: Kt unread
            raise _bad(cmd, f"{style} {what} = {value:g}: {text}")
    if flag not in (0, 1):
        raise _bad(cmd, f"{style} dampflag = {flag:g}: must be 0 or 1")
    if flag == 0:
        gt = 0.0
    xt = gt / gn if gn > 0 else (0.0 if gt == 0 else math.inf)
    limit = "limit_damping" in words[k + 6:]
    notes = [f"{style}: Kt = {kt:.6g}, γt = {gt:.6g} (NULL: Kt = 2/7 Kn, γt = γn/2; dampflag 0: γt = 0), run as "
             "its pair granular equivalent"]
    if style == "gran/hooke":
        spec = {"normal": "hooke", "normal_coeffs": (kn, gn), "damping": "mass_velocity",
                "tangential": "linear_nohistory", "tangential_coeffs": (xt, mu)}
    elif style == "gran/hooke/history":
        spec = {"normal": "hooke", "normal_coeffs": (kn, gn), "damping": "mass_velocity",
                "tangential": "linear_history", "tangential_coeffs": (kt, xt, mu)}
        notes.append("the classic style projects the tangential history without rescaling it (pair granular "
                     "rescales): about 1% in oblique impacts")
    else:
        spec = {"normal": "hertz", "normal_coeffs": (kn, gn), "damping": "viscoelastic",
                "tangential": "mindlin", "tangential_coeffs": (kt, xt, mu)}
        notes.append("the classic style projects the tangential history without rescaling it: about 1% in "
                     "oblique impacts")
    spec.update(limit_damping=limit, rolling="none", twisting="none", extras=[])
    return spec, notes


def _mix_e(e1, nu1, e2, nu2):
    return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)


def _mix_g(e1, nu1, e2, nu2):
    return 1.0 / (2.0 * (2.0 - nu1) * (1.0 + nu1) / e1 + 2.0 * (2.0 - nu2) * (1.0 + nu2) / e2)


def mixed(a: dict, b: dict, cmd_where: str) -> tuple[Native, Native | None, list[str]]:
    """LAMMPS's auto-mixing of two types' granular settings (granular_model.cpp mix_coeffs and each sub-model's):
    hertz/material's E* mixed as Hertz does, every other coefficient by its geometric mean; ``mindlin NULL``
    then computes k_t = 8·E*/(4(2−ν)(1+ν)) from the mixed E* as if it were a modulus. Returns (the explicit
    equivalent of what LAMMPS computes, what the deck most likely means when that differs, notes)."""
    def geo(x, y):
        return math.sqrt(x * y)

    na, nb = a["normal_coeffs"], b["normal_coeffs"]
    notes = []
    if a["normal"] == "hertz/material":
        e_star = _mix_e(na[0], na[2], nb[0], nb[2])
        nu = geo(na[2], nb[2])
        normal, args = "hertz", (4.0 / 3.0 * e_star,)
        damp = geo(na[1], nb[1])
    else:
        normal, args, damp = a["normal"], (geo(na[0], nb[0]),), geo(na[1], nb[1])
    ta, tb = a["tangential_coeffs"], b["tangential_coeffs"]
    intended_t = None
    if a["tangential"] == "linear_nohistory":
        targs = (geo(ta[0], tb[0]), geo(ta[1], tb[1]))
    else:
        if ta[0] is None or tb[0] is None:
            if a["normal"] != "hertz/material":
                raise ScriptError(f"{cmd_where}: mindlin NULL needs hertz/material")
            kt = 8.0 * e_star / (4.0 * (2.0 - nu) * (1.0 + nu))
            right = 8.0 * _mix_g(na[0], na[2], nb[0], nb[2])
            intended_t = (right, geo(ta[1], tb[1]), geo(ta[2], tb[2]))
            notes.append(f"auto-mixed mindlin NULL: LAMMPS computes k_t = 8E*/(4(2−ν)(1+ν)) = {kt:.6g} Pa from the "
                         f"mixed E* = {e_star:.6g} Pa; 8G* = {right:.6g} Pa ({kt / right:.4f}×)")
        else:
            kt = geo(ta[0], tb[0])
        targs = (kt, geo(ta[1], tb[1]), geo(ta[2], tb[2]))
    limit = a["limit_damping"] or b["limit_damping"]
    nat = Native("lammps", normal, args, damping=a["damping"], damping_coeff=damp, tangential=a["tangential"],
                 tangential_args=targs, limit=limit)
    intended = None
    if intended_t is not None:
        intended = Native("lammps", normal, args, damping=a["damping"], damping_coeff=damp,
                          tangential=a["tangential"], tangential_args=intended_t, limit=limit)
    return nat, intended, notes


def _pair_style(cmd: Command, setup: Setup) -> tuple:
    """(the classic style's spec and notes or None, its name or None) of a pair_style line the audit reads."""
    w = cmd.words
    if len(w) < 2:
        raise _bad(cmd, "pair_style needs a style")
    if w[1] == "granular":
        return None, None
    if w[1] == "none":
        setup.not_audited.append((cmd.where(), cmd.text, "pair_style none: the bodies do not touch each other; only "
                                                          "the walls are probed"))
        return None, None
    if w[1] in CLASSIC:
        return classic(cmd, w[1], w, 2), w[1]
    if w[1] in ("hybrid", "hybrid/overlay") and w[2:3] and w[2] in CLASSIC:
        if len(w) > 9 + ("limit_damping" in w):
            raise _bad(cmd, f"pair_style {w[1]}: audit reads one granular sub-style")
        return classic(cmd, w[2], w, 3), w[2]
    raise _bad(cmd, f"pair_style {w[1]}: audit reads granular, {', '.join(CLASSIC)} (also as the one sub-style of "
                    "hybrid), none")


def read(script, root: Path) -> Setup:
    """A read deck (inputs.script.Script) → Setup: bodies, every type pair and wall × type, dt, speeds."""
    setup = Setup("lammps")
    setup.regions = script.regions
    explicit: dict = {}  # (i, j) i ≤ j → (spec, where)
    style_cmd = classic_spec = classic_name = None
    walls = []  # (spec, where, notes)
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
        if name == "pair_style":
            style_cmd = cmd
            classic_spec, classic_name = _pair_style(cmd, setup)
            continue
        if name == "pair_coeff":
            if style_cmd is None:
                raise _bad(cmd, "pair_coeff before pair_style")
            if len(w) < 3:
                raise _bad(cmd, "pair_coeff needs two types")
            ti, tj = type_range(w[1], setup.ntypes, cmd), type_range(w[2], setup.ntypes, cmd)
            if style_cmd.words[1] == "none":
                raise _bad(cmd, "pair_coeff after pair_style none")
            if classic_spec is not None:
                spec, notes = classic_spec
                if len(w) > 3 and w[3:] != [classic_name]:
                    raise _bad(cmd, f"pair_coeff of {classic_name} takes no coefficients")
            else:
                spec, notes = parse_granular(cmd, w, 3), []
                if spec["rest"] != len(w):
                    raise _bad(cmd, f"{w[spec['rest']]!r} is not a keyword of pair granular")
            for i in ti:
                for j in tj:
                    if j >= i or w[1] == w[2]:
                        explicit[(min(i, j), max(i, j))] = (spec, cmd.where(), notes, cmd)
            continue
        if name == "fix" and len(w) >= 4 and w[3] in ("wall/gran", "wall/gran/region"):
            if w[4:5] == ["granular"]:
                spec = parse_granular(cmd, w, 5)
                notes = []
            elif len(w) > 4 and w[4] in ("hooke", "hooke/history", "hertz/history"):
                spec, notes = classic(cmd, "gran/" + w[4], w, 5)
                spec["rest"] = 11 + (1 if spec["limit_damping"] else 0)
                notes.append(f"classic fix wall/gran {w[4]}: LAMMPS 22Jul2025's classic wall styles mishandle "
                             "sliding and give NaN with γn = 0; use fix wall/gran granular")
            elif len(w) > 10 and (to_number(w[4]) is not None) and classic_name:  # the old syntax: the pair's style
                spec, notes = classic(cmd, classic_name, w, 4)
                spec["rest"] = 10 + (1 if spec["limit_damping"] else 0)
                notes.append(f"fix wall/gran without a style (LAMMPS before 2016): read with the pair's "
                             f"{classic_name}, as those versions did; current LAMMPS needs the style word")
            else:
                raise _bad(cmd, "fix wall/gran: audit reads granular and the classic hooke, hooke/history, "
                                "hertz/history styles")
            rest = w[spec["rest"]:] if "rest" in spec else []
            if rest[:1] and rest[0] in ("xplane", "yplane", "zplane") and len(rest) > 1 and to_number(rest[1]) is not None:
                setup.floors.append(("xyz".index(rest[0][0]), float(rest[1])))
            if w[3] == "wall/gran" and rest[:1] and rest[0] not in ("xplane", "yplane", "zplane"):
                notes.append(f"wall {rest[0]}: probed as a flat wall (the contact law is the same; curvature "
                             "is not)")
            if w[2] != "all":
                notes.append(f"fix group '{w[2]}': probed with every type")
            walls.append((spec, cmd.where(), notes, cmd, w[1]))
            continue
        _other(cmd, setup)
    if style_cmd is None:
        raise ScriptError("the deck has no pair_style: nothing defines its contacts")
    finish(setup, "LAMMPS's default")
    types = sorted(setup.populated) or sorted(setup.bodies) or sorted({t for k in explicit for t in k})
    if style_cmd.words[1] != "none":
        _pairs(setup, types, explicit)
    _walls(setup, types, explicit, walls)
    return setup


def _asked(spec: dict) -> dict:
    out = {}
    if spec["damping"] in ("tsuji", "coeff_restitution"):
        out["restitution"] = spec["normal_coeffs"][1]
    tc = spec.get("tangential_coeffs") or ()
    if tc:
        out["friction"] = tc[-1]
    return out


def _static(ps: PairSetting, spec: dict, where: str) -> None:
    if spec["normal"] not in PROBED_NORMALS:
        ps.probe = False
        ps.notes.append(f"normal {spec['normal']}: listed, not probed (no twin of this law in demcheck)")
    ps.beyond = beyond_of(spec)
    if spec.get("rolling", "none") != "none" or spec.get("twisting", "none") != "none":
        ps.notes.append("rolling/twisting resistance: the collision probes run without it; its own probes below "
                        "(comparisons/audit_beyond.py)")
    for extra in spec.get("extras", []):
        ps.notes.append(f"{extra}: not part of the probes")
    if spec["damping"] == "tsuji":
        ps.findings.append(Finding("trap", "tsuji", "damping tsuji: LAMMPS's α(e) misses the input restitution "
                                   "(use damping coeff_restitution)", where))
    if spec["limit_damping"] and spec["damping"] in ("tsuji", "coeff_restitution"):
        ps.findings.append(Finding("trap", "limit", "limit_damping: the normal force is held ≥ 0, which raises the "
                                   "restitution above the input", where))
    if spec["damping"] == "viscoelastic" and spec["normal"] in PROBED_NORMALS:
        ps.notes.append("damping viscoelastic (the default when no damping is given): the 2nd coefficient is η0 "
                        "in 1/(s·m), not a restitution; e then depends on the speed")


def beyond_of(spec: dict, other: dict | None = None) -> dict:
    """The sub-models beyond sliding of a parsed granular spec: slot → {law, args, words} (rolling sds, twisting
    sds/marshall, heat radius/area; adhesion the jkr/dmt normal model: args E, η, ν, γ). ``other``: the second
    type's spec of an auto-mixed pair (LAMMPS mixes every sub-model coefficient by its geometric mean)."""
    out = {}
    for slot in ("rolling", "twisting", "heat"):
        law = spec.get(slot, "none")
        if law != "none":
            args = tuple(spec.get(f"{slot}_coeffs") or ())
            if other is not None and other.get(slot) == law:
                args = tuple(math.sqrt(x * y) for x, y in zip(args, other.get(f"{slot}_coeffs") or ()))
            out[slot] = {"law": law, "args": args, "words": " ".join([slot, law, *(f"{x:g}" for x in args)])}
    if spec["normal"] in ("jkr", "dmt"):
        args = tuple(spec["normal_coeffs"])
        out["adhesion"] = {"law": spec["normal"], "args": args,
                           "words": " ".join([spec["normal"], *(f"{x:g}" for x in args)])}
    return out


def heat_flow(cmd: Command, setup: Setup) -> None:
    """``fix ID group heat/flow constant cp`` or ``type cp1 … cpN``: the specific heat per type (the heat probe's
    capacities)."""
    w = cmd.words
    if w[4:5] == ["constant"] and len(w) > 5:
        cp = _num(cmd, 5, "heat/flow cp")
        setup.heat["cp"] = {t: cp for t in range(1, max(setup.ntypes, 1) + 1)}
        setup.heat["cp_all"] = cp
    elif w[4:5] == ["type"]:
        setup.heat["cp"] = {t: _num(cmd, 4 + t, f"heat/flow cp of type {t}") for t in range(1, len(w) - 4)}
    else:
        raise _bad(cmd, "fix heat/flow takes constant cp or type cp1 … cpN")
    setup.heat["where"] = cmd.where()


def _other(cmd: Command, setup: Setup) -> None:
    """A command the contact reading does not take: fix heat/flow (the heat probe's capacities), else listed."""
    if cmd.name == "fix" and len(cmd.words) > 4 and cmd.words[3] == "heat/flow":
        heat_flow(cmd, setup)
    else:
        note_unread(setup, cmd, QUIET_FIXES)


def _pairs(setup: Setup, types: list[int], explicit: dict) -> None:
    for a in types:
        for b in types:
            if b < a:
                continue
            if (a, b) in explicit:
                spec, where, notes, _ = explicit[(a, b)]
                ps = PairSetting(f"{a}-{b}", a, b, native_of(spec), where, _asked(spec), notes=list(notes))
                _static(ps, spec, where)
                setup.pairs.append(ps)
                continue
            if (a, a) not in explicit or (b, b) not in explicit:
                raise ScriptError(f"type pair {a} {b}: no pair_coeff sets it, or {a} {a} and {b} {b} to mix from "
                                  "(LAMMPS would stop: 'All pair coeffs are not set')")
            sa, wa, _, _ = explicit[(a, a)]
            sb, wb, _, _ = explicit[(b, b)]
            for slot in ("normal", "damping", "tangential"):
                if sa[slot] != sb[slot]:
                    raise ScriptError(f"type pair {a} {b}: auto-mixing {sa[slot]} ({wa}) with {sb[slot]} ({wb}): "
                                      "LAMMPS cannot mix different sub-models; write pair_coeff for the pair")
            where = f"mixed from {wa} and {wb}"
            nat, intended, notes = mixed(sa, sb, where)
            # what the pair asks for is what LAMMPS's mixing rule gives it: the geometric means of e and μ
            asked = _asked(sa)
            if "restitution" in asked:
                asked["restitution"] = nat.damping_coeff
            if "friction" in asked:
                asked["friction"] = nat.tangential_args[-1]
            ps = PairSetting(f"{a}-{b}", a, b, nat, where, asked, intended=intended, notes=notes)
            _static(ps, sa, where)
            ps.beyond = beyond_of(sa, sb)
            if sa["normal_coeffs"] != sb["normal_coeffs"] or sa["tangential_coeffs"] != sb["tangential_coeffs"]:
                ps.notes.append("auto-mixed coefficients: E* as Hertz mixes it, every other one by its geometric "
                                "mean (write pair_coeff for the pair to choose them)"
                                + "".join(f"; {k} {v:.6g}" for k, v in asked.items()))
            if intended is not None:
                ps.findings.append(Finding("trap", "mixing", f"type pair {a} {b} auto-mixed with mindlin NULL: "
                                           "LAMMPS's tangential stiffness is wrong (write pair_coeff "
                                           f"{a} {b} explicitly)", where,
                                           {"kt_ratio": nat.tangential_args[0] / intended.tangential_args[0]}))
            setup.pairs.append(ps)


def _walls(setup: Setup, types: list[int], explicit: dict, walls: list) -> None:
    for spec, where, notes, cmd, fix_id in walls:
        for t in types:
            nat = native_of(spec)
            ps = PairSetting(f"wall {fix_id} × {t}", t, None, nat, where, _asked(spec), notes=list(notes))
            _static(ps, spec, where)
            own = explicit.get((t, t))
            if spec["normal"] == "hertz/material" and own and own[0]["normal"] == "hertz/material":
                e_pair, nu_pair = own[0]["normal_coeffs"][0], own[0]["normal_coeffs"][2]
                e_wall, nu = spec["normal_coeffs"][0], spec["normal_coeffs"][2]
                if math.isclose(e_wall, e_pair, rel_tol=1e-12) and math.isclose(nu, nu_pair, rel_tol=1e-12):
                    intended = Native("lammps", "hertz/material", (2.0 * e_wall, nu), damping=nat.damping,
                                      damping_coeff=nat.damping_coeff, tangential=nat.tangential,
                                      tangential_args=nat.tangential_args, limit=nat.limit)
                    ps.intended = intended
                    ps.findings.append(Finding(
                        "trap", "wall-moduli", f"fix {fix_id} wall/gran hertz/material E = {e_wall:g} is type {t}'s "
                        "own modulus, but LAMMPS reads a wall's E and ν as pair values: E* = E/(2(1−ν²)), half a "
                        f"rigid wall's E/(1−ν²); for a rigid wall pass E = {2 * e_wall:g}", where,
                        {"e_star_ratio": 0.5}))
            setup.pairs.append(ps)


REVERSE_SYNTAX = ("a pair_style granular pair_coeff's arguments after the types: \"hertz/material 63e9 0.6 0.24 "
                  "damping tsuji tangential mindlin NULL 1.0 0.5\", or a classic style with its coefficients: "
                  "\"gran/hooke/history 2000 NULL 50 NULL 0.5 0\"")


def reverse(line: str, setup: Setup | None = None) -> PairSetting:
    """One ``pair_coeff`` argument list (after the types) as the pair setting it defines, with its static traps
    (``demcheck models --engine lammps "…"``); leading types (``* *``, ``1 1``) are read and dropped.
    ``setup`` (the lookup's, shared with other readers) takes nothing from a pair_coeff."""
    words = line.split()
    words = words[1:] if words[:1] == ["pair_style"] else words
    if words[:1] and words[0] in CLASSIC:  # a classic style with its coefficients, as audit reads it
        cmd = Command(["pair_style", *words], "models", 1, line)
        spec, notes = classic(cmd, words[0], cmd.words, 2)
        if len(cmd.words) not in (8, 9) or cmd.words[8:] not in ([], ["limit_damping"]):
            raise _bad(cmd, f"{words[0]} takes Kn Kt γn γt μ dampflag [limit_damping]")
        ps = PairSetting("1-1", 1, 1, native_of(spec), "models", _asked(spec), notes=list(notes))
        _static(ps, spec, "models")
        return ps
    if len(words) > 2 and all(_is_type(w) for w in words[:2]):
        words = words[2:]
    cmd = Command(["pair_coeff", "1", "1", *words], "models", 1, line)
    spec = parse_granular(cmd, cmd.words, 3)
    if spec["rest"] != len(cmd.words):
        raise _bad(cmd, f"{cmd.words[spec['rest']]!r} is not a keyword of pair granular")
    ps = PairSetting("1-1", 1, 1, native_of(spec), "models", _asked(spec))
    _static(ps, spec, "models")
    return ps


# ----------------------------------------------------------------------------- native settings in case files

CASE_KEYS = ("pair_style", "pair_coeff")


def native_from_case(table: dict, case) -> Native:
    """A case's ``[engine.lammps]`` table as the Native of its contact (pair or wall: LAMMPS reads a wall's
    coefficients as a pair's): ``pair_coeff`` = a ``pair_style granular`` argument list (``hertz/material E e ν
    damping tsuji tangential mindlin NULL 1.0 0.5``; leading types ``* *`` are read and dropped), or
    ``pair_style`` = a classic ``gran/hooke``, ``gran/hooke/history`` or ``gran/hertz/history`` line with its
    coefficients. Read by the deck reader's own parsers; the deck is written from the parsed numbers."""
    from ...errors import ConfigError

    for key in table:
        if key not in CASE_KEYS:
            raise ConfigError(f"engine.lammps.{key}", table[key], f"is not a setting read here ({', '.join(CASE_KEYS)})")
    style = table.get("pair_style", "granular").split()
    where = "engine.lammps.pair_style"
    try:
        if style[:1] == ["granular"] and len(style) == 1:
            if "pair_coeff" not in table:
                raise ConfigError("engine.lammps.pair_coeff", None, "missing: pair_style granular needs its "
                                  "pair_coeff arguments (\"hertz/material E e ν damping … tangential …\")")
            text, where = table["pair_coeff"], "engine.lammps.pair_coeff"
            words = text.split()
            if len(words) > 2 and all(_is_type(w) for w in words[:2]):
                words = words[2:]
            cmd = Command(["pair_coeff", "1", "1", *words], where, 1, text)
            spec = parse_granular(cmd, cmd.words, 3)
            if spec["rest"] != len(cmd.words):
                raise _bad(cmd, f"{cmd.words[spec['rest']]!r} is not a keyword of pair granular")
        elif style[:1] and style[0] in CLASSIC:
            if "pair_coeff" in table:
                raise ConfigError("engine.lammps.pair_coeff", table["pair_coeff"], f"pair_style {style[0]} takes "
                                  "its coefficients on the pair_style line, not in pair_coeff")
            cmd = Command(["pair_style", *style], where, 1, table["pair_style"])
            spec, _ = classic(cmd, style[0], cmd.words, 2)
            if len(cmd.words) not in (8, 9) or cmd.words[8:] not in ([], ["limit_damping"]):
                raise _bad(cmd, f"{style[0]} takes Kn Kt γn γt μ dampflag [limit_damping]")
        else:
            raise ConfigError(where, table.get("pair_style"), f"must be granular (with pair_coeff) or one of "
                                                              f"{', '.join(CLASSIC)} with its coefficients")
    except ScriptError as exc:
        raise ConfigError(where, table.get(where.rsplit(".", 1)[1]), str(exc).split(": ", 2)[-1]) from None
    if spec["normal"] not in PROBED_NORMALS:
        raise ConfigError(where, table.get(where.rsplit(".", 1)[1]), f"normal {spec['normal']}: demcheck has no "
                          f"twin of it (it runs {', '.join(PROBED_NORMALS)})")
    for extra in ("rolling", "twisting"):
        if spec.get(extra, "none") != "none":
            raise ConfigError(where, table.get(where.rsplit(".", 1)[1]), f"{extra} {spec[extra]}: demcheck's twin "
                              "has no rolling or twisting resistance (leave it out)")
    if spec.get("extras") or spec.get("heat", "none") != "none":
        raise ConfigError(where, table.get(where.rsplit(".", 1)[1]), f"{', '.join(spec.get('extras') or ['heat'])}: "
                          "not part of a two-body run (leave it out)")
    nat = native_of(spec)
    from .mapping import twin

    try:
        twin(nat, 1.0, 1.0)
    except (ValueError, KeyError) as exc:
        raise ConfigError(where, table.get(where.rsplit(".", 1)[1]), f"no twin: {exc}") from None
    nat.comments.append("the case's own native setting ([engine.lammps])")
    return nat


def _is_type(word: str) -> bool:
    import re

    return re.fullmatch(r"\d*\*\d*|\d+", word) is not None


# ----------------------------------------------------------------------------- units metal and real, in SI

N_AVOGADRO = 6.02214076e23
# LAMMPS's own force-to-acceleration constants (update.cpp: a = ftm2v·F/m), so the SI numbers give its dynamics
FTM2V = {"metal": 1.0 / 1.0364269e-4, "real": 1.0 / 48.88821291 / 48.88821291}
BASE = {"metal": (1e-10, 1e-3 / N_AVOGADRO, 1e-12), "real": (1e-10, 1e-3 / N_AVOGADRO, 1e-15)}  # Å, g/mol, ps|fs


def si_factors(style: str) -> tuple[float, float, float, float]:
    """(length, mass, time, force) of ``metal`` or ``real`` in SI as LAMMPS's dynamics sees them: the force unit
    is what moves a mass unit by ftm2v length units per time unit² (metal: 1 eV/Å; real: 1 kcal/mol/Å)."""
    length, mass, time = BASE[style]
    return length, mass, time, FTM2V[style] * mass * length / time ** 2


def _native_si(nat: Native, length: float, mass: float, time: float, force: float) -> Native:
    """A granular Native of a metal/real deck in SI, each coefficient by its role in the force (LAMMPS's
    granular models use them as they are, in the style's force, length, mass and time units)."""
    import dataclasses

    stiff = {"hooke": force / length, "hertz": force / length ** 2, "hertz/material": force / length ** 2}
    if nat.normal not in stiff:
        return nat  # a law demcheck has no twin of: listed, never probed
    normal_args = (nat.normal_args[0] * stiff[nat.normal], *nat.normal_args[1:])
    damp = {"velocity": force * time / length, "mass_velocity": force * time / (mass * length),
            "viscoelastic": force * time / (mass * length ** 2)}.get(nat.damping, 1.0)
    t = list(nat.tangential_args)
    if nat.tangential == "linear_history" and t:
        t[0] *= force / length
    elif nat.tangential.startswith("mindlin") and t and t[0] is not None:
        t[0] *= force / length ** 2
    return dataclasses.replace(nat, normal_args=normal_args, damping_coeff=nat.damping_coeff * damp,
                               tangential_args=tuple(t), comments=[*nat.comments, "converted to SI from the deck's units"])


def to_si(setup) -> None:
    """A Setup read in units metal or real, converted to SI with LAMMPS's own factors (si_factors): bodies, dt,
    speeds, insertions, gravity, floors, regions, box, atoms and every pair's Native. The probes then run in SI
    (demcheck's twin and case need a consistent system) and the report says so."""
    style = setup.units
    length, mass, time, force = si_factors(style)
    area = setup.dimension == 2
    for b in setup.bodies.values():
        b.radius = None if b.radius is None else b.radius * length
        b.density = None if b.density is None else b.density * mass / length ** (2 if area else 3)
        b.mass = None if b.mass is None else b.mass * mass
        b.sizes = [(r * length, w) for r, w in b.sizes]
    for ps in setup.pairs:
        for sub in ps.beyond.values():  # its coefficients stay in the style's units: listed, never probed in SI
            sub["refused"] = (f"units {style}: the sub-model's coefficients are not converted to SI for a probe "
                              "(the collision probes' are)")
        ps.native = _native_si(ps.native, length, mass, time, force)
        if ps.intended is not None:
            ps.intended = _native_si(ps.intended, length, mass, time, force)
    setup.dt *= time
    speed = length / time
    setup.speeds = [(v * speed, w) for v, w in setup.speeds]
    setup.insertions = [(r, [x * speed for x in v], t, w) for r, v, t, w in setup.insertions]
    if setup.gravity is not None:
        g, axis, where = setup.gravity
        setup.gravity = (g * force / mass, axis, where)
    setup.floors = [(a, c * length) for a, c in setup.floors]
    setup.regions = {k: (None if b is None else tuple(x * length for x in b)) for k, b in setup.regions.items()}
    setup.box = None if setup.box is None else tuple(x * length for x in setup.box)
    setup.atoms = {a: [t, None if x is None else [c * length for c in x], None if v is None else [c * speed for c in v]]
                   for a, (t, x, v) in setup.atoms.items()}
    _units_damping(setup, style)
    setup.units_where = (f"{setup.units_where}: units {style}, converted to SI with LAMMPS's own factors (length "
                         f"{length:g} m, mass {mass:.6g} kg, time {time:g} s, force {force:.6g} N — its ftm2v); the "
                         "probes run and the report speaks in SI")
    setup.dt_where = f"{setup.dt_where}, converted to s"
    setup.units = "si"


def _units_damping(setup, style: str) -> None:
    """LAMMPS's damping tsuji and coeff_restitution compute the dashpot from √(m·k) in the style's own numbers,
    without its ftm2v: in metal and real the dashpot is √ftm2v times the one that gives the asked e (98.2× in metal,
    1/48.9 in real). A trap with its size (for hooke + coeff_restitution the realised e in closed form: the damping
    ratio ζ' = √ftm2v·ζ(e), e' = exp(−πζ'/√(1−ζ'²)), no rebound for ζ' ≥ 1 — checked against LAMMPS running the deck
    in its own units); the pair is listed, not probed (its SI probe would compute the asked e, not LAMMPS's)."""
    root = math.sqrt(FTM2V[style])
    for ps in setup.pairs:
        nat = ps.native
        if nat.damping not in ("tsuji", "coeff_restitution") or nat.normal not in PROBED_NORMALS:
            continue
        e = nat.damping_coeff
        size = {"damping_factor": root}
        text = (f"units {style}: LAMMPS's damping {nat.damping} computes its dashpot from √(m·k) without the style's "
                f"force–mass constant (ftm2v): the dashpot is {root:.4g}× the one that gives e = {e:g}")
        if nat.normal == "hooke" and nat.damping == "coeff_restitution" and 0 < e < 1:
            z = -math.log(e) / math.sqrt(math.pi ** 2 + math.log(e) ** 2) * root
            e_real = math.exp(-math.pi * z / math.sqrt(1.0 - z * z)) if z < 1 else 0.0
            size.update(asked=e, realised=e_real, damping_ratio=z)
            text += (f": e = {e:g} asked, {e_real:.4g} realised (damping ratio {z:.4g}"
                     + ("; above 1, the bodies do not rebound)" if z >= 1 else ")"))
        text += "; give the dashpot as damping velocity (η in force·time/length), which LAMMPS reads as it is given"
        ps.findings.append(Finding("trap", "units-damping", text, ps.where, size))
        ps.probe = False
        ps.notes.append(f"listed, not probed: in units {style} LAMMPS's {nat.damping} dashpot is not the SI one a "
                        "probe would compute (trap units-damping)")
