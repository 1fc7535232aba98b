"""demcheck diff: a planted change is reported with its size and exits 1; a clean rerun is clean."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from demcheck.comparisons import diff as D

from .conftest import CASES


def demcheck(*args, env=None, cwd=None):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          timeout=600, env=env, cwd=cwd)


def verify(tmp, name, *cases, engines="none", extra=()):
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp / "cache"))
    p = demcheck("verify", *cases, "--engines", engines, "--report", tmp / name, *extra, env=env)
    assert p.returncode in (0, 1), p.stderr
    return tmp / name / "latest"


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Two reference-only runs of the same two cases (the second a rerun) and a copy of the first's results."""
    tmp = tmp_path_factory.mktemp("diff")
    cases = (CASES / "hertz-wall.toml", CASES / "kk-wall.toml")
    a = verify(tmp, "a", *cases)
    b = verify(tmp, "b", *cases)
    return tmp, a, b


def plant(src, dst, edit):
    data = json.loads((src / "results.json").read_text())
    edit({c["case"]: c for c in data["cases"]})
    dst.write_text(json.dumps(data))
    return dst


def test_a_clean_rerun_is_clean(runs):
    _, a, b = runs
    p = demcheck("diff", a, b)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "**0 regression(s)**" in p.stdout and "Nothing moved" in p.stdout
    d = D.compare(D.load(a), D.load(b / "results.json"))
    # every metric of both sources (reference, reference-verlet) of both cases, and the closed forms' verdicts:
    # each identical (the runs are deterministic)
    assert d["checked"] > 2 * 2 * 9 and d["unchanged"] == d["checked"] and not d["rows"]


def test_a_planted_move_is_reported_with_its_size_and_exits_1(runs, tmp_path):
    _, a, b = runs
    old = json.loads((a / "results.json").read_text())
    e0 = {c["case"]: c for c in old["cases"]}["kk-wall"]["sources"]["reference"]["metrics"]

    def edit(cases):
        m = cases["kk-wall"]["sources"]["reference"]["metrics"]
        m["restitution"] += 2.5e-4  # a restitution's scale is 1: moved 2.5e-4
        m["contact_time"] *= 1.001  # a time's scale is its OLD value: moved 1e-3

    new = plant(b, tmp_path / "planted.json", edit)
    p = demcheck("diff", a, new, "--json", "--junit", tmp_path / "j.xml")
    assert p.returncode == 1, p.stderr
    d = json.loads(p.stdout)
    moved = {(r["case"], r["source"], r["metric"]): r for r in d["rows"] if r["beyond"]}
    assert set(moved) == {("kk-wall", "reference", "restitution"), ("kk-wall", "reference", "contact_time")}
    r = moved[("kk-wall", "reference", "restitution")]
    assert r["old"] == e0["restitution"] and r["moved"] == pytest.approx(2.5e-4, rel=1e-9)  # round-off of e + 2.5e-4
    assert moved[("kk-wall", "reference", "contact_time")]["moved"] == pytest.approx(1e-3, rel=1e-9)
    assert d["regressions"] == 2 and d["counts"]["moved"] == 2 and d["counts"]["worse"] == 0
    suite = ET.parse(tmp_path / "j.xml").getroot().find("testsuite")
    assert suite.get("failures") == "1"  # one case × source regressed
    failure = suite.find("testcase[@name='reference']/failure")
    assert failure is not None and "moved 0.00025" in failure.text
    md = demcheck("diff", a, new).stdout
    assert "| kk-wall | reference | restitution |" in md and "| 0.00025 | 1e-09 |" in md


def test_fields_diff_does_not_read_may_have_any_shape(runs, tmp_path):
    """results.json fields the schema leaves open and diff never reads (a case's curves and series, a source's
    warnings, a comparison's parts): an odd shape is kept as it is, and the comparison runs (it was a 41-line
    traceback, exit 1 — the code of "regressions found")."""
    _, a, b = runs

    def odd(cases):
        case = cases["kk-wall"]
        case["curves"], case["series"] = "x", 5
        case["sources"]["reference"]["warnings"] = 5
        case["comparisons"][0]["parts"] = [1, 2]

    p = demcheck("diff", plant(a, tmp_path / "odd.json", odd), b)
    assert p.returncode == 0, p.stdout + p.stderr[-2000:]
    assert "**0 regression(s)**" in p.stdout


