"""The command line's text: each command's result (the dicts api.py and comparisons/ return) rendered as the lines
it prints. Pure functions of those dicts, no work and no output of their own: cli.py echoes what they return."""

from __future__ import annotations

import math

from .io import number as as_text


def show(v) -> str:
    """A value in a CLI table: the reports' formatter, ten significant digits."""
    return as_text(v, ".10g")


# ----------------------------------------------------------------------------- cases, sweep


def cases_listing(root, rows: list[dict]) -> list[str]:
    """``demcheck cases``: the shipped case files (resources.case_rows) by folder, a line each."""
    lines = [f"shipped case files ({len(rows)}), in {root}:"]
    for folder in dict.fromkeys(r["folder"] for r in rows):
        group = [r for r in rows if r["folder"] == folder]
        what = "in the default suite" if group[0]["in_default_suite"] else "run by naming them"
        lines.append(f"\n{folder or '.'}/ ({len(group)}, {what})")
        for r in group:
            law = r["kind"] if r["kind"] == "packing" else f"{r['normal']} + {r['tangential']}"
            lines.append(f"  {r['name']:44s} {law}")
    lines.append("\nrun one by its name (demcheck collide glass-pair); copy one: demcheck cases NAME > my-case.toml")
    return lines


def sweep_table(table):
    """``demcheck sweep``: its DataFrame (api.sweep) as a rich Table, a row a point."""
    from rich.table import Table

    t = Table()
    for c in table.columns:
        t.add_column(c, justify="right")
    for _, row in table.iterrows():
        t.add_row(*[show(v) if not isinstance(v, float) else f"{v:.6g}" for v in row])
    return t


def validation(val) -> list[str]:
    """``demcheck validate`` (its records.Validation): the checks counted by kind and verdict, the reference's
    misses, and the laws' own misses (reported, not failed: the model's finding, which the reference computes
    faithfully)."""
    counts: dict = {}
    for c in val.checks:
        counts[(c.kind, c.verdict)] = counts.get((c.kind, c.verdict), 0) + 1
    lines = ["validation: " + ", ".join(f"{k} {v}: {n}" for (k, v), n in sorted(counts.items()))]
    for c in val.failed:
        lines.append(f"reference misses {c.expected} in {c.file}: {c.deviation:.3g} > {c.tolerance:.3g}")
    for c in val.checks:
        if c.law and c.source == "reference":
            lines.append(f"the law's own miss (not a failure) of {c.expected} in {c.file}: "
                         f"{c.deviation:.3g} > {c.tolerance:.3g} (its force pushes along the slip at contact "
                         "onset; the report says why)")
    return lines


def packing(out: dict) -> list[str]:
    """``demcheck pack``: the source, the particles and each packing metric (the fabric tensor a row a line)."""
    lines = [f"{out['case']} in {out['source']}: {out['particles']} particles"]
    for k, v in out["metrics"].items():
        if k == "fabric":  # the 3 × 3 tensor, a row a line
            for label, row in zip(("fabric (x)", "       (y)", "       (z)"), v):
                lines.append(f"  {label:22s} {' '.join(f'{show(c):>16s}' for c in row)}")
        else:
            lines.append(f"  {k:22s} {show(v)}")
    return lines


# ----------------------------------------------------------------------------- models


def models_table(table: list[dict], names) -> list[str]:
    """``demcheck models``: one line a model (slot, id, seed name, each engine's fidelity); fits 80 columns."""
    def cut(text, width):
        return text if len(text) < width else text[:width - 2] + "… "

    short = {"approximate": "approx"}
    widths = {n: max(len(n) + 1, 7) for n in names}  # "approx" and a space, or the engine's name
    seed_w = max(8, min(15, 80 - 27 - sum(widths.values())))  # the seed name gives way to engine columns
    lines = [f"{'slot':<11}{'id':<16}{'seed':<{seed_w}}" + "".join(f"{n:<{widths[n]}}" for n in names).rstrip()]
    for row in table:
        lines.append((f"{row['slot']:<11}{row['id']:<16}{cut(row['seed_name'], seed_w):<{seed_w}}"
                      + "".join(f"{short.get(f := row['engines'][n]['fidelity'], f):<{widths[n]}}"
                                for n in names)).rstrip())
    lines.append("\napprox = approximate. Rolling, twisting, adhesion, heat: each engine's\n"
                 "mapping in its scenario (the suite's beyond-* cases). `demcheck models ID`\n"
                 "shows a model in full, with each engine's reasons; --json gives everything.")
    return lines


