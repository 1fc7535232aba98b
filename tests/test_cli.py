"""The command line, run as a user runs it (a subprocess)."""

import json
import subprocess
import sys

import pytest

from .conftest import CASES, ROOT


def demcheck(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def test_collide_json_has_metrics_model_params_method_and_dt():
    p = demcheck("collide", CASES / "glass-pair.toml", "--set", "contact.normal=lsd",
                 "--set", "contact.stiffness_method=energy", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["model"] == {"normal": "lsd", "tangential": "none", "limit_force": False}
    assert out["method"] == "adaptive" and out["rtol"] == 1e-13
    assert out["params"]["kn"] == pytest.approx(2.0166e6, rel=1e-4)
    assert set(out["metrics"]) >= {"restitution", "contact_time", "force_contact_time", "max_overlap",
                                   "peak_force", "energy_dissipated"}
    assert out["metrics"]["restitution"] == pytest.approx(0.97, rel=1e-9)


def test_collide_verlet_plot_and_csv(tmp_path):
    png, csv = tmp_path / "f.png", tmp_path / "c.csv"
    p = demcheck("collide", CASES / "hls-constant-pair.toml", "--method", "verlet", "--dt", "5e-8",
                 "--plot", png, "--csv", csv, "--json")
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["dt"] == 5e-8
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    header = csv.read_text().splitlines()[0]
    assert header.startswith("t,delta,delta_dot,fn,")


def test_models_json_lists_every_model():
    p = demcheck("models", "--json")
    assert p.returncode == 0, p.stderr
    ids = {(m["slot"], m["id"]) for m in json.loads(p.stdout)["models"]}
    assert {("normal", i) for i in ("lsd", "hertz", "bshp", "kk", "tti", "hls")} <= ids


@pytest.mark.parametrize("args,needle", [
    (["--set", "contact.normal=hertzz"], "contact.normal = 'hertzz': unknown normal model; did you mean 'hertz'?"),
    (["--set", "materials.glass.restitution=1.2"], "materials.glass.restitution = 1.2: must be in (0, 1]"),
    (["--dt", "-1"], "--dt = -1.0: must be > 0"),
])
def test_bad_input_is_one_line_and_exit_2(args, needle):
    p = demcheck("collide", CASES / "glass-pair.toml", *args)
    assert p.returncode == 2
    assert p.stdout == ""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], p.stderr


def test_missing_case_file_exit_2():
    p = demcheck("collide", "no/such.toml")
    assert p.returncode == 2 and "no such case file" in p.stderr


def test_verify_writes_reports_atomically(tmp_path):
    p = demcheck("verify", CASES / "glass-pair.toml", CASES / "hls-variable-wall.toml", "--report", tmp_path, "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["failed"] == 0 and not out["partial"]
    latest = tmp_path / "latest"
    assert json.loads((latest / "results.json").read_text())["run_id"] == out["run_id"]
    assert "glass-pair" in (latest / "report.md").read_text()
    assert not list(tmp_path.rglob("*.tmp"))


def test_sweep_over_incidence_angle_is_one_line(tmp_path):
    csv = tmp_path / "s.csv"
    p = demcheck("sweep", CASES / "oblique-lsd-wall.toml", "--vary", "impact.angle=10:80:3", "--json",
                 "--csv", csv, "--plot", tmp_path / "s.png")
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)["rows"]
    assert [r["impact.angle"] for r in rows] == [10.0, 45.0, 80.0]
    assert all(r["status"] == "ok" for r in rows)
    # a wall impact under LSDn keeps its restitution at every angle; grazing keeps most tangential speed
    assert all(abs(r["restitution"] - 0.9) < 1e-9 for r in rows)
    assert rows[2]["tangential_restitution"] > rows[1]["tangential_restitution"]
    assert (tmp_path / "s.png").read_bytes()[:4] == b"\x89PNG"
    assert csv.read_text().splitlines()[0].startswith("impact.angle,restitution")


def test_sweep_grid_and_bad_vary():
    p = demcheck("sweep", CASES / "glass-pair.toml", "--vary", "impact.speed=0.5,2", "--vary",
                 "contact.normal=hertz,tti", "--json")
    assert p.returncode == 0, p.stderr
    assert len(json.loads(p.stdout)["rows"]) == 4
    bad = demcheck("sweep", CASES / "glass-pair.toml", "--vary", "impact.speed=1:2:x")
    assert bad.returncode == 2 and "--vary impact.speed = '1:2:x': START and STOP must be numbers" in bad.stderr


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_collide_all_sources_side_by_side_in_json():
    p = demcheck("collide", CASES / "oblique-viscous-sliding-pair.toml", "--engine", "all", "--json")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert {"reference", "lammps", "liggghts"} <= set(out)  # and every other registered engine (kratos, …)
    assert "22 Jul 2025" in out["lammps"]["engine_version"]
    assert out["liggghts"]["engine_version"].startswith("LIGGGHTS-PUBLIC 3.8.0")
    assert out["lammps"]["params"]["mapping"] == "exact"
    # the same collision: the engines at the case's dt against the converged reference
    for src in ("lammps", "liggghts"):
        assert out[src]["metrics"]["restitution"] == pytest.approx(out["reference"]["metrics"]["restitution"],
                                                                   rel=1e-2)


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_collide_all_prints_a_table_and_says_what_is_not_expressible():
    p = demcheck("collide", CASES / "hls-constant-pair.toml", "--engine", "all")
    assert p.returncode == 0, p.stderr
    assert "lammps: skipped — lammps cannot express this model" in " ".join(p.stdout.split())
    assert "liggghts (LIGGGHTS-PUBLIC 3.8.0)" in " ".join(p.stdout.split()) or "LIGGGHTS-PUBLIC" in p.stdout


def test_deck_to_stdout_and_to_a_file(tmp_path):
    p = demcheck("deck", CASES / "oblique-lsd-wall.toml", "--engine", "lammps")
    assert p.returncode == 0, p.stderr
    assert "pair_style granular" in p.stdout and "fix wall all wall/gran granular" in p.stdout
    assert "# mapping fidelity: approximate" in p.stdout
    out = tmp_path / "in.oblique"
    p = demcheck("deck", CASES / "oblique-lsd-wall.toml", "--engine", "liggghts", "-o", out)
    assert p.returncode == 0, p.stderr
    assert "read_data data.lmp" in out.read_text()
    assert (tmp_path / "data.lmp").read_text().splitlines()[0].startswith("# demcheck: case oblique-lsd-wall")


def test_deck_bad_engine_is_a_usage_error():
    p = demcheck("deck", CASES / "glass-pair.toml", "--engine", "gromacs")
    assert p.returncode == 2 and "gromacs" in p.stderr


def test_models_shows_the_engine_mapping():
    p = demcheck("models", "--json")
    assert p.returncode == 0, p.stderr
    rows = {(r["slot"], r["id"]): r for r in json.loads(p.stdout)["models"]}
    assert rows[("normal", "hls")]["engines"]["lammps"]["fidelity"] == "none"
    assert rows[("normal", "hls")]["engines"]["liggghts"]["fidelity"] == "exact"
    assert rows[("tangential", "ddt")]["engines"]["lammps"]["config"].endswith("tangential mindlin")


# ----------------------------------------------------------------------------- numbers on the command line


def _one_line_exit_2(p, needle):
    assert p.returncode == 2, (p.returncode, p.stderr[-2000:])
    assert p.stdout == ""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("demcheck: error: ") and needle in lines[0], p.stderr[-2000:]


GLASS = CASES / "glass-pair.toml"
PACKING = CASES / "packing" / "column-lsd.toml"


@pytest.mark.parametrize("args,needle", [
    (["collide", GLASS, "--dt", "inf"], "--dt = inf: must be a finite number > 0 (s)"),
    (["collide", GLASS, "--dt", "nan"], "--dt = nan: must be a finite number > 0 (s)"),
    (["collide", GLASS, "--dt", "fast"], "--dt = 'fast': must be a finite number > 0 (s)"),
    (["collide", GLASS, "--engine", "lammps", "--timeout", "nan"], "--timeout = nan: must be a finite number > 0"),
    (["collide", GLASS, "--timeout", "0"], "--timeout = 0.0: must be > 0 and <= 1e+06 (s)"),
    (["collide", GLASS, "--timeout", "1e300"], "--timeout = 1e+300: must be > 0 and <= 1e+06 (s)"),
    (["deck", GLASS, "--engine", "lammps", "--dt", "-inf"], "--dt = -inf: must be a finite number > 0 (s)"),
    (["sweep", GLASS, "--vary", "impact.speed=1,2", "--dt", "nan"], "--dt = nan: must be a finite number"),
    (["verify", GLASS, "--engines", "none", "--timeout", "nan"], "--timeout = nan: must be a finite number"),
    (["verify", GLASS, "--engines", "none", "--jobs", "0"], "--jobs = 0: must be >= 1 and <= 256"),
    (["verify", GLASS, "--engines", "none", "-j", "1.5"], "--jobs = '1.5': must be an integer >= 1 and <= 256"),
    (["pack", PACKING, "--duration", "inf"], "--duration = inf: must be a finite number > 0 (s)"),
    (["pack", PACKING, "--engine", "lammps", "--mpi", "0"], "--mpi = 0: must be >= 1 and <= 256 (MPI ranks)"),
    (["pack", PACKING, "--engine", "lammps", "--timeout", "nan"], "--timeout = nan: must be a finite number"),
    (["dt", GLASS, "--target", "nan"], "--target = nan: must be a finite number > 0 and < 1"),
    (["dt", GLASS, "--target", "1"], "--target = 1.0: must be > 0 and < 1"),
    (["bench", GLASS, "--steps", "10,inf"], "--steps = inf: must be a finite number >= 1 and <= 1e+06"),
    (["bench", GLASS, "--steps", "10,x"], "--steps = 'x': must be a finite number >= 1"),
    (["bench", GLASS, "--batch", "0"], "--batch = 0: must be >= 1 and <= 10000"),
])
def test_every_numeric_option_is_finite_and_in_range(args, needle, tmp_path):
    _one_line_exit_2(demcheck(*args, cwd=tmp_path), needle)
    assert list(tmp_path.iterdir()) == []  # refused before any work: no report, no deck, no cache


# ----------------------------------------------------------------------------- output paths, checked up front


@pytest.mark.parametrize("args,needle", [
    (["verify", GLASS, "--engines", "none", "--report", "{file}/reports"],
     "--report = '{file}/reports': {file} is a file"),
    (["verify", GLASS, "--engines", "none", "--report", "{file}"], "--report = '{file}': is a file, not a directory"),
    (["verify", GLASS, "--engines", "none", "--report", "/sys/demcheck-reports"],
     "--report = '/sys/demcheck-reports': cannot write in /sys (Permission denied)"),
    (["verify", GLASS, "--engines", "none", "--junit", "{file}/j.xml"], "--junit = '{file}/j.xml': {file} is a file"),
    (["verify", GLASS, "--engines", "none", "--junit", "{dir}"], "--junit = '{dir}': is a directory, not a file"),
    (["deck", GLASS, "--engine", "lammps", "-o", "{file}/in.deck"], "--output = '{file}/in.deck': {file} is a file"),
    (["collide", GLASS, "--plot", "{file}/p.png"], "--plot = '{file}/p.png': {file} is a file"),
    (["collide", GLASS, "--csv", "{dir}"], "--csv = '{dir}': is a directory, not a file"),
    (["sweep", GLASS, "--vary", "impact.speed=1,2", "--csv", "{file}/s.csv"],
     "--csv = '{file}/s.csv': {file} is a file"),
    (["sweep", GLASS, "--vary", "impact.speed=1,2", "--plot", "{file}/a/s.png"],
     "--plot = '{file}/a/s.png': {file} is a file"),
    (["pack", PACKING, "--csv", "{file}/state"], "--csv = '{file}/state': {file} is a file"),
    (["bench", GLASS, "--report", "{file}/r"], "--report = '{file}/r': {file} is a file"),
    (["stress", GLASS, "--report", "{file}/r"], "--report = '{file}/r': {file} is a file"),
])
def test_output_paths_are_checked_before_any_work(args, needle, tmp_path):
    file, out = tmp_path / "a-file", tmp_path / "work"
    file.write_text("x")
    out.mkdir()
    fill = {"file": file, "dir": tmp_path}
    p = demcheck(*[str(a).format(**fill) for a in args], cwd=out)
    _one_line_exit_2(p, needle.format(**fill))
    assert list(out.iterdir()) == []


def test_a_cache_that_is_a_file_is_refused_up_front(tmp_path):
    import os

    cache = tmp_path / "cache"
    cache.write_text("not a directory")
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(GLASS), "--engines", "none", "--report",
                        str(tmp_path / "r")], capture_output=True, text=True, cwd=tmp_path, timeout=300,
                       env=dict(os.environ, DEMCHECK_CACHE=str(cache)))
    _one_line_exit_2(p, f"DEMCHECK_CACHE = '{cache}': is a file, not a directory")
    assert not (tmp_path / "r").exists()


