import numpy as np
import pytest

from pcbdyn.board.laminate import LaminateProperty, Layer, Material
from pcbdyn.fe import ShellProperty


def test_stack_of_one_material_is_the_homogeneous_plate():
    m = Material(26e9, 0.3, 2640.0)
    lam = LaminateProperty(tuple(Layer(0.7e-3, m) for _ in range(4)))
    ref = ShellProperty(26e9, 0.3, 2640.0, 2.8e-3)
    for f in ("membrane", "bending", "shear", "mass_per_area", "rotary_inertia_per_area"):
        np.testing.assert_allclose(getattr(lam, f)(), getattr(ref, f)(), rtol=1e-12)


def test_symmetric_sandwich_bending_by_parallel_axis():
    face, core = Material(70e9, 0.3, 2700.0), Material(1e9, 0.3, 100.0)
    tf, tc = 0.5e-3, 2e-3
    lam = LaminateProperty((Layer(tf, face), Layer(tc, core), Layer(tf, face)))
    c = lambda m: m.E / (1 - m.nu**2)
    d = (tc + tf) / 2
    D11 = 2 * c(face) * (tf**3 / 12 + tf * d**2) + c(core) * tc**3 / 12
    assert lam.bending()[0, 0] == pytest.approx(D11, rel=1e-12)
    assert lam.mass_per_area() == pytest.approx(2 * 2700 * tf + 100 * tc, rel=1e-12)


def test_unsymmetric_stack_bends_about_its_neutral_plane():
    """Two equal-thickness layers E1, E2: D* = E1 E2 t^3 ... equals the beam result about the neutral axis."""
    a, b = Material(100e9, 0.0, 1.0), Material(10e9, 0.0, 1.0)
    t = 1e-3
    lam = LaminateProperty((Layer(t, a), Layer(t, b)))
    zc = (a.E * t * 0.5 * t + b.E * t * 1.5 * t) / (a.E * t + b.E * t)  # neutral axis from the bottom
    EI = a.E * (t**3 / 12 + t * (0.5 * t - zc) ** 2) + b.E * (t**3 / 12 + t * (1.5 * t - zc) ** 2)
    assert lam.bending()[0, 0] == pytest.approx(EI, rel=1e-12)


def test_partial_copper_fill_mixes_properties():
    cu, fr4 = Material(117e9, 0.34, 8960.0), Material(22e9, 0.15, 1850.0)
    layer = Layer(35e-6, cu, fill=0.6, filler=fr4)
    assert layer.mixed().rho == pytest.approx(0.6 * 8960 + 0.4 * 1850)
    assert layer.mixed().E == pytest.approx(0.6 * 117e9 + 0.4 * 22e9)
