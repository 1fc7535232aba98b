"""Atomic file writes: a report is either the old one or the new one, never half of each."""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import secrets
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it is renamed over ``path``. The file is created
    with mode 0666 less the umask, as any other tool's output (mkstemp's 0600 is for secrets)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _create(path)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _create(path: Path) -> str:
    """A new, empty temporary file beside ``path`` (exclusively created, mode 0666 & ~umask)."""
    for _ in range(100):
        tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        return str(tmp)
    raise FileExistsError(f"no free temporary name beside {path}")


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)


def write_json(path, obj) -> None:
    write_text(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")


def plain(obj):
    """``obj`` as strict JSON takes it: non-finite floats as null, numpy scalars as Python numbers, tuples as
    lists, keys as strings — every JSON demcheck writes or prints goes through here."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if hasattr(obj, "item"):
        return plain(obj.item())
    return obj


def number(v, spec: str = ".6g") -> str:
    """A value in a table or a line of text: "—" for a missing or non-finite number, ``format(v, spec)`` for a
    number, ``str(v)`` otherwise — the one formatter of every report and CLI table."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return format(v, spec) if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)


# the ASCII punctuation markdown may read in running text (CommonMark, and GitHub's autolinks, tables and
# strikethrough): every character but - , = + ' " ; % ? ( ) /, which mean nothing in the middle of a line
# once [ ] < > : . & are escaped (no link, autolink or entity can form; no line starts with user text)
MD_PUNCTUATION = re.compile("([" + re.escape("".join(sorted(set(map(chr, range(33, 127))) - set(
    map(chr, [*range(48, 58), *range(65, 91), *range(97, 123)])) - set("-,=+'\";%?()/")))) + "])")


def md_text(text) -> str:
    """Text as markdown that renders as itself: its markdown punctuation backslash-escaped (CommonMark lets
    any ASCII punctuation be; :data:`MD_PUNCTUATION`), a line break a space. Everything a report takes from
    outside its own words goes through it — case names and files (a name may hold ``[ ] ( ) : / _``:
    ``[x](https://…) _y_`` would be a link and emphasis), sources, reasons and messages — so that none is read
    as a link, emphasis, code or a table's ``|``, in report.md or in report.html."""
    return MD_PUNCTUATION.sub(r"\\\1", str(text).replace("\r", " ").replace("\n", " "))


def console(stderr: bool = False, **options):
    """A rich Console for demcheck's tables: on a terminal its width; into a pipe or file (where rich assumes 80
    columns and cuts every column of a wide table to a few characters) wide enough for the tables, unless
    COLUMNS says otherwise."""
    import os
    import sys

    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    if "width" not in options and not os.environ.get("COLUMNS") and not stream.isatty():
        options["width"] = 200
    return Console(stderr=stderr, **options)


def check_output(key: str, path, directory: bool = False, files=(), link: str | None = None) -> None:
    """An output path demcheck can write (a file, or a ``directory`` it creates or fills), checked before any
    work: nothing on the way is a file, the path is not of the other kind, and its first existing directory
    takes a new file. So are the files derived from it: ``files``, names written in the directory (or beside
    the file), each not a directory; and ``link``, the symlink demcheck moves in the directory (``latest``),
    which is demcheck's: absent or a symlink, never a real file or directory. Else ConfigError naming ``key``,
    the path and the rule."""
    import tempfile

    from .errors import ConfigError

    p = Path(path).absolute()
    if p.is_dir() != directory and p.exists():
        raise ConfigError(key, str(path), "is a file, not a directory" if directory else "is a directory, not a file")
    where = p if directory and p.is_dir() else p.parent
    while not where.exists() and not where.is_symlink() and where != where.parent:
        where = where.parent
    if not where.is_dir():
        raise ConfigError(key, str(path), f"{where} is a file, not a directory")
    beside = Path(path) if directory else Path(path).parent
    for name in files:
        if (beside / name).is_dir():
            raise ConfigError(key, str(path), f"{beside / name} is a directory, not a file")
    if link is not None and (beside / link).exists() and not (beside / link).is_symlink():
        what = "directory" if (beside / link).is_dir() else "file"
        raise ConfigError(key, str(path), f"{beside / link} is a {what}, not the symlink demcheck moves to each "
                                          "new run (move it away, or choose another --report)")
    try:
        with tempfile.TemporaryFile(dir=where):
            pass
    except OSError as exc:
        raise ConfigError(key, str(path), f"cannot write in {where} ({exc.strerror or exc})") from None
