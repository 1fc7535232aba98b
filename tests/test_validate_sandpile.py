"""`validate`'s heap benchmarks: Ai, Chen, Rotter & Ooi (2011)'s 2D sandpile, its height against time under each
of the three rolling-resistance models, as digitised by Lethe (data/benchmarks/ai2011-sandpile-*.dat). The judge
is tested on curves built from the paper's own points (the curve itself, the curve scaled by a known factor, a run
that fails or falls short) — never on numbers of demcheck's own solver; the sandpile solver is replaced by a stand-in
wherever a run is needed, so these tests hold whether or not reference/sandpile.py is in the build."""

import math
import sys
import types

import numpy as np
import pytest

from demcheck.comparisons import validate as v
from demcheck.errors import ConfigError

NAMES = ("ai2011-sandpile-constant", "ai2011-sandpile-viscous", "ai2011-sandpile-epsd")
# the Lethe files' point counts, first and last lines (examples/dem/2d-sandpile-formation/data/reference/
# extraction_model_{constant,viscous,epsd}.csv at the commits the data files name), read off those files
SOURCE = {
    "constant": (28, (9.627, 0.24186), (48.3889, 0.219225)),
    "viscous": (37, (9.804, 0.18704), (49.4325, 0.187146)),
    "epsd": (34, (9.1248, 0.272013), (49.5112, 0.272029)),
}


def bench(name):
    return v.by_name(name)[0]


def curve(b):
    return v.read_curve(b.curves[0].file, b.curves[0].key)


def test_the_three_curves_are_in_the_catalogue_as_opt_in_heap_benchmarks():
    for name in NAMES:
        b = bench(name)
        assert b.kind == v.HEAP and b.opt_in and b.case == f"optin/{name}"
        assert b.quantities == (v.HEAP_QUANTITY,) and len(b.curves) == 1 and b.curves[0].tolerance == 0.10
        assert "Lethe" in b.curves[0].why and "15%" in b.curves[0].why  # the tolerance says what it stands for
    assert not set(NAMES) & {b.name for b in v.by_name(None)}  # a run naming no benchmark leaves them out
    assert not set(NAMES) & {b.name for b in v.BENCHMARKS} and [b.name for b in v.HEAPS] == list(NAMES)
    assert not set(NAMES) & set(v.QUICK)
    assert all(v.files_of(bench(n), v.DATA, quick=True) == [] for n in NAMES)  # and --quick


@pytest.mark.parametrize("key", sorted(SOURCE))
def test_the_data_files_carry_the_digitised_points_unchanged_with_their_provenance(key):
    b = bench(f"ai2011-sandpile-{key}")
    pts = curve(b)
    n, first, last = SOURCE[key]
    assert pts.shape == (n, 2)
    assert tuple(pts[0]) == first and tuple(pts[-1]) == last  # exact: the same decimal strings
    assert np.all(np.diff(pts[:, 0]) > 0)
    text = (v.DATA / b.curves[0].file).read_text()
    for needed in ("Powder Technology 206:269", "chaos-polymtl/lethe", f"extraction_model_{key}.csv",
                   "Apache-2.0 WITH LLVM-exception OR LGPL-2.1-or-later", "WebPlotDigitizer"):
        assert needed in text, needed
    data_lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
    assert all(ln.count(",") == 1 for ln in data_lines)  # the source's own "t,h" lines


@pytest.mark.parametrize("name", NAMES)
def test_the_curve_itself_meets_it_exactly(name):
    b = bench(name)
    pts = curve(b)
    check, series = v.judge_heap(b, "f", pts[:, 0], pts[:, 1])
    assert check.deviation == 0.0 and check.verdict == v.MEETS and check.points == len(pts)
    assert series["paper"] == pts.tolist() and series["sources"]["reference"]["y"] == pts[:, 1].tolist()


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("shift", [-0.15, -0.05, 0.03, 0.0999, 0.1001, 0.2])
def test_a_curve_scaled_by_a_known_fraction_is_off_by_that_fraction(name, shift):
    """Heights (1 + f)·h_paper, sampled at the paper's times and half-way between them on the straight segments
    (so the judge's interpolation is exercised and exact): relative deviation |f|, signed mean f."""
    b = bench(name)
    pts = curve(b)
    mid = 0.5 * (pts[1:] + pts[:-1])
    run = np.concatenate([pts, mid])
    run = run[np.argsort(run[:, 0])]
    check, _ = v.judge_heap(b, "f", run[:, 0], (1.0 + shift) * run[:, 1])
    assert check.deviation == pytest.approx(abs(shift), rel=1e-12)
    assert check.extra["mean_deviation"] == pytest.approx(shift, rel=1e-12)
    assert check.verdict == (v.MEETS if abs(shift) <= 0.10 else v.MISSES)
    assert "failed" not in check.extra


