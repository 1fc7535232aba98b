"""The heat-conduction laws, one module each (record, case keys, compiled function, registration in
:data:`.slot.KERNELS`); importing the package registers the built-in laws. laws/heat.py is the slot's face."""

from . import radius, area, lens  # noqa: F401  (registers them)
