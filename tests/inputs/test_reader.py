"""pcbdyn.inputs.Reader's checks of a choice, a whole number and a number in a range: a value that
passes comes back as it is read, and one that fails is refused in one line naming the file, the field,
the value and the fix."""

import math

import pytest

from pcbdyn.domain import StructureError
from pcbdyn.inputs import Reader

R = Reader("/some/folder/board.toml")


def refused(check, *args, **kw) -> str:
    with pytest.raises(StructureError) as exc:
        check(*args, **kw)
    msg = str(exc.value)
    assert "\n" not in msg and "folder" not in msg, msg  # one line, the file by its name
    return msg


def test_choice_names_the_closest_option_and_every_option():
    assert R.choice("hinged", "supports[0].type", ("clamped", "hinged"), "support type") == "hinged"
    msg = refused(R.choice, "wedgelock", "fixtures[1].type", ("free", "wedge_lock", "standoff"), "fixture type")
    assert msg == ("board.toml: fixtures[1].type: unknown fixture type 'wedgelock' (did you mean 'wedge_lock'?); "
                   "use one of free, wedge_lock, standoff")


def test_choice_refuses_a_non_text_and_explains_the_options():
    msg = refused(R.choice, 3, "box.rib_model", ("beam", "shell"), "rib model", {"shell": "shell strips"})
    assert msg == "board.toml: box.rib_model: unknown rib model 3; use one of beam, shell (shell strips)"


@pytest.mark.parametrize("value", [0, 13, 2.0, True, "4"])
def test_whole_refuses_what_is_not_a_whole_number_in_range(value):
    msg = refused(R.whole, value, "study.shots", 1, 12)
    assert msg.startswith("board.toml: study.shots: must be a whole number from 1 to 12, got ")
    assert repr(value) in msg or str(value) in msg


def test_whole_without_an_upper_limit():
    assert R.whole(10**6, "analysis.modes") == 10**6
    assert refused(R.whole, -2, "analysis.modes") == ("board.toml: analysis.modes: must be a whole number of at "
                                                       "least 1, got -2")


@pytest.mark.parametrize("value", [-0.01, 1.5, math.nan, math.inf, False, "0.5"])
def test_number_in_includes_its_ends_and_nothing_past_them(value):
    assert R.number_in(0, "board.stackup[0].fill", 0, 1) == 0.0 and R.number_in(1, "f", 0, 1) == 1.0
    msg = refused(R.number_in, value, "board.stackup[0].fill", 0, 1, "the copper's share of the layer")
    assert msg.startswith("board.toml: board.stackup[0].fill: must be a number from 0 to 1 (the copper's share of "
                          "the layer), got ")


def test_number_with_one_limit_says_which():
    """A bound on one side only was written "between 0.0 and None (exclusive)"."""
    assert refused(R.number, 0, "regions[0].stiffness_factor", lo=0, note="1 leaves it unchanged") == (
        "board.toml: regions[0].stiffness_factor: must be > 0 (1 leaves it unchanged), got 0")
    assert refused(R.number, 2.5, "x", hi=2) == "board.toml: x: must be < 2, got 2.5"
    assert R.number(0.3, "board.material.nu", -1.0, 0.5) == 0.3
