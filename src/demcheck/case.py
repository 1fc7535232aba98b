"""Case files: Material, Particle, Wall, Case; TOML loading, validation and ``--set`` overrides.

SI units throughout. A case is validated completely before anything runs; the first rule it breaks
is reported as a :class:`~demcheck.errors.ConfigError` naming the key, the value and the rule.
"""

from __future__ import annotations

import contextlib
import copy
import difflib
import hashlib
import itertools
import json
import math
import os
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from . import resources
from .errors import ConfigError

KINDS = ("collision", "packing")


@dataclass(frozen=True)
class Material:
    name: str
    density: float
    youngs_modulus: float
    poisson_ratio: float
    restitution: float | None = None
    friction: float | None = None
    friction_kinetic: float | None = None
    dissipative_constant: float | None = None  # BSHP's A, in seconds
    tangential_restitution: float | None = None
    specific_heat: float | None = None  # J/(kg·K): the conduction scenario's heat capacity m·c_p

    @property
    def shear_modulus(self) -> float:
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))


@dataclass(frozen=True)
class Particle:
    material: str
    radius: float
    position: tuple[float, float, float]
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Wall:
    point: tuple[float, float, float]
    normal: tuple[float, float, float]  # unit, pointing into the domain
    rigid: bool = True
    material: str | None = None
    # a packing's segment: the strip p + s·along + t·(normal × along), extent[0] ≤ s ≤ extent[1], t unbounded
    along: tuple[float, float, float] | None = None  # unit, in the wall's plane
    extent: tuple[float, float] | None = None  # m
    until: float | None = None  # s: a packing's wall removed at this time (a hopper's gate)


@dataclass(frozen=True)
class Contact:
    normal: str
    tangential: str = "none"
    limit_force: bool = False
    params: dict = field(default_factory=dict)
    # the slots beyond sliding (laws/slots.py): rolling, twisting, adhesion and heat resistance laws' ids
    rolling: str = "none"
    twisting: str = "none"
    adhesion: str = "none"
    heat: str = "none"


@dataclass(frozen=True)
class Run:
    dt: float | None = None  # None = auto (contact time / steps_per_contact)
    steps_per_contact: int = 200
    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rtol: float = 1e-13
    method: str = "adaptive"
    # how far the verlet method at this case's step may lie from the converged answer (units of each metric's
    # scale); None: the suite's [verlet] rtol. A case run at many steps per contact sets it tight, so that the
    # verlet method checks the adaptive one
    verlet_rtol: float | None = None
    # what is solved: a collision, or a scenario beyond sliding (reference/scenarios.py) with its own metrics
    scenario: str = "collision"
    temperatures: tuple[float, ...] | None = None  # K, one per body (conduction)
    overlap: float | None = None  # m: the fixed overlap of the conduction scenario


@dataclass(frozen=True)
class Insertion:
    """[packing.insertion] of an inserted packing: ``batches`` batches of ``batch`` particles, one every ``every``
    seconds from t = 0, each at rest on a lattice of pitch ``spacing`` largest diameters filling the box ``region``
    (x fastest, then y, then z), each site moved by up to ``offset`` largest diameters at random along the region's
    axes of nonzero extent."""

    every: float  # s
    batch: int
    batches: int
    region: tuple[tuple[float, float, float], tuple[float, float, float]]  # m: two opposite corners, lo and hi
    spacing: float = 1.5
    offset: float = 0.0


@dataclass(frozen=True)
class Height:
    """[packing.height]: the height of a heap, the largest centre coordinate along ``axis`` plus ``offset`` (m),
    every ``every`` seconds from ``start`` (reference/sandpile.height_curve)."""

    axis: tuple[float, float, float]  # unit
    offset: float
    every: float  # s
    start: float  # s


@dataclass(frozen=True)
class Packing:
    """A packing case's [packing] table, validated: how its particles were laid out and how long it settles."""

    layout: str  # column | layer | poured | inserted
    count: int
    material: str
    radii: tuple[float, ...]
    box: tuple[float, float] | None  # the periodic box in x and y (m); None for a column or an inserted packing
    seed: int
    duration: float | None  # s
    # each radius's share of the particles' volume (None: equal numbers of each radius)
    volume_fractions: tuple[float, ...] | None = None
    insertion: Insertion | None = None  # an inserted packing's batches
    height: Height | None = None  # the heap's height measure


