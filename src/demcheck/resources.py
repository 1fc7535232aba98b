"""What demcheck ships inside its package, found with :mod:`importlib.resources` (a checkout, an editable install
and a wheel in site-packages alike): the case files (the default suite, the packings, the published benchmarks,
the opt-in long cases) and the data (expected differences, tolerances, digitised benchmark curves).

One case discovery for every command and the API: :func:`case_path` turns a CASE argument into a file (a path is
taken as given; otherwise a shipped case by its name), :func:`case_files` turns CASE|DIR arguments into the files
a campaign runs (a directory walk leaves out ``optin/`` and ``benchmarks/``: run those by naming them).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .errors import ConfigError

# a directory walk leaves these out: the long cases (large packings) and the published benchmarks (`validate`)
NAMED_ONLY = frozenset({"optin", "benchmarks"})


def _package_dir(name: str) -> Path:
    where = resources.files("demcheck") / name
    if not isinstance(where, Path):  # a zip import: nothing here reads through a Traversable
        raise ConfigError("demcheck", str(where), "is installed in a zip archive; install it as files (pip install)")
    return where


def cases_dir() -> Path:
    """The shipped case files (``demcheck cases`` lists them)."""
    return _package_dir("cases")


def data_dir() -> Path:
    """The shipped data: expected_differences.toml, tolerances.toml, benchmarks/*.dat."""
    return _package_dir("data")


def shipped_cases() -> dict[str, Path]:
    """Every shipped case file by its name (the file's stem; the names are unique): the default suite first."""
    root = cases_dir()

    def order(f: Path):  # the default suite first (the top folder, then its sub-folders), then the named-only ones
        parts = f.relative_to(root).parts
        return bool(NAMED_ONLY & set(parts)), len(parts) > 1, parts

    return {f.stem: f for f in sorted(root.rglob("*.toml"), key=order)}


def case_rows() -> list[dict]:
    """The shipped case files (``demcheck cases``) as rows: name, folder, kind, normal and tangential model, whether
    the default suite runs it, path."""
    import tomllib

    root = cases_dir()
    rows = []
    for stem, path in shipped_cases().items():
        raw = tomllib.loads(path.read_text())
        contact = raw.get("contact") or {}
        folder = path.parent.relative_to(root).as_posix()
        rows.append({"name": stem, "folder": "" if folder == "." else folder, "kind": raw.get("kind", "collision"),
                     "normal": contact.get("normal"), "tangential": contact.get("tangential", "none"),
                     "in_default_suite": not NAMED_ONLY & set(path.relative_to(root).parts),
                     "path": str(path)})
    return rows


def case_path(text: str | Path, key: str = "CASE", what: str = "case file") -> Path:
    """A CASE argument as a file: an existing path as given, else a shipped case by its file's name
    (``glass-pair``), by the ``name`` the file gives (``suite-hertz-wall``) or by its path below the shipped cases (``packing/poured``, ``cases/packing/poured.toml``; ``.toml`` optional). Else ConfigError naming the
    argument and the rule."""
    p = Path(text)
    if p.is_file():
        return p
    if p.exists():
        raise ConfigError(key, str(text), "is a directory, not a case file")
    root = cases_dir()
    rel = p.as_posix().removesuffix(".toml")
    if rel and not p.is_absolute() and ".." not in p.parts:
        # a checkout's spelling (cases/packing/poured.toml) names the shipped file from any directory
        for below in dict.fromkeys((rel, rel.removeprefix("cases/"))):
            if (root / f"{below}.toml").is_file():
                return root / f"{below}.toml"
        named = shipped_cases().get(rel) or _by_case_name().get(rel)
        if named is not None:
            return named
    import difflib

    close = difflib.get_close_matches(rel, [*shipped_cases(), *_by_case_name()], n=1, cutoff=0.8)
    hint = f"; did you mean '{close[0]}'?" if close and ".." not in p.parts else ""
    raise ConfigError(key, str(text), f"no such {what}, nor a shipped case of that name "
                                      f"(`demcheck cases` lists the shipped ones){hint}")


def _by_case_name() -> dict[str, Path]:
    """The shipped cases by the ``name`` their files give (a suite file's stem and name may differ:
    suite/normal-hertz-wall.toml is the case suite-hertz-wall, as its reports call it)."""
    import tomllib

    out: dict[str, Path] = {}
    for path in shipped_cases().values():
        with open(path, "rb") as fh:
            name = tomllib.load(fh).get("name")
        if isinstance(name, str):
            out.setdefault(name, path)
    return out


def case_files(paths, key: str = "CASE") -> list[Path]:
    """The case files a campaign (verify, bench, stress) runs: each argument a file (or a shipped case's name),
    or a directory walked for ``*.toml`` without its ``optin/`` and ``benchmarks/`` folders; no argument: the
    shipped default suite."""
    if isinstance(paths, (str, Path)):
        paths = [paths]
    paths = list(paths) or [cases_dir()]
    files: list[Path] = []
    for text in paths:
        p = Path(text)
        if p.is_dir():
            files += sorted(f for f in p.rglob("*.toml") if not NAMED_ONLY & set(f.relative_to(p).parts))
        else:
            files.append(case_path(text, key, "case file or directory"))
    if not files:
        raise ConfigError(key, ", ".join(map(str, paths)), "holds no *.toml case files")
    return files
