"""Coverage of `demcheck audit` on Yade scripts and Kratos DEM projects (issue 31, item 3).

Run: .venv/bin/python benchmarks/audit_corpus_yk.py DIR [--engine-runs] [--out FILE]

Every Yade script (*.py) and Kratos project (ProjectParameters*.json) under DIR is audited, one after the other
(twin only by default: reading is what this measures; --engine-runs runs each probe in the engine too), and
sorted into: probed (with the fraction of its pairs and walls), refused (exit 2, with the one line), nothing
probed (the audit read it and ran no probe: "not audited", never clean — with the reasons), crash (any other
exception: a defect). A *DEM input* is one with a contact law the audit reads: a Yade script whose O.engines
has an Ip2 functor, a Kratos project whose materials name a discontinuum law. The inputs are public example
files gathered outside the repository (docs/audit.md says where).
"""

from __future__ import annotations

import argparse
import re
import sys
import time
import traceback
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from demcheck.errors import DemcheckError  # noqa: E402

YADE_DEM = re.compile(r"\bIp2_\w+")
KRATOS_DEM = re.compile(r"DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME")


def inputs(root: Path) -> list[Path]:
    out = []
    for p in sorted(root.rglob("*")):
        if p.is_file() and (p.suffix == ".py" or (p.suffix == ".json" and p.name.startswith("ProjectParameters"))):
            out.append(p)
    return out


def is_dem(p: Path) -> bool:
    try:
        text = p.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    if p.suffix == ".py":
        return bool(YADE_DEM.search(text))
    mats = list(p.parent.glob("Materials*.json"))
    return any(KRATOS_DEM.search(m.read_text(encoding="utf-8", errors="replace")) for m in mats)


def audit_one(path: Path, engine_runs: bool) -> dict:
    from demcheck.comparisons.audit import audit

    row = {"input": str(path), "dem": is_dem(path)}
    try:
        r = audit(path, run_engine=engine_runs)
    except DemcheckError as exc:
        row.update(outcome="refused" if getattr(exc, "exit_code", 1) == 2 else "failed",
                   why=str(exc).splitlines()[0][:220])
        return row
    except Exception as exc:  # noqa: BLE001 - a crash is what this counts
        row.update(outcome="crash", why=f"{type(exc).__name__}: {exc}"[:220],
                   trace=traceback.format_exc().splitlines()[-3:])
        return row
    pairs = r.get("pairs", [])
    probed = [p for p in pairs if p.get("probed")]
    codes = sorted({f["code"] for p in pairs for f in p.get("findings", []) if f["kind"] == "trap"})
    notes = sorted({f["code"] for p in pairs for f in p.get("findings", []) if f["kind"] == "note"}
                   | {f["code"] for f in r.get("findings", []) if f.get("kind") == "note"})
    row.update(pairs=len(pairs), probed_pairs=len(probed), status=r.get("status"), codes=codes, notes=notes)
    row["outcome"] = "probed" if probed else "nothing probed"
    if not probed:
        row["why"] = (r.get("status_reason") or "no probe ran")[:220]
    return row


def line(r: dict) -> str:
    return (f"{r['outcome']:<15} {'DEM' if r['dem'] else '   '} {r['input']}"
            + (f"  [{r.get('probed_pairs')}/{r.get('pairs')} pairs and walls probed, {r.get('status')}"
               f"{': ' + ', '.join(r['codes']) if r.get('codes') else ''}]"
               if r["outcome"] in ("probed", "nothing probed") else "")
            + (f"  — {r['why']}" if r.get("why") else ""))


def totals(rows: list, seconds: float, engine_runs: bool) -> str:
    out = []
    for name, rs in (("all inputs", rows), ("DEM inputs", [r for r in rows if r["dem"]])):
        c = Counter(r["outcome"] for r in rs)
        n = len(rs) or 1
        out.append(f"{name}: {len(rs)} — probed {c['probed']} ({100 * c['probed'] / n:.0f} %), refused "
                   f"{c['refused']}, failed {c['failed']}, nothing probed {c['nothing probed']} (called clean: "
                   f"{sum(r['outcome'] == 'nothing probed' and r.get('status') == 'clean' for r in rs)}), "
                   f"crashes {c['crash']}")
    reasons = Counter(re.sub(r"^[^:]*:\d*:? ?", "", r.get("why", ""))[:90] for r in rows
                      if r["outcome"] in ("refused", "nothing probed") and r["dem"])
    out.append("most frequent reasons (DEM inputs not probed):")
    out += [f"  {k:>3} × {why}" for why, k in reasons.most_common(12)]
    out.append(f"({'engine runs' if engine_runs else 'twin only'}; {seconds:.0f} s)")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("--engine-runs", action="store_true", help="run each probe in the engine too")
    ap.add_argument("--out", type=Path, default=None, help="also write the table to this file")
    a = ap.parse_args(argv)
    rows, start = [], time.monotonic()
    for p in inputs(a.dir):
        t0 = time.monotonic()
        row = audit_one(p, a.engine_runs)
        row["seconds"] = time.monotonic() - t0
        row["input"] = str(p.relative_to(a.dir))
        rows.append(row)
        print(line(row), flush=True)
        if row["outcome"] == "crash":
            print("   ", " | ".join(row["trace"]), flush=True)
    summary = totals(rows, time.monotonic() - start, a.engine_runs)
    print(summary)
    if a.out:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text("\n".join(line(r) for r in rows) + "\n\n" + summary + "\n", encoding="utf-8")
    return 1 if any(r["outcome"] == "crash" for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