@dataclass(frozen=True)
class Case:
    name: str
    kind: str
    materials: dict[str, Material]
    particles: tuple[Particle, ...]
    walls: tuple[Wall, ...]
    contact: Contact
    run: Run
    packing: Packing | None = None
    raw: dict = field(repr=False, compare=False, default_factory=dict)
    # [engine.NAME] tables: an engine's own settings for the contact ({name: {key: text}}), parsed by that
    # engine's package (engines.base.Engine.native_from_case); here only their shape is checked
    natives: dict = field(compare=False, default_factory=dict)
    # the case prepared once: laws.model.resolve keeps each pair's resolved model here (a Case is frozen,
    # so what is resolved from it never changes)
    prepared: dict = field(repr=False, compare=False, default_factory=dict, init=False)

    @property
    def hash(self) -> str:
        """Content hash of the resolved case (after overrides): stable across key order."""
        text = json.dumps(self.raw, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def mass(self, i: int) -> float:
        p = self.particles[i]
        return self.materials[p.material].density * 4.0 / 3.0 * math.pi * p.radius**3


# ----------------------------------------------------------------------------- loading


def _read(path: str | Path) -> dict:
    """A case file's raw table (its name defaults to the file's)."""
    path = resources.case_path(path)  # a path as given, else a shipped case by its name
    try:
        raw = tomllib.loads(path.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(str(path), "(file)", f"not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at offset "
                                               f"{exc.start}): a case file is TOML, which is UTF-8") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(str(path), "(file)", f"not valid TOML: {exc}") from None
    if "name" not in raw:
        check_name("name", path.stem, " (the name defaults to the file's: set name = \"...\" in the case)")
        raw["name"] = path.stem
    return raw


def load(path: str | Path, overrides: list[str] | tuple[str, ...] = ()) -> Case:
    """Read a TOML case file, apply ``key=value`` overrides, validate, and build a :class:`Case`."""
    return from_dict(apply_overrides(_read(path), overrides))


def expand(path: str | Path, overrides: list[str] | tuple[str, ...] = ()) -> list[Case]:
    """The cases of a file: one, or with a ``[variants]`` table one per combination of its values
    (``"impact.speed" = [0.1, 1.0, 10.0]``: dotted keys as in ``--set``, each a non-empty list). A sub-table
    ``[variants.GROUP]`` is a group of keys that vary together (their lists zipped, all of one length; an
    optional ``labels`` list names the members, else 1, 2, …): one dimension of the product, labelled
    ``GROUP=label``. Each variant is named ``name[key=value,…]`` after the last part of its keys; a variant that
    breaks a rule raises the ConfigError with its label as ``variant``."""
    raw = apply_overrides(_read(path), overrides)
    variants = raw.pop("variants", None) or {}
    if not isinstance(variants, dict):
        raise ConfigError("variants", variants, "must be a table of dotted keys to lists of values")
    if not variants:
        return [from_dict(raw)]
    base = check_name("name", raw.get("name"))
    # each dimension: (label key, [(label, {dotted key: value})])
    dims = []
    for key, values in variants.items():
        where = f"variants.{_key_text(key)}"
        if isinstance(values, dict):
            if key in TOP_KEYS:  # impact.speed = [...] unquoted: TOML made it a table
                raise ConfigError(where, values, f"a variant's key is quoted, \"{key}.{next(iter(values), 'x')}\" = "
                                                 "[…]; a table [variants.GROUP] is a group of keys that vary together")
            dims.append((check_name(where, key, " (the group's name labels each variant)"), _zipped(where, values)))
            continue
        if not isinstance(values, list) or not values:
            raise ConfigError(where, values, "must be a non-empty list of values, or a table of keys that vary "
                                             "together")
        label_key = check_name(where, key.rsplit(".", 1)[-1], " (the key's last part labels each variant)")
        for v in values:  # a variant's value is part of its name
            if _name_problem(_label(v)):
                raise ConfigError(where, v, f"labels its variant, so its text {NAME_RULE}")
        dims.append((label_key, [(_label(v), {key: v}) for v in values]))
    seen: dict = {}  # a key set by two dimensions would run the last one's value under both labels
    for label_key, members in dims:
        for key in members[0][1]:
            if key in seen:
                raise ConfigError(f"variants.{_key_text(key)}", key, f"is varied twice (in {seen[key]} and in "
                                  f"{label_key}): a key belongs to one dimension of the variants")
            seen[key] = label_key
    labels = [label_key for label_key, _ in dims]
    twice = sorted({k for k in labels if labels.count(k) > 1})
    if twice:
        raise ConfigError("variants", twice[0], "labels two dimensions of the variants (each names its variants: "
                          "give one key's group another name)")
    cases = []
    for combo in itertools.product(*(members for _, members in dims)):
        r = plain_copy(raw)
        for _, settings in combo:
            for key, value in settings.items():
                set_path(r, key, value)
        label = ",".join(f"{label_key}={text}" for (label_key, _), (text, _) in zip(dims, combo))
        r["name"] = f"{base}[{label}]"
        try:
            cases.append(from_dict(r))
        except ConfigError as exc:
            exc.variant = label  # which variant broke the rule (verify names it with the file)
            raise
    return cases


def _zipped(where: str, group: dict) -> list[tuple[str, dict]]:
    """The members of a ``[variants.GROUP]`` table: its keys' lists zipped, with their labels."""
    group = dict(group)
    labels = group.pop("labels", None)
    if not group:
        raise ConfigError(where, {}, "a group of variants needs at least one dotted key with a list of values")
    lengths = set()
    for key, values in group.items():
        if isinstance(values, dict):  # impact.speed = [...] unquoted inside the group: TOML made it a table
            raise ConfigError(f"{where}.{_key_text(key)}", values, f"a variant's key is quoted, \"{key}."
                              f"{next(iter(values), 'x')}\" = […]")
        if not isinstance(values, list) or not values:
            raise ConfigError(f"{where}.{_key_text(key)}", values, "must be a non-empty list of values")
        lengths.add(len(values))
    if len(lengths) != 1:
        raise ConfigError(where, {k: len(v) for k, v in group.items()},
                          "the keys of a group vary together, so their lists must be of one length")
    n = lengths.pop()
    if labels is None:
        labels = [str(i + 1) for i in range(n)]
    if not isinstance(labels, list) or len(labels) != n:
        raise ConfigError(f"{where}.labels", labels, f"must be a list of {n} labels, one per member of the group")
    texts = [_label(v) for v in labels]
    for v, text in zip(labels, texts):
        if _name_problem(text):
            raise ConfigError(f"{where}.labels", v, f"labels its variant, so its text {NAME_RULE}")
    if len(set(texts)) != n:
        raise ConfigError(f"{where}.labels", labels, "must be distinct (each labels its own variant)")
    return [(texts[i], {key: values[i] for key, values in group.items()}) for i in range(n)]


@contextlib.contextmanager
def naming_file(path: str | Path):
    """A ConfigError raised inside names the case file (and the variant, given ``exc.variant``) at fault,
    ``cases/x.toml[speed=2]: key = value: rule``, unless it names the file already. The commands that take
    several case files (verify, bench, stress) read every one so before any work."""
    try:
        yield
    except ConfigError as exc:
        if exc.key == "CASE" or str(path) in exc.key:
            raise
        where = f"{path}[{exc.variant}]" if getattr(exc, "variant", None) else str(path)
        raise ConfigError(f"{where}: {exc.key}", exc.value, exc.rule) from None


def _label(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v).lower() if isinstance(v, bool) else str(v)


def loads(text: str, overrides: list[str] | tuple[str, ...] = (), name: str = "case") -> Case:
    raw = tomllib.loads(text)
    raw.setdefault("name", name)
    return from_dict(apply_overrides(raw, overrides))


def parse_value(text: str) -> Any:
    """A ``--set`` value: any TOML value (numbers, booleans, arrays, strings); bare words are strings."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def plain_copy(value):
    """A deep copy of TOML-shaped data (tables, arrays, strings, numbers, booleans): a tenth of copy.deepcopy's
    cost, which a sweep paid three times a point; anything else is deep-copied."""
    if isinstance(value, dict):
        return {k: plain_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain_copy(v) for v in value]
    if value is None or isinstance(value, (str, int, float)):  # bool is an int
        return value
    return copy.deepcopy(value)


def apply_overrides(raw: dict, overrides) -> dict:
    """Apply dotted ``key=value`` overrides (``particles.0.velocity=[1,0,0]``) to a raw case dict."""
    raw = plain_copy(raw)
    for item in overrides:
        if "=" not in item:
            raise ConfigError("--set", item, "must be KEY=VALUE with a dotted key, e.g. contact.normal=hertz")
        key, _, text = item.partition("=")
        set_path(raw, key.strip(), parse_value(text.strip()))
    return raw


def set_path(raw: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    if not all(part.strip() for part in parts):
        raise ConfigError(_key_text(key) or "(empty key)", value,
                          "must be a dotted case key without an empty part, e.g. impact.speed")
    node: Any = raw
    for depth, part in enumerate(parts[:-1]):
        here = ".".join(parts[: depth + 1])
        if isinstance(node, list):
            node = node[_index(node, part, here)]
        else:
            if part not in node or not isinstance(node[part], (dict, list)):
                node[part] = {}
            node = node[part]
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, key)] = value
    else:
        node[last] = value


def _index(seq: list, part: str, key: str) -> int:
    if not part.isdigit() or int(part) >= len(seq):
        raise ConfigError(key, part, f"must be an index below {len(seq)}")
    return int(part)


# ----------------------------------------------------------------------------- validation helpers


def _number(d: dict, key: str, where: str, *, required=True, default=None, rule=None, check=None):
    full = f"{where}.{key}" if where else key
    if key not in d or d[key] is None:
        if required:
            raise ConfigError(full, None, "missing: a number is required")
        return default
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(full, v, "must be a finite number")
    v = float(v)
    if check is not None and not check(v):
        raise ConfigError(full, v, rule)
    return v


def _vector(d: dict, key: str, where: str, *, default=None, required=False):
    full = f"{where}.{key}" if where else key
    if key not in d:
        if required:
            raise ConfigError(full, None, "missing: a vector of 3 numbers is required")
        return default
    v = d[key]
    if (
        not isinstance(v, list)
        or len(v) != 3
        or not all(isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) for c in v)
    ):
        raise ConfigError(full, v, "must be a vector of 3 finite numbers")
    if not all(_representable(float(c)) for c in v):
        raise ConfigError(full, v, VECTOR_RULE)
    return tuple(float(c) for c in v)


# A vector's component is squared (|v|², distances, energies): 0, or a magnitude whose square is a normal double.
COMPONENT_RANGE = (1e-150, 1e150)
VECTOR_RULE = (f"each component must be 0 or of magnitude in [{COMPONENT_RANGE[0]:g}, {COMPONENT_RANGE[1]:g}] "
               "(its square must be a normal double)")


def _representable(c: float) -> bool:
    return c == 0.0 or COMPONENT_RANGE[0] <= abs(c) <= COMPONENT_RANGE[1]


def _positive(v: float) -> bool:
    return v > 0


def _known_keys(d: dict, allowed: set[str], where: str) -> None:
    for k in d:
        if k not in allowed:
            near = difflib.get_close_matches(k, sorted(allowed), n=1)
            hint = f"; did you mean '{near[0]}'?" if near else f"; known keys: {', '.join(sorted(allowed))}"
            raise ConfigError(f"{where}.{_key_text(k)}" if where else _key_text(k), d[k], f"unknown key{hint}")


def _key_text(key: str) -> str:
    """A user's key as an error names it: as written, or quoted and escaped when it is not one printable line."""
    return key if key.isprintable() else repr(key)


# Names (a case's, its variants' labels, a material's) are written into reports and into the engines' decks (as
# comments): one line of plain characters, none that a deck, a shell or a report would interpret.
NAME_MAX = 200
NAME_PUNCTUATION = frozenset("-_.,:=+[]()/ ")
NAME_RULE = (f"must be one line of 1 to {NAME_MAX} letters, digits, spaces and - _ . , : = + [ ] ( ) / (no #, $, &, "
             "quotes, backslashes or control characters)")


def _name_problem(value) -> bool:
    return (not isinstance(value, str) or not value.strip() or len(value) > NAME_MAX
            or not all(ch.isalnum() or ch in NAME_PUNCTUATION for ch in value))


def check_name(key: str, value, hint: str = "") -> str:
    """``value`` if it is a valid name, else a ConfigError naming ``key`` (``hint``: where the value came from)."""
    if _name_problem(value):
        rule = NAME_RULE if isinstance(value, str) else NAME_RULE.replace("must be ", "must be a string, ", 1)
        raise ConfigError(key, value, rule + hint)
    return value


MATERIAL_KEYS = {
    "density", "youngs_modulus", "poisson_ratio", "restitution", "friction", "friction_kinetic",
    "dissipative_constant", "tangential_restitution", "specific_heat",
}
PARTICLE_KEYS = {"material", "radius", "position", "velocity", "angular_velocity"}
WALL_KEYS = {"point", "normal", "rigid", "material", "along", "extent", "until"}
SEGMENT_TOL = 1e-9  # a segment's ``along``: unit, and normal to the wall's normal, within this
RUN_KEYS = {"dt", "steps_per_contact", "gravity", "rtol", "method", "verlet_rtol", "scenario", "temperatures",
            "overlap"}
SCENARIOS = ("collision", "rolling", "incline", "twist", "pull_off", "adhesive_impact", "conduction")
IMPACT_KEYS = {"speed", "angle", "gap", "spin"}
TOP_KEYS = {"name", "kind", "materials", "particles", "walls", "contact", "run", "impact", "description", "variants",
            "packing", "engine"}
PACKING_KEYS = {"layout", "count", "material", "radius", "radii", "box", "seed", "duration", "volume_fractions",
                "insertion", "height"}
LAYOUTS = ("column", "layer", "poured", "inserted")
INSERTION_KEYS = {"every", "batch", "batches", "region", "spacing", "offset"}
HEIGHT_KEYS = {"axis", "offset", "every", "start"}


def _material(name: str, d: dict) -> Material:
    where = f"materials.{name}"
    if not isinstance(d, dict):
        raise ConfigError(where, d, "must be a table")
    _known_keys(d, MATERIAL_KEYS, where)
    restitution = _number(d, "restitution", where, required=False,
                          rule="must be in (0, 1]", check=lambda v: 0 < v <= 1)
    friction = _number(d, "friction", where, required=False, rule="must be >= 0", check=lambda v: v >= 0)
    friction_kinetic = _number(d, "friction_kinetic", where, required=False,
                               rule="must be >= 0", check=lambda v: v >= 0)
    if friction_kinetic is not None and friction is not None and friction_kinetic > friction:
        raise ConfigError(f"{where}.friction_kinetic", friction_kinetic,
                          f"must not exceed the static coefficient friction = {friction}")
    return Material(
        name=name,
        density=_number(d, "density", where, rule="must be > 0 (kg/m³)", check=_positive),
        youngs_modulus=_number(d, "youngs_modulus", where, rule="must be > 0 (Pa)", check=_positive),
        poisson_ratio=_number(d, "poisson_ratio", where, rule="must be in (-1, 0.5)",
                              check=lambda v: -1 < v < 0.5),
        restitution=restitution,
        friction=friction,
        friction_kinetic=friction_kinetic,
        dissipative_constant=_number(d, "dissipative_constant", where, required=False,
                                     rule="must be >= 0 (s)", check=lambda v: v >= 0),
        tangential_restitution=_number(d, "tangential_restitution", where, required=False,
                                       rule="must be in [0, 1]", check=lambda v: 0 <= v <= 1),
        specific_heat=_number(d, "specific_heat", where, required=False, rule="must be > 0 (J/(kg·K))",
                              check=_positive),
    )


NATIVE_RULE = ("an [engine.NAME] table holds that engine's own settings as text (pair_coeff = \"hertz/material "
               "…\"; docs/api.md, docs/lammps-users.md, docs/liggghts-users.md)")


def _natives(table, kind: str) -> dict:
    """The [engine.NAME] tables' shape: tables of keys to text (or numbers, kept as text); which engines and
    which keys is the engines' to say (engines.base.case_natives)."""
    if table is None:
        return {}
    if not isinstance(table, dict):
        raise ConfigError("engine", table, f"must be a table of [engine.NAME] tables: {NATIVE_RULE}")
    if table and kind != "collision":
        raise ConfigError("engine", sorted(table), "native engine settings are read for collisions only")
    out = {}
    for name, settings in table.items():
        where = f"engine.{_key_text(name)}"
        if not isinstance(settings, dict) or not settings:
            raise ConfigError(where, settings, f"must be a non-empty table: {NATIVE_RULE}")
        values = {}
        for key, value in settings.items():
            k = f"{where}.{_key_text(key)}"
            if isinstance(value, bool) or not isinstance(value, (str, int, float)):
                raise ConfigError(k, value, f"must be text (or a number): {NATIVE_RULE}")
            if isinstance(value, float) and not math.isfinite(value):
                raise ConfigError(k, value, "must be finite")
            text = value if isinstance(value, str) else repr(value)
            if not text.strip() or len(text) > 1000 or any(ch in text for ch in "\n\r\0"):
                raise ConfigError(k, value, "must be one non-empty line of at most 1000 characters")
            values[str(key)] = text
        out[str(name)] = values
    return out


def _unit(v, key):
    n = np.asarray(v, float)
    norm = float(np.linalg.norm(n))
    if norm == 0:
        raise ConfigError(key, list(v), "must be a non-zero vector")
    return tuple(float(c) for c in n / norm)


def from_dict(raw: dict) -> Case:
    """Validate a raw (TOML-shaped) dict and build a Case. Raises ConfigError on the first bad key."""
    if not isinstance(raw, dict):
        raise ConfigError("case", raw, "must be a table")
    _known_keys(raw, TOP_KEYS, "")
    name = check_name("name", raw.get("name", "case"))
    if not isinstance(raw.get("description", ""), str):
        raise ConfigError("description", raw["description"], "must be a string")
    kind = raw.get("kind", "collision")
    if kind not in KINDS:
        raise ConfigError("kind", kind, f"must be one of {', '.join(KINDS)}")

    mats_raw = raw.get("materials")
    if not isinstance(mats_raw, dict) or not mats_raw:
        raise ConfigError("materials", mats_raw, "at least one [materials.NAME] table is required")
    for n in mats_raw:
        check_name(f"materials.{_key_text(n)}", n, " (a material's name)")
    materials = {n: _material(n, d) for n, d in mats_raw.items()}

    raw = plain_copy(raw)
    impact = raw.get("impact")
    packing = None
    if kind == "packing":
        if "particles" not in raw or "packing" in raw:
            packing = packing_spec(raw.get("packing"), materials)
        if "particles" not in raw:
            raw["particles"] = generate_packing(packing)
    elif "packing" in raw:
        raise ConfigError("packing", raw["packing"], "a [packing] table needs kind = \"packing\"")
    parts_raw = raw.get("particles")
    if not isinstance(parts_raw, list) or not parts_raw:
        raise ConfigError("particles", parts_raw, "at least one [[particles]] entry is required")

    particles = _particles(parts_raw, materials, impact)
    _check_masses([(p["material"], p["radius"]) for p in particles], materials)  # before anything uses a mass
    walls = _walls(raw.get("walls", []) or [], materials, kind)
    run = _run(raw.get("run", {}) or {}, kind)
    natives = _natives(raw.get("engine"), kind)
    contact = _contact(raw.get("contact", {}) or {})

    if kind == "collision":
        if impact is not None:
            with np.errstate(all="ignore"):  # a placement beyond doubles is refused in it, by key
                _apply_impact(impact, particles, walls, materials)
        n_bodies = len(particles) + len(walls)
        if len(particles) not in (1, 2) or n_bodies != 2:
            raise ConfigError("particles", len(particles),
                              "a collision has two particles, or one particle and one wall")
    parts = tuple(Particle(**p) for p in particles)
    _check_geometry(parts, tuple(walls))
    _check_batches(packing, tuple(walls))

    resolved_raw = plain_copy(raw)
    resolved_raw.pop("impact", None)
    resolved_raw["name"] = name

    def build(parts: tuple[Particle, ...]) -> Case:
        resolved_raw["particles"] = [
            {"material": p.material, "radius": p.radius, "position": list(p.position),
             "velocity": list(p.velocity), "angular_velocity": list(p.angular_velocity)} for p in parts
        ]
        return Case(name=name, kind=kind, materials=materials, particles=parts, walls=tuple(walls),
                    contact=contact, run=run, packing=packing, raw=resolved_raw, natives=natives)

    case = build(parts)
    # Model ids and parameters are checked here too, so that nothing runs on a bad case.
    from .laws import model as _model

    with _computable(case):
        _model.check_contact(case)
        _check_scenario(case)
        if kind == "collision" and run.scenario == "collision":
            case = _collision_scales(case, build, impact)
        elif packing is not None and packing.duration is not None:
            packing_run(case)  # a packing too long to run is refused here too, before any work
    return case


def _check_batches(packing: Packing | None, walls: tuple[Wall, ...]) -> None:
    """An inserted packing's later batches clear of the walls too (the first is the case's particles)."""
    if packing is None or packing.insertion is None:
        return
    for b, batch in enumerate(insertion_batches(packing)[1:], start=1):
        try:
            _check_geometry(tuple(Particle(**p) for p in batch), walls)
        except ConfigError as exc:
            raise ConfigError("packing.insertion.region", [list(c) for c in packing.insertion.region],
                              f"places batch {b}'s {exc.key.split('.')[0]} {exc.key.split('.')[1]} at "
                              f"{exc.value}, which {exc.rule}") from None


def _particles(parts_raw: list, materials: dict, impact) -> list[dict]:
    """The [[particles]] entries checked, as keyword dicts of Particle (positions may wait for an [impact])."""
    particles = []
    for i, d in enumerate(parts_raw):
        where = f"particles.{i}"
        if not isinstance(d, dict):
            raise ConfigError(where, d, "must be a table")
        _known_keys(d, PARTICLE_KEYS, where)
        mat = d.get("material")
        if mat not in materials:
            near = difflib.get_close_matches(str(mat), list(materials), n=1)
            hint = f"; did you mean '{near[0]}'?" if near else f"; defined: {', '.join(materials)}"
            raise ConfigError(f"{where}.material", mat, f"is not a defined material{hint}")
        radius = _number(d, "radius", where, rule="must be > 0 (m)", check=_positive)
        pos = _vector(d, "position", where, default=None, required=impact is None)
        particles.append(dict(material=mat, radius=radius, position=pos,
                              velocity=_vector(d, "velocity", where, default=(0.0, 0.0, 0.0)),
                              angular_velocity=_vector(d, "angular_velocity", where, default=(0.0, 0.0, 0.0))))
    return particles


def _walls(walls_raw: list, materials: dict, kind: str = "collision") -> list[Wall]:
    """The [[walls]] entries checked (a packing's may be segments and timed: :func:`_segment`)."""
    walls = []
    for i, d in enumerate(walls_raw):
        where = f"walls.{i}"
        if not isinstance(d, dict):
            raise ConfigError(where, d, "must be a table")
        _known_keys(d, WALL_KEYS, where)
        point = _vector(d, "point", where, default=(0.0, 0.0, 0.0))
        normal = _unit(_vector(d, "normal", where, required=True), f"{where}.normal")
        rigid = d.get("rigid", "material" not in d)
        if not isinstance(rigid, bool):
            raise ConfigError(f"{where}.rigid", rigid, "must be true or false")
        mat = d.get("material")
        if not rigid and mat not in materials:
            raise ConfigError(f"{where}.material", mat, "a non-rigid wall needs a defined material")
        if rigid and mat is not None and mat not in materials:
            raise ConfigError(f"{where}.material", mat, "is not a defined material")
        walls.append(Wall(point=point, normal=normal, rigid=rigid, material=mat, **_segment(d, where, normal, kind)))
    return walls


def _segment(d: dict, where: str, normal: tuple, kind: str) -> dict:
    """A wall's optional ``along`` and ``extent`` (a strip of its plane: the points p + s·along + t·(normal × along),
    s0 ≤ s ≤ s1) and ``until`` (removed at that time), which the packing solver reads (reference/packing.py); a
    collision's solvers and the engines' decks take plane walls only."""
    keys = [k for k in ("along", "extent", "until") if k in d]
    if keys and kind != "packing":
        raise ConfigError(f"{where}.{keys[0]}", d[keys[0]], "is read by packing cases only (a collision's wall is a "
                                                            "plane, there from the start)")
    out = {}
    if "extent" in d and "along" not in d:
        raise ConfigError(f"{where}.extent", d["extent"], "needs along = [ex, ey, ez], the unit vector in the wall's "
                                                          "plane that s runs along")
    if "along" in d and "extent" not in d:
        raise ConfigError(f"{where}.along", d["along"], "is read with extent = [s0, s1] (m), the strip's bounds")
    if "along" in d:
        along = np.asarray(_vector(d, "along", where, required=True))
        if not abs(float(np.linalg.norm(along)) - 1.0) <= SEGMENT_TOL:
            raise ConfigError(f"{where}.along", d["along"], f"must be a unit vector (|along| = 1 within "
                                                            f"{SEGMENT_TOL:g}; it is {float(np.linalg.norm(along)):.12g})")
        if not abs(float(along @ np.asarray(normal))) <= SEGMENT_TOL:
            raise ConfigError(f"{where}.along", d["along"], f"must lie in the wall's plane (along · normal = 0 within "
                                                            f"{SEGMENT_TOL:g}; it is {float(along @ normal):.3g})")
        along = along - float(along @ np.asarray(normal)) * np.asarray(normal)  # exactly in the plane, unit
        out["along"] = tuple(float(c) for c in along / np.linalg.norm(along))
        ext = d["extent"]
        if not (isinstance(ext, list) and len(ext) == 2 and all(
                isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) for b in ext)):
            raise ConfigError(f"{where}.extent", ext, "must be [s0, s1]: two finite lengths in m along `along` "
                                                      "from point")
        if not ext[0] < ext[1]:
            raise ConfigError(f"{where}.extent", ext, "must be [s0, s1] with s0 < s1 (m)")
        out["extent"] = (float(ext[0]), float(ext[1]))
    if "until" in d:
        out["until"] = _number(d, "until", where, rule="must be > 0 (s): the time the wall is removed",
                               check=_positive)
    return out


def _run(run_raw: dict, kind: str) -> Run:
    """The [run] table checked."""
    _known_keys(run_raw, RUN_KEYS, "run")
    dt_raw = run_raw.get("dt", "auto")
    if dt_raw == "auto":
        dt = None
    else:
        dt = _number(run_raw, "dt", "run", rule="must be > 0 (s) or \"auto\"", check=_positive)
    spc = run_raw.get("steps_per_contact", 200)
    if isinstance(spc, bool) or not isinstance(spc, int) or not 2 <= spc <= 10**15:
        raise ConfigError("run.steps_per_contact", spc, "must be an integer from 2 to 10^15")
    method = run_raw.get("method", "adaptive")
    if method not in ("adaptive", "verlet"):
        raise ConfigError("run.method", method, "must be adaptive or verlet")
    return Run(
        dt=dt,
        steps_per_contact=spc,
        gravity=_vector(run_raw, "gravity", "run", default=(0.0, 0.0, 0.0)),
        rtol=_number(run_raw, "rtol", "run", required=False, default=1e-13,
                     rule="must be in [1e-14, 1e-2]", check=lambda v: 1e-14 <= v <= 1e-2),
        method=method,
        verlet_rtol=_number(run_raw, "verlet_rtol", "run", required=False, default=None,
                            rule="must be in (0, 1] (a difference in units of each metric's scale)",
                            check=lambda v: 0 < v <= 1),
        **_scenario_keys(run_raw, kind),
    )


def _contact(contact_raw: dict) -> Contact:
    """The [contact] table checked: the model ids of its slots and the parameters the laws read."""
    contact_raw = dict(contact_raw)
    if "normal" not in contact_raw:
        raise ConfigError("contact.normal", None, "missing: a normal model id is required (see `demcheck models`)")
    limit = contact_raw.pop("limit_force", False)
    if not isinstance(limit, bool):
        raise ConfigError("contact.limit_force", limit, "must be true or false")
    normal_id = contact_raw.pop("normal")
    tangential_id = contact_raw.pop("tangential", "none")
    from .laws.slots import BEYOND_SLOTS, check_id

    beyond = {slot: check_id(slot, contact_raw.pop(slot, "none")) for slot in BEYOND_SLOTS}
    return Contact(normal=str(normal_id), tangential=str(tangential_id), limit_force=limit, params=contact_raw,
                   **beyond)


# scenario → (the slot it exercises, one body on a wall?); the laws it has a metric for are those whose record
# names it (``scenarios``, in each law's module: laws/slots.scenario_laws)
SCENARIO_SLOTS = {
    "rolling": ("rolling", True),
    "incline": ("rolling", True),
    "twist": ("twisting", True),
    "pull_off": ("adhesion", None),
    "adhesive_impact": ("adhesion", None),
    "conduction": ("heat", None),
}


def _check_scenario(case: Case) -> None:
    """What a scenario beyond sliding needs of the case (reference/scenarios.py solves it): its slot's law, the
    sphere resting on a wall under gravity (rolling, incline, twist), an approach (adhesive_impact), heat
    capacities, temperatures and an overlap (conduction). A ConfigError names the key, the value and the rule."""
    scenario = case.run.scenario
    if scenario == "collision":
        return
    from .laws.slots import scenario_laws

    slot, on_wall = SCENARIO_SLOTS[scenario]
    laws = scenario_laws(slot, scenario)
    law = getattr(case.contact, slot)  # the id the user wrote, checked against the records that name the scenario
    if law not in laws:
        raise ConfigError(f"contact.{slot}", law, f"run.scenario = \"{scenario}\" needs {slot} = "
                          + " or ".join(f"\"{x}\"" for x in laws))
    if on_wall:
        _resting_on_wall(case, scenario)
    if scenario == "rolling":
        p, n = case.particles[0], np.asarray(case.walls[0].normal)
        v = np.asarray(p.velocity)
        if not np.linalg.norm(v - (v @ n) * n) > 0 or abs(v @ n) > 1e-12 * np.linalg.norm(v):
            raise ConfigError("particles.0.velocity", list(p.velocity),
                              "the rolling scenario needs a velocity along the wall (rolling without slip)")
        g = np.asarray(case.run.gravity)
        if np.linalg.norm(g + (g @ -n) * n) > 1e-12 * np.linalg.norm(g):
            raise ConfigError("run.gravity", list(case.run.gravity),
                              "the rolling scenario is on a level wall: gravity along -normal (run.scenario = "
                              "\"incline\" for a tilt)")
        if _record(case, slot).decays:
            _viscous_roll_grips(case)
    if scenario in ("rolling", "incline"):
        _tangential_holds(case, scenario)
    if scenario == "twist":
        w, n = np.asarray(case.particles[0].angular_velocity), np.asarray(case.walls[0].normal)
        if not abs(w @ n) > 0:
            raise ConfigError("particles.0.angular_velocity", list(case.particles[0].angular_velocity),
                              "the twist scenario needs a spin about the wall's normal")
    if scenario == "pull_off" and not _record(case, slot).replaces_normal:  # a cohesion on the elastic law
        _sjkr_pull_inputs(case)
    if scenario == "adhesive_impact":
        from .laws import model as _model

        if not _model.resolve(case).pair.impact_speed > 0:
            raise ConfigError("particles", "(initial state)", "the bodies never meet: no impact to solve")
    if scenario == "conduction":
        _conduction_inputs(case)


def _record(case: Case, slot: str):
    """The case's record of a slot beyond sliding (its traits say what its scenario checks)."""
    from .laws import model as _model

    return _model.resolve(case).slot(slot)


def rolling_grip(case: Case) -> tuple[float, float, float]:
    """A sphere rolling on the case's wall under a viscous torque −Cr ω (type B): (its deceleration at the start,
    the largest friction can give, the largest Cr it rolls under without slip). Rolling, its angular momentum about
    the contact point (7/5)mRv falls at the torque's rate Cr v/R (the friction force has no moment about that
    point): v' = −v/T, T = 1.4mR²/Cr. On the level wall of the rolling scenario (θ = 0, which the scenario
    requires: on a tilt gravity has a moment about that point and the roll tends to a terminal speed instead) the
    friction force m·v' that keeps it rolling is within μ|Fn| = μ m g while v0/T ≤ μ g, i.e. Cr ≤ 1.4 μ m g R²/v0 —
    the scenario and its closed form assume it; past it the sphere slides, its spin falls faster than its speed and
    the speed decays at μ g, not as e^{−t/T}."""
    from .laws import model as _model

    p, n = case.particles[0], np.asarray(case.walls[0].normal, dtype=float)
    g_vec = np.asarray(case.run.gravity, dtype=float)
    g = float(np.linalg.norm(g_vec))
    theta = math.acos(min(1.0, float(-(g_vec @ n)) / g))
    mass, radius = case.mass(0), p.radius
    v = np.asarray(p.velocity, dtype=float)
    v0 = float(np.linalg.norm(v - (v @ n) * n))
    model = _model.resolve(case)
    grip = (model.pair.friction or 0.0) * g * math.cos(theta)
    law = model.slot("rolling")
    viscous = law is not None and law.decays  # type B: −Cr w
    deceleration = v0 / (1.4 * mass * radius * radius / law.c_r) if viscous else 0.0
    return deceleration, grip, 1.4 * mass * radius * radius * grip / v0 if v0 > 0.0 else math.inf


def _tangential_holds(case: Case, scenario: str) -> None:
    """The rolling and incline scenarios roll the sphere without slip (reference/beyond.py assumes it and checks
    |Ft| ≤ μ|Fn|): the case's tangential law must hold a friction force while the contact point is at rest — a
    history spring (the spring family, LTH, ZZY, Walton) or Coulomb's stick (sliding). No friction, or a force
    only from a slip velocity (viscous, viscous_sliding), lets the sphere slide, and no source would run the
    physics the closed form describes."""
    from .laws import model as _model
    from .laws.tangential import SlidingTangential

    record = _model.resolve(case).tangential_law.slot()
    if record.history_size > 0 or isinstance(record, SlidingTangential):
        return
    raise ConfigError("contact.tangential", case.contact.tangential,
                      f"run.scenario = \"{scenario}\" rolls the sphere without slip: it needs a tangential law that "
                      "holds friction with the contact point at rest (a history spring such as \"spring_sliding\", "
                      "or \"sliding\"), not one whose force needs a slip velocity or is none")


def _viscous_roll_grips(case: Case) -> None:
    """The rolling scenario under type B rolls without slip (:func:`rolling_grip`): above the bound the sphere
    slides and the scenario's closed form (v0 e^{−t/T}) does not hold, so the case is refused before any run."""
    from .laws import model as _model

    deceleration, grip, bound = rolling_grip(case)
    if not grip > 0.0:
        key = "contact.friction" if "friction" in case.contact.params else "materials.*.friction"
        raise ConfigError(key, _model.resolve(case).pair.friction, "must be > 0 with rolling = \"viscous\": a "
                          "viscous rolling torque (type B) rolls the sphere only with friction on the wall")
    if deceleration > grip:
        raise ConfigError("contact.c_r", case.contact.params.get("c_r"),
                          f"must be at most {bound:.6g} N·m·s, the largest Cr the sphere rolls under without slip "
                          f"(Cr ≤ 1.4 μ m g R²/v0 on a level wall): above it the torque decelerates the roll at "
                          f"Cr·v0/(1.4 m R²) = {deceleration:.3g} m/s², more than friction gives (μ g = "
                          f"{grip:.3g} m/s²), and the sphere slides; the rolling scenario's closed form assumes it rolls")


def _sjkr_pull_inputs(case: Case) -> None:
    """sjkr's pull-off has its closed form for like spheres under an elastic Hertz law (reference/beyond.py
    ``sjkr_pull_off_closed``)."""
    from .laws import model as _model

    radii = [p.radius for p in case.particles]
    if len(radii) != 2 or radii[0] != radii[1]:
        raise ConfigError("particles", radii, "the pull_off scenario with adhesion = \"sjkr\" pulls two like spheres "
                          "(equal radii)")
    from .laws.damping import NoDamping
    from .laws.normal import HertzNormal

    normal, damping = _model.resolve(case).normal_law.slots()  # the slot records, by class (never exponents)
    # and the model id the user wrote: the closed form (reference/beyond.py sjkr_pull_off_closed) is written for
    # the case's model "hertz", not for any model whose records are an undamped Hertz spring
    if not isinstance(normal, HertzNormal) or not isinstance(damping, NoDamping) or case.contact.normal != "hertz":
        raise ConfigError("contact.normal", case.contact.normal, "the pull_off scenario with adhesion = \"sjkr\" adds "
                          "the cohesion to the elastic Hertz law: normal = \"hertz\"")


def _resting_on_wall(case: Case, scenario: str) -> None:
    if len(case.particles) != 1 or len(case.walls) != 1:
        raise ConfigError("particles", len(case.particles), f"the {scenario} scenario is one sphere on one wall")
    p, w = case.particles[0], case.walls[0]
    gap = float((np.asarray(p.position) - np.asarray(w.point)) @ np.asarray(w.normal)) - p.radius
    if gap > 1e-9 * p.radius:
        raise ConfigError("particles.0.position", list(p.position),
                          f"the {scenario} scenario's sphere rests on the wall (its centre one radius from it)")
    if not float(np.asarray(case.run.gravity) @ np.asarray(w.normal)) < 0:
        raise ConfigError("run.gravity", list(case.run.gravity),
                          f"the {scenario} scenario needs gravity pressing the sphere onto the wall")


def _conduction_inputs(case: Case) -> None:
    if case.run.temperatures is None:
        raise ConfigError("run.temperatures", None, "missing: the conduction scenario needs one temperature a body")
    if case.run.overlap is None:
        raise ConfigError("run.overlap", None, "missing: the conduction scenario holds the bodies at this overlap (m)")
    if len(case.particles) != 2:
        raise ConfigError("particles", len(case.particles), "the conduction scenario is two particles")
    for p in case.particles:
        if case.materials[p.material].specific_heat is None:
            raise ConfigError(f"materials.{p.material}.specific_heat", None,
                              "missing: the conduction scenario needs each body's heat capacity")


def _scenario_keys(run_raw: dict, kind: str) -> dict:
    """[run] scenario, temperatures and overlap, checked alone (what each scenario needs of the rest of the case
    is reference/scenarios.py's check, run with the contact's)."""
    scenario = run_raw.get("scenario", "collision")
    if scenario not in SCENARIOS:
        raise ConfigError("run.scenario", scenario, f"must be one of {', '.join(SCENARIOS)}")
    if scenario != "collision" and kind != "collision":
        raise ConfigError("run.scenario", scenario, "a scenario beyond sliding needs kind = \"collision\" (two bodies)")
    temps = run_raw.get("temperatures")
    if temps is not None:
        if (not isinstance(temps, list) or len(temps) != 2
                or not all(isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t) and t > 0
                           for t in temps)):
            raise ConfigError("run.temperatures", temps, "must be two temperatures > 0 (K), one per body")
        temps = tuple(float(t) for t in temps)
    overlap = _number(run_raw, "overlap", "run", required=False, default=None, rule="must be > 0 (m)",
                      check=_positive)
    for key, value in (("temperatures", temps), ("overlap", overlap)):
        if value is not None and scenario != "conduction":
            raise ConfigError(f"run.{key}", run_raw[key], "is read by run.scenario = \"conduction\" only")
    return {"scenario": scenario, "temperatures": temps, "overlap": overlap}


