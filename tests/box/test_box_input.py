"""box.toml as input: the example loads as any structure does, and bad input gets one clear error naming the
file, the field and the fix (plates that do not meet with the gap named, a rib off its plate, a support on an
edge that is not there, a test point off every plate, a joint of plates that share no edge)."""

import numpy as np
import pytest
import tomlkit
from click.testing import CliRunner

from pcbdyn.box import Box, BoxError, load_box
from pcbdyn.cli import main
from pcbdyn.domain import StructureError
from pcbdyn.problems import load_structure
from pcbdyn.testdata import Points

from box_helpers import EXAMPLE, edited


def test_the_example_is_a_structure_with_its_plates_edges_and_parameters():
    box = load_structure(EXAMPLE)
    assert isinstance(box, Box) and [p.name for p in box.plates] == ["left", "right", "back", "upper"]
    assert sorted(tuple(sorted(c.plates)) for c in box.contacts) == [
        ("back", "left"), ("back", "right"), ("back", "upper"), ("left", "upper"), ("right", "upper")]
    assert [p.name for p in box.parameters] == ["E_upper", "rho_upper", "h_side", "h_back", "h_upper_x"]
    assert box.parameters[0].value == 70e9 and box.parameters[2].bounds == pytest.approx((4e-3, 20e-3))
    assert box.quantity("masses.relay.mass") == pytest.approx(0.080)


def error(tmp_path, **kw) -> str:
    with pytest.raises(BoxError) as exc:
        load_box(edited(tmp_path, **kw))
    return str(exc.value)


def test_plates_that_do_not_meet_are_named_with_the_gap(tmp_path):
    msg = error(tmp_path, changes={"plates.3.origin": '["0 mm", "0 mm", "122.5 mm"]'})
    assert msg.startswith("box.toml: plates[3]: plate 'upper' does not meet the rest of the box")
    assert "2.5 mm apart" in msg and "move its origin" in msg


def test_a_rib_off_its_plate(tmp_path):
    msg = error(tmp_path, changes={"ribs.0.to": '["50 mm", "130 mm"]'})
    assert msg.startswith("box.toml: ribs[0].to: (50, 130) mm is off plate 'left'")
    assert "0 to 120 mm along v" in msg and "lie on it" in msg


@pytest.mark.parametrize("field, value, expected", [
    ("edge", '"w0"', "supports[0].edge: unknown plate edge 'w0'; use one of u0 (s = 0), u1 (s = 1)"),
    ("plate", '"front"', "supports[0].plate: no plate is called 'front' (plates: left, right, back, upper)"),
])
def test_a_support_on_an_edge_that_is_not_there(tmp_path, field, value, expected):
    assert error(tmp_path, changes={f"supports.0.{field}": value}).startswith(f"box.toml: {expected}")


def test_a_joint_of_plates_that_share_no_edge(tmp_path):
    path = edited(tmp_path)
    doc = tomlkit.parse(path.read_text())
    joint = '[[joints]]\nname = "j"\nplates = ["left", "right"]\nk_rot = "1e4 N*m/rad/m"\n'
    doc["joints"] = tomlkit.parse(joint)["joints"]
    path.write_text(tomlkit.dumps(doc))
    with pytest.raises(BoxError, match=r"joints\[0\].plates: plates 'left' and 'right' share no edge"):
        load_box(path)


def test_a_typo_and_a_target_the_box_lacks(tmp_path):
    assert "plates[0].thikness: unknown field; did you mean 'thickness'?" in error(
        tmp_path, changes={"plates.0.thikness": '"2 mm"'})
    msg = error(tmp_path, changes={"plates.3.E": '["70 GPa", "40 GPa"]'})  # orthotropic: no single E to update
    assert "parameters[0].target: 'plates.upper.E' is not a quantity of this structure" in msg


