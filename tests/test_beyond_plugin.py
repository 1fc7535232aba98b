"""Adding a law to a slot beyond sliding touches that law's module only (issue 29 item 1): a rolling law written as
one module outside demcheck's source — its record with its traits, case keys, docs row and example, its compiled
force and its registration — is named in $DEMCHECK_LAW_PLUGINS and then is a ``contact.rolling`` id with its own
case keys, resolves to its record as a case's [contact] does, torques through the slot's dispatch, rolls to a stop in the reference's rolling
solve (against its closed form) and in the engines' stepped wall scheme, has its docs row, and is refused by every
engine's scenario mapping with a reason — with no other file edited."""

import pytest

from .helpers import with_plugin_law

TOY = '''
"""A toy rolling law: a torque of constant magnitude M0 against the rolling, whatever the load."""
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from demcheck import KERNEL_CACHE
from demcheck.laws.registry import Key, positive
from demcheck.laws.rolling_laws.slot import KERNELS, RollingSubModel, _rolling_part


@dataclass(frozen=True)
class FixedTorqueRolling(RollingSubModel):
    id: ClassVar[str] = "fixed_torque"
    title: ClassVar[str] = "a torque of fixed magnitude"
    stops: ClassVar[bool] = True
    keys: ClassVar[tuple] = (Key("m0", "torque magnitude M0 (N·m)", "must be > 0", positive),)
    formula: ClassVar[str] = "M = −M0 ŵt"
    source: ClassVar[str] = "tests/test_beyond_plugin.py"
    example: ClassVar[dict] = {"m0": 1e-6}
    m0: float = 0.0


@njit(cache=KERNEL_CACHE)
def fixed_torque_rolling_force(c, w, n, fn_abs, dt, history):
    wt = _rolling_part(w, n)
    wm = math.sqrt(wt[0] * wt[0] + wt[1] * wt[1] + wt[2] * wt[2])
    if wm == 0.0:
        return np.zeros(3), history
    return (-c[0] / wm) * wt, history


KERNELS.register(FixedTorqueRolling, fixed_torque_rolling_force)
'''

RUN = r'''
import json, math, tomllib
import numpy as np
from demcheck.case import from_dict
from demcheck.engines import scenario
from demcheck.laws import slots
from demcheck.laws.model import resolve
from demcheck.laws.rolling import rolling_torque
from demcheck.reference import beyond
from demcheck.resources import case_path

case = from_dict(tomllib.loads(case_path("suite/beyond-rolling.toml").read_text()))
p = case.particles[0]
# its record as a case's [contact] resolves it (a scenario runs the laws whose records name it, `scenarios`: none here)
rec = slots.record("rolling", slots.check_id("rolling", "Fixed_Torque"), {"m0": 2e-7}, resolve(case).pair,
                   (p.radius, 0.0))
out = {"ids": slots.law_ids("rolling"), "keys": [k.name for k in slots.KEYS[("rolling", "fixed_torque")]],
       "docs": list(slots.DOCS[("rolling", "fixed_torque")]), "record": type(rec).__name__, "m0": rec.m0}
m, _ = rolling_torque(rec, [0.0, 3.0, 0.0], [0.0, 0.0, -1.0], 1.0, 1e-6)
out["torque"] = m.tolist()
mass, r, v0, g = case.mass(0), p.radius, p.velocity[0], 9.81
out.update(mass=mass, r=r, v0=v0)
out["solve"] = beyond.rolling_on_plane(rec, mass, r, v0, g, t_end=1.0)["rolling_stop_time"]
k = 1.4 * mass * r * v0 / rec.m0  # the stop's scale: the wall run below lasts 1.25 of it
dt = 2e-6
kn = 1e6
delta = mass * g / kn
run = beyond.verlet_wall(r, mass, [0.0, 0.0, r - delta], [v0, 0.0, 0.0], [0.0, v0 / r, 0.0], [0.0, 0.0, -g],
                         [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], dt, int(1.25 * k / dt), 10,
                         normal=lambda d, rate: kn * d, tangential=(1e5, 0.0, 0.3), rolling=rec)
out["stepped"] = beyond.first_stop(run["t"], run["v"][:, 0])[0]
out["engines"] = scenario.law_mappings("rolling", "fixed_torque")
print(json.dumps(out))
'''


def test_a_rolling_law_in_one_module_runs_in_the_reference_and_is_refused_by_every_engine(tmp_path):
    out = with_plugin_law(tmp_path, "toy_rolling_law", TOY, RUN, timeout=900)
    assert "fixed_torque" in out["ids"] and out["keys"] == ["m0"] and out["record"] == "FixedTorqueRolling"
    assert out["docs"] == ["M = −M0 ŵt", "tests/test_beyond_plugin.py"] and out["m0"] == 2e-7
    assert out["torque"] == pytest.approx([0.0, -2e-7, 0.0], rel=1e-15)
    # a torque M0 against the roll of a sphere rolling without slip: (m + I/R²) v' = −M0/R, I = (2/5) m R², so it
    # stops at t = 1.4 m R v0 / M0 (a closed form written here)
    closed = 1.4 * out["mass"] * out["r"] * out["v0"] / 2e-7
    assert out["solve"] == pytest.approx(closed, rel=1e-9)
    assert out["stepped"] == pytest.approx(closed, rel=2e-3)  # the engines' scheme at dt = 2 µs, 10-step samples
    assert set(out["engines"]) >= {"lammps", "liggghts", "yade", "kratos"}
    for name, row in out["engines"].items():
        assert row["fidelity"] == "none" and row["reason"].strip(), (name, row)


