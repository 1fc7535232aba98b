"""Reports of ``demcheck bench`` (work–precision) and ``demcheck stress`` (stability): results.json,
report.md and report.html (plots inline) in <report>/<run-id>/, with <report>/latest switched atomically."""

from __future__ import annotations

import datetime as _dt
import html
import math
import os
from pathlib import Path

from ..io import number, plain, write_json, write_text
from .report import _img, _png, link_latest
from .styles import style



def new_run_dir(root: Path, kind: str) -> Path:
    run_id = f"{kind}-" + _dt.datetime.now().strftime("%Y%m%d-%H%M%S") + f"-{os.getpid()}"
    return root / run_id


def _publish(out_dir: Path, root: Path, data: dict, md: str, page: str) -> None:
    write_json(out_dir / "results.json", plain(data))
    write_text(out_dir / "report.md", md)
    write_text(out_dir / "report.html", page)
    link_latest(root, out_dir, f"latest-{out_dir.name.split('-')[0]}")  # latest-bench, latest-stress: not verify's


# ----------------------------------------------------------------------------- work–precision


def bench_markdown(data: dict) -> str:
    lines = [f"# demcheck bench {data['run_id']}", "", f"Engines: {data['engines']}", "",
             "## Work–precision", "",
             "Error: the worst relative error of restitution, contact time, maximum overlap and peak force (and, "
             "for an oblique impact with friction, of tangential restitution and rebound spin in the suite's units) "
             "against the converged adaptive answer (rtol 1e-13). Time: wall seconds per collision — engines per process "
             f"(start-up included) and per collision in a batch of {data['batch']} independent copies in one process.",
             ""]
    for b in data["cases"]:
        lines += [f"### {b['case']} ({b['model']['normal']} / {b['model']['tangential']})", "",
                  f"Elastic contact time t_c = {b['t_contact']:.4g} s.", ""]
        for src, why in b["skipped"].items():
            lines.append(f"* {src}: {why}")
        targets = ("0.01", "0.001", "0.0001", "1e-05", "1e-06")
        lines += ["", "| source | order | " + " | ".join(f"cheapest for {t}" for t in targets) + " |",
                  "|---|---|" + "---|" * len(targets)]
        for src, s in b["sources"].items():
            cells = []
            for tgt in targets:
                c = s["cheapest"].get(tgt)
                if c is None:
                    cells.append("not reached")
                elif src == "reference-adaptive":
                    cells.append(f"rtol {c['rtol']:g}: {number(c['wall_time'] * 1e3, '.3g')} ms")
                else:
                    batch = f", {number(c['batch_time'] * 1e3, '.3g')} ms batched" if c.get("batch_time") else ""
                    cells.append(f"{c['steps_per_contact']:g} steps: {number(c['wall_time'] * 1e3, '.3g')} ms{batch}")
            lines.append(f"| {src} | {number(s['order'], '.2f')} | " + " | ".join(cells) + " |")
        lines += ["", "| source | steps per contact / rtol | error | ms per collision | ms batched | status |",
                  "|---|---|---|---|---|---|"]
        for p in b["points"]:
            where = f"rtol {p['rtol']:g}" if p["rtol"] else f"{p['steps_per_contact']:g}"
            lines.append(f"| {p['source']} | {where} | {number(p['error'], '.3g')} | {number(p['wall_time'] * 1e3, '.3g')} | "
                         f"{number(p['batch_time'] * 1e3, '.3g') if p['batch_time'] else '—'} | {p['status']} |")
        lines.append("")
    if data.get("speed_goal"):
        lines += ["## Speed goal", "", data["speed_goal"], ""]
    return "\n".join(lines) + "\n"


def bench_plots(b: dict) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.6))
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.15, top=0.86, wspace=0.3)
    for src in dict.fromkeys(p["source"] for p in b["points"]):
        pts = [p for p in b["points"] if p["source"] == src and p["error"] and math.isfinite(p["error"])
               and p["error"] > 0]
        if not pts:
            continue
        st = style(src)
        m = st.marker
        a1.loglog([p["wall_time"] for p in pts], [p["error"] for p in pts], m + "-", color=st.colour,
                  label=f"{src} (per process)")
        batched = [p for p in pts if p.get("batch_time")]
        if batched:
            a1.loglog([p["batch_time"] for p in batched], [p["error"] for p in batched], m + ":", color=st.colour,
                      label=f"{src} (batched)")
        steps = [p for p in pts if p["steps_per_contact"]]
        if steps:
            a2.loglog([p["steps_per_contact"] for p in steps], [p["error"] for p in steps], m + "-", color=st.colour,
                      label=src)
    a1.set(xlabel="wall time per collision (s)", ylabel="worst relative error", title="error against run time")
    a2.set(xlabel="steps per elastic contact time", ylabel="worst relative error", title="error against steps")
    for a in (a1, a2):
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=6)
    fig.suptitle(f"{b['case']}: {b['model']['normal']} / {b['model']['tangential']}", fontsize=9)
    return _png(fig)