def test_shell_strip_ribs_are_geometry_not_parameters(tmp_path):
    msg = error(tmp_path, changes={"box.rib_model": '"shell"'})
    assert "parameters[2].target: 'ribs.left_v1.height' is not a quantity of this structure" in msg
    assert load_box(edited(tmp_path, changes={"box.rib_model": '"shell"'}, remove=("parameters",))).rib_model == "shell"


def test_a_test_point_off_every_plate_is_named_with_its_distance(tmp_path):
    box = load_box(EXAMPLE)
    pts = Points([7, 8], [[0.0, 0.08, 0.06], [0.1, 0.08, 0.06]])  # on the left plate; inside the box
    with pytest.raises(StructureError) as exc:
        box.check_points(pts, tmp_path / "points.csv")
    msg = str(exc.value)
    assert msg.startswith("points.csv: 1 point(s) lie off every plate of box.toml (more than 5 mm away): 8 at "
                          "[100.0, 80.0, 60.0] mm is 60 mm from plate")
    assert "box frame" in msg
    csv = tmp_path / "points.csv"
    csv.write_text("point,x [mm],y [mm],z [mm],dir\n1,0,80,60,+x\n2,100,80,60,+z\n")
    res = CliRunner().invoke(main, ["simulate-test", str(EXAMPLE), "--points", str(csv), "--excite", "0,20,110",
                                    "--out", str(tmp_path / "t.uff")])
    assert res.exit_code == 2 and "error: points.csv: 1 point(s) lie off every plate" in res.output
    assert not (tmp_path / "t.uff").exists()


def test_write_updated_keeps_the_comments_and_rebuilds_the_changed_model(tmp_path):
    box = load_box(edited(tmp_path))
    dst = box.write_updated({"E_upper": 52.5e9, "h_side": 12e-3}, tmp_path / "box.updated.toml")
    text = dst.read_text()
    assert "# x = 0; n = u x v = +x points into the box" in text and "updated by pcbdyn update" in text
    new = load_box(dst)
    assert new.quantity("plates.upper.E") == pytest.approx(52.5e9)
    assert [new.quantity(f"ribs.{r}.height") for r in ("left_v1", "right_v2", "back_h1")] == pytest.approx(
        [12e-3, 12e-3, 10e-3])
    assert new.plate("upper").declared.E == 70e9 and new.plate("left").material.E == 70e9
    old_pm, new_pm = (b.build(mesh_size=0.02) for b in (box, new))
    assert np.array_equal(old_pm.model.nodes, new_pm.model.nodes)  # same geometry and mesh
    assert new_pm.quantities["plates.upper.E"] == 52.5e9 and new_pm.quantities["ribs.left_v2.height"] == 12e-3


def test_a_board_only_command_says_it_takes_a_board():
    res = CliRunner().invoke(main, ["vibe", str(EXAMPLE), "--psd", "gevs-qual"])
    assert res.exit_code == 2
    assert "error: box.toml: top level: describes a box ([box]); this command takes a board.toml" in res.output


def test_the_diagnosed_box_scales_the_fitted_modulus(tmp_path):
    """A region_stiffness effect found on a plate whose modulus is a fitted parameter: the diagnosed box
    holds the fitted modulus times the effect's factor (60 GPa x 1.3), not the declared one's (70 GPa),
    and the other parameters at their fitted values."""
    box = load_box(EXAMPLE)
    effect = {"type": "region_stiffness", "name": "stiffer", "plate": "upper", "value": 0.3, "at": (0.1, 0.08, 0.12)}
    out = box.write_enriched([effect], tmp_path / "box.diagnosed.toml", values={"E_upper": 60e9, "h_back": 12e-3})
    again = load_box(out)
    assert again.plate("upper").material.E == pytest.approx(78e9, rel=1e-12)
    assert {p.name: p.value for p in again.parameters}["h_back"] == pytest.approx(12e-3, rel=1e-12)
    plain = load_box(box.write_enriched([effect], tmp_path / "plain.toml"))
    assert plain.plate("upper").material.E == pytest.approx(91e9, rel=1e-12)
