"""Issue 29, "one contact in slots": outside the laws, code asks a law's slot records what it is (the elastic,
damping and tangential record: its class or its ``id``), never its exponents or the kernels' family numbers. This
reads the source of comparisons/, engines/ and case.py and lists every comparison of a law's exponent (``.a``,
``.b``, ``.exponent``, or a bare ``a``/``b`` against a number) or family (``.family``, a family constant such as
``SPRING`` or ``HYSTERETIC``), and every read of ``.kt_sqrt`` (the flag that tells two tangential records apart)."""

from __future__ import annotations

import ast
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


def _sources():
    files = [SRC / "case.py", *sorted((SRC / "comparisons").rglob("*.py")), *sorted((SRC / "engines").rglob("*.py"))]
    return [(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT))) for f in files]


def test_no_law_recognised_by_exponent_or_family_outside_the_laws():
    families = family_constants()
    found = {hit for source, name in _sources() for hit in by_numbers(source, name, families)}
    assert not found - KNOWN, "\n".join(sorted(found - KNOWN))


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
