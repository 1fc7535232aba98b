"""The reports of a verification run: results.json, report.md, junit.xml and report.html — one module per
renderer (matrix: the matrix and its traps; markdown; junit; html; figures), written here.

Every file is written atomically (io.atomic_path); ``<root>/latest`` is switched to the new run only after
its files exist. report.html carries its plots inline (PNG, base64) and a small script that marks the page
``data-plots-ok`` once every plot has decoded, which the browser test reads back.
"""

from __future__ import annotations

import os
from pathlib import Path

from ...io import plain, write_json, write_text
from ..records import Summary
from .figures import *  # noqa: F401,F403 - the renderers' names, as report.NAME
from .matrix import *  # noqa: F401,F403
from .markdown import *  # noqa: F401,F403
from .junit import *  # noqa: F401,F403
from .html import *  # noqa: F401,F403
from .figures import PLOT_CACHE, _img, _png  # noqa: F401 - perf_report's
from .html import render_html
from .junit import render_junit
from .markdown import _md_packings, render_markdown  # noqa: F401


def write_all(summary: Summary, out_dir: Path, root: Path, junit: Path | None = None, link: str = "latest") -> None:
    """Every report of a run (a records.Summary, or the dict of one) into ``out_dir``: results.json (the summary's
    JSON without the plots' series), report.md, junit.xml (and ``junit``), report.html; then ``root/link``."""
    summary = Summary.of(summary)
    out_dir.mkdir(parents=True, exist_ok=True)
    PLOT_CACHE["dir"] = Path(summary.cache["dir"]) / "plots" if summary.cache is not None else None
    write_json(out_dir / "results.json", plain(summary.to_json(series=False)))
    write_text(out_dir / "report.md", render_markdown(summary))
    junit_text = render_junit(summary)
    write_text(out_dir / "junit.xml", junit_text)
    if junit is not None:
        write_text(junit, junit_text)
    try:
        page = render_html(summary)
    except KeyboardInterrupt:  # interrupted while drawing: the page without its plots, then stop
        write_text(out_dir / "report.html", render_html(summary, draw=False))
        link_latest(root, out_dir, link)
        raise
    write_text(out_dir / "report.html", page)
    link_latest(root, out_dir, link)


def link_latest(root: Path, out_dir: Path, name: str = "latest") -> None:
    """Point the symlink ``<root>/<name>`` (``latest`` is verify's; bench, stress and validate keep their own,
    ``latest-bench`` …) at ``out_dir`` (a run directory in ``root``) in one step: a new
    link beside it renamed over it. ``latest`` is demcheck's own link — the command line refuses a real file
    or directory there before any work (io.check_output) — and should the rename fail all the same, the new
    link is removed, never left behind."""
    tmp = root / f".{name}.{os.getpid()}"
    if tmp.is_symlink() or tmp.exists():
        tmp.unlink()
    tmp.symlink_to(out_dir.name)
    try:
        os.replace(tmp, root / name)
    finally:
        if tmp.is_symlink():
            tmp.unlink()
