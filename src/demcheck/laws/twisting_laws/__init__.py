"""The twisting-resistance laws, one module each (record, case keys, compiled force, registration in
:data:`.slot.KERNELS`); importing the package registers the built-in laws. laws/twisting.py is the slot's face."""

from . import sds, marshall  # noqa: F401  (registers them)
