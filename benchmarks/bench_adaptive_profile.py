"""Where the adaptive 3-D method's time goes (issue 33 item 3: "profile its steps, events and rejected steps").

For every variant of the suite's oblique cases (cases/suite/oblique-*.toml, adaptive3d_suite_child.variants) at
its default tolerance (run.rtol 1e-13), the arguments `collide()` hands the kernel (adaptive3d.adaptive_3d) are
taken, and the kernel is run twice:

* compiled, as the suite runs it: its CPU time (time.process_time: the machine is shared with other long runs,
  and a solve's CPU time depends far less on their load than its wall time; median of REPEAT, one run for a solve
  over 0.3 s) and its output;
* in a child process with NUMBA_DISABLE_JIT=1, the same source run as plain Python, with counters wrapped round
  the kernel's helpers (module globals, looked up at each call in plain Python): every call of the right-hand side
  ``rhs``, attributed to what called it from the driver — the DP5 step (its first stage and the 6 stages of
  ``_dp5_from``), the event functions at a step's end (``_event_values``/``_event_value``), the location of an
  event (``_locate``: its first stage, then 6 stages and one event function per trial step), the step to the
  located event (``_dp5_3``), the record of a point (``_record``), and the fixes after a step or an event
  (``_settle``, ``_ride_truncate``, ``_onto_surface``, the stick/slip switch); the rejected steps (calls of
  ``shrink``), the accepted steps without an event (calls of ``grow``), every located crossing (``_locate``) and
  its trial steps (``illinois_step``, one per trial).

No line of the kernel changes for this, so no result can move; what must hold instead is that the counted run is
the compiled run: the child's output (status, points, every record row, every event time and code) is compared
bit for bit with the compiled kernel's ("bits" column: "same" or "DIFFER"). Where it is the same, the counts are
exactly those of the compiled run's trajectory.

The cost of one rhs: a compiled loop calls the compiled ``rhs`` on a sample of the very states the kernel evaluated
it at (every k-th call of the counted run, ≤ SAMPLE states, with their modes), ~RHS_CALLS calls per variant,
CPU time. The kernel's time is then set beside rhs evaluations × that cost (the rest: the DP5 stage arithmetic,
the error norm, the event logic, the records' kinematics, the driver). The kernel's fixed part: the same call with
t_max = 0 (it returns after its first record: the output arrays' allocation, the first rhs, the call itself).

Run: .venv/bin/python benchmarks/bench_adaptive_profile.py [--repeat N] [--only oblique-lth ...] [--rtol R --append]
(writes benchmarks/results/bench_adaptive_profile.txt, OUT=path to write elsewhere; --rtol solves every variant at
run.rtol R instead of its own, --append adds the report to the file instead of replacing it, and --by-mode times the
rhs sample split by the contact's mode too)
      .venv/bin/python benchmarks/bench_adaptive_profile.py --derive
(reads the file's per-variant tables, runs nothing, and appends what follows from them: per law the event location's
rhs evaluations and their cost, loc × µs/rhs, and per variant the medians of each part's evaluations a point)
      .venv/bin/python benchmarks/bench_adaptive_profile.py --before TREE [--bits-only] [--only oblique-ddt ...]
(TREE: the root of a tree before a change, e.g. `git worktree add --detach /tmp/before BASE`. Each tree's compiled
kernel, in a child process of its own, on every variant: their outputs compared bit for bit; then each tree's
kernel source counted as above, both at once: rhs evaluations per point and by part, before and after. Writes
benchmarks/results/bench_adaptive_reuse.txt, REUSE_OUT=path to write elsewhere; nothing is timed — the kernel's CPU
time before and after is bench_adaptive.py --before TREE --only-suite)
"""

import argparse
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, os.environ.get("DEMCHECK_SRC") or str(ROOT / "src"))  # (--before: a child runs another tree)
sys.path.insert(0, str(ROOT / "benchmarks"))

from adaptive3d_suite_child import variants  # noqa: E402

OUT = Path(os.environ.get("OUT", ROOT / "benchmarks" / "results" / "bench_adaptive_profile.txt"))
SAMPLE = 4096  # rhs states kept from a counted run, for the cost of one rhs
RHS_CALLS = 200_000  # compiled rhs calls timed per variant

# what called rhs from the driver (the outermost helper of adaptive3d.py below adaptive_3d) → its part
PARTS = ("step", "step-end events", "locate", "to event", "record", "fix")
OUTER = {"_dp5_from": "step", "_event_values": "step-end events", "_event_value": "step-end events",
         "_locate": "locate", "_dp5_3": "to event", "_record": "record", "_settle": "fix", "_ride_truncate": "fix",
         "_onto_surface": "fix"}


