"""A bounded, line-based reader of Kratos .mdpa files for ``demcheck audit`` (nothing in them is executed).

It keeps what a DEM project's contact probes need: nodes (id → x, y, z), each element block's type with its
elements' nodes, condition blocks (walls), the nodal data RADIUS and VELOCITY_X/Y/Z, Properties blocks, and
sub-model parts (nested, by their full dotted name) with their nodes, elements, conditions and data
(``VELOCITY [3] (a, b, c)``, ``RADIUS``, …). Comments (``//`` to the end of a line) are dropped. A file of more
than :data:`MAX_LINES` lines or a line of more than :data:`MAX_LINE_CHARS` characters is refused.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from ...inputs.script import ScriptError

MAX_LINES = 5_000_000
MAX_LINE_CHARS = 10_000
VECTOR = re.compile(r"\[\s*3\s*\]\s*\(\s*([^,()]+),\s*([^,()]+),\s*([^,()]+)\)")


@dataclass
class Part:
    name: str
    nodes: list = field(default_factory=list)
    elements: list = field(default_factory=list)
    conditions: list = field(default_factory=list)
    data: dict = field(default_factory=dict)  # KEY → text value (a [3] vector kept as a tuple of floats)


@dataclass
class Mdpa:
    path: Path
    nodes: dict = field(default_factory=dict)  # id → (x, y, z)
    elements: dict = field(default_factory=dict)  # element id → (type, properties id, [node ids])
    conditions: dict = field(default_factory=dict)  # condition id → type
    nodal: dict = field(default_factory=dict)  # VARIABLE → {node id: value}
    properties: dict = field(default_factory=dict)  # id → {KEY: text}
    parts: dict = field(default_factory=dict)  # dotted name → Part


def _float(text: str, where: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise ScriptError(f"{where}: {text[:40]!r} is not a number") from None
    if not math.isfinite(x):
        raise ScriptError(f"{where}: {text[:40]!r} is not a finite number")
    return x


def _int(text: str, where: str) -> int:
    if not re.fullmatch(r"[0-9]{1,12}", text):
        raise ScriptError(f"{where}: {text[:40]!r} is not an id (a whole number ≥ 0)")
    return int(text)


def read(path: Path) -> Mdpa:
    """The .mdpa at ``path`` (ScriptError, exit 2, for a line it cannot read)."""
    out = Mdpa(path)
    stack: list[tuple[str, str]] = []  # (block kind, its argument)
    parts: list[Part] = []
    try:
        stream = path.open(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise ScriptError(f"{path.name}: cannot be read ({exc.strerror})") from None
    with stream:
        for no, raw in enumerate(stream, 1):
            if no > MAX_LINES:
                raise ScriptError(f"{path.name}: more than {MAX_LINES:,} lines")
            if len(raw) > MAX_LINE_CHARS:
                raise ScriptError(f"{path.name}:{no}: a line of more than {MAX_LINE_CHARS:,} characters")
            line = raw.split("//", 1)[0].strip()
            if not line:
                continue
            where = f"{path.name}:{no}"
            words = line.split()
            if words[0] == "Begin" and len(words) >= 2:
                kind, arg = words[1], " ".join(words[2:])
                stack.append((kind, arg))
                if kind == "SubModelPart":
                    prefix = parts[-1].name + "." if parts else ""
                    parts.append(out.parts.setdefault(prefix + arg, Part(prefix + arg)))
                elif kind == "Properties":
                    out.properties.setdefault(_int(words[2] if len(words) > 2 else "", where), {})
                continue
            if words[0] == "End":
                if not stack:
                    raise ScriptError(f"{where}: 'End' without a 'Begin'")
                kind, _ = stack.pop()
                if kind == "SubModelPart" and parts:
                    parts.pop()
                continue
            if stack:
                _line(out, stack[-1], parts, words, line, where)
    return out


def _line(out: Mdpa, block: tuple[str, str], parts: list, words: list, line: str, where: str) -> None:
    kind, arg = block
    if kind == "Nodes" and len(words) >= 4:
        out.nodes[_int(words[0], where)] = tuple(_float(w, where) for w in words[1:4])
    elif kind == "Elements" and len(words) >= 3:
        out.elements[_int(words[0], where)] = (arg, _int(words[1], where), [_int(w, where) for w in words[2:]])
    elif kind == "Conditions" and words:
        out.conditions[_int(words[0], where)] = arg
    elif kind == "NodalData" and len(words) >= 3:
        out.nodal.setdefault(arg.split()[0] if arg else "", {})[_int(words[0], where)] = _float(words[-1], where)
    elif kind == "Properties" and len(words) >= 2:
        out.properties.setdefault(_int(arg.split()[0] if arg else "", where), {})[words[0]] = " ".join(words[1:])
    elif kind == "SubModelPartNodes" and parts:
        parts[-1].nodes += [_int(w, where) for w in words]
    elif kind == "SubModelPartElements" and parts:
        parts[-1].elements += [_int(w, where) for w in words]
    elif kind == "SubModelPartConditions" and parts:
        parts[-1].conditions += [_int(w, where) for w in words]
    elif kind == "SubModelPartData" and parts and len(words) >= 2:
        rest = line.split(None, 1)[1]
        m = VECTOR.fullmatch(rest.strip())
        parts[-1].data[words[0]] = tuple(_float(g, where) for g in m.groups()) if m else rest.strip()