# ----------------------------------------------------------------------------- sweep: every point checked first


@pytest.mark.parametrize("vary,needle", [
    ("impact.angle=0-80", "--vary impact.angle = '0-80': '0-80' is not a value; must be KEY=START:STOP:N"),
    ("impact.angle=0:80", "--vary impact.angle = '0:80': must be KEY=START:STOP:N"),
    ("impact.angle=1:2:0", "--vary impact.angle = '1:2:0': N must be in [1, 10000]"),
    ("impact.angle=1:2:100000000", "--vary impact.angle = '1:2:100000000': N must be in [1, 10000]"),
    ("impact.angel=10,20", "impact.angel = 10: unknown key; did you mean 'angle'?"),
    ("impact.angle=10,95", "impact.angle = 95.0: must be in [0, 90)"),
])
def test_sweep_refuses_a_bad_key_or_value_before_solving(vary, needle):
    _one_line_exit_2(demcheck("sweep", CASES / "oblique-lsd-wall.toml", "--vary", vary), needle)


# ----------------------------------------------------------------------------- files derived from an option


def _tree(root):
    """Every path under ``root`` (files, directories and links), relative: what a refused command must leave."""
    return sorted(str(p.relative_to(root)) for p in root.rglob("*"))


@pytest.mark.parametrize("command", [
    ["verify", GLASS, "--engines", "none"],
    ["bench", GLASS, "--engines", "none", "--steps", "10"],
    ["stress", GLASS, "--engines", "none", "--only", "speed"],
])
@pytest.mark.parametrize("kind", ["directory", "file"])
def test_a_latest_that_is_not_demcheck_s_symlink_is_refused_up_front(command, kind, tmp_path):
    """<report>/latest is the symlink demcheck moves to each new run: a real directory or file there is refused
    before any case runs (it was an IsADirectoryError after every case, with a stray .latest.PID left)."""
    reports = tmp_path / "rep"
    reports.mkdir()
    link = {"verify": "latest"}.get(command[0], f"latest-{command[0]}")  # bench and stress keep links of their own
    if kind == "directory":
        (reports / link).mkdir()
        (reports / link / "mine.txt").write_text("keep")
    else:
        (reports / link).write_text("keep")
    before = _tree(reports)
    p = demcheck(*command, "--report", reports, cwd=tmp_path)
    _one_line_exit_2(p, f"--report = '{reports}': {reports / link} is a {kind}, not the symlink demcheck "
                        "moves to each new run")
    assert _tree(reports) == before


