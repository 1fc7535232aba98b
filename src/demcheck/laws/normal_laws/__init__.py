"""The normal laws' compiled forces, one module each: ``viscoelastic`` (a spring record — hooke, hertz — whose
dashpot is the damping slot's, laws/damping_laws/) and ``hls`` (the hysteretic linear spring), each with its family
id in the law array, its compiled force and its traits; ``common`` holds the array's layout and the power helper.
The records and users' names are laws/normal.py and laws/damping.py; the facade the solvers import, where the
contact's force is composed, is laws/normal_force.py."""

from . import hls, viscoelastic  # noqa: F401

LAWS = (viscoelastic, hls)  # every normal law module (laws/normal_force.py reads their traits)