def _collision_scales(case: Case, build, impact) -> Case:
    """The collision moved near its contact, and its run length checked (run_length) — the case's own numbers
    must give a contact time, a flight and a step a double can hold."""
    from .laws import model as _model

    near = _near_contact(case)
    if near is not None:
        case = build(near)
    model = _model.resolve(case)
    if model.pair.impact_speed > 0:  # bodies that never meet are the solvers' to report
        if impact is None:
            flight = ("particles.0.position", list(case.particles[0].position))
        else:
            flight = ("impact.gap", impact["gap"]) if "gap" in impact else ("impact.speed", impact.get("speed"))
        run_length(case, model=model, flight=flight)
    return case


@contextlib.contextmanager
def _computable(case: Case):
    """An arithmetic fault while a case's scales are computed (an overflow, a division by an underflowed zero, a
    NaN) is a ConfigError naming the case's most extreme number — never a traceback or a numpy warning."""
    try:
        with np.errstate(all="ignore"):
            yield
    except (ArithmeticError, ValueError) as exc:
        key, value = extreme_number(case)
        raise ConfigError(key, value, f"the case's numbers are beyond what double precision computes here "
                                      f"({type(exc).__name__}: {exc})") from None


# everyday values of a case's numbers: the one farthest from its own (in decades) is named when scales fail
EVERYDAY = {"density": 2500.0, "youngs_modulus": 7e10, "radius": 1e-3, "speed": 1.0}


