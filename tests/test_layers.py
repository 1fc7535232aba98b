"""The layering of docs/architecture.md: no module imports from a higher layer (at module level or inside a
function: a lazy import is still a dependency), and no two modules import each other, directly or round a
circle. Engine names stay inside engines/."""

from __future__ import annotations

import ast
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "demcheck"

# lowest first; a module's layer is the first pattern its dotted name (below demcheck) matches
LAYERS = [
    ("base", r"errors|io|resources|__init__"),
    ("laws", r"laws(\..*)?"),
    ("case", r"case|result|metrics"),
    ("reference", r"reference(\..*)?"),
    ("deck helpers", r"inputs(\..*)?"),
    ("engines", r"engines(\..*)?"),
    ("comparisons", r"comparisons(\..*)?"),
    ("api", r"api"),
    ("front ends", r"cli|cli_text|__main__"),
]


def _layer(name: str) -> int:
    for k, (_, pattern) in enumerate(LAYERS):
        if re.fullmatch(pattern, name):
            return k
    raise AssertionError(f"module demcheck.{name} is in no layer of docs/architecture.md")


def _modules() -> dict[str, Path]:
    out = {}
    for f in SRC.rglob("*.py"):
        parts = f.relative_to(SRC).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" and len(parts) > 1 else parts)
        out[name] = f
    return out


def _imports(name: str, path: Path, modules) -> set[str]:
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in _runtime_nodes(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package.split(".") if package else []
            base = base[:len(base) - (node.level - 1)] if node.level > 1 else base
            stem = ".".join([*base, *([node.module] if node.module else [])])
            candidates = [f"{stem}.{a.name}".strip(".") for a in node.names] + [stem]
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("demcheck"):
            stem = node.module.removeprefix("demcheck").lstrip(".")
            candidates = [f"{stem}.{a.name}".strip(".") for a in node.names] + [stem]
        elif isinstance(node, ast.Import):
            candidates = [a.name.removeprefix("demcheck").lstrip(".") for a in node.names
                          if a.name.startswith("demcheck")]
        else:
            continue
        # ``from pkg import a, b`` depends on every named submodule (a, b), else on pkg itself
        named = [c for c in candidates[:-1] if c in modules]
        out.update(c for c in (named or candidates[-1:]) if c in modules and c != name)
    return out


def _runtime_nodes(tree):
    """Every node but those under ``if TYPE_CHECKING:`` (imports for annotations only, never executed)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            stack.extend(node.orelse)
            continue
        yield node
        stack.extend(ast.iter_child_nodes(node))


def _graph():
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def test_no_module_imports_from_a_higher_layer():
    bad = [f"demcheck.{a} ({LAYERS[_layer(a)][0]}) imports demcheck.{b} ({LAYERS[_layer(b)][0]})"
           for a, deps in _graph().items() for b in deps if _layer(b) > _layer(a)]
    assert not bad, "\n".join(sorted(bad))


def test_no_import_circles():
    graph = _graph()
    state: dict[str, int] = {}
    cycles = []

    def visit(node, stack):
        state[node] = 1
        stack.append(node)
        for dep in graph[node]:
            if state.get(dep) == 1:
                cycles.append(" → ".join(stack[stack.index(dep):] + [dep]))
            elif dep not in state:
                visit(dep, stack)
        stack.pop()
        state[node] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name, [])
    assert not cycles, "\n".join(cycles)


def test_engine_names_stay_inside_engines():
    literal = re.compile(r"[\"'](lammps|liggghts|yade|kratos)[\"']")
    bad = []
    for f in SRC.rglob("*.py"):
        if f.relative_to(SRC).parts[0] == "engines":
            continue
        for n, line in enumerate(f.read_text().splitlines(), 1):
            code = line.split("#", 1)[0]
            if literal.search(code):
                bad.append(f"{f.relative_to(SRC)}:{n}: {line.strip()}")
    assert not bad, "\n".join(bad)
