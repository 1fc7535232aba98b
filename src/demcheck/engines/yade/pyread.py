"""A Yade script's syntax tree evaluated as far as it can be without running it (``demcheck audit``).

The script is parsed with :mod:`ast` and never executed or imported. Its top-level statements are walked in
order; an expression is evaluated only from literals, names bound earlier to such values, arithmetic, a few pure
functions (math's, ``pow``, ``radians``, ``Vector3``…) and calls of Yade classes, which become :class:`Call`
records (the class name with its evaluated arguments). Anything else — a value computed at run time, a name
bound inside a loop or a function, an attribute of a live object — is :data:`UNKNOWN`, carrying why.
"""

from __future__ import annotations

import ast
import math
import operator
from dataclasses import dataclass, field

MAX_BYTES = 5_000_000
MAX_POWER = 1e6  # x ** y with |y| above this is not evaluated (a script's numbers, not a calculator's)


class Unknown:
    """A value the script computes at run time (or the reader cannot evaluate), with the reason."""

    def __init__(self, why: str):
        self.why = why

    def __repr__(self):
        return f"<not read: {self.why}>"


UNKNOWN = Unknown("computed at run time")


@dataclass
class Call:
    """A call of a Yade class or function: its name, positional and keyword arguments (evaluated)."""

    name: str
    args: list
    kw: dict
    line: int
    attrs: dict = field(default_factory=dict)  # attributes the script sets on it afterwards (state.vel, …)


FUNCTIONS = {
    "sqrt": math.sqrt, "pow": pow, "abs": abs, "min": min, "max": max, "float": float, "int": int,
    "radians": math.radians, "degrees": math.degrees, "atan": math.atan, "tan": math.tan, "sin": math.sin,
    "cos": math.cos, "exp": math.exp, "log": math.log, "log10": math.log10, "asin": math.asin, "acos": math.acos,
    "atan2": math.atan2, "round": round, "fabs": math.fabs,
}
CONSTANTS = {"pi": math.pi, "e": math.e, "True": True, "False": False, "None": None}
MODULES = ("math", "numpy", "np", "utils", "yade", "yade.utils", "Mathr")
VECTORS = ("Vector3", "Vector3r", "Vector2", "Vector2r")
BINOPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
          ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow}


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


