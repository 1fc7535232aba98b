"""Every body's final velocity and angular velocity in every result (collide --json "final"), whatever solved
it. Chung & Ooi's Test 7 — identical spheres meeting head-on while counter-spinning at ±ω0 about z — has no
slip at the contact (each contact point moves at R ω0 ŷ), so no tangential force acts and ω' = ω0 exactly:
with a friction law (the 3-D solver) and without one (the 1-D solver, which passes the spins through)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from demcheck import case as C
from demcheck.reference.collision import collide

TEST7 = """
name = "chung-ooi-test-7"
[materials.al]
density = 2699.0
youngs_modulus = 7.0e10
poisson_ratio = 0.33
restitution = 0.5
friction = 0.4
[[particles]]
material = "al"
radius = 0.1
position = [-0.1001, 0.0, 0.0]
velocity = [0.2, 0.0, 0.0]
angular_velocity = [0.0, 0.0, {w}]
[[particles]]
material = "al"
radius = 0.1
position = [0.1001, 0.0, 0.0]
velocity = [-0.2, 0.0, 0.0]
angular_velocity = [0.0, 0.0, {mw}]
[contact]
normal = "lsd"
stiffness_method = "energy"
tangential = "{tangential}"
"""


@pytest.mark.parametrize("tangential", ["none", "spring_sliding", "sliding"])
def test_counter_spinning_spheres_keep_their_spin(tangential):
    w0 = 3.0
    res = collide(C.loads(TEST7.format(w=w0, mw=-w0, tangential=tangential)))
    assert res.ok
    final = res.summary()["final"]
    assert [b["id"] for b in final] == [0, 1]
    assert final[0]["angular_velocity"] == [0.0, 0.0, w0] and final[1]["angular_velocity"] == [0.0, 0.0, -w0]
    # the rebound: e = 0.5 of the 0.4 m/s approach, shared by the equal masses
    assert final[0]["velocity"][0] == pytest.approx(-0.1, abs=1e-9)
    assert final[1]["velocity"][0] == pytest.approx(0.1, abs=1e-9)


def test_collide_json_reports_the_final_state(tmp_path):
    path = tmp_path / "t7.toml"
    path.write_text(TEST7.format(w=2.0, mw=-2.0, tangential="none"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(path), "--json"], capture_output=True,
                       text=True)
    assert p.returncode == 0, p.stderr
    final = json.loads(p.stdout)["final"]
    assert [b["angular_velocity"][2] for b in final] == [2.0, -2.0]
