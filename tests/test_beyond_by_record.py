"""Issue 29 item 1 for the slots beyond sliding: the scenario solvers, their twins and the engines' scenario writers
ask a law's record (its class, its traits: ``stops``, ``decays``, ``spring``, ``from_contact_radius``,
``replaces_normal``, ``necks``…), never its id. This reads reference/beyond*.py, reference/scenarios.py,
engines/scenario.py and engines/*/scenario.py and lists every comparison that names a law by its id or kind: an
operand ``x.id`` or a name ``kind`` (``law.id == "epsd"``, ``rec.id in ("jkr", "dmt")``, ``kind == JKR``), a
subscript ``…["kind"]``, or a slot of the case's contact against a string (``case.contact.rolling ==
"viscous"``); and every read of a law's exponents by key (``ln["a"]``, ``ln["b"]``) or a bare exponent ``b`` as
a truth value (``if x_t and b``).

It also reads the deck audit's probes beyond sliding (comparisons/audit_beyond.py), Yade's pair-scenario writer
(engines/yade/pair.py) and the case's scenario checks (case.py), and lists there a law's id against a string: a
deck's sub-model (``sub["law"]``, a name ``law``/``law_id``) against a law id of demcheck's (``sub["law"] ==
"sds"``; an engine's own word such as ``"cdt"`` is spared). In case.py a case's own keys are the user's words
(``kind == "collision"``, ``case.contact.normal != "hertz"``: the closed form is written for that model id), so
there only ``x.id``, the law-id rule and the exponent reads apply."""

from __future__ import annotations

import ast

from .conftest import ROOT

SRC = ROOT / "src" / "demcheck"
BEYOND_SLOTS = {"rolling", "twisting", "adhesion", "heat", "normal", "damping", "tangential"}


def files():
    ref = SRC / "reference"
    return [*sorted(ref.glob("beyond*.py")), ref / "scenarios.py", SRC / "engines" / "scenario.py",
            *sorted((SRC / "engines").glob("*/scenario.py"))]


def user_key_files():
    """Files whose comparisons of a case's own keys (its kind, the model id the user wrote) are the rule itself."""
    return [SRC / "case.py"]


def deck_files():
    return [SRC / "comparisons" / "audit_beyond.py", SRC / "engines" / "yade" / "pair.py"]


def law_ids() -> frozenset:
    """Every id of a registered law beyond sliding (``none`` aside)."""
    from demcheck.laws import slots

    return frozenset(i for slot in slots.BEYOND_SLOTS for i in slots.law_ids(slot)) - {"none"}


def _names_a_law(node) -> bool:
    """A deck's sub-model or a law's name: ``sub["law"]``, ``law``, ``law_id``."""
    if isinstance(node, ast.Subscript):
        return isinstance(node.slice, ast.Constant) and node.slice.value == "law"
    return isinstance(node, ast.Name) and node.id in ("law", "law_id")


def _law_id_string(node) -> bool:
    """A string constant (or a tuple, list or set of them) that is a law id of demcheck's."""
    items = node.elts if isinstance(node, (ast.Tuple, ast.List, ast.Set)) else [node]
    return any(isinstance(x, ast.Constant) and isinstance(x.value, str) and x.value in law_ids() for x in items)


def _law_against_id(left, right) -> bool:
    return any(_names_a_law(a) and _law_id_string(b) for a, b in ((left, right), (right, left)))


def _by_id(node, user_keys: bool = False) -> bool:
    """An operand that names a law by id or kind (``user_keys``: by ``x.id`` only)."""
    if isinstance(node, ast.Attribute):
        return node.attr == "id" or (node.attr == "kind" and not user_keys)
    if user_keys:
        return False
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


def by_id(source: str, name: str, user_keys: bool = False) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(source)):
        hit = False
        if isinstance(node, ast.Compare):
            ops = [node.left, *node.comparators]
            pairs = list(zip(ops, ops[1:]))
            hit = (any(_by_id(x, user_keys) for x in ops) or any(_law_against_id(x, y) for x, y in pairs)
                   or (not user_keys and any(_slot_string(x, y) for x, y in pairs)))
        elif _exponent_read(node) or _bare_exponent_test(node):
            hit = True
        if hit:
            out.append(f"{name}:{node.lineno}: {ast.unparse(node)[:100]}")
    return out


def test_the_scenario_solvers_and_writers_ask_records_never_ids():
    assert len(files()) >= 9
    found = [hit for f in files() for hit in by_id(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))]
    assert not found, "\n".join(found)


def test_the_deck_audit_and_yades_pair_writer_ask_records_never_ids():
    found = [hit for f in deck_files() for hit in by_id(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))]
    assert not found, "\n".join(found)


def test_the_cases_scenario_checks_ask_records_beside_the_users_keys():
    found = [hit for f in user_key_files()
             for hit in by_id(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)), user_keys=True)]
    assert not found, "\n".join(found)


def test_the_law_id_rule_sees_a_decks_law_and_spares_engine_words_and_user_keys():
    caught = ['sub["law"] == "sds"', 'ps.beyond["adhesion"]["law"] in ("jkr", "dmt")', 'law == "viscous"',
              'law_id != "lens"', '"constant_torque" == sub["law"]']
    for text in caught:
        assert by_id(text, "t"), text
        assert by_id(text, "t", user_keys=True), text
    for text in ('law.id == "viscous"', 'normal.id != "hertz"'):
        assert by_id(text, "t", user_keys=True), text
    spared = ['law == "cdt"', 'law not in ("cdt", "epsd3")', 'sub["law"] == "sjkr2"', 'sub["args"] == "jkr"',
              'law not in laws']
    for text in spared:
        assert not by_id(text, "t"), text
    for text in ('kind == "collision"', 'case.contact.normal != "hertz"', *spared):
        assert not by_id(text, "t", user_keys=True), text


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


def test_each_scenario_runs_the_laws_whose_records_name_it():
    """case.py's scenario check reads the laws a scenario runs off the records (``scenarios``): the table it held
    by id before (dbdcd08's SCENARIO_LAWS), law for law and in its order (the refusal lists them)."""
    from demcheck.case import SCENARIO_SLOTS
    from demcheck.laws.slots import scenario_laws

    before = {"rolling": ("constant_torque", "viscous"), "incline": ("constant_torque", "epsd"),
              "twist": ("sds", "marshall"), "pull_off": ("jkr", "dmt", "sjkr"), "adhesive_impact": ("jkr",),
              "conduction": ("radius", "area", "lens")}
    assert {s: scenario_laws(slot, s) for s, (slot, _) in SCENARIO_SLOTS.items()} == before


def test_the_engines_collision_vocabularies_map_records_never_ids():
    """engines/*/mapping.py (a seed model's slots → the engine's collision settings) recognise a record by its
    class (``type(damp) is QuarterDamping``), never by its id (``damp.id == "quarter"``). The user's preset —
    ``model.normal`` / ``model.tangential``, the seed model's name the case wrote — is the user's word, as a case's
    keys are: LAMMPS writes LSD calibrated by restitution as its own ``coeff_restitution``."""
    paths = sorted((SRC / "engines").glob("*/mapping.py"))
    assert len(paths) >= 4
    found = [hit for f in paths for hit in by_id(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))
             if "model.normal.id" not in hit and "model.tangential.id" not in hit]
    assert not found, "\n".join(found)