def extreme_number(case: Case) -> tuple[str, object]:
    """(key, value) of the case's number farthest, in decades, from an everyday grain's: the materials' density
    and modulus, the radii, the impact speed, and any contact parameter outside [1e-100, 1e100]."""
    found = []
    for name, m in case.materials.items():
        for attr in ("density", "youngs_modulus"):
            found.append((f"materials.{_key_text(name)}.{attr}", getattr(m, attr), EVERYDAY[attr]))
    for i, p in enumerate(case.particles):
        found.append((f"particles.{i}.radius", p.radius, EVERYDAY["radius"]))
    v = float(np.linalg.norm(np.subtract(case.particles[0].velocity, case.particles[1].velocity
                                         if len(case.particles) > 1 else 0.0)))
    if v > 0:
        found.append(("particles.0.velocity", v, EVERYDAY["speed"]))
    for k, x in case.contact.params.items():
        if isinstance(x, (int, float)) and not isinstance(x, bool) and x and not 1e-100 <= abs(x) <= 1e100:
            found.append((f"contact.{_key_text(k)}", x, 1.0))
    key, value, _ = max(found, key=lambda f: abs(math.log10(abs(f[1])) - math.log10(f[2])) if f[1] else 0.0)
    return key, value


# Without gravity the bodies fly in straight lines until they touch: they start at most this many elastic
# contact times of flight apart (a tiny impact speed otherwise meant millions of steps of free flight).
MAX_FLIGHT = 10.0


