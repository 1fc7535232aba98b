"""demcheck: does a DEM contact force model, as LAMMPS and LIGGGHTS implement it, do what the textbook model does?"""

__version__ = "0.1.0"