def test_the_deviation_is_the_largest_over_the_curve_and_where_it_is():
    b = bench("ai2011-sandpile-constant")
    pts = curve(b)
    h = pts[:, 1].copy()
    h[7] *= 0.93  # one point 7% low, the rest 2% high
    h[np.arange(len(h)) != 7] *= 1.02
    check, _ = v.judge_heap(b, "f", pts[:, 0], h)
    assert check.deviation == pytest.approx(0.07, rel=1e-12) and check.at == pts[7, 0]
    assert check.verdict == v.MEETS


def test_a_dense_run_is_interpolated_at_the_curve_s_times():
    """A run on a fine grid of a closed-form line h(t) = a + b t: the judge compares a + b t_i with h_i."""
    b = bench("ai2011-sandpile-viscous")
    pts = curve(b)
    t = np.linspace(0.0, 50.0, 5001)
    a, slope = 0.19, -2e-5
    check, _ = v.judge_heap(b, "f", t, a + slope * t)
    expected = np.max(np.abs(a + slope * pts[:, 0] - pts[:, 1]) / pts[:, 1])
    assert check.deviation == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("bad, reason", [
    (lambda t, h: (t, np.where(np.arange(len(h)) == 3, np.nan, h)), "not finite"),
    (lambda t, h: (t, np.where(np.arange(len(h)) == 3, np.inf, h)), "not finite"),
    (lambda t, h: (t[t < 40.0], h[t < 40.0]), "spans"),  # stops before the curve's end
    (lambda t, h: (t[t > 12.0], h[t > 12.0]), "spans"),  # starts after the curve's start
    (lambda t, h: (t, h[:-1]), "heights"),
    (lambda t, h: (t[::-1], h), "increase"),
    (lambda t, h: ([], []), "no height curve"),
])
def test_a_run_that_is_not_finite_or_short_is_a_failure_never_an_agreement(bad, reason):
    b = bench("ai2011-sandpile-epsd")
    t = np.linspace(0.0, 50.0, 501)
    h = np.full_like(t, 0.272013)  # on the curve, but for the fault
    check, _ = v.judge_heap(b, "f", *bad(t, h))
    assert check.verdict == v.MISSES and check.deviation == math.inf
    assert reason in check.extra["failed"] and "failed" in check.to_json()


def test_a_run_that_raised_is_a_failure():
    check, _ = v.judge_heap(bench("ai2011-sandpile-epsd"), "f", None, None, error="RuntimeError: boom")
    assert check.verdict == v.MISSES and check.deviation == math.inf and "boom" in check.why


def _stand_in(monkeypatch, tmp_path, height_curve):
    """cases/optin/<name>.toml stand-ins under tmp_path and a sandpile module whose height_curve is given."""
    (tmp_path / "optin").mkdir(parents=True, exist_ok=True)
    for name in NAMES:
        (tmp_path / "optin" / f"{name}.toml").write_text("")
    mod = types.ModuleType("demcheck.reference.sandpile")
    mod.height_curve = height_curve
    monkeypatch.setitem(sys.modules, "demcheck.reference.sandpile", mod)
    monkeypatch.setattr(v, "_load_case", lambda path: path.stem)  # the "case" the stand-in receives
    monkeypatch.setattr(v.resources, "cases_dir", lambda: tmp_path)


def test_run_heap_calls_the_sandpile_solver_by_name_and_judges_its_curve(monkeypatch, tmp_path):
    seen = []

    def height_curve(case, progress=None):
        seen.append(case)
        pts = curve(bench(case))
        return pts[:, 0], 0.96 * pts[:, 1]

    _stand_in(monkeypatch, tmp_path, height_curve)
    for name in NAMES:
        check, series = v.run_heap(bench(name))
        assert check.deviation == pytest.approx(0.04, rel=1e-12) and check.verdict == v.MEETS
        assert check.file == name and series["benchmark"] == name
    assert seen == list(NAMES)


def test_run_heap_without_the_solver_or_with_a_failing_one_fails(monkeypatch, tmp_path):
    def boom(case, progress=None):
        raise FloatingPointError("overflow in the pile")

    _stand_in(monkeypatch, tmp_path, boom)
    check, _ = v.run_heap(bench("ai2011-sandpile-constant"))
    assert "FloatingPointError: overflow in the pile" in check.extra["failed"]
    monkeypatch.setitem(sys.modules, "demcheck.reference.sandpile", None)  # not in this build: import fails
    check, _ = v.run_heap(bench("ai2011-sandpile-constant"))
    assert "demcheck.reference.sandpile" in check.extra["failed"] and check.verdict == v.MISSES


