"""Packing cases in ``demcheck verify``: the reference's N-body solver and each engine from the same
initial state; static closed forms where the layout has one (a column, a layer on the floor), bulk values
compared with statistical tolerances otherwise (the trajectories are chaotic), and the physical ranges.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import EngineInterrupted, UnsupportedByEngine
from . import packing_metrics, sources, verdicts
from .records import CaseResult, PackingPanel, SourceResult

# statistical tolerances between sources (absolute for solid fraction and coordination, relative else)
TOLERANCES = {"solid_fraction": 0.02, "coordination_number": 0.5, "bed_height": 0.02, "mean_contact_force": 0.1}
# the contact-force distributions P(f/⟨f⟩) of two sources are compared by the two-sample Kolmogorov–Smirnov
# distance, held to its critical value at this significance for the two sample sizes
KS_ALPHA = 1e-3
# the fabric's vertical component φ_zz of a poured packing: two sources' values, each the mean of n_z² over its
# N contacts, are held to the difference critical at this significance, z(α/2)·√(s_a²/N_a + s_b²/N_b) with s² the
# sample variance of n_z² (contacts taken as independent: on the poured packings this is about twice the spread
# measured between realisations, docs/packing.md); the anisotropy and the full tensor are reported, not compared
FABRIC_ALPHA = KS_ALPHA
RANGES = {"solid_fraction": (0.55, 0.64), "coordination_number": (4.0, 6.0)}
# a poured packing is settled when its translational kinetic energy is below this fraction of N m g d (the
# energy of lifting every sphere by one diameter): a mean speed of about 1.4 % of √(g d); the bulk values of
# a packing still moving are not compared as settled ones
SETTLED = 1e-4
CLOSED_FORM_RTOL = 1e-6


def static_overlaps(case, x) -> list[tuple[float, float]] | None:
    """(overlap, closed form) of every load-bearing contact of a settled column or floor layer: each contact
    carries the weight above it, δ = (F/k)^{1/a} on the law's loading branch. None for other layouts."""
    from ..laws.normal import NormalLaw
    from ..reference.packing import resolve_laws

    layout = case.packing.layout if case.packing else None
    if layout not in ("column", "layer") or not case.walls:
        return None
    sp, laws_n, _, wall_n, _ = resolve_laws(case)
    g = float(np.linalg.norm(case.run.gravity))

    def solve(law, force):
        return NormalLaw.from_array(law).loading_overlap(force)

    out = []
    if layout == "layer":
        for i, p in enumerate(case.particles):
            out.append((p.radius - x[i, 2], solve(wall_n[sp[i]], case.mass(i) * g)))
        return out
    order = np.argsort(x[:, 2])
    for rank, i in enumerate(order):
        above = sum(case.mass(int(k)) for k in order[rank:]) * g
        p = case.particles[i]
        if rank == 0:
            out.append((p.radius - x[i, 2], solve(wall_n[sp[i]], above)))
        else:
            j = order[rank - 1]
            gap = float(np.linalg.norm(x[i] - x[j]))
            out.append((p.radius + case.particles[j].radius - gap, solve(laws_n[sp[i], sp[j]], above)))
    return out


def ks_distance(a, b) -> tuple[float, float]:
    """(KS distance between the distributions of f/⟨f⟩ of two sets of contact forces, its critical value at
    KS_ALPHA for these sample sizes): c(α)·√((n+m)/(n·m)), c(α) = √(−ln(α/2)/2)."""
    from scipy.stats import ks_2samp

    a, b = np.asarray(a, float), np.asarray(b, float)
    a, b = a[a > 0], b[b > 0]
    if len(a) < 2 or len(b) < 2:
        return math.nan, math.nan
    d = float(ks_2samp(a / a.mean(), b / b.mean()).statistic)
    return d, math.sqrt(-math.log(KS_ALPHA / 2.0) / 2.0) * math.sqrt((len(a) + len(b)) / (len(a) * len(b)))