def incidence(case: Case) -> tuple[float, float]:
    """(v_n, |v_t|) of the initial relative velocity (v0 − v1, or v0 at a wall) on the contact normal (from body 0
    into body 1 or the wall): v_n > 0 approaching."""
    p0 = case.particles[0]
    v = np.asarray(p0.velocity, float)
    if case.walls:
        n = -np.asarray(case.walls[0].normal, float)
    else:
        p1 = case.particles[1]
        v = v - np.asarray(p1.velocity, float)
        d = np.asarray(p1.position, float) - np.asarray(p0.position, float)
        n = d / np.linalg.norm(d)
    vn = float(v @ n)
    return vn, float(np.linalg.norm(v - vn * n))


def free_flight(case: Case) -> tuple[float, bool]:
    """(t, touches) of a collision's free flight (gravity included: both bodies fall alike, so only a wall
    sees it): the time until the surfaces first touch, touches = True (0 when they touch at the start); for
    bodies that never touch, the time of their closest approach (0 when they only separate), False. Kept in
    ``case.prepared`` (loading the case computes it; the solvers read it again)."""
    got = case.prepared.get("free_flight")
    if got is None:
        got = case.prepared["free_flight"] = _free_flight(case)
    return got


def _free_flight(case: Case) -> tuple[float, bool]:
    p0 = case.particles[0]
    x0, v0 = np.asarray(p0.position, float), np.asarray(p0.velocity, float)
    if case.walls:
        w = case.walls[0]
        nw = np.asarray(w.normal, float)
        gap = float((x0 - np.asarray(w.point, float)) @ nw) - p0.radius
        vn, an = -float(v0 @ nw), -float(np.asarray(case.run.gravity, float) @ nw)
        if gap <= 0:
            return 0.0, True
        disc = vn * vn + 2.0 * an * gap  # gap − vn t − an t²/2 = 0
        if disc < 0:  # turns back before the wall
            return (-vn / an if an < 0 and vn > 0 else 0.0), False
        root = math.sqrt(disc)
        if vn + root <= 0:
            return 0.0, False
        return 2.0 * gap / (vn + root), True
    p1 = case.particles[1]
    d0 = np.asarray(p1.position, float) - x0
    v_rel = v0 - np.asarray(p1.velocity, float)  # d(t) = d0 − v_rel t
    a, b = float(v_rel @ v_rel), float(d0 @ v_rel)
    c = float(d0 @ d0) - (p0.radius + p1.radius) ** 2
    if c <= 0:
        return 0.0, True
    if a == 0.0 or b <= 0:
        return 0.0, False
    if b * b < a * c:
        return b / a, False
    return c / (b + math.sqrt(b * b - a * c)), True  # the smaller root of a t² − 2 b t + c, without cancellation


