"""A generated module of compiled switches (laws/tangential_dispatch.py, laws/damping_laws/dispatch.py,
laws/normal_laws/dispatch.py): the source written once into numba's kernel cache and imported from there, so that
its functions' ``cache=True`` holds."""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
import types
from pathlib import Path

from .. import KERNEL_CACHE

_STAMP = 1_000_000_000  # the file's mtime (2001-09-09): the same bytes, the same stamp (numba keys its cache by it)


def generated_module(name: str, stem: str, text: str):
    """The module ``name`` of the generated source ``text``: written once (atomically) to
    ``$NUMBA_CACHE_DIR/generated/<stem>_<hash of text>.py`` and imported from there, so that ``cache=True`` holds
    for its functions; compiled from the text where there is no kernel cache. (The tangential, damping and normal
    switches are all written here.)"""
    path = None
    if KERNEL_CACHE and os.environ.get("NUMBA_CACHE_DIR"):
        digest = hashlib.sha256(text.encode()).hexdigest()[:16]
        path = Path(os.environ["NUMBA_CACHE_DIR"]) / "generated" / f"{stem}_{digest}.py"
        if not (path.exists() and path.read_text() == text):
            path.parent.mkdir(parents=True, exist_ok=True)
            with tempfile.NamedTemporaryFile("w", dir=path.parent, suffix=".tmp", delete=False) as fh:
                try:
                    fh.write(text)
                    fh.close()
                    os.utime(fh.name, (_STAMP, _STAMP))
                    os.replace(fh.name, path)
                finally:
                    if os.path.exists(fh.name):
                        os.unlink(fh.name)
    if path is None:
        module = types.ModuleType(name)
        exec(compile(text, f"<{name}>", "exec"), module.__dict__)  # noqa: S102 - our own generated source
    else:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    sys.modules[name] = module
    return module