def test_latest_moves_when_it_is_demcheck_s_symlink(tmp_path):
    reports = tmp_path / "rep"
    p = demcheck("verify", GLASS, "--engines", "none", "--report", reports, "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    first = (reports / "latest").resolve()
    p = demcheck("verify", GLASS, "--engines", "none", "--report", reports, "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    assert (reports / "latest").is_symlink() and (reports / "latest").resolve() != first
    assert not [x for x in reports.iterdir() if x.name.startswith(".latest")]


def test_a_latest_link_that_cannot_be_moved_leaves_no_stray_link(tmp_path):
    """Should the place change under a run (the up-front check passed), the error leaves no .latest.* behind."""
    from demcheck.comparisons.report import link_latest

    (tmp_path / "run-1").mkdir()
    (tmp_path / "latest").mkdir()
    with pytest.raises(OSError):
        link_latest(tmp_path, tmp_path / "run-1")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["latest", "run-1"]


@pytest.mark.parametrize("name", ["particles.csv", "contacts.csv"])
def test_pack_checks_the_files_of_its_csv_directory_up_front(name, tmp_path):
    out = tmp_path / "pc"
    (out / name).mkdir(parents=True)
    p = demcheck("pack", PACKING, "--csv", out, cwd=tmp_path)
    _one_line_exit_2(p, f"--csv = '{out}': {out / name} is a directory, not a file")
    assert _tree(out) == [name]  # neither table written


@pytest.mark.parametrize("case,engine", [(GLASS, "liggghts"), (PACKING, "lammps"), (PACKING, "liggghts")])
def test_deck_checks_the_files_it_writes_beside_the_deck_up_front(case, engine, tmp_path):
    out = tmp_path / "dk"
    (out / "data.lmp").mkdir(parents=True)
    p = demcheck("deck", case, "--engine", engine, "-o", out / "deck.in", cwd=tmp_path)
    _one_line_exit_2(p, f"--output = '{out / 'deck.in'}': {out / 'data.lmp'} is a directory, not a file")
    assert _tree(out) == ["data.lmp"]  # the deck was not written without its data file


def test_models_is_a_compact_table_and_one_model_in_full():
    """One line a model that fits 80 columns (plain text when piped, as here); `models ID` (or an alias) in
    full; an unknown id is one line with the nearest, exit 2."""
    p = demcheck("models")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    # one line a model (26 of the seeds' slots, 11 beyond sliding), a header and a legend
    assert len(lines) < 45 and max(len(line) for line in lines) <= 80
    assert any(line.split()[:2] == ["normal", "hls"] for line in lines)
    full = demcheck("models", "TTIn")
    assert full.returncode == 0 and "formula:" in full.stdout and "LAMMPS 22Jul2025: exact" in full.stdout
    bad = demcheck("models", "ttx")
    assert bad.returncode == 2 and bad.stderr.strip().count("\n") == 0 and "did you mean 'tti'" in bad.stderr


def test_a_usage_error_is_one_line_with_exit_2():
    """click's own errors (an unknown option or command, a value that looks like an option) are one line on
    stderr naming what is wrong and where help is, exit 2 — as every other bad input, never click's usage block."""
    import subprocess
    import sys

    for args, says in ((["models", "--engine", "lammps", "-1"], "No such option '-1'"),
                       (["frobnicate"], "No such command 'frobnicate'"),
                       (["verify", "--no-such-flag"], "No such option '--no-such-flag'")):
        p = subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, timeout=120)
        assert p.returncode == 2, (args, p.stderr)
        lines = p.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("demcheck: error: ") and says in lines[0], (args, p.stderr)
        assert "--help" in lines[0] and p.stdout == ""


def test_pack_refuses_a_duration_shorter_than_the_first_fall():
    """`pack --duration 1e-300` reported the starting lattice as a packing, exit 0 (issue 32): a run shorter than the
    lowest body's free fall to the floor, √(2h/g), ends before any contact with it forms. The column's lowest body
    starts 1 µm above its floor (g = 9.81 m/s²): 4.52e-4 s."""
    import math
    import subprocess
    import sys

    fall = f"{math.sqrt(2 * 1e-6 / 9.81):.3g}"
    for args, key in ((["pack", "column-lsd", "--duration", "1e-300"], "--duration = 1e-300"),
                      (["pack", "column-lsd", "--duration", "4.4e-4"], "--duration = 0.00044"),
                      (["pack", "column-lsd", "--set", "packing.duration=1e-5"], "packing.duration = 1e-05")):
        p = subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, timeout=300)
        assert p.returncode == 2 and p.stdout == "", (args, p.stderr)
        line, = p.stderr.strip().splitlines()
        assert line.startswith(f"demcheck: error: {key}: must be at least the fall") and f"= {fall} s" in line, line
