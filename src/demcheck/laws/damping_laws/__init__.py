"""The damping laws, one module each: its record (a ``Damping``), its family id, its compiled functions and their
registration (``common.compiled``). Importing the package imports every module in it, in name order (a new law
is a new module here, and nothing else); ``dispatch`` assembles the kernels' switch from them."""

import importlib as _importlib
import pkgutil as _pkgutil

_SHARED = {"common", "dispatch"}
LAWS = tuple(_importlib.import_module(f"{__name__}.{m.name}") for m in sorted(_pkgutil.iter_modules(__path__),
                                                                               key=lambda m: m.name)
             if m.name not in _SHARED)