def kernel_args(raw: dict) -> tuple:
    """The arguments collide() passes the adaptive kernel for this case (the kernel itself is not run)."""
    from demcheck import case as C
    from demcheck.laws.model import resolve
    from demcheck.reference import adaptive3d, collision3d

    class Taken(Exception):
        pass

    got = []

    def take(*a):
        got.append(a)
        raise Taken

    case = C.from_dict(raw)
    model = resolve(case)
    orig = adaptive3d.adaptive_3d
    collision3d.adaptive3d.adaptive_3d = take
    try:
        collision3d.collide(case, model, "adaptive")
    except Taken:
        pass
    finally:
        collision3d.adaptive3d.adaptive_3d = orig
    return got[0]


# ----------------------------------------------------------------------------------------- the counted (child) run


def counted_run(args: tuple) -> dict:
    """adaptive_3d(*args) as plain Python (NUMBA_DISABLE_JIT=1) with its helpers counted."""
    from demcheck.reference import adaptive3d as A

    assert not hasattr(A.adaptive_3d, "py_func"), "the counted run needs NUMBA_DISABLE_JIT=1"
    here = A.__file__
    src, first = __import__("inspect").getsourcelines(A.adaptive_3d)
    # the step's first stage (``rhs(…, k1)`` or ``f1 = rhs(…, k1)``: the tree before the reuse of f(yn), and since)
    k1_line = first + next(i for i, s in enumerate(src) if s.strip().endswith("rhs(y, aux, nl, tl, geo, rules, k1)"))
    c = {"rhs": dict.fromkeys(PARTS, 0), "by_site": {}, "rejected": 0, "accepted": 0, "attempts": 0,
         "trials": 0, "per_locate": [], "calls": 0, "stride": 1, "Y": [], "AUX": []}
    saved = {k: getattr(A, k) for k in ("rhs", "shrink", "grow", "illinois_step", "_locate", "_dp5_from")}

    def rhs(y, aux, *rest):
        f = sys._getframe(1)
        outer, top = None, None
        while f is not None:
            if f.f_code.co_filename == here:
                if f.f_code.co_name == "adaptive_3d":
                    top = f
                    break
                outer = f.f_code.co_name
            f = f.f_back
        if outer is None:  # called by the driver itself
            site = f"adaptive_3d:{top.f_lineno}"
            part = "step" if top.f_lineno == k1_line else "fix"
        else:
            site, part = outer, OUTER[outer]
        c["rhs"][part] += 1
        c["by_site"][site] = c["by_site"].get(site, 0) + 1
        if c["calls"] % c["stride"] == 0:
            c["Y"].append(np.array(y, dtype=np.float64))
            c["AUX"].append(np.array(aux, dtype=np.float64))
            if len(c["Y"]) >= 2 * SAMPLE:
                c["Y"], c["AUX"], c["stride"] = c["Y"][::2], c["AUX"][::2], 2 * c["stride"]
        c["calls"] += 1
        return saved["rhs"](y, aux, *rest)

    def shrink(e):
        c["rejected"] += 1
        return saved["shrink"](e)

    def grow(e):
        c["accepted"] += 1
        return saved["grow"](e)

    def illinois_step(*a):
        c["trials"] += 1
        return saved["illinois_step"](*a)

    def _locate(*a):
        before = c["trials"]
        out = saved["_locate"](*a)
        c["per_locate"].append(c["trials"] - before)
        return out

    def _dp5_from(*a):
        if sys._getframe(1).f_code.co_name == "adaptive_3d":
            c["attempts"] += 1
        return saved["_dp5_from"](*a)

    for k, v in (("rhs", rhs), ("shrink", shrink), ("grow", grow), ("illinois_step", illinois_step),
                 ("_locate", _locate), ("_dp5_from", _dp5_from)):
        setattr(A, k, v)
    try:
        t0 = time.process_time()
        out = A.adaptive_3d(*args)
        c["python_s"] = time.process_time() - t0
    finally:
        for k, v in saved.items():
            setattr(A, k, v)
    c["Y"], c["AUX"] = np.array(c["Y"]), np.array(c["AUX"])
    c["out"] = out
    return c


def cases(only: tuple, rtol: float | None):
    """The suite's oblique variants, at run.rtol ``rtol`` when given (their own, 1e-13, when not)."""
    for label, raw in variants(only):
        if rtol:
            raw.setdefault("run", {})["rtol"] = rtol
        yield label, raw


def child(where: Path, only: tuple, rtol: float | None) -> None:
    for i, (label, raw) in enumerate(cases(only, rtol)):
        c = counted_run(kernel_args(raw))
        with open(where / f"{i:04d}.pkl", "wb") as f:
            pickle.dump((label, c), f)
        print(f"counted {label}: {c['out'][1]} points, {c['calls']} rhs, {c['python_s']:.1f} s", file=sys.stderr,
              flush=True)


