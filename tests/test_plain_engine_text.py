"""An engine's text is text (issue 32, class 7): a run's log tail loses the engine's escape sequences before a
failure message or a report shows it, and verify's summary prints versions and reasons as they are, never as rich
markup (a '[bold]' in a build's version was swallowed)."""

import io

from rich.console import Console

from demcheck.comparisons import suite
from demcheck.engines import run


def test_a_runs_log_is_read_without_escape_sequences(tmp_path):
    (tmp_path / "log.txt").write_text("LAMMPS (22 Jul 2025)\n\x1b[31mERROR: Lost atoms\x1b[0m\n\x1b]0;title\x07done\n")
    text = run._read_log(tmp_path, None, "lammps")
    assert "\x1b" not in text and "\x07" not in text
    assert "ERROR: Lost atoms" in text and "done" in text


def test_verify_summary_prints_versions_and_reasons_literally():
    out = io.StringIO()
    console = Console(file=out, width=200, force_terminal=False, color_system=None)
    summary = {"cases": [{"case": "kk-wall", "status": "failed",
                          "comparisons": [{"verdict": "failed", "source": "lammps", "metric": "restitution",
                                           "reason": "a run said [bold]no[/bold]"}]}],
               "planned": 1, "partial": False, "failed": 1, "wall_time": 1.0, "report": "r",
               "engines": {"lammps": {"found": True, "version": "[bold]22 Jul 2025[/bold]"}}}
    suite._print(console, summary)
    text = out.getvalue()
    assert "lammps [bold]22 Jul 2025[/bold]" in text
    assert "a run said [bold]no[/bold]" in text