class Evaluator:
    """Names bound so far (name → value) and the evaluation of one expression against them."""

    def __init__(self):
        self.names: dict = {}
        self.attrs: dict = {}  # dotted names the script set literally (O.engines), readable again

    def __call__(self, node, depth: int = 0):
        if depth > 60:
            return Unknown("an expression nested too deep")
        try:
            return self._eval(node, depth + 1)
        except (ArithmeticError, ValueError, TypeError, OverflowError, IndexError, KeyError, RecursionError):
            return Unknown(f"line {getattr(node, 'lineno', '?')}: not evaluable")

    def _eval(self, node, depth):
        ev = lambda n: self(n, depth)  # noqa: E731
        if isinstance(node, ast.Constant):
            return node.value if isinstance(node.value, (int, float, str, bool, type(None))) else UNKNOWN
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            return Unknown(f"line {node.lineno}: {node.id} is not bound to a value the script gives literally")
        if isinstance(node, ast.Attribute):
            if _dotted(node) in self.attrs:
                return self.attrs[_dotted(node)]
            base = _dotted(node.value)
            if base in MODULES and node.attr in CONSTANTS:
                return CONSTANTS[node.attr]
            return Unknown(f"line {node.lineno}: {_dotted(node) or node.attr} is read at run time")
        if isinstance(node, ast.UnaryOp):
            v = ev(node.operand)
            if isinstance(node.op, ast.USub) and _number(v):
                return -v
            if isinstance(node.op, ast.UAdd) and _number(v):
                return v
            if isinstance(node.op, ast.Not) and isinstance(v, bool):
                return not v
            return v if isinstance(v, Unknown) else UNKNOWN
        if isinstance(node, ast.BinOp):
            a, b = ev(node.left), ev(node.right)
            op = BINOPS.get(type(node.op))
            if isinstance(a, Unknown):
                return a
            if isinstance(b, Unknown):
                return b
            if op is None:
                return UNKNOWN
            if _number(a) and _number(b):
                if op is operator.pow and (abs(b) > MAX_POWER or abs(a) > 1e150):
                    return UNKNOWN
                r = op(a, b)
                return r if _number(r) and math.isfinite(r) else Unknown(f"line {node.lineno}: not a finite number")
            if isinstance(a, tuple) and isinstance(b, tuple) and op is operator.add:
                return a + b
            if isinstance(a, tuple) and _number(b) and op in (operator.mul, operator.truediv) and \
                    all(_number(x) for x in a):
                return tuple(op(x, b) for x in a)
            if isinstance(b, tuple) and _number(a) and op is operator.mul and all(_number(x) for x in b):
                return tuple(a * x for x in b)
            return UNKNOWN
        if isinstance(node, (ast.Tuple, ast.List)):
            return tuple(ev(e) for e in node.elts)
        if isinstance(node, ast.Dict):
            if any(k is None for k in node.keys):
                return UNKNOWN
            keys = [ev(k) for k in node.keys]
            if not all(isinstance(k, str) for k in keys):
                return UNKNOWN
            return {k: ev(v) for k, v in zip(keys, node.values)}
        if isinstance(node, ast.Call):
            return self._call(node, depth)
        return Unknown(f"line {getattr(node, 'lineno', '?')}: a {type(node).__name__} is evaluated at run time")

    def _call(self, node, depth):
        name = _dotted(node.func) or ""
        short = name.rsplit(".", 1)[-1]
        args = [self(a, depth) for a in node.args if not isinstance(a, ast.Starred)]
        kw = {}
        for k in node.keywords:
            v = self(k.value, depth)
            if k.arg is None:
                if isinstance(v, dict):
                    kw.update(v)
                else:
                    kw["**"] = Unknown(f"line {node.lineno}: ** of a value read at run time")
            else:
                kw[k.arg] = v
        if any(isinstance(a, ast.Starred) for a in node.args):
            kw["*"] = Unknown(f"line {node.lineno}: * arguments")
        base = name.rsplit(".", 1)[0] if "." in name else ""
        if short in FUNCTIONS and (base in MODULES or base == "") and not kw:
            if all(_number(a) for a in args):
                r = FUNCTIONS[short](*args)
                return r if _number(r) and math.isfinite(r) else UNKNOWN
            return next((a for a in args if isinstance(a, Unknown)), UNKNOWN)
        if short in VECTORS and not kw:
            if len(args) == 1 and isinstance(args[0], tuple):
                return args[0]
            return tuple(args)
        if short in ("list", "tuple") and len(args) == 1 and isinstance(args[0], tuple):
            return args[0]
        if short and short[0].isupper() or short in YADE_FUNCTIONS:
            return Call(short, args, kw, node.lineno)
        return Unknown(f"line {node.lineno}: {name or 'a call'}() is computed at run time")


YADE_FUNCTIONS = frozenset({"sphere", "wall", "facet", "box", "facetBox", "facetCylinder", "PWaveTimeStep",
                            "makeCloud", "toSimulation", "regularHexa", "regularOrtho", "randomDensePack",
                            "defaultMaterial", "clump", "appendClumped", "ymport", "textExt", "gtsSurface2Facets"})


def _dotted(node) -> str | None:
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        base = _dotted(node.value)
        return f"{base}.{node.attr}" if base else None
    return None


def parse(text: str, name: str):
    """The script's syntax tree (SyntaxError → ScriptError naming the line)."""
    from ...inputs.script import ScriptError

    if len(text) > MAX_BYTES:
        raise ScriptError(f"{name}: larger than {MAX_BYTES:,} characters")
    try:
        return ast.parse(text, filename=name)
    except SyntaxError as exc:
        raise ScriptError(f"{name}:{exc.lineno}: not Python the audit can parse ({exc.msg})") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise ScriptError(f"{name}: not Python the audit can parse ({type(exc).__name__})") from None
