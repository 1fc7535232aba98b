"""Issue 29, "one contact in slots": outside the laws, code asks a law's slot records what it is (the elastic,
damping and tangential record: its class or its ``id``), never its exponents or the kernels' family numbers. This
reads the source of comparisons/, engines/ and case.py and lists every comparison of a law's exponent (``.a``,
``.b``, ``.exponent``, or a bare ``a``/``b`` against a number) or family (``.family``, a family constant such as
``SPRING`` or ``HYSTERETIC``), and every read of ``.kt_sqrt`` (the flag that tells two tangential records apart).
The engines' twins (engines/, reference/twins*.py) and the closed forms (reference/expected.py) are read too, and
for more: a law built from numbers — a family constant, ``ELASTIC_BY_EXPONENT``, ``BY_EXPONENT`` or ``damping_of``
named at all, the kernels' ``NormalLaw(family, …)`` called directly, or ``twins.normal_law(…)`` given an exponent —
where an engine should name the records it means (``NormalLaw.from_slots(HertzNormal(k=…), QuarterDamping(eta=…),
limit)``)."""

from __future__ import annotations

import ast
import math
import sys

from .conftest import ROOT

SRC = ROOT / "src" / "demcheck"
EXPONENTS = {"a", "b", "exponent"}

# comparisons that are allowed to stay (none: validate.py's two family tests now ask the ViscousSlidingTangential record)
KNOWN: set[str] = set()


def family_constants() -> set[str]:
    """The names of the kernels' family numbers: the normal law's two and each tangential record's module's."""
    from demcheck.laws import normal, tangential  # noqa: F401  (registers every tangential record)
    from demcheck.laws.base import SUBMODELS

    names = {"VISCOELASTIC", "HYSTERETIC"}
    for (slot, _), cls in SUBMODELS.items():
        if slot == "tangential" and isinstance(cls.family, int):
            module = sys.modules[cls.__module__]
            names |= {n for n, v in vars(module).items() if n.isupper() and v == cls.family
                      and type(v) is int}
    return names


def _by_number(node, families: set[str]) -> bool:
    """Whether an operand of a comparison names a law's exponent or family."""
    if isinstance(node, ast.Attribute):
        return node.attr in EXPONENTS | {"family"}
    return isinstance(node, ast.Name) and node.id in families


def record_exponents() -> set[float]:
    """The exponents the elastic and damping records have, but 0 (δ^0: a constant dashpot, and every other zero)."""
    from demcheck.laws.damping import BY_EXPONENT
    from demcheck.laws.normal import ELASTIC_BY_EXPONENT

    return (set(ELASTIC_BY_EXPONENT) | set(BY_EXPONENT)) - {0.0}


def _bare_exponent(left, right) -> bool:
    """``a == 1.5``: a bare exponent name against one of the records' exponents."""
    pair = (left, right)
    return (any(isinstance(x, ast.Name) and x.id in ("a", "b") for x in pair)
            and any(isinstance(x, ast.Constant) and x.value in record_exponents() for x in pair))


def by_numbers(source: str, name: str, families: set[str]) -> list[str]:
    """'name: source' of every comparison of a law by its exponents or family, and every ``.kt_sqrt`` read."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            if any(_by_number(x, families) for x in operands) or any(
                    _bare_exponent(x, y) for x, y in zip(operands, operands[1:])):
                out.append(f"{name}: {ast.unparse(node)}")
        elif isinstance(node, ast.Attribute) and node.attr == "kt_sqrt":
            out.append(f"{name}: {ast.unparse(node)}")
    return out


# the maps from numbers to records: only laws/ may use them (NormalLaw.slots, the one place an exponent names a record)
BY_NUMBER_MAPS = {"ELASTIC_BY_EXPONENT", "BY_EXPONENT", "damping_of"}


def _callee(node) -> str:
    return node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")


def _exponent(node) -> bool:
    """An argument that is an exponent: a number, ``x.a``/``x.b``/``x.exponent``, ``x["a"]``, or a bare a/b."""
    if isinstance(node, ast.UnaryOp):
        node = node.operand
    if isinstance(node, ast.Subscript):
        node = node.slice
        return isinstance(node, ast.Constant) and node.value in EXPONENTS
    return (isinstance(node, ast.Constant) and type(node.value) in (int, float)
            or isinstance(node, ast.Attribute) and node.attr in EXPONENTS
            or isinstance(node, ast.Name) and node.id in ("a", "b"))


def built_by_numbers(source: str, name: str, families: set[str]) -> list[str]:
    """'name: source' of every law built from exponents or family ids: a family constant or a number → record map
    named (imported, read or called), ``NormalLaw(…)`` called directly (its first field is the family id), and
    ``normal_law(…)`` called with an exponent among its arguments (a number, ``.exponent``, ``ln["a"]``…)."""
    names = families | BY_NUMBER_MAPS
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            hit = [a.name for a in node.names if a.name in names]
        elif isinstance(node, ast.Name):
            hit = [node.id] if node.id in names else []
        elif isinstance(node, ast.Attribute):
            hit = [node.attr] if node.attr in names else []
        elif isinstance(node, ast.Call):
            callee = _callee(node)
            hit = [callee] if callee == "NormalLaw" or callee == "normal_law" and any(
                _exponent(x) for x in [*node.args, *(k.value for k in node.keywords)]) else []
        else:
            continue
        out += [f"{name}:{node.lineno}: {ast.unparse(node)}" for _ in hit[:1]]
    return out


def _read(files):
    return [(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT))) for f in files]


def _twin_sources():
    """The engines' twins and the closed forms: where a law is built for an engine or recognised for a formula."""
    return _read([*sorted((SRC / "engines").rglob("*.py")), *sorted((SRC / "reference").glob("twins*.py")),
                  SRC / "reference" / "expected.py"])