def normals_zz(x, rad, box=None) -> np.ndarray:
    """n_z² of every particle–particle contact's unit normal (packing_metrics' contacts and branch vectors): the
    sample whose mean is the fabric's φ_zz."""
    pairs = packing_metrics.contacts(x, rad, box)
    b = packing_metrics.branch_vectors(x, pairs, box)
    return (b[:, 2] / np.linalg.norm(b, axis=1)) ** 2 if len(b) else np.empty(0)


def fabric_zz_distance(a, b) -> tuple[float, float]:
    """(|φ_zz(a) − φ_zz(b)|, its critical value at FABRIC_ALPHA) of two samples of n_z² (``normals_zz``)."""
    from scipy.stats import norm

    a, b = np.asarray(a, float), np.asarray(b, float)
    if len(a) < 2 or len(b) < 2:
        return math.nan, math.nan
    se = math.sqrt(a.var(ddof=1) / len(a) + b.var(ddof=1) / len(b))
    return abs(float(a.mean()) - float(b.mean())), float(norm.isf(FABRIC_ALPHA / 2.0)) * se


def reference_packing(case, cache=None):
    """The reference's settled packing: (x, rad, contacts [i, j, δ, Fn, |Ft|], ke [(t, e)], time, seconds).
    ``cache`` (engines.cache.Cache): keyed by the case, the time step and the solver's source fingerprint, so
    a warm verify does not settle a large packing again — and a changed solver always does."""
    import json
    import time

    import pandas as pd

    from ..engines.cache import key as cache_key
    from ..engines.cache import ke_series, number
    from ..inputs.packing_decks import CONTACT_COLUMNS
    from ..reference import packing

    k = None
    if cache is not None:
        what = {"case": case.hash, "dt": packing.packing_dt(case), "rest": 0.0}
        if case.packing is not None and case.packing.insertion is not None:
            # the case's hash holds its first batch only: the later batches (case.insertion_batches) key it too
            import hashlib

            full = packing.with_batches(case).particles
            what["batches"] = hashlib.sha256(repr(full).encode()).hexdigest()
        what = json.dumps(what)
        k = cache_key("reference-packing", packing.solver_fingerprint(), what, {})
        hit = cache.get(k, columns=("x", "y", "z", "radius"), min_rows=1,
                        meta_keys={"ke": ke_series, "time": number, "seconds": number})
        hit_c = cache.get(k + "-contacts", columns=CONTACT_COLUMNS)
        if hit is not None and hit_c is not None:
            (table, meta), (con, _) = hit, hit_c
            return (table[["x", "y", "z"]].to_numpy(), table["radius"].to_numpy(), con.to_numpy(),
                    [tuple(e) for e in meta["ke"]], meta["time"], meta["seconds"])
    t0 = time.perf_counter()
    st = packing.simulate(case, rest=0.0)
    seconds = time.perf_counter() - t0
    nc = min(st.n_contacts, len(st.contacts))
    contacts = st.contacts[:nc].copy()
    if k is not None:
        cache.put(k + "-contacts", pd.DataFrame(contacts, columns=list(CONTACT_COLUMNS)), {})
        table = pd.DataFrame({"x": st.x[:, 0], "y": st.x[:, 1], "z": st.x[:, 2], "radius": st.rad})
        cache.put(k, table, {"ke": st.ke, "time": st.time, "seconds": seconds})
    return st.x.copy(), st.rad.copy(), contacts, list(st.ke), st.time, seconds


def engine_blind(case) -> str | None:
    """What of a packing case the engines' packing decks (inputs/packing_decks) do not write — a rolling law, a
    segment wall, a timed wall, batch insertion — as the reason an engine is not run on it; None where they write it all. Run
    without it, an engine would settle another packing, and a verdict on it would judge what was not asked."""
    what = []
    if case.contact.rolling != "none":
        what.append(f"the rolling law '{case.contact.rolling}'")
    if any(w.extent is not None for w in case.walls):
        what.append("segment walls (extent)")
    if any(w.until is not None for w in case.walls):
        what.append("timed walls (until)")
    if case.packing is not None and case.packing.insertion is not None:
        what.append("batch insertion (layout = inserted: the decks hold the first batch only)")
    if not what:
        return None
    return f"the packing decks do not write {', '.join(what)}: only the reference solves this packing"