# ------------------------------------------------------------------------------------------ the compiled timings


def _rhs_loop_kernel():
    from numba import njit

    from demcheck.reference.adaptive3d import rhs

    @njit
    def rhs_loop(Y, AUX, nl, tl, geo, rules, reps):
        dy = np.empty(21)
        acc = 0.0
        for _ in range(reps):
            for i in range(Y.shape[0]):
                lam, fn, req, ft = rhs(Y[i], AUX[i], nl, tl, geo, rules, dy)
                acc += lam + fn + dy[0]
        return acc

    return rhs_loop


def cpu(fn, repeat: int) -> tuple[float, object]:
    """Median CPU time of fn() (warm: one call first; a single call when that one took over 0.3 s)."""
    t0 = time.process_time()
    out = fn()
    once = time.process_time() - t0
    if once > 0.3:
        return once, out
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return statistics.median(times), out


def same_bits(a, b) -> bool:
    """Two kernel outputs (status, n, rec, ne, ev_t, ev_c) equal to the last bit."""
    return (int(a[0]) == int(b[0]) and int(a[1]) == int(b[1]) and int(a[3]) == int(b[3])
            and all(np.asarray(x).tobytes() == np.asarray(y).tobytes() and np.shape(x) == np.shape(y)
                    for x, y in ((a[2], b[2]), (a[4], b[4]), (a[5], b[5]))))


def git_head() -> str:
    def git(*a):
        return subprocess.run(["git", "-C", str(ROOT), *a], capture_output=True, text=True).stdout.strip()

    dirty = git("status", "--porcelain", "--untracked-files=no")
    return git("rev-parse", "--short", "HEAD") + (" (with uncommitted changes)" if dirty else "")


def fit(x, y):
    """Least squares y = a x + b."""
    a, b = np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)
    return a, b


