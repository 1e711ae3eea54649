"""pcbdyn: vibration of electronic equipment, from FE model to a model that agrees with a modal test."""

__version__ = "0.1.0"
