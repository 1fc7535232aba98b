"""Command line: ``demcheck models | collide | deck | sweep | verify`` (the README lists every command).

Exit codes: 0 success, 1 an unexpected disagreement or a failed run, 2 bad input or usage.
``--json`` prints one JSON object on stdout and nothing else there.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import click

from . import __version__
from .errors import ConfigError, DemcheckError
from . import cli_text, resources
from .io import check_output, console, plain



def _engine_names() -> list[str]:
    """The registered engines; a plug-in that cannot be loaded is one line and exit 2, before anything runs."""
    from .engines import registry

    try:
        return list(registry.names())
    except DemcheckError as exc:
        click.echo(f"demcheck: error: {exc}", err=True)
        sys.exit(exc.exit_code)


ENGINE_NAMES = _engine_names()  # the registered engines (built-ins, then plug-ins): every --engine choice


def emit_json(obj) -> None:
    click.echo(json.dumps(plain(obj), indent=2, allow_nan=False))


# ----------------------------------------------------------------------------- checked options


def number(key: str, value, *, lo=None, hi=None, lo_open=False, hi_open=False, integer=False, unit=""):
    """``value`` (text or a number) as a finite number in [lo, hi] (an open end with lo_open/hi_open), else
    ConfigError naming ``key``, the value and the rule."""
    kind = "an integer" if integer else "a finite number"
    bounds = []
    if lo is not None:
        bounds.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        bounds.append(f"{'<' if hi_open else '<='} {hi:g}")
    where = " and ".join(bounds) + (f" ({unit})" if unit else "")
    try:
        parsed = (int(value) if isinstance(value, int) else int(str(value).strip())) if integer \
            else float(value)
    except (TypeError, ValueError):
        raise ConfigError(key, value, f"must be {kind} {where}".rstrip()) from None
    if not math.isfinite(parsed):
        raise ConfigError(key, parsed, f"must be {kind} {where}".rstrip())
    if (lo is not None and (parsed < lo or (lo_open and parsed == lo))) or \
            (hi is not None and (parsed > hi or (hi_open and parsed == hi))):
        raise ConfigError(key, parsed, f"must be {where}")
    return parsed


class Number(click.ParamType):
    """A command-line number: finite and in range, else one line ``demcheck: error: --dt = inf: must be a
    finite number > 0 (s)`` and exit 2 (``number``)."""

    def __init__(self, **bounds):
        self.bounds = bounds
        self.name = "integer" if bounds.get("integer") else "number"

    def convert(self, value, param, ctx):
        return number(_option_name(param), value, **self.bounds)


def _option_name(param) -> str:
    return max(param.opts, key=len) if param is not None and param.opts else "value"


class OutputPath(click.ParamType):
    """An output file (or ``directory``) checked up front by ``check_output``, with the files and the link
    the command derives from it."""

    name = "path"

    def __init__(self, directory: bool = False, files=(), link: str | None = None):
        self.directory, self.files, self.link = directory, tuple(files), link

    def convert(self, value, param, ctx):
        check_output(_option_name(param), value, self.directory, self.files, self.link)
        return str(value)


DT = Number(lo=0, lo_open=True, unit="s")
TIMEOUT = Number(lo=0, lo_open=True, hi=1e6, unit="s")  # the pipes' poll() takes at most ~2.1e6 s
OUT_FILE = OutputPath()
REPORT_DIR = OutputPath(directory=True, link="latest")  # <report>/<run-id>/… and the symlink <report>/latest
# the other report-writing commands keep links of their own: <report>/latest is verify's
BENCH_DIR = OutputPath(directory=True, link="latest-bench")
STRESS_DIR = OutputPath(directory=True, link="latest-stress")
VALIDATE_DIR = OutputPath(directory=True, link="latest-validate")
PACK_CSV_DIR = OutputPath(directory=True, files=("particles.csv", "contacts.csv"))
PACK_VTK_DIR = OutputPath(directory=True, files=("particles.vtu", "contacts.vtu"))  # packing_output.VTK_FILES
PACK_XYZ_FILE = OutputPath()


class SchedulerAddress(click.ParamType):
    """A Dask scheduler's address, ``tcp://HOST:PORT`` (comparisons/dispatch.py); its form checked here, whether
    a scheduler answers there when the command starts its campaign — both before any work."""

    name = "address"

    def convert(self, value, param, ctx):
        from .comparisons.dispatch import check_address

        return check_address(value, _option_name(param))


def _campaign_options(jobs: int, runs: str, jobs_help: str | None = None):
    """``--jobs`` (default ``jobs``) and ``--scheduler``: where a command's independent ``runs`` go
    (comparisons/dispatch.py, docs/scaling.md)."""

    def add(command):
        command = click.option("--scheduler", "scheduler", type=SchedulerAddress(), default=None,
                               metavar="tcp://HOST:PORT",
                               help=f"run the {runs} on the workers of this Dask cluster (its workers set the "
                                    "parallelism: not with --jobs; docs/scaling.md)")(command)
        return click.option("--jobs", "-j", type=Number(lo=1, hi=256, integer=True), default=jobs,
                            show_default=True, help=jobs_help or f"{runs} run in parallel: 1 in this process, N in a "
                                                                 "local Dask cluster of N worker processes")(command)

    return add


def _check_jobs(jobs: int, scheduler: str | None) -> None:
    """``--jobs`` given with ``--scheduler`` is refused: the cluster's workers set the parallelism, and the size of
    a local cluster would be silently ignored."""
    source = click.get_current_context().get_parameter_source("jobs")
    if scheduler and source is not click.core.ParameterSource.DEFAULT:
        raise ConfigError("--jobs", jobs, "sizes a local cluster; with --scheduler the cluster's workers run the "
                                          "tasks: leave out --jobs")


def _campaign(jobs: int, scheduler: str | None, sources=()):
    """The dispatch.Campaign of ``--jobs`` and ``--scheduler`` (checked by ``_check_jobs``)."""
    from .comparisons.dispatch import Campaign

    _check_jobs(jobs, scheduler)
    return Campaign(jobs, scheduler, sources=sources)


SET_KEYS = {"overrides": "--set"}  # the API's argument names as the command line's options


def _load(case_path: str, overrides) -> "object":
    """The case (api.load: the one loader, its [engine.NAME] settings read by their engines before any work)."""
    from . import api

    return api.load(case_path, list(overrides), keys=SET_KEYS, base=True)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="demcheck")
def cli():
    """Verify DEM contact force models: a Python reference against the registered engines (LAMMPS, LIGGGHTS,
    Yade, Kratos DEM and plug-ins) and the published benchmarks."""


# ----------------------------------------------------------------------------- models


@cli.command()
@click.argument("model_id", metavar="[ID]", required=False)
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--engine", "engine", default=None,
              help="reverse lookup: ID is an engine's native setting — lammps: a pair_coeff's arguments "
                   "(\"hertz/material 63e9 0.6 0.24 damping tsuji tangential mindlin NULL 1.0 0.5\"); liggghts: "
                   "the pair_style gran arguments and the property/global values as NAME=VALUE (\"model hertz "
                   "tangential history coefficientRestitution=0.6 coefficientFriction=0.5 youngsModulus=63e9 "
                   "poissonsRatio=0.24\")")
@click.option("--radius", type=Number(lo=0, lo_open=True, unit="m"), default=None,
              help="reverse lookup: the like pair's radius (default 1e-3 m)")
@click.option("--density", type=Number(lo=0, lo_open=True, unit="kg/m³"), default=None,
              help="reverse lookup: the like pair's density (default 2500 kg/m³)")
@click.option("--speed", type=Number(lo=0, lo_open=True, hi=1e4, unit="m/s"), default=None,
              help="reverse lookup: the impact speed of the fidelity probes (default 1 m/s)")
def models(model_id, as_json, engine, radius, density, speed):
    """Registered models: one line each (id, seed name, each engine's fidelity); `demcheck models ID` shows one
    model in full (formula, source, parameters, each engine's configuration and reason); `demcheck models
    --engine E "SETTING"` looks a native setting up (seed model, fidelity, implied parameters, traps)."""
    if engine is None:
        for key, value in (("--radius", radius), ("--density", density), ("--speed", speed)):
            if value is not None:
                raise ConfigError(key, value, "applies to a reverse lookup (--engine E \"SETTING\")")
    if engine is not None:
        from .comparisons.audit import reverse

        if model_id is None:
            raise ConfigError("SETTING", None, "--engine needs the native setting to look up")
        r = reverse(engine, model_id, radius or 1e-3, density or 2500.0, speed or 1.0)
        if as_json:
            emit_json(r)
        else:
            click.echo("\n".join(cli_text.reverse_lookup(engine, r)))
        if r["fidelity"] == "failed":
            sys.exit(1)
        return
    from . import api
    from .engines import registry

    table = api.models(model_id, "ID")
    if as_json:
        emit_json({"models": table})
    elif model_id is None:  # one line a model: fits 80 columns, plain text when piped
        click.echo("\n".join(cli_text.models_table(table, registry.names())))
    else:
        click.echo("\n".join(cli_text.model_details(table, registry.all_engines())))


# ----------------------------------------------------------------------------- collide

_set_option = click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                           help="override a case key (dotted, e.g. contact.normal=tti); repeatable")


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--engine", "engine", default="reference", show_default=True, metavar="SOURCE[,SOURCE…]",
              help=f"the source(s): reference, an engine ({', '.join(ENGINE_NAMES)}: its deck run for real), a build "
                   "of one (ENGINE=PATH, or ENGINE@LABEL=PATH beside it), a comma-separated list side by side, or all")
@click.option("--method", type=click.Choice(["adaptive", "verlet"]), default=None,
              help="reference method (default: the case's run.method, adaptive)")
@click.option("--dt", type=DT, default=None, help="time step of the verlet method and of the engines (s)")
@_set_option
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--plot", type=OUT_FILE, default=None, help="write force–overlap and force–time panels")
@click.option("--csv", "csv_path", type=OUT_FILE, default=None,
              help="write the contact time series (of the first source)")
@click.option("--timeout", type=TIMEOUT, default=600.0, show_default=True, help="engine run timeout (s)")
@click.option("--precision", "precision", type=click.Choice(["float128", "mpfr150"]), default=None,
              help="run each engine that has one as its build in this floating-point precision (Yade: "
                   "yade-float128, yade-mpfr150), e.g. to show a difference is the scheme's and not round-off")
def collide(case_path, engine, method, dt, overrides, as_json, plot, csv_path, timeout, precision):
    """Solve one collision case and print its metrics (per source, side by side)."""
    from . import api

    sources = _collide_sources(engine, precision)  # each checked before any work
    if engine != "all" and len(sources) == 1:
        engine = sources[0]
    case = _load(case_path, overrides)
    skipped = {}
    if engine == "all":  # what can run the case: comparisons.sources.plan, the suite's answer
        from .comparisons.sources import plan
        from .comparisons.verdicts import NOT_EXPRESSIBLE

        for p in plan(case, sources[1:]):
            if not p.runs:
                skipped[p.source.label] = (f"{p.source.label} cannot express this model: {p.why}"
                                           if p.status == NOT_EXPRESSIBLE else p.why)
    # an engine: [engine.NAME] (a build reads its engine's table) at the native law's own step, what `deck` writes
    results = {src: api.collide(case, src, method if src == "reference" else None, dt, timeout=timeout)
               for src in sources if src not in skipped}
    first = next(iter(results.values()), None)
    if csv_path and first is not None:
        from .io import atomic_path

        with atomic_path(csv_path) as tmp:
            first.contact.to_csv(tmp, index=False, float_format="%.17g")
    if plot and results:
        from .comparisons.plots import collision_panels

        collision_panels(list(results.values()), plot)
    summaries = {k: r.summary() for k, r in results.items()}
    if as_json:
        if engine == "reference" or (engine != "all" and len(summaries) == 1):
            emit_json(next(iter(summaries.values())))
        else:
            emit_json({**summaries, **{k: {"source": k, "status": "skipped", "message": v}
                                       for k, v in skipped.items()}})
    elif len(summaries) == 1 and not skipped:
        _print_summary(next(iter(summaries.values())))
    else:
        _print_side_by_side(summaries, skipped)
    bad = [r for r in results.values() if not r.ok]
    for r in bad:
        click.echo(f"demcheck: {r.source}: {r.status}: {r.message}", err=True)
    if bad:
        sys.exit(1)


def _collide_sources(engine: str, precision: str | None) -> list[str]:
    """``collide --engine``'s sources: reference, engines and builds (engines/builds.py, each registered under its
    label), or all (the reference and every registered engine); checked before any work."""
    if engine == "all":
        if precision:
            raise ConfigError("--precision", precision, "names the builds of engines given by name (--engine yade), "
                              "not all")
        return ["reference", *ENGINE_NAMES]
    from .engines import discovery
    from .engines.builds import with_precision

    specs = [s.strip() for s in engine.split(",") if s.strip()]
    if not specs:
        raise ConfigError("--engine", engine, "must name a source: reference, an engine, a build or all")
    rest = [s for s in specs if s != "reference"]
    if precision and not rest:
        raise ConfigError("--precision", precision, "applies to an engine (--engine yade)")
    rest = with_precision(",".join(rest), precision).split(",") if rest else []
    labels = iter(discovery.resolve(",".join(rest), "--engine") if rest else [])
    return ["reference" if s == "reference" else next(labels) for s in specs]


def _print_side_by_side(summaries: dict, skipped: dict) -> None:
    con = console()
    for item in cli_text.side_by_side(summaries, skipped):
        con.print(item)


# ----------------------------------------------------------------------------- deck


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--engine", type=click.Choice(ENGINE_NAMES), required=True)
@click.option("-o", "--output", type=OUT_FILE, default=None,
              help="write the deck here (files it reads go beside it); default: stdout")
@click.option("--dt", type=DT, default=None, help="time step (s); default: the case's")
@_set_option
def deck(case_path, engine, output, dt, overrides):
    """Write the engine's input deck of a collision, packing or scenario case (run.scenario beyond sliding: the
    deck verify runs), runnable by hand: lmp -in / liggghts -in (a packing's deck reads data.lmp, its initial
    state, written beside it), yade -x -n (a Python script that reads no file), Kratos: python in.deck beside the
    parameter and model files written with it."""
    from .comparisons.sources import Source
    from .engines.collide import finite, setting_deck

    case = _load(case_path, overrides)
    source = Source.of(engine)
    if case.run.scenario != "collision":  # the deck the suite runs (engines/scenario.py): its layout fixes dt
        from .engines import scenario

        if dt is not None:
            raise ConfigError("--dt", dt, f"is not taken with run.scenario = \"{case.run.scenario}\": the "
                                          "scenario's layout fixes its step (the one verify runs)")
        dk = scenario.deck(case, source.engine)
    elif case.kind == "packing":
        from .comparisons.packing_suite import engine_blind

        if (why := engine_blind(case)) is not None:  # a deck without them would run another packing
            raise ConfigError("--engine", engine, why)
        dk = finite(source.engine.packing_deck(case, dt=dt), case)
    else:  # the case's [engine.NAME] setting at its own step: the deck `collide --engine` runs
        dk = setting_deck(case, source.engine, dt)
    if output:  # the files the deck reads go beside it: each checked before any is written
        check_output("--output", output, files=list(dk.files))
        for path in dk.write(output):
            click.echo(f"wrote {path}", err=True)
    else:
        click.echo(dk.text, nl=False)
        for name, text in dk.files.items():
            click.echo(f"# --- {name} (read by the deck; written beside it with -o) ---\n"
                       + "\n".join(f"# {line}" for line in text.splitlines()))


def _print_summary(s: dict) -> None:
    con = console()
    head, metrics, params, note = cli_text.summary_tables(s)
    con.print(head)
    con.print(metrics)
    con.print(params)
    if note:
        click.echo(note)


# ----------------------------------------------------------------------------- sweep


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--vary", "varies", multiple=True, required=True, metavar="KEY=START:STOP:N",
              help="a case key and its values (N evenly spaced, or KEY=a,b,c); several make a grid")
@click.option("--engine", "source", default="reference", show_default=True, metavar="SOURCE",
              help=f"the source: reference (the seed model), an engine ({', '.join(ENGINE_NAMES)}: its deck run "
                   "for real, or a build ENGINE@LABEL=PATH) or an engine's twin (NAME-twin); an engine and its twin "
                   "run the case's [engine.NAME] setting when it has one")
@click.option("--method", type=click.Choice(["adaptive", "verlet"]), default=None,
              help="the reference's method (default: the case's run.method)")
@click.option("--dt", type=DT, default=None, help="time step of the verlet method and of an engine or twin (s)")
@_set_option
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--csv", "csv_path", type=OUT_FILE, default=None, help="write the table")
@click.option("--plot", type=OUT_FILE, default=None, help="plot metrics against the first key")
@_campaign_options(1, "points")
def sweep(case_path, varies, source, method, dt, overrides, as_json, csv_path, plot, jobs, scheduler):
    """Metrics of a collision over one or more case keys, e.g. --vary impact.angle=5:85:17, from one source.
    With the case's own setting for the source's engine ([engine.NAME]), a contact.* key (the seed model's) or
    a materials.* key the setting does not read is refused: it would not change the law that runs."""
    from rich.progress import Progress

    from . import api
    from .comparisons.sweep import parse_vary, plot_sweep, sweep_source

    source, _ = sweep_source(source, method)  # the source's label (a build registered under it), before any work
    vary = {}
    for text in varies:
        key, values = parse_vary(text)
        if key in vary:
            raise ConfigError("--vary", text, f"{key} is varied twice: give each key once")
        vary[key] = values
    _check_jobs(jobs, scheduler)
    progress = Progress(transient=True, disable=as_json)
    task = progress.add_task("sweep", total=math.prod(len(v) for v in vary.values()))

    def advance():  # the bar shows once a point is solved: a refusal before any work prints nothing on stdout
        if not progress.live.is_started:
            progress.start()
        progress.advance(task)

    try:
        table = api.sweep(case_path, vary, source, method, dt, list(overrides), jobs=jobs, scheduler=scheduler,
                          progress=advance, base=True, keys={**SET_KEYS, "source": "--engine", "method": "--method",
                                                             "dt": "--dt", "vary": "--vary"})
    finally:
        if progress.live.is_started:  # (Progress.stop prints a line off a terminal, started or not)
            progress.stop()
    if csv_path:
        from .io import atomic_path

        with atomic_path(csv_path) as tmp:
            table.to_csv(tmp, index=False, float_format="%.12g")
    if plot:
        plot_sweep(table, parse_vary(varies[0])[0], plot)
    if as_json:
        emit_json({"vary": [parse_vary(v)[0] for v in varies], "rows": table.to_dict(orient="records")})
    else:
        console().print(cli_text.sweep_table(table))
    if (table["status"] != "ok").any():
        sys.exit(1)


# ----------------------------------------------------------------------------- warmup


@cli.command()
@click.option("--jobs", "-j", "jobs", type=Number(lo=1, hi=256, integer=True), default=None, metavar="N",
              help="compile in N processes at once, a kernel each (default: the machine's cores, at most 5 — "
                   "there are five entry kernels; 1: in this process)")
def warmup(jobs):
    """Compile every reference kernel the suite uses into the on-disk cache (numba), so that the first
    verify starts warm; the Makefile's setup runs it. Each scene's time is printed (compiled or loaded), then
    the wall time of the whole."""
    import os
    import time

    from .comparisons.warmup import tasks, warm

    jobs = jobs or max(1, min(os.cpu_count() or 1, len(tasks())))
    click.echo(f"demcheck warmup: numba cache {os.environ.get('NUMBA_CACHE_DIR', '(numba default)')}, "
               f"{jobs} process{'es' if jobs > 1 else ''}")
    t = time.perf_counter()
    warm(lambda label, s: click.echo(f"  {label:32s} {s:8.2f} s"), jobs=jobs)
    click.echo(f"  {'total (wall)':32s} {time.perf_counter() - t:8.2f} s")


# ----------------------------------------------------------------------------- cases


@cli.command("cases")
@click.argument("name", required=False, metavar="[NAME]")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
def cases_command(name, as_json):
    """The case files shipped with demcheck, by name and folder: the default suite (what `demcheck verify` runs),
    packing/, benchmarks/ (`demcheck validate`) and optin/ (long cases, run by naming them). Every command takes a
    shipped case by its name (`demcheck collide glass-pair`). With NAME: that file's text, to copy and edit
    (`demcheck cases glass-pair > my-case.toml`)."""
    from . import api

    found = api.case_files(name, "NAME")
    if as_json:
        emit_json(found)
    elif name is not None:
        click.echo(found["text"], nl=False)
    else:
        click.echo("\n".join(cli_text.cases_listing(Path(found["root"]), found["cases"])))


# ----------------------------------------------------------------------------- verify


@cli.command()
@click.argument("paths", nargs=-1, metavar="[CASE|DIR]...")
@click.option("--engines", "engines", default=",".join(ENGINE_NAMES), show_default=True, metavar="LIST",
              help=f"comma-separated engines to compare ({', '.join(ENGINE_NAMES)}), builds of one beside it "
                   "(ENGINE@LABEL=PATH, e.g. lammps@2024=/opt/lammps-2024/bin/lmp; ENGINE=PATH replaces its "
                   "executable), or 'none' for the reference alone")
@_campaign_options(2, "cases")
@click.option("--report", "report_dir", type=REPORT_DIR, default="reports", show_default=True,
              help="where reports/<run-id> and reports/latest go")
@click.option("--junit", "junit", type=OUT_FILE, default=None, help="also write JUnit XML here")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--no-cache", "no_cache", is_flag=True,
              help="run every engine deck again (read no cached run; the fresh runs replace the cached ones)")
@click.option("--timeout", type=TIMEOUT, default=600.0, show_default=True, help="per engine run (s)")
@click.option("--baseline", "baseline", default=None, metavar="PATH",
              help="also judge every source against a stored earlier run (a baseline file, results.json or report "
                   "directory): a worse verdict or a value moved beyond its tolerance differs unexpectedly")
@click.option("--write-baseline", "write_baseline", type=OUT_FILE, default=None, metavar="PATH",
              help="store this run as a baseline (metrics, verdicts, engine versions, per-quantity tolerances)")
@click.option("--precision", "precision", type=click.Choice(["float128", "mpfr150"]), default=None,
              help="run each listed engine that has one as its build in this floating-point precision (Yade)")
def verify(paths, engines, jobs, scheduler, report_dir, junit, as_json, no_cache, timeout, baseline, write_baseline,
           precision):
    """Run the verification suite (default: the built-in cases/) and report where each source agrees with
    the seed model. Exit 0 when everything agrees or differs as expected, 1 on an unexpected difference or
    a failed run, 2 on bad input."""
    from . import api
    from .comparisons import diff
    from .engines import run as runner

    _check_jobs(jobs, scheduler)
    try:
        summary = api.verify(list(paths), engines, report_dir, jobs, True, timeout, refresh=no_cache,
                             scheduler=scheduler, baseline=baseline, precision=precision, junit=junit,
                             quiet=as_json, argv=["demcheck", "verify", *sys.argv[2:]],
                             keys={"paths": "CASE", "engines": "--engines", "baseline": "--baseline",
                                   "precision": "--precision"})
    except KeyboardInterrupt as exc:
        click.echo("demcheck: interrupted; the engines were stopped and the finished cases are in the partial "
                   f"report {Path(report_dir) / 'latest'}", err=True)
        sys.exit(runner.interrupt_exit_code(exc))
    if write_baseline:
        from .io import write_json

        write_json(write_baseline, diff.baseline(summary))
        click.echo(f"baseline: {write_baseline}", err=True)
    if as_json:
        emit_json(({k: v for k, v in summary.items() if k != "cases"}
                        | {"cases": [{k: v for k, v in c.items() if k != "series"} for c in summary["cases"]]}))
    sys.exit(0 if summary["failed"] == 0 else 1)


@cli.command()
@click.argument("old", metavar="OLD")
@click.argument("new", metavar="NEW")
@click.option("--tolerance", type=Number(lo=0), default=None,
              help="scaled move allowed for every quantity (default: the baseline's per-quantity tolerances, "
                   "else the implementation bar, 1e-9)")
@click.option("--source", "renames", multiple=True, metavar="OLD_NAME=NEW_NAME",
              help="compare OLD's source under NEW's name (e.g. lammps@2024=lammps); repeatable")
@click.option("--report", "report_dir", type=OutputPath(directory=True, files=("diff.md", "diff.json", "junit.xml")),
              default=None, help="write diff.md, diff.json and junit.xml into this directory")
@click.option("--junit", "junit", type=OUT_FILE, default=None, help="also write JUnit XML here")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
def diff(old, new, tolerance, renames, report_dir, junit, as_json):
    """What moved between two verification runs (results.json, a report directory, or a baseline file): per
    case, source and metric, the move in units of the metric's scale and every verdict that changed. Exit 1
    when a verdict got worse, a value moved beyond its tolerance or a source is gone; 2 on bad input."""
    from .comparisons import diff
    from .io import write_json, write_text

    rename = {}
    for r in renames:
        a, eq, b = r.partition("=")
        if not (eq and a.strip() and b.strip()):
            raise ConfigError("--source", r, "must be OLD_NAME=NEW_NAME")
        rename[a.strip()] = b.strip()
    d = diff.compare(diff.load(old, "OLD"), diff.load(new, "NEW"), tolerance, rename)
    md = diff.render_markdown(d)
    if report_dir:
        out = Path(report_dir)
        write_text(out / "diff.md", md + "\n")
        write_json(out / "diff.json", plain(d))
        write_text(out / "junit.xml", diff.render_junit(d))
    if junit:
        write_text(junit, diff.render_junit(d))
    if as_json:
        emit_json(d)
    else:
        click.echo(md)
    sys.exit(1 if d["regressions"] else 0)


@cli.command()
@click.argument("name", required=False, metavar="[NAME]")
@click.option("--engines", "engines", default=",".join(ENGINE_NAMES), show_default=True, metavar="LIST",
              help=f"comma-separated engines ({', '.join(ENGINE_NAMES)}), or 'none' for the reference alone")
@_campaign_options(2, "cases")
@click.option("--report", "report_dir", type=VALIDATE_DIR, default="reports", show_default=True,
              help="where reports/<run-id> and reports/latest-validate go")
@click.option("--junit", "junit", type=OUT_FILE, default=None, help="also write JUnit XML here")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--no-cache", "no_cache", is_flag=True, help="run every engine deck again")
@click.option("--timeout", type=TIMEOUT, default=600.0, show_default=True, help="per engine run (s)")
@click.option("--quick", is_flag=True, help="one case file per benchmark (68 of the 614 cases): a first look in minutes")
def validate(name, engines, jobs, scheduler, report_dir, junit, as_json, no_cache, timeout, quick):
    """Run the published benchmarks (cases/benchmarks/: Chung & Ooi's eight tests, Thornton's oblique
    impacts; NAME one of them, e.g. chung-ooi-4) in the reference and every engine, and judge each source
    against the exact limits and the papers' curves (docs/benchmarks.md). The opt-in heap benchmarks
    ai2011-sandpile-constant, -viscous and -epsd (Ai et al. 2011's rolling resistance, one to two hours each, the
    reference alone, a line of progress per simulated second) run only when named. Exit 1 when the reference
    misses an exact limit or a run fails, 2 on bad input."""
    from .comparisons.suite import Options
    from .comparisons.validate import by_name, run
    from .engines import run as runner
    from .engines.cache import Cache, default_dir

    by_name(name)  # an unknown NAME: one line, exit 2, before any work
    _check_jobs(jobs, scheduler)
    names = _engine_list(engines)
    check_output("DEMCHECK_CACHE", default_dir(), directory=True)
    opts = Options(engines=tuple(names), jobs=jobs, scheduler=scheduler, cache=Cache(refresh=no_cache), timeout=timeout)
    try:
        summary = run(name, resources.cases_dir() / "benchmarks", Path(report_dir), opts, quiet=as_json,
                      junit=Path(junit) if junit else None, argv=["demcheck", "validate", *sys.argv[2:]], quick=quick)
    except KeyboardInterrupt as exc:
        click.echo("demcheck: interrupted; the engines were stopped and the finished cases are in the partial "
                   f"report {Path(report_dir) / 'latest-validate'}", err=True)
        sys.exit(runner.interrupt_exit_code(exc))
    val = summary.validation
    if as_json:
        emit_json({"report": summary.report, "engines": summary.engines, "failed": summary.failed,
                   "validation": {k: v for k, v in val.to_json().items() if k != "series"}})
    else:
        click.echo("\n".join(cli_text.validation(val)), err=True)
    sys.exit(0 if summary.failed == 0 else 1)


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--engine", type=click.Choice(["reference", *ENGINE_NAMES]), default="reference",
              show_default=True)
@click.option("--duration", type=DT, default=None, help="simulated time (s); default: the case's packing.duration")
@click.option("--mpi", "mpi", type=Number(lo=1, hi=256, integer=True, unit="MPI ranks"), default=1,
              show_default=True,
              help="run the engine on this many MPI ranks (its own domain decomposition)")
@click.option("--threads", "threads", type=Number(lo=1, integer=True, unit="threads"), default=1,
              show_default=True,
              help="run the reference's force loop on this many threads (numba's; at most NUMBA_NUM_THREADS, by "
                   "default the machine's cores): the same physics, a particle's forces summed in another order — "
                   "not one thread's bits, and a pour, being chaotic, then agrees in its statistics, not sphere by "
                   "sphere (docs/packing.md)")
@click.option("--timeout", type=TIMEOUT, default=3600.0, show_default=True, help="engine run timeout (s)")
@click.option("--csv", "csv_dir", type=PACK_CSV_DIR, default=None,
              help="write the settled state here: particles.csv (id, x, y, z, radius) and contacts.csv "
                   "(i, j, overlap, fn, ft of every particle pair in contact)")
@click.option("--vtk", "vtk_dir", type=PACK_VTK_DIR, default=None,
              help="write the settled state for ParaView here (meshio, float64): particles.vtu (a vertex per centre: "
                   "id, type, radius, mass, velocity, angular_velocity, and force — the net force — from an engine's "
                   "final dump only: the reference keeps no per-particle force) and contacts.vtu (a line per "
                   "particle-particle contact, to the minimum image across a periodic boundary: normal_force, "
                   "tangential_force, overlap, i, j; wall contacts are not drawn)")
@click.option("--xyz", "xyz_file", type=PACK_XYZ_FILE, default=None,
              help="write the settled state as one extended XYZ frame (ase; OVITO reads it): Lattice and pbc from "
                   "the box (x, y periodic), per particle id, species_id, radius, velo, omega; ase writes eight "
                   "decimals, so SI values to 5e-9 — masses and forces are in --vtk (float64) only")
@_set_option
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
def pack(case_path, engine, duration, mpi, threads, timeout, csv_dir, vtk_dir, xyz_file, overrides, as_json):
    """Settle a packing case in the N-body reference solver, or in an engine from the same initial state
    (a LAMMPS data file both engines read), and print its packing metrics (with the contact network's fabric
    tensor); --csv, --vtk and --xyz write the settled state."""
    from . import api

    out = api.pack(case_path, engine, duration, mpi, threads, timeout, list(overrides), csv=csv_dir, vtk=vtk_dir,
                   xyz=xyz_file, wrote=lambda path: click.echo(f"wrote {path}", err=True), base=True,
                   keys={**SET_KEYS, "engine": "--engine", "duration": "--duration", "mpi": "--mpi",
                         "threads": "--threads", "timeout": "--timeout", "csv": "--csv", "vtk": "--vtk",
                         "xyz": "--xyz"})
    if as_json:
        emit_json(out)
        return
    click.echo("\n".join(cli_text.packing(out)))


def _show_report(data: dict, out_dir: Path, as_json: bool) -> None:
    if as_json:
        emit_json(data)
    else:
        click.echo(Path(out_dir / "report.md").read_text())
        click.echo(f"report: {out_dir}/report.md (and report.html, results.json)", err=True)


def _engine_list(engines: str) -> list[str]:
    """The engines and builds of an --engines list (``lammps,lammps@2024=/opt/lmp-2024/lmp``), as verify reads it."""
    from .engines import discovery

    return discovery.resolve(engines, "--engines")


def _engine_text(names) -> str:
    from .engines import discovery

    out = []
    for e in names:
        info = discovery.find(e)
        out.append(f"{e} {info.version}" if info else f"{e}: missing ({discovery.how_to_install(e)})")
    return "; ".join(out) or "none (reference only)"


@cli.command()
@click.argument("paths", nargs=-1, required=True, metavar="CASE|DIR...")
@click.option("--engines", "engines", default=",".join(ENGINE_NAMES), show_default=True, metavar="LIST",
              help=f"comma-separated engines ({', '.join(ENGINE_NAMES)}), or 'none'")
@click.option("--steps", "steps", default=None, metavar="LIST",
              help="steps per elastic contact time to sweep (default 5,10,20,50,100,200,500,1000,2000,5000)")
@click.option("--batch", type=Number(lo=1, hi=10000, integer=True), default=16, show_default=True,
              help="copies per engine batch run")
@click.option("--report", "report_dir", type=BENCH_DIR, default="reports", show_default=True,
              help="where reports/<run-id> and reports/latest-bench go")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@_set_option
@_campaign_options(1, "points", "points run in parallel: 1 in this process, N in a local Dask cluster of N worker "
                                "processes (the points are timed: side by side they share the machine)")
def bench(paths, engines, steps, batch, report_dir, as_json, overrides, jobs, scheduler):
    """Run time against error: sweep the time step of the reference's verlet method and of each engine (one
    collision per process, and a batch of copies per process), and the adaptive method's tolerance; fit the
    order of convergence and find the cheapest step for each target error."""
    from rich.progress import Progress

    from .case import naming_file
    from .comparisons import bench
    from .comparisons.perf_report import new_run_dir, write_bench

    names = _engine_list(engines)
    grid = bench.STEPS_PER_CONTACT
    if steps:
        grid = tuple(number("--steps", x, lo=1, hi=1e6, unit="steps per contact") for x in steps.split(","))
    cases = []
    for f in _case_files(paths):  # every file read and checked before any work; an error names the file
        with naming_file(f):
            cases.append(bench.check_case(_load(f, overrides)))
    root = Path(report_dir)
    out_dir = new_run_dir(root, "bench")
    results = []
    per_case = len(bench.ADAPTIVE_RTOLS) + len(grid) * (1 + len(names))
    twins = sum(len(bench.native_sources(c, names)) for c in cases)  # a native law's twin: one more grid
    with _campaign(jobs, scheduler, names) as campaign, Progress(transient=True, disable=as_json) as progress:
        task = progress.add_task("bench", total=per_case * len(cases) + len(grid) * twins)
        for case in cases:
            results.append(bench.bench_case(case, names, grid, batch=batch, progress=lambda: progress.advance(task),
                                            campaign=campaign).summary())
    data = {"run_id": out_dir.name, "report": str(out_dir), "engines": _engine_text(names), "batch": batch,
            "command": ["demcheck", "bench", *sys.argv[2:]], "cases": results,
            "speed_goal": bench.speed_goal_text(results)}
    write_bench(data, root)
    _show_report(data, out_dir, as_json)
    if not as_json:
        for b in results:
            for engine, law in b["natives"].items():
                click.echo("\n".join(cli_text.bench_native(b["case"], engine, law, b["reference"])))


@cli.command()
@click.argument("paths", nargs=-1, required=True, metavar="CASE|DIR...")
@click.option("--engines", "engines", default=",".join(ENGINE_NAMES), show_default=True, metavar="LIST")
@click.option("--only", "only", multiple=True, metavar="NAME",
              help="stress only parameters whose name contains NAME (stiffness, restitution, radius, speed, "
                   "angle, mass); repeatable")
@click.option("--report", "report_dir", type=STRESS_DIR, default="reports", show_default=True,
              help="where reports/<run-id> and reports/latest-stress go")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@_campaign_options(2, "stability searches")
def stress(paths, engines, only, report_dir, as_json, jobs, scheduler):
    """Numerical stability: the largest stable time step of each source against stiffness, mass ratio,
    impact speed, restitution, radius and incidence, with the failures and where the engines and the
    reference disagree."""
    from rich.progress import Progress

    from .case import naming_file
    from .comparisons.perf_report import new_run_dir, write_stress
    from .comparisons.stress import check_case, read_table, stress_case

    names = _engine_list(engines)
    cases = []
    for f in _case_files(paths):  # every file read and checked before any work; an error names the file
        raw = read_table(f)
        with naming_file(f):
            cases.append((raw, check_case(_load(raw, ()))))  # api.load: its [engine.NAME] settings read too
    root = Path(report_dir)
    out_dir = new_run_dir(root, "stress")
    results = []
    with _campaign(jobs, scheduler, names) as campaign, Progress(transient=True, disable=as_json) as progress:
        task = progress.add_task("stress", total=None)
        for raw, case in cases:
            results.append(stress_case(raw, case, names, list(only) or None, progress=lambda: progress.advance(task),
                                       campaign=campaign).summary())
    data = {"run_id": out_dir.name, "report": str(out_dir), "engines": _engine_text(names),
            "command": ["demcheck", "stress", *sys.argv[2:]], "cases": results}
    write_stress(data, root)
    _show_report(data, out_dir, as_json)
    for c in results if not as_json else ():
        for engine, native in c["natives"].items():
            click.echo(cli_text.stress_native(c["case"], engine, native))
    if any(c["disagreements"] for c in results):
        sys.exit(1)


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--target", type=Number(lo=0, hi=1, lo_open=True, hi_open=True), default=1e-3, show_default=True,
              help="the worst relative error to allow (restitution, contact time, max overlap, peak force)")
@_set_option
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
def dt(case_path, target, overrides, as_json):
    """A recommended time step for the case's model, from the Rayleigh and Hertz times and the measured
    work–precision of the engines' scheme, with the error to expect."""
    from .comparisons.bench import recommend

    from .comparisons.sources import collision_only

    case = collision_only(_load(case_path, overrides), "a time step is recommended for an impact; the scenarios "
                                                       "beyond sliding are solved by the adaptive reference only")
    rec = recommend(case, target)
    if as_json:
        emit_json(rec)
        if rec["dt"] is None or any(n["dt"] is None for n in rec["natives"].values()):
            sys.exit(1)
        return
    click.echo("\n".join(cli_text.recommendation(rec, target)))
    if rec["dt"] is None or any(n["dt"] is None for n in rec["natives"].values()):
        sys.exit(1)


@cli.command()
@click.argument("deck_path", metavar="DECK")
@click.option("--engine", "engine", default=None,
              help="the deck's engine (default: from its vocabulary or file: lammps, liggghts, kratos, yade)")
@click.option("--speed", type=Number(lo=0, lo_open=True, hi=1e4, unit="m/s"), default=None,
              help="characteristic impact speed (default: the deck's largest speed, or characteristicVelocity)")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@click.option("--report", "report_dir", type=OutputPath(directory=True, files=("audit.json", "audit.txt")),
              default=None, help="write audit.json and audit.txt into this directory")
def audit(deck_path, engine, speed, as_json, report_dir):
    """Audit a user's own input: a LAMMPS or LIGGGHTS deck, a Kratos DEM project (ProjectParametersDEM.json) or a
    Yade script (read as a syntax tree): each type pair's and wall's contact law, probed in the
    engine, its twin and the nearest seed model; the traps it falls into. The deck is read, never run as written.
    Exit 0: every pair and wall probed or listed, nothing found; 1: a trap; 2: a line it cannot read; 3: nothing
    probed (never "clean"). --json prints one JSON object in every case, a refusal included."""
    from . import api
    from .comparisons import audit
    from .errors import DemcheckError, EngineInterrupted
    from .io import write_text

    try:
        result = api.audit(deck_path, engine, speed)
    except EngineInterrupted:
        raise
    except DemcheckError as exc:
        if as_json:  # the refusal as a JSON object too; the one line still goes to stderr
            emit_json({"deck": str(deck_path), "status": "refused" if exc.exit_code == 2 else "failed",
                       "error": audit.safe_text(str(exc).splitlines()[0] if str(exc) else type(exc).__name__),
                       "exit_code": exc.exit_code})
        raise
    text = audit.text_report(result)
    if report_dir:
        out = Path(report_dir)
        out.mkdir(parents=True, exist_ok=True)
        write_text(out / "audit.json", json.dumps(plain(result), indent=2) + "\n")
        write_text(out / "audit.txt", text + "\n")
    if as_json:
        emit_json(result)
    else:
        click.echo(text)
    if result["status"] == "not audited":
        sys.exit(AUDIT_NOTHING_PROBED)
    if result["traps"]:
        sys.exit(1)


AUDIT_NOTHING_PROBED = 3  # `demcheck audit`: the deck was read, nothing was probed — its own status, never 0


@cli.command()
@click.argument("case_path", metavar="CASE")
@click.option("--engine", "engine", type=click.Choice(ENGINE_NAMES), required=True,
              help="the engine whose native input is calibrated")
@click.option("--target", "targets", multiple=True, required=True, metavar="METRIC=VALUE",
              help="a metric to realise: restitution=0.6, tangential_restitution=0.4 (repeatable)")
@click.option("--dt", type=DT, default=None, help="the engine's time step (s); default: the case's")
@_set_option
@click.option("--no-confirm", "no_confirm", is_flag=True, help="the twin only: no confirming engine run")
@click.option("--json", "as_json", is_flag=True, help="one JSON object on stdout")
@_campaign_options(1, "confirming engine run", "1: the confirming engine run in this process; 2 or more: in the "
                                               "worker of a local Dask cluster (one run: nothing runs side by side)")
def calibrate(case_path, engine, targets, dt, overrides, no_confirm, as_json, jobs, scheduler):
    """The native input (the coefficient of restitution or damping an engine reads, k_t, …) that realises a
    target metric in ENGINE at the run's dt: root finding on the engine's twin, confirmed by one engine run;
    prints the line to paste. Exit 0: confirmed; 1: the engine run misses the target; 2: bad input."""
    from . import api
    from .comparisons import calibrate

    wanted = {}
    for item in targets:
        key, sep, value = item.partition("=")
        if not sep:
            raise ConfigError("--target", item, "must be METRIC=VALUE, e.g. restitution=0.6")
        if key.strip() in wanted:
            raise ConfigError("--target", item, f"{key.strip()} is given twice: give each metric once")
        wanted[key.strip()] = number(f"--target {key.strip()}", value)
    calibrate.check_targets(wanted, "--target")  # bad input: one line, before any work
    _check_jobs(jobs, scheduler)
    result = api.calibrate(case_path, engine, wanted, dt, not no_confirm, list(overrides), jobs=jobs,
                           scheduler=scheduler, base=True,
                           keys={**SET_KEYS, "engine": "--engine", "targets": "--target", "dt": "--dt"})
    if as_json:
        emit_json(result)
    else:
        click.echo(calibrate.text_report(result))
    if result["confirmed"] is False:
        sys.exit(1)


def _case_files(paths) -> list[Path]:
    return resources.case_files(paths)


# ----------------------------------------------------------------------------- entry point


def main(argv=None) -> None:
    import threading

    from .engines import run as runner
    from .errors import EngineInterrupted

    received: list[int] = []  # the signals that reached demcheck during this command
    restore = lambda: None  # noqa: E731
    if threading.current_thread() is threading.main_thread():
        runner.handle_sigterm()  # SIGTERM, SIGHUP as SIGINT: engines stopped, a partial report, exit 143, 129
        restore = _record_signals(received)
    try:
        cli.main(args=argv, prog_name="demcheck", standalone_mode=False)
    except click.exceptions.Abort as exc:  # click's KeyboardInterrupt (or Terminated)
        runner.kill_all()
        click.echo("demcheck: interrupted", err=True)
        sys.exit(runner.interrupt_exit_code(exc))
    except EngineInterrupted as exc:
        runner.kill_all()
        click.echo(f"demcheck: interrupted: {str(exc).splitlines()[0]}", err=True)
        sys.exit(exc.exit_code)
    except click.UsageError as exc:  # one line, as every other bad input: what is wrong, and where help is
        ctx = exc.ctx
        where = f"{ctx.command_path} --help" if ctx is not None else "demcheck --help"
        message = exc.format_message().rstrip(".")
        hint = " (a value that starts with '-' goes after '--')" if "No such option" in message else ""
        click.echo(f"demcheck: error: {message}{hint}; see {where}", err=True)
        sys.exit(2)
    except click.exceptions.ClickException as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.exceptions.Exit as exc:
        sys.exit(exc.exit_code)
    except DemcheckError as exc:
        click.echo(f"demcheck: error: {exc}", err=True)
        sys.exit(exc.exit_code)
    except Exception as exc:  # an interrupt that surfaced as another error, or a fault (raised again)
        code = _interrupt_behind(exc, received)
        if code is None:
            raise
        runner.kill_all()
        click.echo("demcheck: interrupted", err=True)
        sys.exit(code)
    finally:
        restore()


def _record_signals(received: list[int]):
    """Let the SIGINT, SIGTERM and SIGHUP handlers (KeyboardInterrupt, engines.run's Terminated) note each signal in
    ``received`` before they raise; returns the function that puts them back. An interrupt raised where Python
    cannot pass it on (a ctypes callback during numba's compilation prints it and drops it, and numba then
    fails with an error of its own) is still known to have happened."""
    import signal

    previous = {}
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        handler = signal.getsignal(sig)
        if callable(handler):  # not SIG_IGN (a background job's SIGINT) nor SIG_DFL

            def noted(signum, frame, handler=handler):
                received.append(signum)
                handler(signum, frame)

            previous[sig] = handler
            signal.signal(sig, noted)

    def restore():
        for sig, handler in previous.items():
            signal.signal(sig, handler)

    return restore


def _interrupt_behind(exc: BaseException, received: list[int]) -> int | None:
    """The exit code (128 + the signal) when ``exc`` is an interrupt's doing, else None: a KeyboardInterrupt
    (or engines.run.Terminated) among its causes and contexts — numba raises a pending signal inside its own
    callback (_numba_unpickle) as it returns from a compiled kernel, and reports it as ``SystemError:
    CPUDispatcher(...) returned a result with an exception set`` caused by the KeyboardInterrupt — or, where
    the chain lost it, a signal received during the command."""
    from .engines import run as runner

    stop = runner.interrupt_in(exc)
    if stop is not None:
        return runner.interrupt_exit_code(stop)
    return 128 + received[-1] if received else None


if __name__ == "__main__":  # pragma: no cover
    main()
