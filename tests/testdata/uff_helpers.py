"""Shared by the UFF tests."""

import numpy as np

E13, E20 = "%13.5E", "%20.12E"


def fixed(values, fmt):
    """What a fixed-width field keeps of each value: the value printed in ``fmt`` and read back."""
    v = np.asarray(values)
    if np.iscomplexobj(v):
        return fixed(v.real, fmt) + 1j * fixed(v.imag, fmt)
    return np.vectorize(lambda x: float(fmt % x))(v)


#: the head of a dataset 55 (a real normal mode, 3 values a node) up to its record 8, ``{rec8}``
HEADER55 = """    -1
    55
NONE
NONE
NONE
NONE
NONE
         1         2         2         8         2         3
         2         4         1         1
{rec8}
"""
