"""Shared by the UFF tests."""

import numpy as np

E13, E20 = "%13.5E", "%20.12E"


def fixed(values, fmt):
    """What a fixed-width field keeps of each value: the value printed in ``fmt`` and read back."""
    v = np.asarray(values)
    if np.iscomplexobj(v):
        return fixed(v.real, fmt) + 1j * fixed(v.imag, fmt)
    return np.vectorize(lambda x: float(fmt % x))(v)
