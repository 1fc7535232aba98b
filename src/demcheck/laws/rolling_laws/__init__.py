"""The rolling-resistance laws, one module each (its record, its case keys, its compiled force and their
registration in :data:`.slot.KERNELS`); importing the package registers the built-in laws in this order.
laws/rolling.py is the slot's face (the records, :func:`~demcheck.laws.rolling.rolling_torque`)."""

from . import constant_torque, viscous, epsd, ai_viscous, ai_epsd  # noqa: F401  (registers them)