def test_a_missing_case_file_is_refused_with_the_catalogue_key(tmp_path):
    with pytest.raises(ConfigError) as exc:
        v.heap_case_path(bench("ai2011-sandpile-viscous"), cases=tmp_path)
    assert "ai2011-sandpile-viscous.case" in exc.value.key and exc.value.value == "optin/ai2011-sandpile-viscous"


@pytest.mark.parametrize("scale, verdict, failed", [(1.02, v.MEETS, 0),
                                                   (0.5, v.MISSES, 0),  # a finite run off the curve: a finding
                                                   (math.nan, v.MISSES, 1)])  # a run not finite: a failure
def test_validate_run_of_a_heap_benchmark_alone_writes_its_report(monkeypatch, tmp_path, scale, verdict, failed):
    def height_curve(case, progress=None):
        pts = curve(bench(case))
        return pts[:, 0], scale * pts[:, 1]

    _stand_in(monkeypatch, tmp_path / "cases", height_curve)
    summary = v.run("ai2011-sandpile-epsd", tmp_path / "cases", tmp_path / "reports", opts=None, quiet=True,
                    argv=["demcheck", "validate", "ai2011-sandpile-epsd"])
    assert summary.failed == failed
    (check,) = summary.validation.checks
    assert check.benchmark == "ai2011-sandpile-epsd" and check.verdict == verdict
    assert summary.wall_time is not None and summary.wall_time >= 0.0 and not summary.partial
    assert (tmp_path / "reports" / "latest-validate" / "report.md").is_file()


def test_a_heap_run_logs_its_progress_every_simulated_second(monkeypatch, tmp_path, capsys):
    """A run of about an hour says how far it is: validate passes a progress callback, which prints one line per
    simulated second (the solver calls it at every measure, here every 0.25 s)."""
    def height_curve(case, progress=None):
        t = np.arange(0.0, 3.01, 0.25)
        for ti in t:
            progress(float(ti), 0.2)
        return t, np.full_like(t, 0.2)

    _stand_in(monkeypatch, tmp_path / "cases", height_curve)
    v.run("ai2011-sandpile-constant", tmp_path / "cases", tmp_path / "reports", opts=None, quiet=False,
          argv=["demcheck", "validate", "ai2011-sandpile-constant"])
    lines = [ln for ln in capsys.readouterr().err.splitlines() if "height 0.2000 m" in ln]
    assert [ln.split("t = ")[1].split(" s,")[0] for ln in lines] == ["0.00", "1.00", "2.00", "3.00"]


def test_an_interrupted_heap_run_keeps_its_heights_in_a_partial_report_and_stops(monkeypatch, tmp_path):
    """Ctrl-C in the middle of an hour's run: the report is written (the heights so far, the benchmark failed as
    "interrupted at t = …", the run partial), and the interrupt goes on to the command (its exit code)."""
    import json

    def height_curve(case, progress=None):
        for ti in (9.0, 9.02, 9.04):
            progress(ti, 0.25)
        raise KeyboardInterrupt

    _stand_in(monkeypatch, tmp_path / "cases", height_curve)
    with pytest.raises(KeyboardInterrupt) as exc:
        v.run("ai2011-sandpile-viscous", tmp_path / "cases", tmp_path / "reports", opts=None, quiet=True,
              argv=["demcheck", "validate", "ai2011-sandpile-viscous"])
    assert isinstance(exc.value, v.HeapInterrupted)
    assert exc.value.check.verdict == v.MISSES and exc.value.check.extra["failed"] == "interrupted at t = 9.04 s"
    assert exc.value.series["sources"]["reference"] == {"x": [9.0, 9.02, 9.04], "y": [0.25, 0.25, 0.25]}
    latest = tmp_path / "reports" / "latest-validate"
    assert (latest / "report.md").is_file()
    text = (latest / "report.md").read_text() + json.dumps(json.loads((latest / "results.json").read_text()))
    assert "interrupted at t = 9.04 s" in text
    assert json.loads((latest / "results.json").read_text())["partial"] is True


