"""Coverage of `demcheck audit` on a folder of real decks (issue 28, item 8).

Run: .venv/bin/python benchmarks/audit_corpus.py DIR [--engine-runs] [--out FILE]

Every deck under DIR (a file named in.*, *.in, *.lammps or *.liggghts, or a text file whose commands include
atom_style or pair_style) is audited, one after the other, and sorted into:

- probed:          the audit ran at least one probe (its report says which fraction of pairs and walls);
- refused:         a line it cannot read (exit 2), with the line;
- nothing probed:  the audit finished without running any probe — and, counted apart, how many of those
                   still called the deck "clean" (the false clean of issue 28);
- crash:           any other exception (a traceback: a defect).

A deck is a DEM deck when it defines a granular contact (pair_style granular | gran* | hybrid with gran*, or
fix wall/gran); the goal counts DEM decks. By default the collision probes run the twin only (the engine's formulas
in the reference: reading is what this measures, and it keeps the run short); --engine-runs runs each probe in the
engine too. The probes beyond sliding (rolling, twisting, adhesion, heat: comparisons/audit_beyond.py) always run
in the engine, its twin and the closed form (a few seconds each); each row counts the sub-models its deck sets, the
probes that ran to a result, failed, or are listed with a reason, and their trap codes. The decks are public example decks gathered outside the repository (docs/audit.md says where).
"""

from __future__ import annotations

import argparse
import re
import sys
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from demcheck.errors import DemcheckError  # noqa: E402

DECK_NAME = re.compile(r"^in\.|\.in$|\.lammps$|\.liggghts$")
SKIP_SUFFIX = {".stl", ".vtk", ".data", ".dat", ".json", ".m", ".txt", ".md", ".png", ".jpg", ".pdf", ".sh",
               ".multisphere", ".test", ".vshape", ".plot", ".profile"}
COMMAND = re.compile(r"^\s*(atom_style|pair_style)\s", re.M)
GRANULAR = re.compile(r"^\s*(pair_style\s+(granular|gran\b|gran/|hybrid[^\n]*gran)|fix\s+\S+\s+\S+\s+wall/gran)",
                      re.M)


def decks(root: Path) -> list[Path]:
    out = []
    for p in sorted(root.rglob("*")):
        if not p.is_file() or (p.suffix in SKIP_SUFFIX and not DECK_NAME.search(p.name)) or "post" in p.parts:
            continue
        try:
            text = p.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue
        if DECK_NAME.search(p.name) and COMMAND.search(text) or COMMAND.search(text) and "run" in text:
            out.append(p)
    return out


def audit_one(path: Path, engine_runs: bool) -> dict:
    from demcheck.comparisons.audit import audit

    dem = bool(GRANULAR.search(path.read_text(encoding="utf-8")))
    row = {"deck": str(path), "dem": dem}
    try:
        r = audit(path, run_engine=engine_runs, beyond_engine=True)
    except DemcheckError as exc:
        row.update(outcome="refused" if getattr(exc, "exit_code", 1) == 2 else "failed",
                   why=str(exc).splitlines()[0][:200])
        return row
    except Exception as exc:  # noqa: BLE001 - a crash is what this counts
        row.update(outcome="crash", why=f"{type(exc).__name__}: {exc}"[:200],
                   trace=traceback.format_exc().splitlines()[-3:])
        return row
    pairs = r.get("pairs", [])
    probed = [p for p in pairs if p.get("probed")]  # the report's own count: a probe that measured a contact
    codes = sorted({f["code"] for f in [*r.get("findings", []), *(f for p in pairs for f in p.get("findings", []))]
                    if f["kind"] == "trap"})  # the deck's own (engine-refuses) and each pair's
    row.update(pairs=len(pairs), probed_pairs=len(probed), status=r.get("status"), traps=r.get("traps"),
               coverage=r.get("coverage"), codes=codes, units=(r.get("units") or {}).get("style"),
               speed_from=str(r.get("speed_from", ""))[:60],
               read_by="engine" if str(r.get("read_by", "")).startswith("the engine") else "reader")
    beyond = [b for p in pairs for b in p.get("beyond", [])]
    row["beyond"] = {"total": len(beyond), "ran": sum(b.get("status") == "ok" for b in beyond),
                     "failed": sum(b.get("status") == "failed" for b in beyond),
                     "listed": sum(b.get("status") == "not probed" for b in beyond),
                     "engine_vs_twin": max((b["engine_vs_twin"] for b in beyond if b.get("status") == "ok"),
                                           default=float("nan")),
                     "traps": sorted({f["code"] for p in pairs for f in p.get("findings", [])
                                      if f["kind"] == "trap" and f["code"].startswith("beyond-")}),
                     "sizes": sorted({f"{b['probe']}: " + ", ".join(f"{k} {q:.3f}×" for k, q in
                                                                      b["engine_vs_reference"].items()
                                                                      if abs(q - 1) > 0.01)
                                      for b in beyond if b.get("status") == "ok"
                                      and any(abs(q - 1) > 0.01 for q in b["engine_vs_reference"].values())})}
    row["outcome"] = "probed" if probed else "nothing probed"
    if not probed:
        row["why"] = r.get("status_reason") or "no probe ran"
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("--engine-runs", action="store_true", help="run each probe in the engine too")
    ap.add_argument("--out", type=Path, default=None, help="also write the table to this file")
    a = ap.parse_args(argv)
    rows = []
    start = time.monotonic()
    for p in decks(a.dir):
        t0 = time.monotonic()
        row = audit_one(p, a.engine_runs)
        row["seconds"] = time.monotonic() - t0
        row["deck"] = str(p.relative_to(a.dir))
        rows.append(row)
        print(f"{row['outcome']:<15} {'DEM' if row['dem'] else '   '} {row['deck']}"
              + (f"  [{row.get('probed_pairs')}/{row.get('pairs')} pairs probed, {row.get('status')}]"
                 if row["outcome"] in ("probed", "nothing probed") else "")
              + (f"  — {row['why']}" if row.get("why") else ""), flush=True)
    lines = [report_totals(rows, time.monotonic() - start, a.engine_runs)]
    print(lines[0])
    if a.out:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        body = [f"{r['outcome']:<15} {'DEM' if r['dem'] else '   '} {r['deck']}"
                + (f"  [{r.get('probed_pairs')}/{r.get('pairs')} pairs and walls probed, read by the {r.get('read_by')}, "
                   f"units {r.get('units')}, "
                   f"{r.get('status')}{': ' + ', '.join(r['codes']) if r.get('codes') else ''}]"
                   if r["outcome"] in ("probed", "nothing probed") else "")
                + (f"  — {r['why']}" if r.get("why") else "") + _beyond_text(r) for r in rows]
        a.out.write_text("\n".join(body) + "\n\n" + lines[0] + "\n", encoding="utf-8")
    return 0


