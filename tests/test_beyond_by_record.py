"""Issue 29 item 1 for the slots beyond sliding: the scenario solvers, their twins and the engines' scenario writers
ask a law's record (its class, its traits: ``stops``, ``decays``, ``spring``, ``from_contact_radius``,
``replaces_normal``, ``necks``…), never its id. This reads reference/beyond*.py, reference/scenarios.py,
engines/scenario.py and engines/*/scenario.py and lists every comparison that names a law by its id or kind: an
operand ``x.id`` or a name ``kind`` (``law.id == "epsd"``, ``rec.id in ("jkr", "dmt")``, ``kind == JKR``), a
subscript ``…["kind"]``, or a slot of the case's contact against a string (``case.contact.rolling ==
"viscous"``); and every read of a law's exponents by key (``ln["a"]``, ``ln["b"]``) or a bare exponent ``b`` as
a truth value (``if x_t and b``). comparisons/audit_beyond.py is not read (another change's file)."""

from __future__ import annotations

import ast

from .conftest import ROOT

SRC = ROOT / "src" / "demcheck"
BEYOND_SLOTS = {"rolling", "twisting", "adhesion", "heat", "normal", "damping", "tangential"}


def files():
    ref = SRC / "reference"
    return [*sorted(ref.glob("beyond*.py")), ref / "scenarios.py", SRC / "engines" / "scenario.py",
            *sorted((SRC / "engines").glob("*/scenario.py"))]


def _by_id(node) -> bool:
    """An operand that names a law by id or kind."""
    if isinstance(node, ast.Attribute):
        return node.attr == "id" or node.attr == "kind"
    if isinstance(node, ast.Name):
        return node.id == "kind"
    if isinstance(node, ast.Subscript):
        return isinstance(node.slice, ast.Constant) and node.slice.value == "kind"
    return False


def _slot_string(left, right) -> bool:
    """``case.contact.rolling == "viscous"``: a contact slot (an attribute of ``…contact``) against a string."""
    for a, b in ((left, right), (right, left)):
        if (isinstance(a, ast.Attribute) and a.attr in BEYOND_SLOTS and isinstance(a.value, ast.Attribute)
                and a.value.attr == "contact" and isinstance(b, ast.Constant) and isinstance(b.value, str)):
            return True
    return False


def _exponent_read(node) -> bool:
    return (isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant)
            and node.slice.value in ("a", "b"))


def _bare_exponent_test(node) -> bool:
    """``if x_t and b``: a bare ``a``/``b`` (an exponent) used as a truth value."""
    tests = [node.test] if isinstance(node, (ast.If, ast.IfExp, ast.While)) else []
    out = []
    for t in tests:
        out += t.values if isinstance(t, ast.BoolOp) else [t]
    return any(isinstance(x, ast.Name) and x.id in ("a", "b") for x in out)


def by_id(source: str, name: str) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(source)):
        hit = False
        if isinstance(node, ast.Compare):
            ops = [node.left, *node.comparators]
            hit = any(_by_id(x) for x in ops) or any(_slot_string(x, y) for x, y in zip(ops, ops[1:]))
        elif _exponent_read(node) or _bare_exponent_test(node):
            hit = True
        if hit:
            out.append(f"{name}:{node.lineno}: {ast.unparse(node)[:100]}")
    return out


def test_the_scenario_solvers_and_writers_ask_records_never_ids():
    assert len(files()) >= 9
    found = [hit for f in files() for hit in by_id(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))]
    assert not found, "\n".join(found)


def test_the_rule_sees_each_form_and_spares_the_records():
    caught = ['law.id == "epsd"', 'stops = law.id == "constant_torque"', 'rec.id not in ("jkr", "dmt")',
              "kind == JKR", 'x if p["kind"] == "jkr" else y', 'case.contact.rolling == "viscous"',
              'resolve(case).slot("rolling").id != "viscous"', "model.contact.damping.id != 'none'",
              '(weight / ln["k_el"]) ** (1.0 / ln["a"])', "f = lambda d: ln['c'] * d ** ln['b']",
              "if x_t and b:\n    pass"]
    for text in caught:
        assert by_id(text, "t"), text
    spared = ["law.decays", "isinstance(rec, EpsdRolling)", "type(tl) is SpringTangential", "if law.necks:\n    pass",
              'nat.normal == "jkr"', 's == "rolling"', 'f"heat {HEAT[type(rec)]}"', "spring.k * d ** spring.exponent",
              'nat.props["rolling"]', "if x_t and not isinstance(dashpot, ConstantDamping):\n    pass"]
    for text in spared:
        assert not by_id(text, "t"), text
