"""The verification suite run by ``demcheck verify``.

For every case: the reference's adaptive method (converged), checked against the model's closed forms
where the notes derive them, and the verlet method at the case's time step, compared with the adaptive
answer. Reports go to <report>/<run-id>/ (results.json, report.md) and <report>/latest, written
atomically; finished results are kept if the run is interrupted.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
import time
from pathlib import Path

from rich.console import Console
from rich.progress import Progress

from .. import __version__
from ..case import load
from ..errors import DemcheckError
from ..io import write_json, write_text
from ..reference.collision import collide
from ..reference.expected import closed_form_metrics
from ..reference.model import resolve

CLOSED_FORM_RTOL = 1e-8  # the adaptive method at rtol 1e-13 against an exact solution


def _rel(a, b):
    if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)):
        return math.nan
    scale = max(abs(a), abs(b))
    return 0.0 if scale == 0 else abs(a - b) / scale


def run_case(path: Path) -> dict:
    case = load(path)
    entry = {"case": case.name, "file": str(path), "case_hash": case.hash, "kind": case.kind, "checks": []}
    if case.kind != "collision":
        entry["status"] = "skipped"
        entry["message"] = "packing cases are not run by this version"
        return entry
    adaptive = collide(case, "adaptive")
    verlet = collide(case, "verlet")
    entry["model"] = adaptive.model
    entry["params"] = adaptive.params
    entry["results"] = {"adaptive": adaptive.summary(), "verlet": verlet.summary()}
    failed = not adaptive.ok or verlet.status not in ("ok",)
    ma, mv = adaptive.metrics(), verlet.metrics()
    for metric, value in closed_form_metrics(resolve(case)).items():
        diff = _rel(ma[metric], value)
        if metric == "energy_dissipated":  # relative to the impact energy: a small loss is not a large error
            ke = 0.5 * adaptive.params["m_eff"] * adaptive.params["impact_speed"] ** 2
            diff = abs(ma[metric] - value) / ke
        ok = diff <= CLOSED_FORM_RTOL
        failed |= not ok
        entry["checks"].append({"check": "adaptive vs closed form", "metric": metric, "value": ma[metric],
                                "expected": value, "rel_diff": diff, "tolerance": CLOSED_FORM_RTOL,
                                "verdict": "agree" if ok else "differs"})
    for metric in ma:
        entry["checks"].append({"check": f"verlet (dt={verlet.dt:.3g}) vs adaptive", "metric": metric,
                                "value": mv[metric], "expected": ma[metric], "rel_diff": _rel(mv[metric], ma[metric]),
                                "tolerance": None, "verdict": "reported"})
    entry["status"] = "failed" if failed else "ok"
    entry["message"] = "; ".join(m for m in (adaptive.message, verlet.message) if m and not (adaptive.ok and verlet.ok))
    return entry


def run_suite(files: list[Path], report_root: Path, quiet: bool = False) -> dict:
    console = Console(stderr=True, quiet=quiet)
    run_id = _dt.datetime.now().strftime("%Y%m%d-%H%M%S") + f"-{os.getpid()}"
    out_dir = report_root / run_id
    summary = {"demcheck": __version__, "run_id": run_id, "report": str(out_dir), "partial": True,
               "engines": {}, "cases": [], "failed": 0}
    started = time.perf_counter()
    try:
        with Progress(console=console, transient=True) as progress:
            task = progress.add_task("verify", total=len(files))
            for path in files:
                progress.update(task, description=path.stem)
                try:
                    entry = run_case(path)
                except DemcheckError as exc:
                    entry = {"case": path.stem, "file": str(path), "status": "failed", "message": str(exc),
                             "checks": []}
                summary["cases"].append(entry)
                summary["failed"] += entry["status"] == "failed"
                progress.advance(task)
        summary["partial"] = False
    finally:
        summary["wall_time"] = time.perf_counter() - started
        _write_reports(summary, out_dir, report_root)
    _print(console, summary)
    return summary


def _clean(obj):
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_clean(v) for v in obj]
    return obj


def _write_reports(summary: dict, out_dir: Path, root: Path) -> None:
    write_json(out_dir / "results.json", _clean(summary))
    write_text(out_dir / "report.md", render_markdown(summary))
    latest = root / "latest"
    tmp = root / f".latest.{os.getpid()}"
    if tmp.is_symlink() or tmp.exists():
        tmp.unlink()
    tmp.symlink_to(out_dir.name)
    os.replace(tmp, latest)


def render_markdown(summary: dict) -> str:
    lines = [f"# demcheck verification {summary['run_id']}", ""]
    if summary["partial"]:
        lines += ["**PARTIAL REPORT: the run was interrupted; the cases below finished.**", ""]
    lines += [f"demcheck {summary['demcheck']}; engines: reference only in this version.", "",
              "| case | model | status | checks | worst closed-form rel. diff |", "|---|---|---|---|---|"]
    for c in summary["cases"]:
        model = c.get("model", {})
        cf = [k["rel_diff"] for k in c.get("checks", []) if k["check"] == "adaptive vs closed form"]
        worst = f"{max(cf):.2e}" if cf else "no closed form"
        lines.append(f"| {c['case']} | {model.get('normal', '—')}/{model.get('tangential', '—')} | {c['status']} "
                     f"| {len(c.get('checks', []))} | {worst} |")
    for c in summary["cases"]:
        lines += ["", f"## {c['case']}", ""]
        if c.get("message"):
            lines += [c["message"], ""]
        if c.get("checks"):
            lines += ["| check | metric | value | expected | rel. diff | verdict |", "|---|---|---|---|---|---|"]
            for k in c["checks"]:
                lines.append(f"| {k['check']} | {k['metric']} | {_f(k['value'])} | {_f(k['expected'])} "
                             f"| {_f(k['rel_diff'], '.2e')} | {k['verdict']} |")
    return "\n".join(lines) + "\n"


def _f(v, spec=".10g"):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return format(v, spec)


def _print(console: Console, summary: dict) -> None:
    for c in summary["cases"]:
        colour = {"ok": "green", "failed": "red"}.get(c["status"], "yellow")
        console.print(f"[{colour}]{c['status']:>7}[/] {c['case']}" + (f"  {c['message']}" if c.get("message") else ""))
    console.print(f"{len(summary['cases'])} cases, {summary['failed']} failed; report: {summary['report']}/report.md")