def _engine_mapping(case, name, _native):
    """A packing's engine mapping (its type pair's), refused where the decks cannot write the case (engine_blind)."""
    from ..engines.base import refused
    from ..engines.mapping import pair_mapping

    why = engine_blind(case)
    return refused(name, why) if why else pair_mapping(case, name, 0, 0)


def run_packing(case, opts, found, file=None) -> CaseResult:
    from ..engines.packing import run_engine
    from ..reference import packing

    from ..laws.model import models_of

    entry = CaseResult(case.name, str(file), case.hash, "packing", packing={}, impact={}, scales={})
    normal, tangential = models_of(case)
    entry.model = {"normal": normal.id, "tangential": tangential.id, "limit_force": case.contact.limit_force,
                   **({"rolling": case.contact.rolling} if case.contact.rolling != "none" else {})}
    box = case.packing.box if case.packing else None
    comps = entry.comparisons
    x, rad, contacts, ke, t_end, seconds = reference_packing(case, opts.cache)
    states = {"reference": (x, rad)}
    ref_forces = contacts[:, 3]
    ref_m = packing_metrics.compute(x, rad, box=box, forces=ref_forces, overlaps=contacts[:, 2],
                       ke=[e for _, e in ke])
    entry.sources["reference"] = SourceResult("ok", metrics=ref_m, time=t_end, wall_time=seconds,
                                              keys=("status", "metrics", "time", "wall_time"))
    entry.packing["reference"] = PackingPanel(ke, packing_metrics.force_distribution(ref_forces),
                                              packing_metrics.profile(x, rad, box) if box else None)

    for planned in sources.plan(case, opts.engines, found, _engine_mapping):
        if not entry.note_plan(planned):
            continue
        engine = planned.source.label
        started = time.perf_counter()
        try:
            run = run_engine(case, engine, timeout=opts.timeout, cache=opts.cache)
            seconds = time.perf_counter() - started  # the run (or the cache's answer), not the metrics after it
        except EngineInterrupted:
            raise  # the case did not finish: it is left out of the (partial) report
        except UnsupportedByEngine as exc:  # an engine whose package writes no packing decks
            entry.sources[engine] = SourceResult.status_only(verdicts.NOT_EXPRESSIBLE, str(exc))
            comps.append(verdicts.status_comparison(engine, verdicts.NOT_EXPRESSIBLE, str(exc)))
            continue
        except Exception as exc:  # noqa: BLE001 - any engine failure is reported, never fatal to the suite
            entry.sources[engine] = SourceResult.status_only("failed", str(exc))
            comps.append(verdicts.status_comparison(engine, verdicts.FAILED, str(exc).splitlines()[0]))
            continue
        x = run.table[["x", "y", "z"]].to_numpy()
        rad = run.table["radius"].to_numpy()
        states[engine] = (x, rad)
        fn = run.contacts["fn"].to_numpy()
        m = packing_metrics.compute(x, rad, box=box, forces=fn, overlaps=run.contacts["overlap"].to_numpy(),
                       ke=[e for _, e in run.ke])
        entry.sources[engine] = SourceResult("ok", metrics=m, engine_version=run.version,
                                             wall_time=seconds, cached=run.cached,
                                             keys=("status", "metrics", "engine_version", "wall_time", "cached"))
        dt = packing.packing_dt(case)
        entry.packing[engine] = PackingPanel([(step * dt, e) for step, e in run.ke],
                                             packing_metrics.force_distribution(fn),
                                             packing_metrics.profile(x, rad, box) if box else None)
        _judge_engine(case, engine, m, ref_m, fn, ref_forces, x, rad, states, box, comps)
    _judge_settled(case, entry, states, comps)
    return entry.judged()