def _beyond_text(r: dict) -> str:
    b = r.get("beyond") or {}
    if not b.get("total"):
        return ""
    text = (f"\n    beyond sliding: {b['total']} sub-model probe(s), {b['ran']} ran (engine, twin, closed form), "
            f"{b['failed']} failed, {b['listed']} listed with a reason"
            + (f"; largest engine − twin {b['engine_vs_twin']:.2g}" if b["ran"] else "")
            + (f"; traps: {', '.join(b['traps'])}" if b["traps"] else ""))
    return text + "".join(f"\n      {s}" for s in b["sizes"])


def _beyond_totals(rows: list) -> str:
    with_b = [r for r in rows if (r.get("beyond") or {}).get("total")]
    tot = {k: sum(r["beyond"][k] for r in with_b) for k in ("total", "ran", "failed", "listed")}
    codes = sorted({c for r in with_b for c in r["beyond"]["traps"]})
    ran = sum(r["beyond"]["ran"] > 0 for r in with_b)
    gap = max((r["beyond"]["engine_vs_twin"] for r in with_b if r["beyond"]["ran"]), default=float("nan"))
    return (f"  beyond sliding: {len(with_b)} decks set rolling, twisting, adhesion or heat; {ran} of them got a probe "
            f"that ran; probes {tot['total']}: ran {tot['ran']}, failed {tot['failed']}, listed with a reason "
            f"{tot['listed']}; largest engine − twin {gap:.2g}; traps: {', '.join(codes) or 'none'}")


def report_totals(rows: list, seconds: float, engine_runs: bool) -> str:
    dem = [r for r in rows if r["dem"]]

    def count(rs, outcome):
        return sum(r["outcome"] == outcome for r in rs)

    false_clean = sum(r["outcome"] == "nothing probed" and r.get("status") == "clean" for r in rows)
    out = [f"decks: {len(rows)} ({len(dem)} DEM decks); probes: {'engine and twin' if engine_runs else 'twin only'}"]
    for label, rs in (("all", rows), ("DEM", dem)):
        n = len(rs) or 1
        out.append(f"  {label:<4} probed {count(rs, 'probed')} ({100 * count(rs, 'probed') / n:.0f} %), "
                   f"refused {count(rs, 'refused')}, nothing probed {count(rs, 'nothing probed')}, "
                   f"failed {count(rs, 'failed')}, crashes {count(rs, 'crash')}")
    out.append(f"  nothing probed but called clean: {false_clean}")
    by_engine = [r for r in dem if r.get("read_by") == "engine"]
    out.append(f"  DEM decks read by the engine itself: {len(by_engine)} (the others by demcheck's reader: the engine "
               "has no read path there, or its read stopped — each report's read_by says why)")
    out.append(_beyond_totals(rows))
    out.append(f"  wall time {seconds:.0f} s")
    return "\n".join(out)


if __name__ == "__main__":
    sys.exit(main())
