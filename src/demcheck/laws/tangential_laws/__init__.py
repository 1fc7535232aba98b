"""The tangential laws, one module each: its record (a ``TangentialSubModel``), its family id, its compiled
functions and their registration (``tangential_slot.compiled``). Importing the package registers the built-in
laws, in family order; a plug-in law is a module of the same shape named in ``$DEMCHECK_LAW_PLUGINS``
(``laws/tangential.py`` imports those after these)."""

from . import none, sliding, viscous, viscous_sliding, spring, lth, zzy, walton  # noqa: F401  (registers them)
