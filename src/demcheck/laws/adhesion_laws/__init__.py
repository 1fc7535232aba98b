"""The adhesion laws, one module each (record, case keys, compiled force, registration in :data:`.slot.KERNELS`);
importing the package registers the built-in laws. laws/adhesion.py is the slot's face."""

from . import jkr, dmt, sjkr  # noqa: F401  (registers them)
