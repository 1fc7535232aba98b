"""Yade runs only scripts named ``*.py``; demcheck's runner names every deck ``in.deck``. This file, run by
Yade as ``yade -x -n launch.py in.deck``, executes the deck in Yade's own namespace. It is not imported by
demcheck: the deck was checked by the Yade engine's guard (``yade.deck.check_script``) before the run."""

import sys

with open(sys.argv[1], encoding="utf-8") as _fh:
    _source = _fh.read()
exec(compile(_source, sys.argv[1], "exec"), globals())  # noqa: S102 - a deck demcheck wrote and checked