def _near_contact(case: Case) -> tuple[Particle, ...] | None:
    """Without gravity, the particles moved along their velocities to MAX_FLIGHT contact times before they
    touch, when they start farther (the motion until contact is exactly linear and nothing else changes);
    None when they already start close enough, under gravity, or never meet."""
    if any(case.run.gravity):
        return None
    tau, touches = free_flight(case)
    if not touches:
        return None
    from .laws.model import characteristic_time, resolve

    shift = tau - MAX_FLIGHT * characteristic_time(resolve(case))
    if not shift > 0:
        return None
    return tuple(replace(p, position=tuple(float(x + shift * v) for x, v in zip(p.position, p.velocity)))
                 for p in case.particles)


# A DEM particle's mass (kg): within this the pair's m̄ = m₁m₂/(m₁+m₂) and the contact scales are representable
# (density 1e-300 made m̄ underflow to 0, the contact time 0 and the solver divide by zero).
MASS_RANGE = (1e-30, 1e30)


def _check_masses(kinds: list[tuple[str, float]], materials: dict) -> None:
    """Each particle's mass (``kinds``: its material and radius) in MASS_RANGE, computed in logarithms (r³ of a
    1e200 m radius overflows a double)."""
    lo, hi = MASS_RANGE
    seen: dict[tuple[str, float], int] = {}
    for i, kind in enumerate(kinds):
        seen.setdefault(kind, i)
    for (mat, r), i in seen.items():
        rho = materials[mat].density
        log_m = math.log10(rho) + math.log10(4.0 / 3.0 * math.pi) + 3.0 * math.log10(r)
        if math.log10(lo) <= log_m <= math.log10(hi):
            continue
        # name the factor farther from an everyday grain (1 mm, 2500 kg/m³)
        by_density = abs(math.log10(rho) - math.log10(2500.0)) >= 3.0 * abs(math.log10(r) + 3.0)
        key, value = (f"materials.{_key_text(mat)}.density", rho) if by_density else (f"particles.{i}.radius", r)
        raise ConfigError(key, value, f"gives particle {i} (density {rho:g} kg/m³, radius {r:g} m) a mass of "
                                      f"{_power(log_m)} kg: a particle's mass must be in [{lo:g}, {hi:g}] kg")


def _power(log10_x: float) -> str:
    """10^log10_x as text, also beyond a double's range."""
    return f"{10.0 ** log10_x:.3g}" if abs(log10_x) < 300 else f"10^{log10_x:.1f}"


def _species(parts: tuple[Particle, ...]) -> dict[int, tuple[str, float]]:
    """{first particle index: (material, radius)} of each distinct kind of particle."""
    seen: dict[tuple[str, float], int] = {}
    for i, p in enumerate(parts):
        seen.setdefault((p.material, p.radius), i)
    return {i: k for k, i in seen.items()}


def _apply_impact(impact: dict, particles: list[dict], walls: list[Wall], materials) -> None:
    """Place the bodies for an impact at ``speed`` (m/s, relative, at the contact point) and incidence
    ``angle`` (degrees from the normal). The contact normal is x for a pair, the wall normal for a wall;
    the tangential direction is y (or a tangent of the wall). ``spin`` (rad/s) is the angular velocity of
    particle 0 about the axis n × t. ``gap`` is the initial surface separation (m); without gravity the bodies
    are then moved to at most MAX_FLIGHT contact times of flight apart (_near_contact)."""
    if not isinstance(impact, dict):
        raise ConfigError("impact", impact, "must be a table")
    _known_keys(impact, IMPACT_KEYS, "impact")
    lo_v, hi_v = COMPONENT_RANGE
    speed = _number(impact, "speed", "impact", rule=f"must be > 0 (m/s), in [{lo_v:g}, {hi_v:g}] (its square must "
                                                    "be a normal double)", check=lambda v: lo_v <= v <= hi_v)
    angle = _number(impact, "angle", "impact", required=False, default=0.0,
                    rule="must be in [0, 90) degrees from the normal", check=lambda v: 0 <= v < 90)
    spin = _number(impact, "spin", "impact", required=False, default=0.0)
    theta = math.radians(angle)
    if len(particles) == 1 and len(walls) == 1:
        p, w = particles[0], walls[0]
        n = np.asarray(w.normal)
        t = _tangent(n)
        gap = _number(impact, "gap", "impact", required=False, default=1e-3 * p["radius"],
                      rule="must be >= 0 (m)", check=lambda v: v >= 0)
        v = speed * (-math.cos(theta) * n + math.sin(theta) * t)
        tau = gap / (speed * math.cos(theta))  # time to contact
        p["position"] = tuple(np.asarray(w.point) + p["radius"] * n - tau * v)
        p["velocity"] = tuple(v)
        p["angular_velocity"] = tuple(spin * np.cross(n, t))
    elif len(particles) == 2 and not walls:
        p0, p1 = particles
        m = [materials[p["material"]].density * p["radius"] ** 3 for p in (p0, p1)]
        r_eff = p0["radius"] * p1["radius"] / (p0["radius"] + p1["radius"])
        gap = _number(impact, "gap", "impact", required=False, default=1e-3 * r_eff,
                      rule="must be >= 0 (m)", check=lambda v: v >= 0)
        n, t = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
        v_rel = speed * (math.cos(theta) * n + math.sin(theta) * t)  # v0 - v1
        tau = gap / (speed * math.cos(theta))  # time to contact; the line of centres is n at contact
        p0["position"] = (0.0, 0.0, 0.0)
        p1["position"] = tuple((p0["radius"] + p1["radius"]) * n + tau * v_rel)
        p0["velocity"] = tuple(m[1] / (m[0] + m[1]) * v_rel)
        p1["velocity"] = tuple(-m[0] / (m[0] + m[1]) * v_rel)
        p0["angular_velocity"] = tuple(spin * np.cross(n, t))
    else:
        raise ConfigError("impact", impact, "applies to a collision of two particles or of a particle and a wall")
    for p in particles:  # the placed state: positions (gap / speed of flight), velocities, spins
        for part, key in (("position", "gap"), ("velocity", "speed"), ("angular_velocity", "spin")):
            if not all(math.isfinite(c) and _representable(c) for c in p[part]):
                raise ConfigError(f"impact.{key}", impact.get(key), f"places a particle at {part} "
                                  f"{[float(c) for c in p[part]]}: {VECTOR_RULE}")


def packing_spec(p: dict | None, materials) -> Packing:
    """The validated [packing] table: layout, count, material, radii, periodic box (x, y), seed, duration."""
    if not isinstance(p, dict):
        raise ConfigError("packing", p, "a packing case needs a [packing] table (layout, count, material, radius)")
    _known_keys(p, PACKING_KEYS, "packing")
    layout = p.get("layout")
    if layout not in LAYOUTS:
        raise ConfigError("packing.layout", layout, f"must be one of {', '.join(LAYOUTS)}")
    count = p.get("count")
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise ConfigError("packing.count", count, "must be an integer >= 1")
    _check_memory(count)
    mat = p.get("material")
    if mat not in materials:
        raise ConfigError("packing.material", mat, f"is not a defined material (defined: {', '.join(materials)})")
    if "radii" in p:
        radii = p["radii"]
        if not isinstance(radii, list) or not radii or not all(
                isinstance(r, (int, float)) and not isinstance(r, bool) and r > 0 for r in radii):
            raise ConfigError("packing.radii", radii, "must be a non-empty list of radii > 0 (m)")
        radii = [float(r) for r in radii]
    else:
        radii = [_number(p, "radius", "packing", rule="must be > 0 (m)", check=_positive)]
    rmax = max(radii)
    fractions = _fractions(p, radii)
    box = p.get("box")
    if layout == "inserted" and box is not None:
        raise ConfigError("packing.box", box, "an inserted packing has no periodic box (its container is its walls)")
    if layout in ("column", "inserted"):
        box = None
    elif box is None:
        side = 2.0 * rmax * math.ceil(math.sqrt(count)) * (1.0 + 1e-3) if layout == "layer" else None
        if side is None:
            raise ConfigError("packing.box", None, "missing: a poured packing needs its periodic box [lx, ly] (m)")
        box = [side, side]
    if box is not None:
        if not (isinstance(box, list) and len(box) == 2 and all(
                isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) for b in box)):
            raise ConfigError("packing.box", box, "must be [lx, ly]: two finite lengths in m")
        if min(box) <= 2.0 * rmax:
            raise ConfigError("packing.box", box, f"must be larger than a particle's diameter ({2 * rmax:g} m) "
                                                  "in x and y")
    seed = p.get("seed", 1)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise ConfigError("packing.seed", seed, "must be an integer")
    duration = _number(p, "duration", "packing", required=False, default=None, rule="must be > 0 (s)",
                       check=_positive)
    insertion = _insertion(p, layout, count, rmax, duration)
    height = _height(p, duration)
    return Packing(layout=layout, count=count, material=mat, radii=tuple(radii),
                   box=tuple(float(b) for b in box) if box is not None else None, seed=seed, duration=duration,
                   volume_fractions=fractions, insertion=insertion, height=height)