def _sources():
    return _read([SRC / "case.py", *sorted((SRC / "comparisons").rglob("*.py"))]) + _twin_sources()


def test_no_law_recognised_by_exponent_or_family_outside_the_laws():
    families = family_constants()
    found = {hit for source, name in _sources() for hit in by_numbers(source, name, families)}
    assert not found - KNOWN, "\n".join(sorted(found - KNOWN))


def test_no_twin_builds_its_law_from_exponents_or_family_ids():
    """Issue 29: an engine maps slot records, never exponents or ids — its twin names the records it means."""
    families = family_constants()
    found = [hit for source, name in _twin_sources() for hit in built_by_numbers(source, name, families)]
    assert not found, "\n".join(found)


def test_the_rule_sees_each_form_and_spares_the_records():
    families = family_constants()
    assert {"SPRING", "NONE", "VISCOUS_SLIDING", "HYSTERETIC", "WALTON"} <= families
    caught = ["nl.a == 1.5", "nl.b != 0.25", "tl.family == SPRING", "nl.family == HYSTERETIC", "x if nl.a == 1.0 else y",
              "damp.exponent == 0.5", "a == 1.0", "mu > 0 and tl.family in (NONE, VISCOUS_SLIDING)",
              "k = tl.kt * (2 if tl.kt_sqrt else 1)"]
    for text in caught:
        assert by_numbers(text, "t", families), text
    spared = ["normal.id == 'hertz'", "isinstance(rec, SpringTangential)", "damping.id in ('none', 'quarter')",
              "tl.truncation != TRUNC_SPRING", "k * d ** nl.a", "a == b", "tl.mu_s > 0", "n == 2",
              "a == 0.0 or b <= 0"]
    for text in spared:
        assert not by_numbers(text, "t", families), text


def test_the_build_rule_sees_each_form_and_spares_the_records():
    families = family_constants()
    caught = ["nl = twins.normal_law(p['kno'], 1.5, c, 0.25, nat.limit)", "normal_law(k, 1.0, c, -0.0, True)",
              "NormalLaw(HYSTERETIC, kl=kl, ku=0.0, s=s, limit=True)", "from ...laws.normal import HYSTERETIC",
              "law = NormalLaw(family, k=k)", "ELASTIC_BY_EXPONENT[a](k=k)", "rec = damping_of(c, b)",
              "from ..laws.damping import damping_of", "d = damping.BY_EXPONENT[b](eta=c)", "x = normal.VISCOELASTIC",
              "twins.normal_law(k, a=1.5, c=c, b=b, limit=True)", "normal_law(spring.k, spring.exponent, c, b, lim)",
              "twins.normal_law(ln['k_el'], ln['a'], ln['c'], ln['b'], True)"]
    for text in caught:
        assert built_by_numbers(text, "t", families), text
    spared = ["NormalLaw.from_slots(HertzNormal(k=k), QuarterDamping(eta=c), True)", "NormalLaw.from_array(law)",
              "from ..laws.normal import HertzNormal, HookeNormal, NormalLaw", "twins.no_friction()",
              "damping('tsuji', 0.5, spring, m, r)", "normal_law(spring, dashpot, limit)", "model.normal_law.array()",
              "tl.truncation != TRUNC_SPRING"]
    for text in spared:
        assert not built_by_numbers(text, "t", families), text


def test_the_damping_styles_name_their_damping_record():
    """engines/damping.py gives each style's dashpot as the record it is (never a (c, b) pair): constant, √δ, or
    the spring's secant √(m̄F/δ) — constant beside hooke, δ^¼ beside hertz — with the documented prefactor."""
    from demcheck.engines.damping import damping
    from demcheck.laws.damping import ConstantDamping, QuarterDamping, SqrtDamping
    from demcheck.laws.normal import HertzNormal, HookeNormal

    m, r, e = 2.0, 0.25, 0.5
    hooke, hertz = HookeNormal(k=8.0), HertzNormal(k=8.0)  # √(m̄k) = 4
    beta = -math.log(e) / math.sqrt(math.pi ** 2 + math.log(e) ** 2)
    cases = [("velocity", hertz, 3.0, ConstantDamping(eta=3.0)),
             ("mass_velocity", hertz, 3.0, ConstantDamping(eta=6.0)),
             ("stiffness_hooke", hooke, 3.0, ConstantDamping(eta=6.0)),
             ("viscoelastic", hooke, 3.0, SqrtDamping(eta=3.0)),
             ("stiffness_hertz", hertz, 3.0, SqrtDamping(eta=3.0)),
             ("coeff_restitution", hooke, e, ConstantDamping(eta=2.0 * beta * 4.0)),
             ("restitution_hooke", hooke, e, ConstantDamping(eta=2.0 * beta * 4.0)),
             ("coeff_restitution", hertz, e, QuarterDamping(eta=math.sqrt(5.0) * beta * 4.0)),
             ("restitution_hertz", hertz, 1.0, QuarterDamping(eta=0.0)),
             ("coeff_restitution", hooke, 1.0, ConstantDamping())]
    for style, spring, coeff, want in cases:
        got = damping(style, coeff, spring, m, r)
        assert type(got) is type(want) and math.isclose(got.eta, want.eta, rel_tol=1e-15), (style, spring, got)
    assert type(damping("tsuji", e, hooke, m, r)) is ConstantDamping
    assert type(damping("tsuji", e, hertz, m, r)) is QuarterDamping
