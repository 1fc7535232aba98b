"""The solvers ask a law what it is (its traits, its compiled hooks), never which it is (issue 29 items 1 and 2): no
solver module names a built-in tangential or normal family, and a plug-in law with a history and stick/slip
states — a spring under another family id, declared in one module — runs in the 3-D adaptive and verlet solvers
exactly as the built-in spring does, with no solver edited."""

import ast
import sys
from pathlib import Path

from .helpers import code_names, with_plugin_law

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "src" / "demcheck" / "reference"
# expected.py holds the closed forms of named seed models (it asks for the hysteretic normal law by its constant, a
# mapping, not a solver)
NOT_SOLVERS = {"expected.py"}
# the one named fast path: the packing loop's scalar copy of the spring (every deck's law); every other law, and the
# spring itself without it, goes through the traits (test_the_packing_loop_runs_a_plugin_spring_as_the_builtin)
FAST_PATHS = {"packing.py": {"SPRING", "T_FAMILY"}}  # its test: tl[T_FAMILY] == SPRING


def _family_constants() -> set[str]:
    """The names of every registered tangential law's family id in its own module (SPRING, WALTON, …), and the
    law array's family column."""
    from demcheck.laws import tangential_force  # noqa: F401  (every law registered)
    from demcheck.laws import tangential_slot

    names = {"T_FAMILY"}
    for family in tangential_slot.KERNELS:
        for record in tangential_slot.records(family):
            tree = ast.parse(Path(sys.modules[record.__module__].__file__).read_text())
            names |= {t.id for node in tree.body if isinstance(node, ast.Assign)
                      and isinstance(node.value, ast.Constant) and node.value.value == family
                      for t in node.targets if isinstance(t, ast.Name) and t.id.isupper()}
    return names


NORMAL_FAMILIES = {"L_FAMILY", "HYSTERETIC", "VISCOELASTIC", "BRANCHED_FAMILY"}


def test_no_solver_names_a_tangential_or_normal_family():
    from demcheck.laws import tangential_slot
    from demcheck.laws.tangential_laws import spring, walton

    constants = _family_constants()
    # not vacuous: every seed family is registered and its constant found
    assert len(tangential_slot.KERNELS) >= 8 and {"SPRING", "WALTON", "T_FAMILY"} <= constants
    assert spring.SPRING in tangential_slot.KERNELS and walton.WALTON in tangential_slot.KERNELS
    solvers = [p for p in sorted(REFERENCE.glob("*.py")) if p.name not in NOT_SOLVERS]
    assert {"adaptive3d.py", "verlet3d.py", "collision3d.py", "kernels.py", "kernels3d.py"} <= {p.name for p in solvers}
    assert "packing.py" in {p.name for p in solvers}
    for path in solvers:
        named = code_names(path.read_text()) & constants - FAST_PATHS.get(path.name, set())
        assert not named, f"{path.name} names the tangential family {sorted(named)}: ask the law's traits (has)"
        named = code_names(path.read_text()) & NORMAL_FAMILIES
        assert not named, f"{path.name} names the normal family {sorted(named)}: ask loads_and_unloads"
    # the check sees a name where one is used
    assert "SPRING" in code_names((ROOT / "src" / "demcheck" / "laws" / "tangential_laws" / "spring.py").read_text())
    assert "L_FAMILY" in code_names((ROOT / "src" / "demcheck" / "laws" / "normal_force.py").read_text())


COPY = '''
"""The spring under another family id: its record (traits inherited) and its compiled functions, one module."""
from dataclasses import dataclass
from typing import ClassVar

from demcheck.laws.tangential_laws import spring as S
from demcheck.laws.tangential_slot import compiled


@dataclass(frozen=True)
class CopySpring(S.SpringTangential):
    id: ClassVar[str] = "copy_spring"
    family: ClassVar[int] = 41


compiled(CopySpring, force=S.spring_tangential_force, slip_surface=S.spring_slip_surface,
         return_map=S.spring_return_map, discrete_slip=S.spring_discrete_slip)
'''

