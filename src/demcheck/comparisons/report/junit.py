"""junit.xml: a test case per comparison, failures for the failing verdicts."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import defaultdict

from ...io import number
from .. import verdicts
from ..records import Summary
from .matrix import _model


# ----------------------------------------------------------------------------- junit


def render_junit(summary: Summary) -> str:
    """One testcase per case × source (the reference's checks, each engine): failure for an unexpected
    difference or a failed run, skipped for not expressible or a missing engine."""
    summary = Summary.of(summary)
    suite = ET.Element("testsuite", name="demcheck-verify", timestamp=summary.started,
                       time=f"{summary.wall_time or 0:.3f}")
    n = fails = errors = skips = 0
    for c in summary.cases:
        by_source: dict = defaultdict(list)
        for k in c.comparisons:
            src = "reference" if k.source in ("closed-form", "reference-verlet") else k.source
            by_source[src].append(k)
        for src, comps in by_source.items():
            n += 1
            tc = ET.SubElement(suite, "testcase", classname=f"{c.case}", name=f"{_model(c)} · {src}")
            bad = [k for k in comps if k.verdict == verdicts.UNEXPECTED]
            failed = [k for k in comps if k.verdict == verdicts.FAILED]
            skipped = [k for k in comps if k.verdict in (verdicts.NOT_EXPRESSIBLE, verdicts.MISSING)]
            if failed:
                errors += 1
                ET.SubElement(tc, "error", message=failed[0].reason[:500]).text = "\n".join(
                    f"{k.source} {k.metric}: {k.reason}" for k in failed)
            elif bad:
                fails += 1
                ET.SubElement(tc, "failure", message=f"{len(bad)} unexpected difference(s)").text = "\n".join(
                    f"{k.metric}: {number(k.value)} vs {number(k.reference)} (scaled {number(k.rel_diff, '.3g')} > "
                    f"{number(k.tolerance, '.3g')}): {k.reason}" for k in bad)
            elif skipped:
                skips += 1
                ET.SubElement(tc, "skipped", message=skipped[0].reason[:500])
            expected = [k for k in comps if k.verdict == verdicts.EXPECTED]
            if expected:
                ET.SubElement(tc, "system-out").text = "\n".join(
                    f"differs as expected: {k.metric} ({number(k.rel_diff, '.3g')}): {k.reason}" for k in expected)
    suite.set("tests", str(n))
    suite.set("failures", str(fails))
    suite.set("errors", str(errors))
    suite.set("skipped", str(skips))
    root = ET.Element("testsuites")
    root.append(suite)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