def _fractions(p: dict, radii: list) -> tuple[float, ...] | None:
    """packing.volume_fractions: one positive share per radius, summing to 1 (within 1e-9)."""
    if "volume_fractions" not in p:
        return None
    f = p["volume_fractions"]
    if p.get("layout") != "inserted":
        raise ConfigError("packing.volume_fractions", f, "is read with layout = \"inserted\" only (the other "
                                                         "layouts take equal numbers of each radius)")
    if not (isinstance(f, list) and len(f) == len(radii) and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0 for v in f)):
        raise ConfigError("packing.volume_fractions", f, f"must be {len(radii)} shares > 0, one per radius "
                                                         "(packing.radii)")
    if abs(sum(f) - 1.0) > 1e-9:
        raise ConfigError("packing.volume_fractions", f, f"must sum to 1 (they sum to {sum(f):.12g})")
    return tuple(float(v) for v in f)


def _table(p: dict, key: str, keys: set) -> dict | None:
    t = p.get(key)
    if t is None:
        return None
    if not isinstance(t, dict):
        raise ConfigError(f"packing.{key}", t, "must be a table")
    _known_keys(t, keys, f"packing.{key}")
    return t


def _count(t: dict, key: str, where: str) -> int:
    v = t.get(key)
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ConfigError(f"{where}.{key}", v, "must be an integer >= 1")
    return v


def _insertion(p: dict, layout: str, count: int, rmax: float, duration: float | None) -> Insertion | None:
    """[packing.insertion], which an inserted packing needs and no other layout reads."""
    t = _table(p, "insertion", INSERTION_KEYS)
    if layout != "inserted":
        if t is not None:
            raise ConfigError("packing.insertion", t, "is read with layout = \"inserted\" only")
        return None
    if t is None:
        raise ConfigError("packing.insertion", None, "missing: an inserted packing needs its batches (every, batch, "
                                                     "batches, region)")
    where = "packing.insertion"
    every = _number(t, "every", where, rule="must be > 0 (s)", check=_positive)
    batch, batches = _count(t, "batch", where), _count(t, "batches", where)
    if batch * batches != count:
        raise ConfigError(f"{where}.batches", batches, f"batches × batch = {batches * batch} must be packing.count "
                                                       f"= {count}")
    if duration is not None and (batches - 1) * every >= duration:
        raise ConfigError(f"{where}.every", every, f"inserts the last batch at {(batches - 1) * every:g} s, not "
                                                   f"before the end of the run (packing.duration = {duration:g} s)")
    region = t.get("region")
    if not (isinstance(region, list) and len(region) == 2 and all(
            isinstance(c, list) and len(c) == 3 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                        and math.isfinite(v) for v in c) for c in region)):
        raise ConfigError(f"{where}.region", region, "must be [[x0, y0, z0], [x1, y1, z1]]: two opposite corners (m)")
    lo, hi = (tuple(float(v) for v in c) for c in region)
    if any(b < a for a, b in zip(lo, hi)):
        raise ConfigError(f"{where}.region", region, "must be [lo, hi] with lo <= hi along each axis")
    spacing = _number(t, "spacing", where, required=False, default=1.5, rule="must be >= 1 (largest diameters)",
                      check=lambda v: v >= 1)
    offset = _number(t, "offset", where, required=False, default=0.0, rule="must be >= 0 (largest diameters)",
                     check=lambda v: v >= 0)
    if spacing - 2.0 * offset < 1.0:
        raise ConfigError(f"{where}.offset", offset, f"moves two neighbours of the lattice into each other: spacing "
                                                     f"- 2 offset = {spacing - 2 * offset:g} must be >= 1")
    ins = Insertion(every=every, batch=batch, batches=batches, region=(lo, hi), spacing=spacing, offset=offset)
    sites = int(np.prod(_lattice_counts(ins, rmax)))
    if sites < batch:
        raise ConfigError(f"{where}.region", region, f"holds {sites} lattice sites at a pitch of {spacing:g} "
                                                     f"largest diameters ({2 * rmax * spacing:.4g} m): a batch "
                                                     f"needs {batch}")
    return ins


def _height(p: dict, duration: float | None) -> Height | None:
    """[packing.height]: what the heap's height is and when it is measured."""
    t = _table(p, "height", HEIGHT_KEYS)
    if t is None:
        return None
    where = "packing.height"
    axis = _unit(_vector(t, "axis", where, required=True), f"{where}.axis")
    offset = _number(t, "offset", where, required=False, default=0.0)
    every = _number(t, "every", where, rule="must be > 0 (s)", check=_positive)
    start = _number(t, "start", where, required=False, default=0.0, rule="must be >= 0 (s)", check=lambda v: v >= 0)
    if duration is not None and start > duration:
        raise ConfigError(f"{where}.start", start, f"must not be past the end of the run (packing.duration = "
                                                   f"{duration:g} s)")
    return Height(axis=axis, offset=offset, every=every, start=start)


def _lattice_counts(ins: Insertion, rmax: float) -> tuple[int, int, int]:
    """The insertion lattice's sites along x, y, z: the region's length over the pitch (one site along an axis of
    zero extent, at the region's lo)."""
    pitch = 2.0 * rmax * ins.spacing
    return tuple(1 if b == a else int(math.floor((b - a) / pitch)) for a, b in zip(*ins.region))


def insertion_batches(spec: Packing) -> list[list[dict]]:
    """The particles of an inserted packing, batch by batch (each a list of Particle keyword dicts), seeded: batch b
    from numpy's generator seeded with (seed, b). Sites x fastest, then y, then z, from the region's lo corner (the
    first site half a pitch in, or at lo along an axis of zero extent); each moved by up to ``offset`` largest
    diameters (uniform) along the axes of nonzero extent; radii drawn with the numbers' shares the volume fractions
    give (n_i ∝ φ_i / r_i³), or in turn where none are given."""
    ins, radii = spec.insertion, spec.radii
    rmax = max(radii)
    pitch = 2.0 * rmax * ins.spacing
    counts = _lattice_counts(ins, rmax)
    lo, hi = (np.asarray(c, float) for c in ins.region)
    flat = hi == lo
    first = np.where(flat, lo, lo + 0.5 * pitch)
    if spec.volume_fractions is not None:
        share = np.asarray(spec.volume_fractions) / np.asarray(radii) ** 3
        share = share / share.sum()
    out = []
    for b in range(ins.batches):
        rng = np.random.default_rng([spec.seed, b])
        batch = []
        for k in range(ins.batch):
            i, rest = k % counts[0], k // counts[0]
            j, l = rest % counts[1], rest // counts[1]
            pos = first + pitch * np.array([i, j, l], float)
            jitter = rng.uniform(-1.0, 1.0, 3) * ins.offset * 2.0 * rmax
            pos = np.where(flat, pos, pos + jitter)
            r = radii[int(rng.choice(len(radii), p=share))] if spec.volume_fractions is not None else \
                radii[(b * ins.batch + k) % len(radii)]
            batch.append({"material": spec.material, "radius": float(r), "position": [float(c) for c in pos]})
        out.append(batch)
    return out


# What a packing costs in memory per particle, measured: building the case (~2.5 KiB at the peak, tracemalloc, for
# 2e4 to 1e5 particles), with the solver's arrays and a deck's data file on top.
PACKING_BYTES_PER_PARTICLE = 4096


def _check_memory(count: int) -> None:
    """Refuse a packing whose particles alone would not fit in this machine's memory, before building any."""
    need = count * PACKING_BYTES_PER_PARTICLE
    have = _physical_memory()
    if have and need > have:
        raise ConfigError("packing.count", count,
                          f"needs about {_bytes(need)} of memory ({PACKING_BYTES_PER_PARTICLE // 1024} KiB a "
                          f"particle), more than this machine has ({_bytes(have)})")


def _physical_memory() -> int | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def _bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024