def _judge_engine(case, engine: str, m: dict, ref_m: dict, fn, ref_forces, x, rad, states, box, comps) -> None:
    """An engine's packing against the reference's: the contact-force distribution (Kolmogorov–Smirnov), a
    poured packing's fabric φ_zz, and each bulk metric within its statistical tolerance."""
    d, crit = ks_distance(fn, ref_forces)
    if math.isfinite(d):
        ok = d <= crit
        comps.append(verdicts.Comparison(engine, "force_distribution_ks", d, 0.0, d, d, crit,
                                  verdicts.AGREE if ok else verdicts.UNEXPECTED,
                                  "" if ok else f"the contact-force distributions P(f/⟨f⟩) differ beyond the "
                                                f"Kolmogorov–Smirnov critical distance at α = {KS_ALPHA:g}"))
    if case.packing is not None and case.packing.layout == "poured":
        d, crit = fabric_zz_distance(normals_zz(x, rad, box), normals_zz(*states["reference"], box))
        if math.isfinite(d) and crit > 0:
            ok = d <= crit
            comps.append(verdicts.Comparison(engine, "fabric_zz", m["fabric_zz"], ref_m["fabric_zz"], d, d, crit,
                                      verdicts.AGREE if ok else verdicts.UNEXPECTED,
                                      "" if ok else "the contact fabric's vertical component φ_zz differs beyond "
                                                    f"its sampling error at α = {FABRIC_ALPHA:g}"))
    for metric, tol in TOLERANCES.items():
        a, b = m[metric], ref_m[metric]
        if not (math.isfinite(a) and math.isfinite(b)):
            continue
        diff = abs(a - b) / (abs(b) if metric in ("bed_height", "mean_contact_force") else 1.0)
        verdict = verdicts.AGREE if diff <= tol else verdicts.UNEXPECTED
        comps.append(verdicts.Comparison(engine, metric, a, b, abs(a - b), diff, tol, verdict,
                                  "" if verdict == verdicts.AGREE else
                                  f"beyond the statistical tolerance {tol:g} between chaotic packings"))


def _judge_settled(case, entry: CaseResult, states: dict, comps: list) -> None:
    """Each source's settled state: the static overlaps' closed form where there is one, else (a poured packing)
    the kinetic energy left and each bulk metric within its physical range."""
    for src, (x, rad) in states.items():
        pairs = static_overlaps(case, x)
        if pairs is not None:
            worst = max(abs(d / e - 1.0) for d, e in pairs)
            comps.append(verdicts.Comparison(src, "static_overlap", worst, 0.0, worst, worst, CLOSED_FORM_RTOL,
                                      verdicts.AGREE if worst <= CLOSED_FORM_RTOL else verdicts.UNEXPECTED,
                                      "" if worst <= CLOSED_FORM_RTOL else
                                      "the settled overlaps miss the static closed form (not settled?)"))
        elif case.packing is not None and case.packing.layout == "poured":
            m = entry.sources[src].metrics
            ke = m.get("kinetic_energy", math.nan)
            lift = sum(case.mass(i) for i in range(len(case.particles))) * float(np.linalg.norm(case.run.gravity)) \
                * 2.0 * float(np.mean(rad))
            ratio = ke / lift if lift > 0 else math.nan
            ok = math.isfinite(ratio) and ratio <= SETTLED
            comps.append(verdicts.Comparison(src, "settled (kinetic energy / N m g d)", ratio, 0.0, ratio, ratio, SETTLED,
                                      verdicts.AGREE if ok else verdicts.UNEXPECTED,
                                      "" if ok else "still moving at the end of packing.duration: its bulk values "
                                                    "are not those of a settled packing (lengthen the duration)"))
            for metric, (lo, hi) in RANGES.items():
                val = m[metric]
                ok = math.isfinite(val) and lo <= val <= hi
                comps.append(verdicts.Comparison(src, f"{metric} (range)", val, lo, 0.0, 0.0, hi - lo,
                                          verdicts.AGREE if ok else verdicts.EXPECTED,
                                          "" if ok else f"outside the physical range {lo:g}–{hi:g} of a "
                                                        "settled poured packing (not settled, or too small a bulk)"))
