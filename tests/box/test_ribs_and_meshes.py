"""A box's ribs and mesh checked against finer and other models: an offset beam rib against the same rib
resolved as a shell strip on a fine mesh, the example box on three meshes, and the example box against
CalculiX (Debian's calculix-ccx; skipped where it is not installed, installed by scripts/setup.sh)."""

import numpy as np
import pytest

from pcbdyn.box import load_box
from pcbdyn.fe.modal import solve_modes

from box_helpers import EXAMPLE, edited, plate_box, supports
from calculix import CCX, frequencies

RIB = ('[[ribs]]\nname = "r"\nplate = "p"\nfrom = ["0 mm", "50 mm"]\nto = ["200 mm", "50 mm"]\nheight = "10 mm"\n'
       'width = "3 mm"\nside = "+n"\n\n')


@pytest.mark.parametrize("held", ["free", "clamped"])
def test_an_offset_beam_rib_matches_a_shell_strip_on_a_fine_mesh(tmp_path, held):
    """A 200 x 100 x 2 mm aluminium plate with a 10 x 3 mm rib along its middle, free or clamped along one
    short edge (the rib's end held with it): the beam on the 5 mm mesh against the strip of shells on the
    2.5 mm mesh, the first six elastic modes within 2 %; without its offset the beam would be far off."""
    body = RIB + (supports("p", "clamped", ("u0",)) if held == "clamped" else "")
    beam = load_box(plate_box(tmp_path, 200, 100, 2, body, mesh_mm=5))
    strip = load_box(plate_box(tmp_path, 200, 100, 2, body, mesh_mm=2.5, name="s.toml"))
    strip.rib_model = "shell"
    fb = solve_modes(beam.build().model, n_modes=6).frequencies
    fs = solve_modes(strip.build().model, n_modes=6).frequencies
    np.testing.assert_allclose(fb, fs, rtol=0.02)
    plain = solve_modes(load_box(plate_box(tmp_path, 200, 100, 2, body.replace(RIB, ""), mesh_mm=5,
                                           name="p.toml")).build().model, n_modes=6).frequencies
    assert np.max(np.abs(fs / plain - 1)) > 0.2  # the rib matters


def test_the_example_box_converges_on_three_meshes():
    """20, 10 and 5 mm: each of the first eight frequencies moves less from 10 to 5 mm than from 20 to 10
    mm, by at least 1.7 (an element of order 2 gives 4; the relay's point mass and the beam ribs on
    Mindlin shells converge more slowly), and the 5 mm value lies within 1.5 % of the Richardson limit."""
    box = load_box(EXAMPLE)
    f = np.array([solve_modes(box.build(mesh_size=h).model, n_modes=8).frequencies for h in (0.02, 0.01, 0.005)])
    d = np.diff(f, axis=0)
    ratio = d[0] / d[1]
    assert np.all(ratio > 1.7), ratio
    order = np.log2(ratio)
    limit = f[2] + d[1] / (2.0**order - 1.0)
    assert np.all(np.abs(f[2] / limit - 1) < 0.015)


@pytest.mark.skipif(CCX is None, reason="CalculiX (ccx, Debian package calculix-ccx) is not installed")
def test_the_example_box_against_calculix(tmp_path):
    """The box without the relay on the same 5 mm plate mesh: pcbdyn's MITC4 shells and eccentric beam ribs
    against CalculiX's S4 shells with the ribs as shell strips, the first eight modes within 3 %."""
    box = load_box(edited(tmp_path, remove=("masses",), changes={"box.mesh_size": '"5 mm"'}))
    pm = box.build()
    ours = solve_modes(pm.model, n_modes=8).frequencies
    theirs = frequencies(tmp_path, box, pm, 8)
    np.testing.assert_allclose(ours, theirs, rtol=0.03)
