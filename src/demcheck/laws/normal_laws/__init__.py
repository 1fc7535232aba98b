"""The normal laws, one module each: its record (a ``NormalSubModel``), its family id, its compiled functions and
their registration (``common.compiled``) — ``hooke`` (k δ), ``hertz`` (k δ^{3/2}), ``hls`` (the hysteretic linear
spring). Importing the package imports every module in it, in name order (a new law is a new module here, and
nothing else); ``dispatch`` assembles the kernels' switch from them, and laws/normal_force.py composes the
contact's force (spring + the damping slot's dashpot + limit_force's clip). The users' names are laws/normal.py."""

import importlib as _importlib
import pkgutil as _pkgutil

_SHARED = {"common", "dispatch"}
LAWS = tuple(_importlib.import_module(f"{__name__}.{m.name}") for m in sorted(_pkgutil.iter_modules(__path__),
                                                                               key=lambda m: m.name)
             if m.name not in _SHARED)