def main(repeat: int, only: tuple, rtol: float | None = None, append: bool = False, by_mode: bool = False) -> None:
    if not any(True for _ in variants(only)):
        sys.exit(f"no suite oblique case file named {' '.join(only)}")
    load0 = os.getloadavg()
    started = datetime.now(timezone.utc)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.time()
        env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(ROOT / "src"))
        subprocess.run([sys.executable, __file__, "--child", tmp, *(["--rtol", repr(rtol)] if rtol else []), *only],
                       env=env, check=True)
        child_wall = time.time() - t0
        counted = []
        for p in sorted(Path(tmp).glob("*.pkl")):
            with open(p, "rb") as f:
                counted.append(pickle.load(f))

    from demcheck.reference import adaptive3d

    rhs_loop = _rhs_loop_kernel()
    raws = dict(cases(only, rtol))
    first = kernel_args(next(iter(raws.values())))
    adaptive3d.adaptive_3d(*first[:7], 0.0, first[8])  # the compiled kernel loaded (numba's cache) before any timing
    rows = []
    for label, c in counted:
        args = kernel_args(raws[label])
        k, out = cpu(lambda: adaptive3d.adaptive_3d(*args), repeat)
        y0, nl, tl, geo, rules, rtol, scales, t_max, capacity = args
        fixed, _ = cpu(lambda: adaptive3d.adaptive_3d(y0, nl, tl, geo, rules, rtol, scales, 0.0, capacity), 50)
        Y, AUX = np.ascontiguousarray(c["Y"]), np.ascontiguousarray(c["AUX"])
        reps = max(1, RHS_CALLS // len(Y))
        rhs_loop(Y[:1], AUX[:1], nl, tl, geo, rules, 1)  # compiled once, on the first variant
        t0 = time.process_time()
        rhs_loop(Y, AUX, nl, tl, geo, rules, reps)
        per_rhs = (time.process_time() - t0) / (reps * len(Y))
        modes = {}
        if by_mode:  # the same sample split by the contact's mode: before contact, sticking, slipping
            from demcheck.reference.kernels import M_PRE
            from demcheck.reference.kernels3d import A_NMODE, A_TMODE, SLIP

            free = AUX[:, A_NMODE] == M_PRE
            slip = ~free & (AUX[:, A_TMODE] == SLIP)
            for name, m in (("free", free), ("stick", ~free & ~slip), ("slip", slip)):
                if m.sum() >= 16:
                    Ym, Am = np.ascontiguousarray(Y[m]), np.ascontiguousarray(AUX[m])
                    rm = max(1, RHS_CALLS // 2 // len(Ym))
                    t0 = time.process_time()
                    rhs_loop(Ym, Am, nl, tl, geo, rules, rm)
                    modes[name] = (m.mean(), (time.process_time() - t0) / (rm * len(Ym)))
        rhs_total = sum(c["rhs"].values())
        rows.append({"label": label, "file": label.split("[")[0], "status": int(out[0]), "points": int(out[1]),
                     "events": int(out[3]), "kernel": k, "fixed": fixed, "per_rhs": per_rhs, "rhs": c["rhs"],
                     "rhs_total": rhs_total, "by_site": c["by_site"], "attempts": c["attempts"],
                     "rejected": c["rejected"], "accepted": c["accepted"], "locates": len(c["per_locate"]),
                     "trials": c["trials"], "max_trials": max(c["per_locate"], default=0),
                     "same": same_bits(out, c["out"]), "python_s": c["python_s"], "sampled": len(Y),
                     "modes": modes})
        print(f"timed {label}: kernel {k * 1e3:.2f} ms, rhs {per_rhs * 1e6:.2f} us", file=sys.stderr, flush=True)
    load1 = os.getloadavg()
    text = report(rows, started, load0, load1, repeat, child_wall, rtol)
    print(text)
    OUT.write_text((OUT.read_text() + "\n" if append and OUT.exists() else "") + text)


# ------------------------------------------------------------- --before: the tree before a change and this one


def outputs_child(where: Path, only: tuple) -> None:
    """The compiled kernel's output for every variant, from the tree on DEMCHECK_SRC, pickled into ``where``."""
    from demcheck.reference import adaptive3d

    print(f"compiled outputs of {adaptive3d.__file__}", file=sys.stderr, flush=True)
    outs = {label: adaptive3d.adaptive_3d(*kernel_args(raw)) for label, raw in cases(only, None)}
    with open(where / "outputs.pkl", "wb") as f:
        pickle.dump(outs, f)


def _children(before: Path, flag: str, only: tuple, jit: bool) -> dict:
    """``flag`` (--outputs or --child) run in two child processes at once, one per tree (DEMCHECK_SRC)."""
    got, procs = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for name, src in (("before", before / "src"), ("after", ROOT / "src")):
            (Path(tmp) / name).mkdir()
            env = dict(os.environ, PYTHONPATH=str(src), DEMCHECK_SRC=str(src))
            env.pop("NUMBA_DISABLE_JIT", None)
            if not jit:
                env["NUMBA_DISABLE_JIT"] = "1"
            procs.append((name, subprocess.Popen([sys.executable, __file__, flag, str(Path(tmp) / name), *only],
                                                 env=env)))
        for name, p in procs:
            if p.wait() != 0:
                sys.exit(f"the {name} tree's {flag} child failed")
            got[name] = {}
            for f in sorted((Path(tmp) / name).glob("*.pkl")):
                with open(f, "rb") as fh:
                    obj = pickle.load(fh)
                if flag == "--outputs":
                    got[name].update(obj)
                else:
                    got[name][obj[0]] = obj[1]
    return got


def before_after(before: Path, only: tuple, out: Path, bits_only: bool = False) -> None:
    """The compiled kernel of both trees compared bit for bit on every variant, and both trees' rhs evaluations
    counted (the same source as plain Python, each counted run's output compared with its tree's compiled one)."""
    load0 = os.getloadavg()
    started = datetime.now(timezone.utc)
    t0 = time.time()
    compiled = _children(before, "--outputs", only, jit=True)
    if bits_only:
        for label, cb in compiled["before"].items():
            print(f"{label:36s} {'same' if same_bits(cb, compiled['after'][label]) else 'DIFFER'}")
        nsame = sum(same_bits(cb, compiled["after"][k]) for k, cb in compiled["before"].items())
        print(f"compiled before = compiled after, bit for bit: {nsame} of {len(compiled['before'])} variants "
              "(nothing written)")
        return
    counted = _children(before, "--child", only, jit=False)
    wall = time.time() - t0
    load1 = os.getloadavg()
    med = statistics.median
    L = [f"adaptive 3-D method, rhs evaluations before ({before}, git "
         + subprocess.run(["git", "-C", str(before), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True).stdout.strip()
         + f") and after (git {git_head()}), the suite's oblique cases at their default tolerance (run.rtol 1e-13): "
         f"{started:%d %b %Y %H:%M} UTC, {wall:.0f} s wall",
         f"load average (1, 5, 15 min) at the start {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, at the end "
         f"{load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} (2 cores, shared; nothing here is timed)",
         "compiled: each tree's compiled adaptive_3d (a child process with PYTHONPATH on its src), before vs after "
         "bit for bit: status, points, every record row, every event time and code; counted: each tree's kernel "
         "source run as plain Python (NUMBA_DISABLE_JIT=1) with rhs counted by caller (as above), its output "
         "bit for bit its tree's compiled one. Parts: step (first stages + 6 stages an attempt), end (event functions "
         "at a step's ends), loc, to-ev, rec, fix (as in section 1 of the profile)",
         f"{'variant':36s} {'pts':>6s} {'compiled':>8s} {'counted':>7s} {'rhs before':>10s} {'after':>8s} "
         f"{'/pt before':>10s} {'after':>6s} {'saved':>6s}   " + " ".join(f"{p[:5]:>13s}" for p in
                                                                          ("step", "end", "rec", "fix"))]
    labels = list(compiled["before"])
    rows = []
    for label in labels:
        cb, ca = compiled["before"][label], compiled["after"][label]
        nb, na = counted["before"][label], counted["after"][label]
        bits = same_bits(cb, ca)
        counted_same = same_bits(nb["out"], cb) and same_bits(na["out"], ca)
        rb, ra = sum(nb["rhs"].values()), sum(na["rhs"].values())
        pts = int(ca[1])
        rows.append({"label": label, "file": label.split("[")[0], "bits": bits, "counted": counted_same,
                     "pts": pts, "rb": rb, "ra": ra, "pb": nb["rhs"], "pa": na["rhs"], "sb": nb["by_site"],
                     "sa": na["by_site"]})
        L.append(f"{label:36s} {pts:6d} {'same' if bits else 'DIFFER':>8s} {'same' if counted_same else 'DIFFER':>7s} "
                 f"{rb:10d} {ra:8d} {rb / int(cb[1]):10.2f} {ra / pts:6.2f} {1 - ra / rb:6.1%}   "
                 + " ".join(f"{nb['rhs'][p]:>6d}/{na['rhs'][p]:<6d}" for p in
                            ("step", "step-end events", "record", "fix")))
    nsame = sum(r["bits"] for r in rows)
    ncount = sum(r["counted"] for r in rows)
    tb, ta = sum(r["rb"] for r in rows), sum(r["ra"] for r in rows)
    L += ["", f"compiled before = compiled after, bit for bit (status, points, every record row, every event): "
              f"{nsame} of {len(rows)} variants; counted run = its tree's compiled run, both trees: {ncount} of "
              f"{len(rows)}",
          f"rhs per point: median {med(r['rb'] / r['pts'] for r in rows):.2f} before, "
          f"{med(r['ra'] / r['pts'] for r in rows):.2f} after; saved per point: median "
          f"{med((r['rb'] - r['ra']) / r['pts'] for r in rows):.2f} (least "
          f"{min((r['rb'] - r['ra']) / r['pts'] for r in rows):.2f}, most "
          f"{max((r['rb'] - r['ra']) / r['pts'] for r in rows):.2f}); share of a variant's evaluations saved: median "
          f"{med(1 - r['ra'] / r['rb'] for r in rows):.1%} (least {min(1 - r['ra'] / r['rb'] for r in rows):.1%}, "
          f"most {max(1 - r['ra'] / r['rb'] for r in rows):.1%})",
          f"all {len(rows)} variants: {tb} evaluations before, {ta} after ({1 - ta / tb:.1%} fewer); by part, before → "
          "after: " + ", ".join(f"{p} {sum(r['pb'][p] for r in rows)} → {sum(r['pa'][p] for r in rows)}"
                                for p in PARTS)]
    for tag, key in (("before", "sb"), ("after", "sa")):
        sites = {}
        for r in rows:
            for k, v in r[key].items():
                sites[k] = sites.get(k, 0) + v
        L.append(f"rhs by call site {tag}: " + ", ".join(f"{k} {v}" for k, v in
                                                         sorted(sites.items(), key=lambda kv: -kv[1])))
    L += ["", "per case file (law): rhs per point before → after, medians over its variants; share saved, median",
          f"{'case file':28s} {'n':>2s} {'before':>7s} {'after':>7s} {'saved':>6s}"]
    for fname in sorted({r["file"] for r in rows}):
        g = [r for r in rows if r["file"] == fname]
        L.append(f"{fname:28s} {len(g):2d} {med(r['rb'] / r['pts'] for r in g):7.2f} "
                 f"{med(r['ra'] / r['pts'] for r in g):7.2f} {med(1 - r['ra'] / r['rb'] for r in g):6.1%}")
    text = "\n".join(L) + "\n"
    print(text)
    out.write_text(text)


def _med_max(vals, fmt):
    vals = list(vals)
    return f"{format(statistics.median(vals), fmt)} / {format(max(vals), fmt)}"


def report(rows, started, load0, load1, repeat, child_wall, rtol=None) -> str:
    import numba

    tol = f"at run.rtol {rtol:g} (every variant)" if rtol else "at their default tolerance (run.rtol 1e-13)"
    L = [f"adaptive 3-D method, profile of the suite's oblique cases {tol}: "
         f"{started:%d %b %Y %H:%M} UTC, git {git_head()}, numba {numba.__version__}",
         f"load average (1, 5, 15 min) at the start {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, at the end "
         f"{load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} (2 cores, shared with other long runs: every time is CPU "
         f"time, time.process_time)",
         f"kernel: compiled adaptive_3d, median CPU of {repeat} (one run over 0.3 s); counts: the same source as "
         f"plain Python (NUMBA_DISABLE_JIT=1, {child_wall:.0f} s wall for all), its output compared bit for bit "
         "with the compiled kernel's (bits); rhs: compiled rhs on a sample of the states the run evaluated it at "
         f"(≤ {SAMPLE}, ~{RHS_CALLS} calls); fixed: the kernel called with t_max = 0",
         "",
         "1. per variant. attempts: DP5 steps tried by the driver (accepted + rejected + ended at an event or halved "
         "at a stick kink); rej: rejected by the error test; acc: accepted without an event; loc: crossings located "
         "(every event function that changed sign in an accepted step; the earliest is taken); trials: trial DP5 "
         "steps in them (mean, max); ev: events kept; rhs: evaluations of the right-hand side, all and per point, "
         "then by part: step (first stages + the 6 stages of each attempt), end (event functions at a step's end), "
         "loc (location), to-ev (the step to a located event), rec (records), fix (settle/truncate/switch)",
         f"{'variant':34s} {'bits':>4s} {'pts':>6s} {'att':>6s} {'rej':>5s} {'acc':>6s} {'loc':>4s} "
         f"{'trials':>9s} {'ev':>3s} {'rhs':>8s} {'/pt':>5s} {'step':>7s} {'end':>6s} {'loc':>6s} {'to-ev':>5s} "
         f"{'rec':>6s} {'fix':>6s} {'µs/rhs':>6s} {'kernel ms':>9s} {'rhs×µs ms':>9s} {'share':>5s} "
         f"{'fixed ms':>8s}"]
    for r in rows:
        h = r["rhs"]
        trials = f"{r['trials'] / r['locates']:.1f},{r['max_trials']}" if r["locates"] else "-"
        L.append(f"{r['label']:34s} {'same' if r['same'] else 'DIFF':>4s} {r['points']:6d} {r['attempts']:6d} "
                 f"{r['rejected']:5d} {r['accepted']:6d} {r['locates']:4d} {trials:>9s} {r['events']:3d} "
                 f"{r['rhs_total']:8d} {r['rhs_total'] / r['points']:5.1f} {h['step']:7d} {h['step-end events']:6d} "
                 f"{h['locate']:6d} {h['to event']:5d} {h['record']:6d} {h['fix']:6d} {r['per_rhs'] * 1e6:6.2f} "
                 f"{r['kernel'] * 1e3:9.2f} {r['rhs_total'] * r['per_rhs'] * 1e3:9.2f} "
                 f"{r['rhs_total'] * r['per_rhs'] / r['kernel']:5.2f} {r['fixed'] * 1e3:8.3f}")
    same = sum(r["same"] for r in rows)
    L += [f"counted run = compiled run, bit for bit (status, points, every record row, every event): {same} of "
          f"{len(rows)} variants", ""]
    L += ["2. per case file (law), median / max over its variants",
          f"{'case file':24s} {'n':>2s} {'points':>15s} {'rejected':>11s} {'rhs per point':>13s} "
          f"{'step+end+other /pt':>18s} {'loc /pt':>11s} {'located':>7s} {'trials/located':>14s} "
          f"{'rhs':>15s} {'µs per rhs':>11s} {'rhs × µs, ms':>13s} {'kernel CPU ms':>15s} {'share':>11s}"]
    files = sorted({r["file"] for r in rows})
    for fname in files:
        g = [r for r in rows if r["file"] == fname]
        tp = [r["trials"] / r["locates"] for r in g if r["locates"]]
        L.append(f"{fname:24s} {len(g):2d} {_med_max((r['points'] for r in g), '.0f'):>15s} "
                 f"{_med_max((r['rejected'] for r in g), '.0f'):>11s} "
                 f"{_med_max((r['rhs_total'] / r['points'] for r in g), '.1f'):>13s} "
                 f"{_med_max(((r['rhs_total'] - r['rhs']['locate']) / r['points'] for r in g), '.1f'):>18s} "
                 f"{_med_max((r['rhs']['locate'] / r['points'] for r in g), '.1f'):>11s} "
                 f"{_med_max((r['locates'] for r in g), '.0f'):>7s} "
                 f"{_med_max(tp, '.1f') if tp else '-':>14s} "
                 f"{_med_max((r['rhs_total'] for r in g), '.0f'):>15s} "
                 f"{_med_max((r['per_rhs'] * 1e6 for r in g), '.2f'):>11s} "
                 f"{_med_max((r['rhs_total'] * r['per_rhs'] * 1e3 for r in g), '.2f'):>13s} "
                 f"{_med_max((r['kernel'] * 1e3 for r in g), '.2f'):>15s} "
                 f"{_med_max((r['rhs_total'] * r['per_rhs'] / r['kernel'] for r in g), '.2f'):>11s}")
    # the whole suite
    med = statistics.median
    rhs_pt = [r["rhs_total"] / r["points"] for r in rows]
    per_rhs = [r["per_rhs"] for r in rows]
    tot = sum(r["rhs_total"] for r in rows)
    loc_rhs = sum(r["rhs"]["locate"] for r in rows)
    n_loc = sum(r["locates"] for r in rows)
    n_trials = sum(r["trials"] for r in rows)
    steprhs = {p: sum(r["rhs"][p] for r in rows) for p in PARTS}
    L += ["", "3. all variants"]
    L.append(f"rhs per point: median {med(rhs_pt):.1f} (least {min(rhs_pt):.1f}, most {max(rhs_pt):.1f}); of all "
             f"{tot} evaluations: " + ", ".join(f"{p} {steprhs[p] / tot:.1%}" for p in PARTS))
    L.append(f"one rhs (compiled, on the run's own states): median {med(per_rhs) * 1e6:.2f} µs (least "
             f"{min(per_rhs) * 1e6:.2f}, most {max(per_rhs) * 1e6:.2f})")
    L.append(f"rejected steps: {sum(r['rejected'] for r in rows)} of {sum(r['attempts'] for r in rows)} attempts "
             f"({sum(r['rejected'] for r in rows) / sum(r['attempts'] for r in rows):.1%}); per variant median "
             f"{med(r['rejected'] for r in rows):.0f}")
    if n_loc:
        L.append(f"located crossings: {n_loc}, {n_trials} trial steps ({n_trials / n_loc:.1f} per location, most "
                 f"{max(r['max_trials'] for r in rows)}), {loc_rhs / n_loc:.0f} rhs per location; per variant "
                 f"median {med(r['locates'] for r in rows):.0f} located, {med(r['events'] for r in rows):.0f} "
                 f"events kept")
    sites = {}
    for r in rows:
        for k, v in r["by_site"].items():
            sites[k] = sites.get(k, 0) + v
    L.append("rhs by call site (all variants): " + ", ".join(f"{k} {v}" for k, v in
                                                           sorted(sites.items(), key=lambda kv: -kv[1])))
    acc = sum(r["accepted"] for r in rows)
    L.append(f"per accepted step: {steprhs['step'] / acc:.2f} rhs stepping (rejected steps included), "
             f"{steprhs['step-end events'] / acc:.2f} event functions at its end")
    share = [r["rhs_total"] * r["per_rhs"] / r["kernel"] for r in rows]
    if any(r["modes"] for r in rows):
        L.append("one rhs by the contact's mode (--by-mode: the same sample split; share of the sample, µs): "
                 "before contact / sticking / slipping")
        for r in rows:
            L.append(f"  {r['label']:34s} " + "   ".join(
                f"{k} {r['modes'][k][0]:4.0%} {r['modes'][k][1] * 1e6:5.2f}" if k in r["modes"] else f"{k}    -      -"
                for k in ("free", "stick", "slip")))
    L.append(f"kernel CPU against rhs evaluations × µs per rhs: the rhs part is a median {med(share):.0%} of the "
             f"kernel (least {min(share):.0%}, most {max(share):.0%})")
    fx = [r["fixed"] for r in rows]
    L.append(f"fixed part (the kernel called with t_max = 0): median {med(fx) * 1e3:.3f} ms (most "
             f"{max(fx) * 1e3:.3f} ms)")
    for name, sel in (("all variants", rows), ("all but walton", [r for r in rows if r["file"] != "oblique-walton"])):
        if len(sel) < 3:
            continue
        a, b = fit([r["rhs_total"] for r in sel], [r["kernel"] for r in sel])
        a2, b2 = fit([r["points"] for r in sel], [r["kernel"] for r in sel])
        L.append(f"line through {name} ({len(sel)}): kernel = {a * 1e6:.2f} µs × rhs evaluations + "
                 f"{b * 1e3:.2f} ms; kernel = {a2 * 1e6:.1f} µs × points + {b2 * 1e3:.2f} ms")
    per_loc = [r["rhs"]["locate"] * r["per_rhs"] / r["locates"] for r in rows if r["locates"]]
    per_pt = [(r["rhs_total"] - r["rhs"]["locate"] - r["rhs"]["to event"]) * r["per_rhs"] / r["points"]
              for r in rows]
    L.append(f"cost by the rhs it evaluates: a point (its step, rejected steps, step-end events, record, fixes) "
             f"median {med(per_pt) * 1e6:.1f} µs; a location median {med(per_loc) * 1e6:.0f} µs "
             f"(most {max(per_loc) * 1e6:.0f} µs)")
    floor = sorted(r["rhs_total"] * r["per_rhs"] for r in rows)
    L.append(f"the rhs evaluations alone take a median {med(floor) * 1e3:.2f} ms per collision (least "
             f"{floor[0] * 1e3:.2f} ms); variants whose rhs evaluations alone exceed 1 ms: "
             f"{sum(x > 1e-3 for x in floor)} of {len(rows)}")
    return "\n".join(L) + "\n"


def derive() -> str:
    """Numbers that follow from the per-variant tables already in OUT (one block per section)."""
    med = statistics.median
    sections, rows = [], None
    for line in OUT.read_text().splitlines():
        if line.startswith("adaptive 3-D method, profile"):
            rows = []
            sections.append((line.split(":")[0], rows))
        f = line.split()
        if rows is not None and len(f) == 22 and f[0].startswith("oblique-") and f[1] in ("same", "DIFF"):
            rows.append({"file": f[0].split("[")[0], "pts": int(f[2]), "att": int(f[3]), "rej": int(f[4]),
                         "rhs": int(f[9]), "step": int(f[11]), "end": int(f[12]), "loc": int(f[13]),
                         "rec": int(f[15]), "fix": int(f[16]), "us": float(f[17])})
    L = ["", "4. derived from the per-variant tables above (--derive: products and medians of their columns, nothing "
         "run): the event location per collision, its rhs evaluations (loc) and their cost (loc × µs/rhs), median "
         "[least, most] over each law's variants; the share of the location in the rhs evaluations"]
    for title, rows in sections:
        L.append(f"{title}:")
        L.append(f"  {'case file':28s} {'location rhs':>22s} {'location ms':>24s} {'share':>6s}")
        for fname in sorted({r["file"] for r in rows}):
            g = [r for r in rows if r["file"] == fname]
            lr = [r["loc"] for r in g]
            lm = [r["loc"] * r["us"] / 1e3 for r in g]
            L.append(f"  {fname:28s} {med(lr):8.0f} [{min(lr):5d}, {max(lr):5d}] {med(lm):8.2f} [{min(lm):6.2f}, "
                     f"{max(lm):6.2f}] {med(r['loc'] / r['rhs'] for r in g):6.2f}")
        lm = [r["loc"] * r["us"] / 1e3 for r in rows]
        L.append(f"  all {len(rows)} variants: location a median {med(lm):.2f} ms a collision (least {min(lm):.2f}, most "
                 f"{max(lm):.1f}); per point, medians: step {med(r['step'] / r['pts'] for r in rows):.2f}, "
                 f"end {med(r['end'] / r['pts'] for r in rows):.2f}, location {med(r['loc'] / r['pts'] for r in rows):.2f}"
                 f", record + fix {med((r['rec'] + r['fix']) / r['pts'] for r in rows):.2f}; rejected a median "
                 f"{med(r['rej'] / r['att'] for r in rows):.1%} of the attempts")
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--only", nargs="*", default=())
    ap.add_argument("--child", default=None)
    ap.add_argument("--rtol", type=float, default=None)
    ap.add_argument("--append", action="store_true")
    ap.add_argument("--derive", action="store_true")
    ap.add_argument("--by-mode", action="store_true")
    ap.add_argument("--before", type=Path, default=None,
                    help="a tree's root (git worktree add --detach): compare its compiled kernel with this one's bit "
                         "for bit and count both trees' rhs evaluations (writes REUSE_OUT, default "
                         "benchmarks/results/bench_adaptive_reuse.txt)")
    ap.add_argument("--bits-only", action="store_true", help="with --before: the compiled comparison only")
    ap.add_argument("--outputs", default=None)
    ap.add_argument("names", nargs="*")
    a = ap.parse_args()
    if a.outputs:
        outputs_child(Path(a.outputs), tuple(a.names))
    elif a.before:
        before_after(a.before, tuple(a.only), Path(os.environ.get(
            "REUSE_OUT", ROOT / "benchmarks" / "results" / "bench_adaptive_reuse.txt")), a.bits_only)
    elif a.derive:
        text = derive()
        print(text)
        OUT.write_text(OUT.read_text() + text)
    elif a.child:
        child(Path(a.child), tuple(a.names), a.rtol)
    else:
        main(a.repeat, tuple(a.only), a.rtol, a.append, a.by_mode)