def test_an_entry_without_its_verdict_is_judged_from_its_comparisons():
    from demcheck.comparisons.records import CaseResult

    bad = {"case": "c", "comparisons": [{"source": "lammps", "metric": "restitution", "verdict": "failed"}]}
    entry = CaseResult.from_json(bad)
    assert entry.verdict == "failed" and entry.status == "failed"


def test_a_tolerance_lets_a_small_move_pass(runs, tmp_path):
    _, a, b = runs
    new = plant(b, tmp_path / "p.json",
                lambda c: c["hertz-wall"]["sources"]["reference"]["metrics"].__setitem__(
                    "max_overlap", c["hertz-wall"]["sources"]["reference"]["metrics"]["max_overlap"] * (1 + 1e-7)))
    assert demcheck("diff", a, new).returncode == 1  # 1e-7 > the default 1e-9
    p = demcheck("diff", a, new, "--tolerance", "1e-6")
    assert p.returncode == 0 and "1 other value(s) moved within their tolerance (largest 1e-07" in p.stdout


def test_a_worse_verdict_exits_1_and_a_better_one_does_not(runs, tmp_path):
    _, a, b = runs

    def set_verdict(verdict):
        def edit(cases):
            for k in cases["hertz-wall"]["comparisons"]:
                if k["source"] == "reference-verlet" and k["metric"] == "peak_force":
                    k["verdict"] = verdict
        return edit

    worse = plant(b, tmp_path / "w.json", set_verdict("differs unexpectedly"))
    p = demcheck("diff", a, worse, "--json")
    assert p.returncode == 1
    rows = json.loads(p.stdout)["rows"]
    assert [(r["metric"], r["old_verdict"], r["new_verdict"], r["change"]) for r in rows] == [
        ("peak_force", "agree", "differs unexpectedly", "worse")]
    # the other way round: the verdict improved, nothing regressed
    p = demcheck("diff", worse, a)
    assert p.returncode == 0 and "| hertz-wall | reference-verlet | peak\\_force | differs unexpectedly | agree | better |" \
        in p.stdout


def test_a_gone_source_or_case_is_a_regression(runs, tmp_path):
    _, a, b = runs
    gone = plant(b, tmp_path / "g.json", lambda c: c["kk-wall"]["sources"].pop("reference-verlet"))
    d = D.compare(D.load(a), D.load(gone))
    # its values are gone and so are its verdicts: still compared through the verdicts it had
    assert d["regressions"] >= 1
    data = json.loads((b / "results.json").read_text())
    data["cases"] = [c for c in data["cases"] if c["case"] != "kk-wall"]
    (tmp_path / "c.json").write_text(json.dumps(data))
    p = demcheck("diff", a, tmp_path / "c.json")
    assert p.returncode == 1 and "kk-wall · \\*: case not in NEW" in p.stdout
    assert demcheck("diff", tmp_path / "c.json", a).returncode == 0  # a case added is news, not a regression


def test_a_metric_new_in_NEW_is_news_and_one_gone_from_NEW_a_regression(runs, tmp_path):
    """A newer demcheck measures more (the packings' fabric_zz, say): a metric OLD never had is listed as new,
    not as a move from NaN; one NEW lost is a regression."""
    _, a, b = runs
    more = plant(b, tmp_path / "m.json", lambda c: c["kk-wall"]["sources"]["reference"]["metrics"].update(fabric_zz=0.35))
    d = D.compare(D.load(a), D.load(more))
    assert d["regressions"] == 0 and not d["rows"]
    assert {"case": "kk-wall", "source": "reference", "what": "metric fabric_zz not in OLD"} in d["added"]
    p = demcheck("diff", a, more)
    assert p.returncode == 0 and "metric fabric\\_zz not in OLD" in p.stdout  # markdown-escaped (a name is text, never markup)
    d = D.compare(D.load(more), D.load(a))  # the other way round: gone from NEW
    assert d["regressions"] == 1 and d["rows"][0]["metric"] == "fabric_zz"


