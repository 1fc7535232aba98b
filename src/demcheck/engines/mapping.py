"""Which engine configuration computes which seed model, and how faithfully.

For one type pair (two particles, or a particle and a wall) :func:`map_model` asks the engine's package
(:meth:`demcheck.engines.base.Engine.map`) for the seed model in its own terms — a :class:`Native`
configuration with every coefficient computed — and how faithful it is:

* ``exact``: the engine computes the seed model's force law; its twin is the seed law itself (with the
  engine's kinematic rules: lever arms and history rotation, which differ at O(δ/R) only in oblique
  impacts);
* ``approximate``: the engine computes a named variant (the twin), and the reason says how it differs;
* ``none``: the engine cannot express the model, and the reason says why. No deck is written then.

Every Native has a twin (:meth:`Native.twin`): the reference laws that compute exactly what the engine
computes, run with the engine's scheme (verlet) and rules (:attr:`Engine.rules`). The contract test
(tests/test_engine_contract.py) holds every claim of every registered engine for every registered law.
"""

from __future__ import annotations

from dataclasses import replace

from ..case import Case
from ..laws.model import ResolvedModel, resolve
from . import registry
from .base import APPROXIMATE, EXACT, NATIVE, NONE_, Mapping, Native, refused, worst

__all__ = ["APPROXIMATE", "EXACT", "NATIVE", "NONE_", "Mapping", "Native", "refused", "worst", "as_engine",
           "map_model", "pair_mapping", "contact_mapping", "twin_model", "table", "by_model", "native_summary",
           "markdown_table", "mu_of", "HUGE_MU", "SLIDING_XT"]

HUGE_MU = 1e100  # "no Coulomb limit" for a viscous law expressed through a capped one (the cap μ|Fn| then
# bites only where Fn is exactly 0; a finite 1e6 changed the tangential restitution by 2e-5 near Fn's sign change)
SLIDING_XT = 1e4  # a dashpot far above the cap: the regularised slider


def map_model(model: ResolvedModel, engine, contact_params: dict | None = None) -> Mapping:
    """The engine configuration for one type pair of a resolved seed model, with its fidelity. ``engine``: the
    Engine object (a deck writer passes the one it is handed: a build's own), or its registered name."""
    return as_engine(engine).map(model, contact_params or {})


def as_engine(engine):
    """The Engine ``engine`` names (an Engine is returned as it is): the functions here take either."""
    return registry.get(engine) if isinstance(engine, str) else engine


def pair_mapping(case: Case, engine, i: int, j: int | None, native: Native | None = None) -> Mapping:
    """The mapping of one type pair by ``engine`` (an Engine, or its registered name). Pairs that never touch in
    this case (a particle with itself) are resolved at the contact's own impact speed, where a model calibrates its
    stiffness at one. A ``native`` configuration given directly (tests of engine traps, twins of configurations no
    seed model maps to) is used for every pair as it is. A particle–wall pair of a wall the engines' flat walls
    cannot place (not axis-aligned) is not expressible."""
    from ..inputs.common import wall_axis
    from ..errors import UnsupportedByEngine

    engine = as_engine(engine)
    if j is None:
        for k, w in enumerate(case.walls):
            try:
                wall_axis(w, k)
            except UnsupportedByEngine as exc:
                return refused(engine.name, str(exc))
    if native is not None:
        return Mapping(engine.name, NATIVE, ["a native engine configuration, given directly"], native)
    params = case.contact.params
    if (i, j) != contact_pair(case) and "reference_velocity" not in params:
        v = resolve(case).pair.impact_speed
        case = replace(case, contact=replace(case.contact, params={**params, "reference_velocity": v}))
    return map_model(resolve(case, i, j), engine, params)


def contact_pair(case: Case) -> tuple[int, int | None]:
    """The contact of interest: particle 0 with particle 1, or with the wall."""
    return (0, 1) if len(case.particles) == 2 else (0, None)


def contact_mapping(case: Case, engine, native: Native | None = None) -> Mapping:
    """The mapping of the contact of interest (particle 0 with particle 1, or with the wall) by ``engine`` (an
    Engine, or its registered name)."""
    return pair_mapping(case, engine, *contact_pair(case), native=native)


def mu_of(model: ResolvedModel, reasons: list[str]) -> tuple[float, str]:
    tl = model.tangential_law
    if tl.mu_s != tl.mu_k:
        reasons.append(f"one friction coefficient only: μ = μs = {tl.mu_s:g} (the case's μk = {tl.mu_k:g} "
                       "is not expressible)")
        return tl.mu_s, APPROXIMATE
    return tl.mu_k, EXACT