def _write(data: dict, root: Path, kind: str, section: str, md: str, plot) -> Path:
    """report.html: one plot per case under ``section``, then the markdown report verbatim."""
    out = Path(data["report"])
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>demcheck {kind}</title>"
             "<style>body{font-family:system-ui,sans-serif;margin:2em}img{max-width:100%}</style></head><body>",
             f"<h1>demcheck {kind} {html.escape(data['run_id'])}</h1><h2>{section}</h2>"]
    for c in data["cases"]:
        parts.append(f"<h3>{html.escape(c['case'])}</h3>" + _img(plot(c), f"{section} {c['case']}"))
    parts.append("<pre>" + html.escape(md) + "</pre></body></html>")
    _publish(out, root, data, md, "\n".join(parts))
    return out


def write_bench(data: dict, root: Path) -> Path:
    return _write(data, root, "bench", "Work–precision", bench_markdown(data), bench_plots)


# ----------------------------------------------------------------------------- stability


def stress_markdown(data: dict) -> str:
    lines = [f"# demcheck stress {data['run_id']}", "", f"Engines: {data['engines']}", "", "## Stability", "",
             "The largest stable time step over the elastic contact time t_c (bisection over a grid of steps per "
             "contact) for each parameter value and source; failure: the first coarser step's reason (NaN, "
             "overlap beyond half the radius, energy created, no separation, an engine error).", ""]
    for s in data["cases"]:
        lines += [f"### {s['case']} ({s['model']['normal']} / {s['model']['tangential']})", ""]
        for src, why in s["skipped"].items():
            lines.append(f"* {src}: {why}")
        lines += ["", "| parameter | value | source | dt_max / t_c | failure beyond |", "|---|---|---|---|---|"]
        for l in s["limits"]:
            lines.append(f"| {l['parameter']} | {l['value']:g} | {l['source']} | {number(l['dt_max_over_tc'], '.3g')} | "
                         f"{l['failure'][:140]} |")
        flags = s["disagreements"]
        lines += ["", f"Disagreements about stability (more than one grid step): {len(flags)}", ""]
        for f in flags:
            lines.append(f"* {f['parameter']} = {f['value']:g}: reference {number(f['reference_dt_max_over_tc'], '.3g')}, "
                         f"{f['source']} {number(f['engine_dt_max_over_tc'], '.3g')} ({f['engine_failure'][:100]})")
        lines.append("")
    return "\n".join(lines) + "\n"


def stress_plots(s: dict) -> str:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    params = list(dict.fromkeys(l["parameter"] for l in s["limits"]))
    n = max(len(params), 1)
    cols = min(3, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 2.8 * rows), squeeze=False)
    for ax, prm in zip(axes.ravel(), params):
        for src in dict.fromkeys(l["source"] for l in s["limits"]):
            pts = [(l["value"], l["dt_max_over_tc"]) for l in s["limits"]
                   if l["parameter"] == prm and l["source"] == src and l["dt_max_over_tc"]]
            if pts:
                ax.plot(*zip(*pts), style(src).marker + "-", color=style(src).colour, label=src, alpha=0.8)
        if any(l["value"] > 0 for l in s["limits"] if l["parameter"] == prm) and "angle" not in prm \
                and "restitution" not in prm:
            ax.set_xscale("log")
        ax.set_title(prm, fontsize=8)
        ax.set_ylabel("dt_max / t_c", fontsize=7)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    for ax in axes.ravel()[len(params):]:
        ax.axis("off")
    axes[0][0].legend(fontsize=6)
    fig.suptitle(f"stability map: {s['case']}", fontsize=9)
    fig.tight_layout()
    return _png(fig)


def write_stress(data: dict, root: Path) -> Path:
    return _write(data, root, "stress", "Stability", stress_markdown(data), stress_plots)