NAMED = TOY.replace('    stops: ClassVar[bool] = True\n',
                    '    stops: ClassVar[bool] = True\n    scenarios: ClassVar[tuple] = ("rolling",)\n')

ACCEPT = r'''
import json, tomllib
from demcheck.case import from_dict
from demcheck.errors import ConfigError
from demcheck.resources import case_path

raw = tomllib.loads(case_path("suite/beyond-rolling.toml").read_text())
raw["contact"] = {**{k: v for k, v in raw["contact"].items() if k != "mu_r"}, "rolling": "fixed_torque", "m0": 2e-7}
out = {"rolling": from_dict(raw).contact.rolling}
raw["run"]["scenario"] = "incline"
try:
    from_dict(raw)
except ConfigError as exc:
    out["incline"] = [exc.key, exc.rule]
from demcheck.engines import scenario
out["engines"] = scenario.law_mappings("rolling", "fixed_torque")
print(json.dumps(out))
'''


def test_a_plugin_law_is_a_cases_law_in_the_scenarios_its_record_names(tmp_path):
    """The laws a scenario accepts are read off the records (``scenarios``): the toy law naming ``rolling`` is a
    case's law there, and the incline, which it does not name, lists the laws whose records do."""
    out = with_plugin_law(tmp_path, "toy_named_rolling_law", NAMED, ACCEPT, timeout=900)
    assert "scenarios" in NAMED and out["rolling"] == "fixed_torque"
    assert out["incline"] == ["contact.rolling", 'run.scenario = "incline" needs rolling = "constant_torque" or "epsd"']
    # a law the engines' writers do not know, in a scenario it names: refused with its own name, never read as
    # one they know (LIGGGHTS's writer took it for type A and crashed; LAMMPS and Yade called it viscous)
    for name, row in out["engines"].items():
        assert row["fidelity"] == "none" and "type B" not in row["reason"] and "viscous" not in row["reason"], (name, row)
    assert all("fixed_torque" in out["engines"][e]["reason"] for e in ("lammps", "liggghts", "yade")), out["engines"]


TWIST_TOY = '''
"""A toy twisting law with Marshall's field names but another law: a fixed torque against the twist."""
import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from demcheck import KERNEL_CACHE
from demcheck.laws.registry import Key, positive
from demcheck.laws.twisting_laws.slot import KERNELS, TwistingSubModel


@dataclass(frozen=True)
class FixedTwisting(TwistingSubModel):
    id: ClassVar[str] = "fixed_twist"
    title: ClassVar[str] = "a twisting torque of fixed magnitude"
    scenarios: ClassVar[tuple] = ("twist",)
    keys: ClassVar[tuple] = (Key("kt", "torque magnitude (N·m)", "must be > 0", positive),
                             Key("mu_t", "unused", default=0.0), Key("gamma_t", "unused", default=0.0))
    formula: ClassVar[str] = "Mt = −kt sign(φ̇)"
    source: ClassVar[str] = "tests/test_beyond_plugin.py"
    example: ClassVar[dict] = {"kt": 1e-6}
    kt: float = 0.0
    mu_t: float = 0.0
    gamma_t: float = 0.0


@njit(cache=KERNEL_CACHE)
def fixed_twist_twisting_force(c, w, n, fn_abs, a, dt, phi):
    rate = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    return (-c[0] * math.copysign(1.0, rate) if rate != 0.0 else 0.0), phi


KERNELS.register(FixedTwisting, fixed_twist_twisting_force)
'''

TWIST_MAP = r'''
import json
from demcheck.engines import scenario
print(json.dumps(scenario.law_mappings("twisting", "fixed_twist")))
'''


def test_a_twisting_law_the_engines_do_not_know_is_refused_with_its_name(tmp_path):
    """A plug-in twisting law naming the twist scenario, with Marshall's field names: every engine refuses it
    with its own name — LAMMPS's writer took any non-sds twisting law for Marshall (an AttributeError, or an EXACT
    `twisting marshall` of another law when the fields matched), Yade's refused it as Marshall."""
    rows = with_plugin_law(tmp_path, "toy_twisting_law", TWIST_TOY, TWIST_MAP, timeout=900)
    assert set(rows) >= {"lammps", "liggghts", "yade", "kratos"}
    for name, row in rows.items():
        assert row["fidelity"] == "none", (name, row)
        assert "marshall takes kt" not in row["reason"] and "Marshall's stiffness" not in row["reason"], (name, row)
    assert all("fixed_twist" in rows[e]["reason"] for e in ("lammps", "yade")), rows