def model_details(table: list[dict], engines) -> list[str]:
    """``demcheck models ID``: each model in full — formula, source, parameters, each engine's configuration and
    reason (``engines``: the registered Engine objects, for their releases)."""
    lines = []
    for row in table:
        lines.append(f"{row['id']} ({row['slot']}; seed name {row['seed_name']}"
                     + (f"; aliases {', '.join(row['aliases'])}" if row["aliases"] else "") + f"): {row['title']}")
        lines.append(f"  formula: {row['formula']}")
        lines.append(f"  source:  {row['source']}")
        lines += [f"  {p}: {meaning}" for p, meaning in row["params"].items()]
        for e in engines:
            m = row["engines"][e.name]
            lines.append(f"  {e.release}: {m['fidelity']} (with {m['with']})" + (f": {m['config']}" if m["config"] else ""))
            if m["reason"]:
                lines.append(f"    {m['reason']}")
    return lines


def reverse_lookup(engine: str, r: dict) -> list[str]:
    """``demcheck models --engine E SETTING``: the native setting's nearest seed model, what it asks for and
    implies, the probes, notes and traps (comparisons/audit.reverse's dict); every line safe to print."""
    from .comparisons.audit import safe_text

    pair, s = r["pair"], r["seed"]
    lines = [f"{engine}: {r['native']}"]
    if s is None:
        lines.append("  nearest seed model: none (demcheck has no twin of this law); fidelity none")
    elif r["fidelity"] == "failed":
        lines.append(f"  nearest seed model: normal {s['normal']}, tangential {s['tangential']} — FAILED: the probes "
                     "measured no contact to compare: " + "; ".join(r["failures"]))
    else:
        lines.append(f"  nearest seed model: normal {s['normal']}, tangential {s['tangential']} — {r['fidelity']}"
                     f" (largest gap {r['gap']:.3g} between its converged contact and the seed model's at "
                     f"{pair['speed']:g} m/s, " + ", ".join(f"{p['angle']:g}°" for p in r["probes"]) + ")"
                     + (f"; {'; '.join(s['reasons'])}" if s["reasons"] else ""))
    if r["asked"]:
        lines.append("  asks for: " + ", ".join(f"{k} {v:g}" for k, v in r["asked"].items()))
    if r["implied"]:
        lines.append(f"  implied (like pair, R = {pair['radius']:g} m, ρ = {pair['density']:g} kg/m³): "
                     + ", ".join(f"{k} {v:.6g}" if isinstance(v, float) else f"{k} {v}"
                                 for k, v in r["implied"].items()))
    for p in r.get("probes", []):
        tw, sd = p["twin"], p["seed"]
        lines.append(f"  {p['angle']:>3g}°: e {tw['restitution']:.4f} (seed {sd['restitution']:.4f})"
                     + (f", et {tw['tangential_restitution']:.4f} (seed {sd['tangential_restitution']:.4f})"
                        if math.isfinite(tw["tangential_restitution"]) else "")
                     + f", tc {tw['contact_time']:.4g} s (seed {sd['contact_time']:.4g} s)")
    lines += [f"  note: {n}" for n in r["notes"]]
    lines += [f"  {f['kind'].upper()} [{f['code']}]: {f['text']}" for f in r["findings"]]
    lines.append("  `demcheck audit DECK` measures each trap in the engine (docs/audit.md)")
    return [safe_text(line) for line in lines]


# ----------------------------------------------------------------------------- collide


def summary_tables(s: dict):
    """``demcheck collide`` of one source: (its heading, its metrics table, its parameters table, its note or
    None), the tables rich's."""
    from rich.table import Table

    m = s["model"]
    head = f"[bold]{s['case']}[/]  normal={m['normal']} tangential={m['tangential']}"
    head += f" limit_force={m['limit_force']}  method={s['method']}"
    head += f"  dt={show(s['dt'])}" if s["dt"] else f"  rtol={show(s['rtol'])}"
    t = Table(show_header=True)
    t.add_column("metric")
    t.add_column("value", justify="right")
    for k, v in s["metrics"].items():
        t.add_row(k, show(v))
    p = Table(show_header=True)
    p.add_column("parameter")
    p.add_column("value", justify="right")
    for k, v in s["params"].items():
        p.add_row(k, show(v))
    return head, t, p, (f"note: {s['message']}" if s.get("message") else None)