def test_an_interrupt_inside_a_compiled_kernel_is_an_interrupt_not_a_failed_run(monkeypatch, tmp_path):
    """numba reports a signal raised as a compiled kernel returns as ``SystemError: CPUDispatcher(...) returned a
    result with an exception set``, the interrupt its cause (a SIGTERM to a running validate was reported as a
    failed run this way): the run is interrupted, with the signal's exit code, not a benchmark that failed."""
    from demcheck.engines import run as runner

    def height_curve(case, progress=None):
        progress(9.0, 0.25)
        try:
            raise runner.Terminated()
        except KeyboardInterrupt as stop:
            raise SystemError("CPUDispatcher(<function run>) returned a result with an exception set") from stop

    _stand_in(monkeypatch, tmp_path, height_curve)
    with pytest.raises(v.HeapInterrupted) as exc:
        v.run_heap(bench("ai2011-sandpile-epsd"))
    assert exc.value.check.extra["failed"] == "interrupted at t = 9 s"
    assert runner.interrupt_exit_code(exc.value) == 143


def _catalogue_with(tmp_path, entry: str):
    path = tmp_path / "benchmarks.toml"
    path.write_text('[notes]\nx = "y"\n\n[[benchmark]]\n' + entry)
    return lambda: v.catalogue(path, v.DATA, cases=tmp_path)


GOOD = ('name = "h"\ntitle = "t"\nkind = "heap"\ncase = "optin/h"\nopt_in = true\n'
        'curves = [{ quantity = "heap_height", file = "ai2011-sandpile-epsd.dat", key = "epsd", tolerance = 0.1, '
        'why = "w" }]\n')


@pytest.mark.parametrize("change, key", [
    (("kind = \"heap\"", "kind = \"pile\""), "kind"),
    (("case = \"optin/h\"", "case = \"../h\""), "case"),
    (("case = \"optin/h\"", "case = \"optin/h.toml\""), "case"),
    (("tolerance = 0.1", "tolerance = 1.5"), "tolerance"),
    (("tolerance = 0.1", "tolerance = 0"), "tolerance"),
    (("key = \"epsd\"", "key = \"viscous\""), "key"),
    (("file = \"ai2011-sandpile-epsd.dat\"", "file = \"nope.dat\""), "file"),
    (("quantity = \"heap_height\"", "quantity = \"beta\""), "curves"),
])
def test_a_bad_heap_entry_is_refused_naming_its_key(tmp_path, change, key):
    assert _catalogue_with(tmp_path, GOOD)()[0].kind == v.HEAP
    load = _catalogue_with(tmp_path, GOOD.replace(*change))
    with pytest.raises(ConfigError) as exc:
        load()
    assert exc.value.key.split(".")[-1] == key or exc.value.key.endswith(key), exc.value.key


@pytest.mark.parametrize("name,rolling", [("ai2011-sandpile-constant", "constant_torque"),
                                          ("ai2011-sandpile-viscous", "ai_viscous"),
                                          ("ai2011-sandpile-epsd", "ai_epsd")])
def test_each_heap_benchmark_names_a_shipped_case_with_its_model(name, rolling):
    """The three cases exist, load, and differ from each other in the rolling law only (Lethe's three .prm files
    differ in `rolling resistance torque method` alone): model A constant_torque, B ai_viscous, C ai_epsd (Ai's
    model C with kr from each contact's kn(δ), which the packing loop writes per contact and step, as Lethe)."""
    from demcheck import case as C
    from demcheck import resources

    b = bench(name)
    path = resources.cases_dir() / f"{b.case}.toml"
    case = C.load(path)
    assert case.contact.rolling == rolling
    base = C.load(resources.cases_dir() / "optin" / "ai2011-sandpile-constant.toml")
    assert case.packing == base.packing and case.walls == base.walls and case.particles == base.particles
    assert (case.contact.normal, case.contact.tangential) == (base.contact.normal, base.contact.tangential)
    assert case.contact.params.get("mu_r") == base.contact.params.get("mu_r") == 0.3  # every .prm's rolling friction


@pytest.mark.parametrize("name", NAMES)
def test_each_heap_case_measures_over_its_whole_curve(name):
    """The judge fails a run that does not span its curve (9.1-49.5 s for EPSD): the shipped case's first height
    must come before the curve's first time and its run end after the curve's last (a case measuring from Lethe's
    10 s could never pass, whatever the physics)."""
    from demcheck import case as C
    from demcheck import resources
    from demcheck.reference import sandpile as S

    b = bench(name)
    case = C.load(resources.cases_dir() / f"{b.case}.toml")
    pts = curve(b)
    times = S.measure_steps(case, case.run.dt) * case.run.dt
    assert times[0] <= pts[0, 0] and times[-1] >= pts[-1, 0]
