"""Cards in their housing (box.toml [[cards]]): one model of the box and the boards it holds."""

import re
import shutil

import numpy as np
import pytest
import tomlkit
from calculix import CCX
from calculix_system import system_frequencies
from system_helpers import ALUMINIUM, EXAMPLES, STEEL, housing

from pcbdyn.board import load_board
from pcbdyn.box import BoxError, load_box
from pcbdyn.box.cards import DEFAULT_REDUCTION_MODES
from pcbdyn.fe.assembly import assemble
from pcbdyn.fe.modal import solve_modes


def _modes(structure, n=4):
    return solve_modes(structure.build().model, n).frequencies


@pytest.mark.parametrize("strip", ["", 'width = "4 mm"\n'], ids=["line", "strip"])
def test_a_card_in_stiff_walls_has_the_modes_of_the_card_alone(tmp_path, strip):
    """30 mm steel walls hold the guides as the fixed frame does: the first four modes within 0.5 % (the
    guides on their support lines, or holding 4 mm strips along the edges)."""
    path = housing(tmp_path, 30.0, STEEL)
    card = tmp_path / "card.toml"
    card.write_text(card.read_text().replace('type = "wedge_lock"\n', 'type = "wedge_lock"\n' + strip))
    box = load_box(path)
    alone = _modes(load_board(card))
    housed = _modes(box)
    assert np.allclose(housed, alone, rtol=5e-3), (housed, alone)
    assert not np.allclose(housed, alone, rtol=1e-9)  # the walls do give a little


def test_thin_walls_lower_the_first_mode_and_the_mass_is_the_sum_of_the_parts(tmp_path):
    box = load_box(housing(tmp_path, 1.5, ALUMINIUM))
    card = load_board(tmp_path / "card.toml")
    system = box.build()
    f1 = solve_modes(system.model, 1).frequencies[0]
    assert f1 < 0.99 * _modes(card, 1)[0]  # 2.3 % below
    empty = load_box(housing(tmp_path, 1.5, ALUMINIUM, cards=False, name="empty.toml"))
    parts = empty.build().mass() + card.build().mass()
    assert system.mass() == pytest.approx(parts, rel=1e-9)


def test_a_fixture_that_touches_nothing_is_named_with_its_gap(tmp_path):
    path = housing(tmp_path, 2.0, ALUMINIUM)
    path.write_text(path.read_text().replace('origin = ["0 mm", "10 mm", "60 mm"]', 'origin = ["30 mm", "10 mm", "60 mm"]'))
    with pytest.raises(BoxError, match=r"cards\[0\]: fixture 'left_guide' \(wedge_lock\) of card 'card1' .* touches "
                                       r"nothing: the nearest, plate 'left', is 29 mm away"):
        load_box(path)


def test_craig_bampton_cards_match_the_full_system():
    """The example box with both cards reduced to their interface (the default 40 fixed-interface modes
    each): the first 12 modes within 0.5 % of the full model's, and above them (a Rayleigh-Ritz); with
    two modes per card the cards' higher modes are lost."""
    box = load_box(EXAMPLES / "box.toml")
    system = box.build()
    K, M = assemble(system.model)
    full = system.solve(12, K=K, M=M).frequencies
    reduced = system.solve(12, K=K, M=M, reduce=DEFAULT_REDUCTION_MODES)
    assert np.allclose(reduced.frequencies, full, rtol=5e-3)
    assert np.all(reduced.frequencies >= full * (1 - 1e-9))
    assert np.allclose(np.einsum("ij,ij->j", reduced.shapes, M @ reduced.shapes), 1.0)  # mass-normalised, full length
    crude = system.solve(12, K=K, M=M, reduce=2).frequencies
    assert np.max(crude / full - 1) > 0.05


@pytest.mark.slow
@pytest.mark.skipif(CCX is None, reason="CalculiX (ccx, Debian package calculix-ccx) is not installed")
def test_the_example_system_against_calculix(tmp_path):
    """The example box with its two cards (four standoff springs on the back plate's ribs; the shelf's
    guides clamped, as CalculiX has no rotational springs on shells), housing at 5 mm and cards at 2.5 mm:
    pcbdyn's MITC4 shells, eccentric beam ribs, placed cards and twin-node ties against CalculiX's S4
    shells, rib strips, rigid pads and SPRING2 springs on the same meshes, the first 12 modes within 1.5 %."""
    for f in EXAMPLES.glob("*.toml"):
        shutil.copy(f, tmp_path)
    card = tmp_path / "card_guides.toml"
    text, n = re.subn(r'k_rot = "[^"]*"', 'k_rot = "clamped"', card.read_text())
    assert n == 2
    card.write_text(text)
    doc = tomlkit.parse((tmp_path / "box.toml").read_text())
    doc["parameters"] = [p for p in doc["parameters"] if "shelf" not in str(p["target"])]
    (tmp_path / "box.toml").write_text(tomlkit.dumps(doc))
    box = load_box(tmp_path / "box.toml")
    system = box.build(mesh_size=0.005)
    ours = solve_modes(system.model, 12).frequencies
    theirs = system_frequencies(tmp_path, box, system, 12)
    np.testing.assert_allclose(ours, theirs, rtol=0.015)
