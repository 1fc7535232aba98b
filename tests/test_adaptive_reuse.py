"""Issue 33 item 3 (the adaptive 3-D collision's cost): the adaptive 3-D kernel does not evaluate its right-hand side
again at a state it has just evaluated it at. A Dormand–Prince step computes f at its end as its last stage (FSAL),
and a snap of the history onto its slip surface evaluates f at the snapped state: the event functions at that state,
its record, a riding load's truncation there and the next step's first stage read that f instead (rhs is pure).

The kernel's own source is run as plain Python (NUMBA_DISABLE_JIT=1, in a child process) on two suite variants — a
law whose slip is snapped onto its surface (DDt with spin) and Walton's riding load — with every rhs call logged by
the bits of its state (y, aux) and the chain of kernel functions that made it. The expected number of such repeats
is 0 by the method's definition, not a count taken from the code. Repeats that remain, and are not what this tests:
a DP5 stage at a state an earlier step's stage reached (the step to a located event retakes the location's last
trial), and the fixes after an event (_settle, the stick/slip switch, the record of the event's state)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

VARIANTS = (("oblique-ddt", 5.0, 1500.0), ("oblique-walton", 30.0, 0.0))

CHILD = r'''
import json, linecache, sys, tomllib
from demcheck import case as C
from demcheck.laws.model import resolve
from demcheck.reference import adaptive3d as A, collision3d
from demcheck.resources import case_path

assert not hasattr(A.adaptive_3d, "py_func"), "needs NUMBA_DISABLE_JIT=1"
HERE = A.__file__


def kernel_args(name, angle, spin):
    raw = tomllib.loads(case_path(f"suite/{name}").read_text())
    raw.pop("variants")
    raw["impact"].update(angle=angle, spin=spin)
    case = C.from_dict(raw)
    got = []

    class Taken(Exception):
        pass

    def take(*a):  # the arguments collide() hands the kernel, the kernel not run
        got.append(a)
        raise Taken

    orig = collision3d.adaptive3d.adaptive_3d
    collision3d.adaptive3d.adaptive_3d = take
    try:
        collision3d.collide(case, resolve(case), "adaptive")
    except Taken:
        pass
    finally:
        collision3d.adaptive3d.adaptive_3d = orig
    return got[0]


def chain():
    """The kernel's functions from rhs's caller out to adaptive_3d (that one with its line's text)."""
    out, f = [], sys._getframe(2)
    while f is not None:
        if f.f_code.co_filename == HERE:
            if f.f_code.co_name == "adaptive_3d":
                out.append("adaptive_3d: " + linecache.getline(HERE, f.f_lineno).strip())
                break
            out.append(f.f_code.co_name)
        f = f.f_back
    return out


result = {}
orig = A.rhs
for name, angle, spin in json.loads(sys.argv[1]):
    seen, repeats, calls = {}, [], [0]

    def rhs(y, aux, *rest):
        key = y.tobytes() + aux.tobytes()
        c = chain()
        calls[0] += 1
        if key in seen:
            repeats.append((seen[key], c))
        else:
            seen[key] = c
        return orig(y, aux, *rest)

    A.rhs = rhs
    try:
        out = A.adaptive_3d(*kernel_args(name, angle, spin))
    finally:
        A.rhs = orig
    result[name] = {"status": int(out[0]), "points": int(out[1]), "calls": calls[0], "repeats": repeats}
print(json.dumps(result))
'''


def _redundant(first: list[str], again: list[str]) -> bool:
    """Whether a repeated evaluation is one the kernel has no reason to make: f where a step just computed it (its
    last stage) or a snap did, read again by the event functions, a record, a truncation, a snap or a first stage."""
    inner = again[0]
    if inner in ("_event_values", "_event_value", "_event_value_with"):
        return True  # the event functions at a step's (or a trial step's) end: that step's last stage is f there
    if inner.startswith("adaptive_3d: ") and inner.endswith("k1)"):
        return True  # a step's first stage where f is known
    at_step_end = first[0] == "_dp5_from" and len(first) == 2  # the driver's own step (not a trial, not to an event)
    return (at_step_end or first[0] == "_onto_surface") and inner in ("_record", "_ride_truncate", "_onto_surface")


def test_no_rhs_is_evaluated_again_where_a_step_or_a_snap_has_just_evaluated_it():
    src = Path(__file__).resolve().parents[1] / "src"
    env = dict(os.environ, NUMBA_DISABLE_JIT="1",
               PYTHONPATH=os.pathsep.join(p for p in (os.environ.get("PYTHONPATH"), str(src)) if p))
    p = subprocess.run([sys.executable, "-c", CHILD, json.dumps(VARIANTS)], env=env, capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    result = json.loads(p.stdout.strip().splitlines()[-1])
    for name, r in result.items():
        assert r["status"] == 0 and r["points"] > 100 and r["calls"] > 1000, (name, {k: r[k] for k in r
                                                                                    if k != "repeats"})
        bad = [(a, b) for a, b in r["repeats"] if _redundant(a, b)]
        assert not bad, (name, len(bad), bad[:5])
