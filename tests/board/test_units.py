import pytest

from pcbdyn.units import UnitError, to_si


@pytest.mark.parametrize(
    "text, unit, si",
    [
        ("2.8 mm", "mm", 2.8e-3),
        ("26 GPa", "Pa", 26e9),
        ("1e4 N*m/rad/m", "N*m/rad/m", 1e4),
        ("13 g", "kg", 0.013),
        ("2640 kg/m^3", "kg/m^3", 2640.0),
        ("6.309e-6 kg*m^2", "kg*m^2", 6.309e-6),
        ("90 deg", "rad", 1.5707963267948966),
        ("0.43 N*m/rad/mm", "N*m/rad/m", 430.0),
    ],
)
def test_quantities_convert_to_si(text, unit, si):
    assert to_si(text, unit) == pytest.approx(si, rel=1e-12)


def test_wrong_dimension_names_field_and_units():
    with pytest.raises(UnitError, match=r"board.toml: board.thickness: '2.8 GPa'.*expected a unit like 'mm'"):
        to_si("2.8 GPa", "mm", "board.toml: board.thickness")


def test_bare_number_needs_a_unit_unless_dimensionless():
    with pytest.raises(UnitError, match="has no unit"):
        to_si(2.8, "mm", "x")
    assert to_si(0.3, "dimensionless") == 0.3


def test_unreadable_quantity():
    with pytest.raises(UnitError, match="cannot read 'two mm'"):
        to_si("two mm", "mm", "x")


def test_g_in_an_acceleration_unit_is_standard_gravity():
    """Vibration specifications write accelerations in g; where a mass is expected g stays grams."""
    assert to_si("0.04 g^2/Hz", "m^2/s^3") == pytest.approx(0.04 * 9.80665**2, rel=1e-12)
    assert to_si("0.04 G^2/Hz", "m^2/s^3") == pytest.approx(0.04 * 9.80665**2, rel=1e-12)
    assert to_si("3 g", "m/s^2") == pytest.approx(3 * 9.80665, rel=1e-12)
    assert to_si("13 g", "kg") == pytest.approx(0.013, rel=1e-12)
    with pytest.raises(UnitError, match="expected a unit like 'm/s'"):
        to_si("3 g", "m/s")