def generate_packing(spec: Packing) -> list[dict]:
    """The initial positions of a packing (seeded): a vertical column of spheres just apart, a square layer
    on the floor, or spheres on a loose jittered lattice above the floor to be poured. The floor is z = 0."""
    radii, n, mat = spec.radii, spec.count, spec.material
    if spec.layout == "inserted":  # the first batch: the others join the run (reference/packing.simulate)
        return insertion_batches(spec)[0]
    gap = 1e-3
    out = []
    if spec.layout == "column":
        z = 0.0
        for k in range(n):
            r = radii[k % len(radii)]
            z += r * (1.0 + gap)
            out.append({"material": mat, "radius": r, "position": [0.0, 0.0, z]})
            z += r * (1.0 + gap)
        return out
    lx, ly = spec.box
    if spec.layout == "layer":
        side = int(math.ceil(math.sqrt(n)))
        a = lx / side
        for k in range(n):
            r = radii[k % len(radii)]
            out.append({"material": mat, "radius": r,
                        "position": [(k % side + 0.5) * a, (k // side + 0.5) * ly / side, r * (1.0 + gap)]})
        return out
    # poured: a loose lattice of cells 2.2 r_max wide, each sphere jittered inside its cell
    rng = np.random.default_rng(spec.seed)
    rmax = max(radii)
    a = 2.2 * rmax
    nx, ny = max(1, int(lx / a)), max(1, int(ly / a))
    ax, ay = lx / nx, ly / ny
    if ax < 2.0 * rmax * 1.05 or ay < 2.0 * rmax * 1.05:
        raise ConfigError("packing.box", spec.box, "is too small for a layer of the particles")
    slack_x, slack_y, slack_z = ax - 2.0 * rmax, ay - 2.0 * rmax, 0.2 * rmax
    for k in range(n):
        layer, cell = divmod(k, nx * ny)
        i, j = cell % nx, cell // nx
        r = radii[k % len(radii)]
        jit = rng.uniform(-0.5, 0.5, 3) * np.array([slack_x, slack_y, slack_z]) * 0.9
        out.append({"material": mat, "radius": r,
                    "position": [(i + 0.5) * ax + jit[0], (j + 0.5) * ay + jit[1],
                                 rmax * 1.2 + layer * a + jit[2]]})
    return out


def _tangent(n: np.ndarray) -> np.ndarray:
    """A fixed unit tangent of a wall normal (x, unless the normal is nearly x; then y)."""
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = a - (a @ n) * n
    return t / np.linalg.norm(t)


# up to this many particles the layout's pairs are checked all against all (a millisecond); past it through a k-d tree
# of the positions (scipy's cKDTree: only the pairs closer than the largest touching distance, O(N log N) — the
# all-pairs check took minutes at the 128 000-sphere packing), which costs its import (~0.3 s) once
PAIRWISE_MAX = 1000


def _first_overlap(x: np.ndarray, r: np.ndarray) -> tuple[int, int, float] | None:
    """The first overlapping pair (i < j, the least i, then the least j) and by how much, or None."""
    if len(r) <= PAIRWISE_MAX:
        for i in range(len(r) - 1):
            d = np.linalg.norm(x[i + 1:] - x[i], axis=1)
            touch = r[i] + r[i + 1:]
            bad = np.flatnonzero(d < touch * (1 - 1e-12))
            if bad.size:
                return i, i + 1 + int(bad[0]), float(touch[bad[0]] - d[bad[0]])
        return None
    from scipy.spatial import cKDTree

    pairs = cKDTree(x).query_pairs(2.0 * float(r.max()), output_type="ndarray")
    if not len(pairs):
        return None
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.linalg.norm(x[j] - x[i], axis=1)
    touch = r[i] + r[j]
    bad = np.flatnonzero(d < touch * (1 - 1e-12))
    if not bad.size:
        return None
    k = bad[np.lexsort((j[bad], i[bad]))[0]]
    return int(i[k]), int(j[k]), float(touch[k] - d[k])


def wall_distance(w: Wall, x: np.ndarray) -> np.ndarray:
    """The distance of each centre x (N × 3) from a wall: its height over the plane ((x − p)·n, negative behind it:
    a plane wall is a half-space); for a segment (a thin plate, touched from either side) the height's magnitude
    where the centre projects into its strip, else its distance to the strip's nearer edge line (what the packing
    solver's contact takes: reference/packing.py)."""
    d = x - np.asarray(w.point)
    h = d @ np.asarray(w.normal)
    if w.extent is None:
        return h
    s = d @ np.asarray(w.along)
    beyond = np.clip(s, *w.extent) - s
    return np.where(beyond == 0.0, np.abs(h), np.hypot(beyond, h))


def _check_geometry(particles: tuple[Particle, ...], walls: tuple[Wall, ...]) -> None:
    x = np.array([p.position for p in particles], float)
    r = np.array([p.radius for p in particles], float)
    first = _first_overlap(x, r)
    if first is not None:
        i, j, by = first
        raise ConfigError(f"particles.{j}.position", list(particles[j].position),
                          f"overlaps particle {i} by {by:.3g} m: particles must not start overlapping")
    for k, w in enumerate(walls):
        s = wall_distance(w, x)
        bad = np.flatnonzero(s < r * (1 - 1e-12))
        if bad.size:
            i = int(bad[0])
            raise ConfigError(f"particles.{i}.position", list(particles[i].position),
                              f"is {s[i]:.3g} m in front of wall {k}, less than its radius: "
                              "particles must not start overlapping a wall")


# An engine run dumps every step (~1 kB a step for two bodies): a collision's run is refused past this many steps
# (500 MB of dump; the default suite's longest run, bench at 5000 steps per contact, takes 120 000).
MAX_STEPS = 500_000
MIN_TIME = 1e-300  # s: a contact time or step below it has lost a double's precision (subnormals)


def run_length(case: Case, dt: float | None = None, length: float = 1.0, model=None,
               flight: tuple[str, object] | None = None) -> tuple[float, float, int]:
    """(dt, t_end, steps) of a collision's run in an engine (and in the verlet reference): dt (``dt``, the
    case's, or auto), free flight to contact plus ``length`` × 6 elastic contact times. More than MAX_STEPS
    steps is a ConfigError naming what makes the run long: the free flight (``flight``: its key and value,
    default the first particle's position) or the step (``dt`` given here: --dt; run.dt; the auto dt's
    run.steps_per_contact)."""
    from .laws.model import characteristic_time, resolve

    model = model or resolve(case)
    t_c = characteristic_time(model)
    if not (math.isfinite(t_c) and t_c >= MIN_TIME):
        key, value = extreme_number(case)
        raise ConfigError(key, value, f"gives an elastic contact time of {t_c:.3g} s: the case's numbers must give "
                                      f"a finite time >= {MIN_TIME:g} s (a double's precision)")
    step = dt or case.run.dt or t_c / case.run.steps_per_contact  # dt = auto
    t_flight, t_contact = free_flight(case)[0], 6.0 * t_c * length
    if not math.isfinite(t_flight):
        key, value = flight or ("particles.0.position", list(case.particles[0].position))
        raise ConfigError(key, value, f"gives a free flight of {t_flight} s before the contact: not a finite time")
    t_end = t_flight + t_contact
    steps = t_end / step
    if not step >= MIN_TIME:  # a step given that small (auto steps are >= t_c / 10^15)
        key, value = ("--dt", dt) if dt else ("run.dt", case.run.dt)
        raise ConfigError(key, value, f"gives a time step of {step:.3g} s: it must be >= {MIN_TIME:g} s")
    if steps > MAX_STEPS:
        if t_flight > t_contact:
            key, value = flight or ("particles.0.position", list(case.particles[0].position))
            why = f"{t_flight:.3g} s of free flight before the contact"
        else:
            key, value = (("--dt", dt) if dt else ("run.dt", case.run.dt) if case.run.dt else
                          ("run.steps_per_contact", case.run.steps_per_contact))
            why = f"{t_contact:.3g} s of contact"
        raise ConfigError(key, value, f"the run would take {steps:.3g} steps ({why} at dt = {step:.3g} s), more "
                                      f"than the {MAX_STEPS:,} an engine run (every step dumped; the "
                                      "verlet method is bounded by its record's memory) is allowed")
    return step, t_end, int(math.ceil(steps))


# A packing runs N particles for many steps; its engines write the final state and a thermo line every steps/50
# only, so what bounds it is the time it takes: at most this many steps, and this many particle-steps (the
# reference solver takes about 0.4 µs a particle-step on one core, an engine about as long: 1e10 is about an
# hour). The default suite's longest packing takes 89 109 steps (layer-kk) and 7.5e7 particle-steps (poured); the
# opt-in cases at most 521 654 steps (poured-small-poly) and 3.7e8 particle-steps (poured-large).
MAX_PACKING_STEPS = 5_000_000
MAX_PARTICLE_STEPS = 1e10


def packing_step(case: Case, steps_per_contact: int | None = None) -> float:
    """A packing's dt: the case's run.dt, or auto — the shortest elastic contact time of a species' pair law (at
    the speed of a one-diameter drop) over run.steps_per_contact (``steps_per_contact`` instead: auto regardless
    of run.dt)."""
    if case.run.dt and steps_per_contact is None:
        return case.run.dt
    from .laws.contact import pair_of
    from .laws.model import models_of

    normal, _ = models_of(case)
    g = float(np.linalg.norm(case.run.gravity)) or 9.81
    best = math.inf
    for i in _species(case.particles):
        pair = pair_of(case, i, i)
        law, _ = normal.resolve(pair, case.contact.params, case.contact.limit_force)
        best = min(best, law.characteristic_time(pair.m_eff, math.sqrt(2.0 * g * 2.0 * case.particles[i].radius)))
    return best / (steps_per_contact or case.run.steps_per_contact)


def packing_run(case: Case, duration: float | None = None, dt: float | None = None) -> tuple[float, float, int]:
    """(dt, duration, steps) of a packing's run, in the reference solver and in every engine: dt (``dt``, else
    ``packing_step``), the duration (``duration``, else packing.duration). More than MAX_PACKING_STEPS steps or
    MAX_PARTICLE_STEPS particle-steps is a ConfigError naming what makes the run long: the step (``dt`` given here:
    --dt; run.dt; the auto dt's run.steps_per_contact) when the run would fit at the default auto step, else the
    duration (``duration`` given here: --duration; packing.duration)."""
    given = duration
    duration = duration or (case.packing.duration if case.packing else None)
    if not duration:
        raise ConfigError("packing.duration", None, "missing: how long to let the packing settle (s)")
    step = dt or packing_step(case)
    n, steps = len(case.particles), duration / step
    if case.packing is not None and case.packing.insertion is not None:
        n = case.packing.count  # every batch in by the end
    if steps <= MAX_PACKING_STEPS and n * steps <= MAX_PARTICLE_STEPS:
        return step, duration, int(math.ceil(steps))
    default = duration / packing_step(case, Run.steps_per_contact)  # the steps at the default auto step
    if default <= MAX_PACKING_STEPS and n * default <= MAX_PARTICLE_STEPS:
        key, value = (("--dt", dt) if dt else ("run.dt", case.run.dt) if case.run.dt else
                      ("run.steps_per_contact", case.run.steps_per_contact))
    else:
        key, value = ("--duration", given) if given else ("packing.duration", duration)
    if steps > MAX_PACKING_STEPS:
        rule = (f"the run would take {steps:.3g} steps ({duration:g} s at dt = {step:.3g} s), more than the "
                f"{MAX_PACKING_STEPS:,} steps a packing run is allowed")
    else:
        rule = (f"the run would take {steps:.3g} steps of {n:,} particles ({n * steps:.3g} particle-steps; "
                f"{duration:g} s at dt = {step:.3g} s), more than the {MAX_PARTICLE_STEPS:.3g} particle-steps a "
                "packing run is allowed")
    raise ConfigError(key, value, rule)