def twin_model(model: ResolvedModel, native: Native) -> ResolvedModel:
    """The resolved model whose laws are the engine configuration's twin (for the reference solvers)."""
    nl, tl = registry.get(native.engine).twin(native, model.pair.m_eff, model.pair.r_eff)
    return replace(model, normal_law=nl, tangential_law=tl, limit_force=native.limit)


def table(examples: list[tuple[str, str]] | None = None) -> list[dict]:
    """The mapping of every registered model for ``demcheck models`` and docs/models.md: each normal model
    with tangential none, each tangential model with its natural normal partner, on the glass pair."""
    from ..case import apply_overrides, from_dict
    from ..laws import normal, tangential
    from ..laws.model import resolve

    import copy
    import tomllib

    base = tomllib.loads(_TABLE_CASE)
    rows = []
    combos = examples or ([(n, "none", {}) for n in normal.REGISTRY] + [
        (_PARTNER.get(t, "lsd"), t, {}) for t in tangential.REGISTRY if t != "none"] + _VARIANTS)
    for combo in combos:
        nid, tid, extra = combo if len(combo) == 3 else (*combo, {})
        params = {**normal.REGISTRY[nid].example, **tangential.REGISTRY[tid].example, **extra}
        params.pop("friction", None)
        sets = [f"contact.normal={nid}", f"contact.tangential={tid}"]
        sets += [f"contact.{k}={_toml(v)}" for k, v in params.items()]
        case = from_dict(apply_overrides(copy.deepcopy(base), sets))
        model = resolve(case)
        row = {"normal": nid, "tangential": tid,
               "variant": ", ".join(f"{k} = {_toml(v)}" for k, v in extra.items())}
        for engine in registry.names():
            mp = map_model(model, engine, case.contact.params)
            row[engine] = mp.fidelity
            row[f"{engine}_config"] = native_summary(mp.native) if mp.native else ""
            row[f"{engine}_reason"] = "; ".join(mp.reasons)
        rows.append(row)
    return rows


_PARTNER = {"tti": "tti", "ddt": "hertz"}
# parameter variants whose mapping differs from the model's default row
_VARIANTS = [("hls", "none", {"unloading": "variable", "S": 1e4, "kl": 3e6}),
             ("lsd", "viscous", {"limit_force": True}),
             ("lsd", "lsd_sliding", {"truncation": "overlap"}), ("lsd", "lsd_sliding", {"truncation": "spring"}),
             ("tti", "tti", {"truncation": "overlap"}), ("kk", "ddt", {})]
_TABLE_CASE = """
name = "mapping-table"
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = 0.9
friction = 0.3
dissipative_constant = 1e-7
tangential_restitution = 0.5
[[particles]]
material = "glass"
radius = 1.59e-3
position = [-1.59e-3, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]
[[particles]]
material = "glass"
radius = 1.59e-3
position = [1.59e-3, 0.0, 0.0]
[contact]
normal = "lsd"
"""


def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return f'"{v}"' if isinstance(v, str) else repr(v)


def by_model() -> dict:
    """{(slot, id): {engine: {fidelity, config, reason, with}}} from :func:`table` (``with``: the partner
    model of the other slot the row was evaluated with)."""
    out = {}
    for row in table():
        if row["variant"] or (row["tangential"] == "ddt" and row["normal"] != "hertz"):
            continue
        for slot, other in (("normal", "tangential"), ("tangential", "normal")):
            if slot == "normal" and row["tangential"] != "none":
                continue
            if slot == "tangential" and row["tangential"] == "none" and row["normal"] != "lsd":
                continue
            out[(slot, row[slot])] = {e: {"fidelity": row[e], "config": row[f"{e}_config"],
                                          "reason": row[f"{e}_reason"], "with": f"{other} {row[other]}"}
                                      for e in registry.names()}
    return out


def native_summary(nat: Native) -> str:
    """A native configuration in one line of its engine's own words."""
    return registry.get(nat.engine).summary(nat)


def markdown_table() -> str:
    """The mapping table as docs/models.md carries it (tests/test_docs.py keeps the two equal): a column per
    registered engine, headed by its title and the release its decks are written for."""
    engines = registry.all_engines()
    lines = ["| normal | tangential | " + " | ".join(e.release for e in engines) + " |",
             "|---|---|" + "---|" * len(engines)]
    for row in table():
        cells = []
        for e in registry.names():
            text = f"**{row[e]}**"
            if row[f"{e}_config"]:
                text += f": `{row[f'{e}_config']}`"
            if row[f"{e}_reason"]:
                text += f" — {row[f'{e}_reason']}"
            cells.append(text.replace("|", "\\|"))
        variant = f" ({row['variant']})" if row["variant"] else ""
        lines.append(f"| `{row['normal']}` | `{row['tangential']}`{variant} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
