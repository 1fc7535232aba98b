"""Small builders shared by the tests."""

from demcheck import case as C
from demcheck import cli


def cli_main(argv, capsys) -> tuple[int, str, str]:
    """``demcheck ARGV`` in this process: (exit code, stdout, stderr)."""
    try:
        cli.main([str(a) for a in argv])
        code = 0
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr()
    return code, out.out, out.err


def record_engine_runs(monkeypatch) -> list:
    """engines.run.run recorded, still running: the list of (deck text, the files beside it) of each run."""
    from demcheck.engines import run as runner

    ran, real = [], runner.run

    def recording(eng, text, *args, **kwargs):
        ran.append((text, dict(kwargs.get("files") or {})))
        return real(eng, text, *args, **kwargs)

    monkeypatch.setattr(runner, "run", recording)
    return ran


def write_deck(tmp_path, text, name="in.deck"):
    """``text`` written to ``tmp_path / name``; its path."""
    p = tmp_path / name
    p.write_text(text)
    return p

GLASS = """
name = "t"
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = {restitution}

[[particles]]
material = "glass"
radius = 1.59e-3
{second}
[impact]
speed = {speed}

[contact]
normal = "{normal}"
"""
PAIR = """
[[particles]]
material = "glass"
radius = 1.59e-3
"""
WALL = """
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
"""


def glass_case(normal="hertz", params=None, *, wall=False, speed=1.0, restitution=0.97, overrides=()):
    text = GLASS.format(restitution=restitution, second=WALL if wall else PAIR, speed=speed, normal=normal)
    sets = [f"contact.{k}={_toml(v)}" for k, v in (params or {}).items()]
    return C.loads(text, sets + list(overrides))


def _toml(v):
    return f'"{v}"' if isinstance(v, str) else repr(v).lower() if isinstance(v, bool) else repr(v)


def oblique_case(tangential, params=None, *, normal="lsd", normal_params=None, wall=True, speed=1.0, angle=45.0,
                 spin=0.0, restitution=0.9, friction=0.3, overrides=()):
    """An oblique impact of a glass sphere on a rigid wall (or a pair) with a tangential law."""
    from demcheck.laws import normal as _normal, tangential as _tangential

    nparams = dict(_normal.REGISTRY[normal].example if normal_params is None else normal_params)
    tparams = dict(_tangential.REGISTRY[tangential].example if params is None else params)
    tparams.pop("friction", None)
    text = GLASS.format(restitution=restitution, second=WALL if wall else PAIR, speed=speed, normal=normal)
    text = text.replace("[impact]", f"[impact]\nangle = {angle}\nspin = {spin}")
    text = text.replace("restitution = ", f"friction = {friction}\nrestitution = ", 1)
    sets = [f"contact.{k}={_toml(v)}" for k, v in {**nparams, **tparams}.items()]
    return C.loads(text, sets + [f"contact.tangential={tangential}"] + list(overrides))


def md_plain(md: str) -> str:
    """Markdown with its backslash escapes undone (CommonMark: a backslash before ASCII punctuation): the text a
    reader sees, for tests that look for a phrase in report.md (names, versions and sources are escaped there)."""
    import re

    return re.sub(r"\\([!-/:-@\[-`{-~])", r"\1", md)


def proc_stat(pid) -> list[str] | None:
    """/proc/<pid>/stat after the command name: [state, ppid, pgrp, ...], or None once it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return None


def _alive_where(field: int, value: int) -> list[int]:
    """The live (not zombie) processes whose /proc stat field ``field`` (1: the parent, 2: the process group) is
    ``value``."""
    import os

    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            st = proc_stat(d)
            if st and st[field] == str(value) and st[0] != "Z":
                out.append(int(d))
    return out


def group_alive(pgid: int) -> list[int]:
    """The live (not zombie) processes of a process group."""
    return _alive_where(2, pgid)


def children_alive(pid: int) -> list[int]:
    """The live (not zombie) children of a process."""
    return _alive_where(1, pid)


def _script_json(script: str, path: list, cache, timeout: float, plugins: str | None = None) -> dict:
    """``script``'s JSON (its last line), run in a fresh process with ``path`` first on PYTHONPATH (then the
    repository, for the tests' helpers), on an empty kernel cache under ``cache`` ($XDG_CACHE_HOME): the kernels'
    cache directory is named by the fingerprint of the laws' sources, so a law added to the path compiles afresh.
    ``plugins``: $DEMCHECK_LAW_PLUGINS (unset when None)."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, XDG_CACHE_HOME=str(cache),
               PYTHONPATH=os.pathsep.join([*map(str, path), str(root)]))
    env.pop("NUMBA_CACHE_DIR", None)
    env.pop("DEMCHECK_LAW_PLUGINS", None)
    if plugins is not None:
        env["DEMCHECK_LAW_PLUGINS"] = plugins
    p = subprocess.run([sys.executable, "-c", script], cwd=root, env=env, capture_output=True, text=True,
                       timeout=timeout)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def with_plugin_law(tmp_path, module: str, source: str, script: str, timeout: float = 1500) -> dict:
    """``script``'s JSON (its last line), run in a fresh process with ``source`` written as the plug-in law module
    ``module`` named in $DEMCHECK_LAW_PLUGINS, on an empty kernel cache (the plug-in's source in its fingerprint)."""
    from pathlib import Path

    (tmp_path / f"{module}.py").write_text(source)
    return _script_json(script, [tmp_path, Path(__file__).resolve().parents[1] / "src"], tmp_path / "cache", timeout,
                        plugins=module)


def with_law_modules(tmp_path, folder: str, modules: dict[str, str], script: str, timeout: float = 2400) -> dict:
    """``script``'s JSON (its last line), run in a fresh process on a copy of demcheck's source with ``modules``
    (name → text) added to laws/``folder``/ and nothing else changed (a law added as one module of the package, not
    a plug-in), on an empty kernel cache."""
    import shutil
    from pathlib import Path

    src = tmp_path / "src"
    shutil.copytree(Path(__file__).resolve().parents[1] / "src" / "demcheck", src / "demcheck",
                    ignore=shutil.ignore_patterns("__pycache__"))
    for name, text in modules.items():
        (src / "demcheck" / "laws" / folder / f"{name}.py").write_text(text)
    return _script_json(script, [src], tmp_path / "cache", timeout)


def code_names(text: str) -> set[str]:
    """The identifiers a module's code uses (comments and strings left out)."""
    import io
    import tokenize

    return {t.string for t in tokenize.generate_tokens(io.StringIO(text).readline) if t.type == tokenize.NAME}
