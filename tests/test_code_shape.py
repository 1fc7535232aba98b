"""The redesign's rule on size: no function of the package is longer than 80 lines, outside the compiled kernels
(numba's @njit functions, where a solver's step loop is kept whole so that the compiler sees it at once)."""

import ast

from .conftest import ROOT

LIMIT = 80


def long_functions(source: str, name: str = "<source>") -> list[str]:
    """'file:line name (N lines)' of every function over LIMIT lines that no njit decorator marks."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        length = node.end_lineno - node.lineno + 1
        compiled = any("njit" in ast.unparse(d) for d in node.decorator_list)
        if length > LIMIT and not compiled:
            out.append(f"{name}:{node.lineno} {node.name} ({length} lines)")
    return out


def test_no_function_over_80_lines_outside_the_compiled_kernels():
    found = []
    for path in sorted((ROOT / "src" / "demcheck").rglob("*.py")):
        found += long_functions(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))
    assert not found, "\n".join(found)


def test_the_rule_sees_a_long_function_and_spares_a_kernel():
    body = "".join(f"    x{i} = {i}\n" for i in range(LIMIT))
    plain = f"def f():\n{body}"
    kernel = f"@njit(cache=True)\ndef g():\n{body}"
    short = "def h():\n" + "".join(f"    x{i} = {i}\n" for i in range(LIMIT - 1))
    assert long_functions(plain) == ["<source>:1 f (81 lines)"]
    assert long_functions(kernel) == []
    assert long_functions(short) == []