def test_sources_compared_under_another_name(runs, tmp_path):
    _, a, b = runs

    def rename(cases):
        for c in cases.values():
            c["sources"]["verlet-again"] = c["sources"].pop("reference-verlet")
            for k in c["comparisons"]:
                if k["source"] == "reference-verlet":
                    k["source"] = "verlet-again"

    new = plant(b, tmp_path / "r.json", rename)
    assert demcheck("diff", a, new).returncode == 1  # reference-verlet gone
    p = demcheck("diff", a, new, "--source", "reference-verlet=verlet-again")
    assert p.returncode == 0 and "OLD reference-verlet → NEW verlet-again" in p.stdout


@pytest.mark.parametrize("args,message", [
    (("nothing.json", "{b}"), "OLD = 'nothing.json': no such file or directory"),
    (("{tmp}", "{b}"), "a directory without results.json"),
    (("{b}", "{tmp}/bad.json"), "cannot be read as JSON"),
    (("{b}", "{tmp}/list.json"), "is not a demcheck results.json or baseline"),
    (("{b}", "{b}", "--source", "lammps"), "--source = 'lammps': must be OLD_NAME=NEW_NAME"),
    (("{b}", "{b}", "--tolerance", "-1"), "--tolerance = -1.0: must be >= 0"),
])
def test_bad_input_is_one_line_and_exit_2(runs, tmp_path, args, message):
    _, _, b = runs
    (tmp_path / "bad.json").write_text("{")
    (tmp_path / "list.json").write_text('{"cases": [1]}')
    p = demcheck("diff", *(x.format(b=b, tmp=tmp_path) for x in args))
    assert p.returncode == 2 and message in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr


@pytest.mark.engine("lammps")
def test_a_rerun_of_lammps_is_clean_and_a_planted_engine_change_is_caught(tmp_path):
    case = CASES / "hertz-wall.toml"
    a = verify(tmp_path, "a", case, engines="lammps")
    b = verify(tmp_path, "b", case, engines="lammps", extra=("--no-cache",))  # the engine run again, for real
    assert demcheck("diff", a, b).returncode == 0
    new = plant(b, tmp_path / "p.json", lambda c: c["hertz-wall"]["sources"]["lammps"]["metrics"].__setitem__(
        "peak_force", c["hertz-wall"]["sources"]["lammps"]["metrics"]["peak_force"] * 1.02))
    p = demcheck("diff", a, new, "--json")
    assert p.returncode == 1
    (r,) = [r for r in json.loads(p.stdout)["rows"] if r["beyond"]]
    assert (r["source"], r["metric"]) == ("lammps", "peak_force") and r["moved"] == pytest.approx(0.02, rel=1e-9)
    assert r["old_version"] == r["new_version"] and r["old_version"].startswith("22 Jul 2025")


def test_a_case_name_is_text_in_the_diff_report_never_a_link(runs, tmp_path):
    """A case name may hold [ ] ( ) : / _ (the name rule): in diff.md it is escaped, so rendered markdown shows
    it as text — no link, no emphasis."""
    from markdown_it import MarkdownIt

    _, a, b = runs
    name = "[click](https://evil.example/x) _em_ wall"

    def rename(c):
        c[name] = c.pop("kk-wall")
        c[name]["case"] = name

    old = plant(a, tmp_path / "o.json", rename)
    new = plant(b, tmp_path / "n.json", lambda c: c.pop("kk-wall"))  # gone from NEW: listed by name
    html = MarkdownIt("commonmark", {"html": False}).enable("table").render(D.render_markdown(D.compare(D.load(old), D.load(new))))
    assert "<a " not in html and "<em>" not in html and "[click](https://evil.example/x) _em_ wall" in html
