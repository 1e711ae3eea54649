"""pcbdyn: vibration of electronic equipment, from FE model to a model that agrees with a modal test."""

from .fe.threads import cap_openmp

__version__ = "0.1.0"

cap_openmp()  # before gmsh or CHOLMOD load OpenMP (pcbdyn.fe.threads)