def side_by_side(summaries: dict, skipped: dict) -> list:
    """``demcheck collide`` of several sources: what to print in order — the heading, a rich table of every metric
    per source, each engine's message and each source skipped and why."""
    from rich.table import Table

    out: list = []
    first = next(iter(summaries.values()), None)
    if first is not None:
        m = first["model"]
        out.append(f"[bold]{first['case']}[/]  normal={m['normal']} tangential={m['tangential']} "
                   f"limit_force={m['limit_force']}")
    t = Table(show_header=True)
    t.add_column("metric")
    for name, s in summaries.items():
        t.add_column(name if s["source"] == "reference" else f"{name} ({s['engine_version']})", justify="right")
    for k in list(first["metrics"]) if first else []:
        t.add_row(k, *[show(s["metrics"].get(k)) for s in summaries.values()])
    t.add_row("dt / rtol", *[show(s["dt"] or s["rtol"]) for s in summaries.values()])
    t.add_row("mapping", *[str(s["params"].get("mapping", "—")) for s in summaries.values()])
    out.append(t)
    out += [f"{name}: {s['message']}" for name, s in summaries.items() if s["source"] != "reference" and s["message"]]
    out += [f"{name}: skipped — {why}" for name, why in skipped.items()]
    return out


# ----------------------------------------------------------------------------- bench, stress, dt


def _twin(engine: str) -> str:
    from .comparisons.sources import Source

    return Source.of(engine, twin=True).label


def bench_native(case: str, engine: str, law: dict, seed: dict) -> list[str]:
    """What bench measured a native law against, and how far its converged answer lies from the seed model's
    (``seed``: its converged metrics), after the report."""
    lines = [f"{case}: {engine} runs the case's own setting ({law['native']}); {engine} and {_twin(engine)} are "
             f"measured against {_twin(engine)} converged ({law['converged_by']})"]
    gap = {k: v for k, v in (law.get("seed_gap") or {}).items() if math.isfinite(v)}
    if gap:
        k = max(gap, key=gap.get)
        e_n, e_s = law["converged"].get("restitution"), seed.get("restitution")
        lines.append(f"  the seed model of [contact] is another law: converged, they differ by up to {gap[k]:.3g} "
                     f"({k})" + (f"; restitution {e_n:.4f} native, {e_s:.4f} seed" if e_n is not None and
                                 e_s is not None and math.isfinite(e_n) and math.isfinite(e_s) else ""))
    if law.get("note"):
        lines.append(f"  note: {law['note']}")
    return lines


def stress_native(case: str, engine: str, native: str) -> str:
    """What stress's limits of a native law are in and flagged against (after the report)."""
    from .comparisons.sources import VERLET

    return (f"{case}: {engine} runs the case's own setting ({native}): {engine} and {_twin(engine)}'s dt_max / t_c "
            f"are in that law's elastic contact time, and {engine} is flagged against {_twin(engine)}, not the seed "
            f"model's {VERLET.label}")


def recommendation(rec: dict, target: float) -> list[str]:
    """``demcheck dt``: the times, the rules of thumb, the recommended step, and each native law's."""
    lines = [f"{rec['case']}: normal={rec['model']['normal']} tangential={rec['model']['tangential']}",
             f"  elastic contact time t_c = {rec['t_contact']:.4g} s; Hertz time {rec['hertz_time']:.4g} s; "
             f"Rayleigh time {rec['rayleigh_time']:.4g} s",
             f"  rules of thumb: 0.2 t_Rayleigh = {rec['rules_of_thumb']['0.2 t_Rayleigh']:.4g} s, "
             f"t_Hertz/50 = {rec['rules_of_thumb']['t_Hertz / 50']:.4g} s"]
    if rec["dt"] is None:
        lines.append(f"  {rec['message']}")
    else:
        lines.append(f"  recommended dt = {rec['dt']:.4g} s ({rec['steps_per_contact']:g} steps per contact, "
                     f"{rec['dt_over_rayleigh']:.3g} t_Rayleigh): expected error {rec['expected_error']:.2g} "
                     f"in {rec['limited_by']} (target {target:g}; measured order {rec['order']:.2f}; errors of "
                     f"{', '.join(rec['metrics'])})")
    for engine, n in rec["natives"].items():
        lines.append(f"{engine} (the case's own setting: {n['native']}): elastic contact time {n['t_contact']:.4g} s")
        if n["dt"] is None:
            lines.append(f"  {n['message']}")
        else:
            lines.append(f"  recommended dt = {n['dt']:.4g} s ({n['steps_per_contact']:g} steps per contact): "
                         f"expected error {n['expected_error']:.2g} in {n['limited_by']} against {_twin(engine)} "
                         f"converged ({n['converged_by']}; measured order {n['order']:.2f}; errors of "
                         f"{', '.join(n['metrics'])}; the engine computes its twin's numbers)")
        if n["note"]:
            lines.append(f"  note: {n['note']}")
    return lines