RUN = r'''
import dataclasses, json
from demcheck.laws.model import resolve
from demcheck.reference import collision3d
from demcheck.reference.collision import auto_dt
from tests.tangential_bits import _case

out = {}
for trunc in ("force", "overlap"):
    case = _case("lsd_sliding", {"truncation": trunc, "tangential_restitution": 0.5}, False)
    model = resolve(case)
    copy = dataclasses.replace(model, tangential_law=dataclasses.replace(model.tangential_law, family=41))
    for method in ("adaptive", "verlet"):
        dt = None if method == "adaptive" else auto_dt(case)
        a, b = (collision3d.collide(case, m, method, dt=dt) for m in (model, copy))
        slips = bool(a.contact["slipping"].any())
        bits = [[t.contact[c].to_numpy().astype(float).tobytes() for c in t.contact.columns] for t in (a, b)]
        out[f"{trunc}-{method}"] = [bits[0] == bits[1] and list(a.contact.columns) == list(b.contact.columns),
                                   len(a.contact), float(copy.tangential_law.array()[0]), slips]
print(json.dumps(out))
'''


def _with_the_copy(tmp_path, script: str) -> dict:
    """``script``'s JSON, run in a fresh process with the spring's copy (COPY) registered as a plug-in law, on an
    empty kernel cache."""
    return with_plugin_law(tmp_path, "copy_spring_law", COPY, script)


def test_a_plugin_law_with_a_history_runs_as_the_builtin_it_copies(tmp_path):
    out = _with_the_copy(tmp_path, RUN)
    assert len(out) == 4
    for key, (same, rows, family, slips) in out.items():
        assert family == 41.0 and rows > 10, (key, rows, family)
        assert slips, f"{key}: the contact never slipped (the states would not be exercised)"
        assert same, f"{key}: the plug-in spring's contact differs from the built-in spring's"


PACK = r'''
import hashlib, json
import numpy as np
from demcheck import case as C
from demcheck.laws.tangential import T_FAMILY
from demcheck.reference import packing as P

out = {}
for mu_k in ("", "friction_kinetic = 0.3\n"):
    text = open("src/demcheck/cases/optin/poured-small.toml").read()
    text = text.replace("[contact]\n", "[contact]\n" + mu_k)
    case = C.loads(text, name="pour")
    laws = P.resolve_laws(case)
    sp, ln, lt, wn, wt = laws
    copy = (sp, ln, lt.copy(), wn, wt.copy())
    copy[2][..., T_FAMILY] = 41.0
    copy[4][..., T_FAMILY] = 41.0
    dt = P.packing_dt(case)
    digests, contacts = [], []
    for use in (laws, copy):
        st = P.PackState(case)
        ke, nc, flags = P.advance(case, st, dt, 20000, laws=use)
        digests.append(hashlib.sha256(b"".join(a.tobytes() for a in (st.x, st.v, st.w, st.hist))).hexdigest())
        contacts.append(int(nc))
    out[mu_k or "one mu"] = [digests[0] == digests[1], contacts[0], int(st.hist.shape[1]),
                             float(np.abs(st.hist[:, 3]).max()) if st.hist.shape[1] > 3 else 0.0]
print(json.dumps(out))
'''


def test_the_packing_loop_runs_a_plugin_spring_as_the_builtin(tmp_path):
    """The packing loop's traits path (reference/packing.py _other_tangential: history, increment, projection, the
    law's own discrete slip and its slip state) gives the bits of its named fast path for the spring: a copy of the
    spring under family 41 runs the pour (150 spheres, 20 000 steps, with one μ and with μk < μs, whose slip state
    is then used) to the same positions, velocities, spins and histories as the built-in spring."""
    out = _with_the_copy(tmp_path, PACK)
    assert len(out) == 2
    for key, (same, contacts, width, slip_state) in out.items():
        assert contacts > 10, (key, contacts)  # the pour has landed: contacts exercised (26 with one μ)
        assert same, f"{key}: the plug-in spring's pour differs from the built-in spring's"
    assert out["friction_kinetic = 0.3\n"][2] == 4 and out["friction_kinetic = 0.3\n"][3] == 1.0  # slip state used
