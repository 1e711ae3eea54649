"""UFF in and out: round trips to the precision each dataset holds, files written directly with
pyuff, variants other tools write, and clear errors on files that cannot be read."""

import os
from pathlib import Path
import re

import numpy as np
import pytest
import pyuff
from uff_helpers import E13, E20, HEADER55, fixed

from pcbdyn.correlation import mac
from pcbdyn.testdata import Dofs, FRFs, MeasuredModes, Points, TestData, TestDataError, read_uff, real_modes, write_uff


def sample(kind="accelerance", f_axis=None):
    rng = np.random.default_rng(11)
    pts = Points(np.arange(101, 113), rng.uniform(0, 0.17, (12, 3)) * [1, 1, 0.01])
    dofs = Dofs.from_codes(np.r_[pts.ids, [104, 105]], ["+z"] * 12 + ["+x", "+y"])
    modes = MeasuredModes(pts, dofs, [211.123456789012, 302.7, 397.81234567], rng.standard_normal((14, 3)),
                  [0.0123456789, 0.02, 0.005])
    f = np.linspace(0.0, 1000.0, 801) if f_axis is None else f_axis
    H = rng.standard_normal((f.size, 4, 2)) + 1j * rng.standard_normal((f.size, 4, 2))
    frfs = FRFs(pts, f, 1e-3 * H, kind, Dofs.from_codes([101, 102, 103, 104], [3, 3, 3, -3]),
                Dofs.from_codes([107, 110], [3, -1]))
    return TestData(pts, modes, frfs)


def physical(modes):
    """Shapes sorted by (point, axis) with the direction sign applied: the same motion however stored."""
    codes = modes.dofs.codes()
    order = np.lexsort((np.abs(codes), modes.dofs.point_ids))
    return modes.shapes[order] * np.sign(codes[order])[:, None]


def rel(a, b):
    return np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(b).max()


@pytest.mark.parametrize("binary", [None, False, True])
def test_round_trip_keeps_what_each_dataset_holds(tmp_path, binary):
    """Points (2411) and binary FRFs exactly, ASCII FRFs to E20.12, modes (55) to E13.5."""
    data = sample()
    path = tmp_path / "test.uff"
    write_uff(path, data, binary=binary)
    back = read_uff(path)
    assert np.array_equal(back.points.ids, data.points.ids)
    assert np.array_equal(back.points.xyz, data.points.xyz)
    assert np.array_equal(back.modes.frequencies, fixed(data.modes.frequencies, E13))
    assert np.array_equal(back.modes.damping, fixed(data.modes.damping, E13))
    assert np.array_equal(physical(back.modes), fixed(physical(data.modes), E13))
    assert np.allclose(back.modes.mpc, 1.0)
    assert back.frfs.kind == "accelerance" and back.frfs.units == "m/s^2/N"
    assert np.array_equal(back.frfs.frequencies, data.frfs.frequencies)
    assert np.array_equal(back.frfs.H, data.frfs.H if binary else fixed(data.frfs.H, E20))
    assert back.frfs.response.codes().tolist() == [3, 3, 3, -3]
    assert back.frfs.reference.point_ids.tolist() == [107, 110]
    assert back.frfs.reference.codes().tolist() == [3, -1]
    assert back.skipped == []


def test_an_uneven_frequency_axis_survives_the_round_trip(tmp_path):
    f = np.sort(np.random.default_rng(1).uniform(5, 900, 300))
    data = sample(kind="mobility", f_axis=f)
    write_uff(tmp_path / "u.uff", data)  # the axis cannot be stored in the ASCII header: 58b is chosen
    back = read_uff(tmp_path / "u.uff")
    assert np.array_equal(back.frfs.frequencies, f) and np.array_equal(back.frfs.H, data.frfs.H)
    assert back.frfs.kind == "mobility"


def test_a_file_written_directly_with_pyuff_reads_the_same(tmp_path):
    """mm units (164), geometry in dataset 15, complex modes (55, analysis type 3), receptance in mm/N."""
    rng = np.random.default_rng(4)
    ids = np.arange(1, 21)
    xyz_mm = np.column_stack([rng.uniform(0, 162, 20), rng.uniform(0, 178, 20), np.zeros(20)]).round(3)
    phi = rng.standard_normal((20, 2))
    f = np.array([214.1, 302.7])
    zeta = np.array([0.01, 0.02])
    lam = -zeta * 2 * np.pi * f + 1j * 2 * np.pi * f * np.sqrt(1 - zeta**2)
    sets = [
        {"type": 164, "units_code": 5, "units_description": "mm/N", "temp_mode": 2, "length": 1000.0,
         "force": 1.0, "temp": 1.0, "temp_offset": 273.15},
        {"type": 15, "node_nums": ids, "def_cs": np.zeros(20, int), "disp_cs": np.zeros(20, int),
         "color": np.zeros(20, int), "x": xyz_mm[:, 0], "y": xyz_mm[:, 1], "z": xyz_mm[:, 2]},
    ]
    phases = [0.4, -1.1]
    for j in range(2):
        psi = phi[:, j] * np.exp(1j * phases[j])  # a normal mode written as a complex one, phase-rotated
        sets.append(pyuff.prepare_55(model_type=1, analysis_type=3, data_ch=2, spec_data_type=8, data_type=5,
                                     n_data_per_node=3, node_nums=ids, load_case=1, mode_n=j + 1, eig=lam[j],
                                     modal_a=0j, modal_b=0j, r1=0 * psi, r2=0 * psi, r3=psi,
                                     return_full_dict=True))
    x = np.arange(0.0, 500.0, 0.5)
    h_mm = rng.standard_normal(x.size) + 1j * rng.standard_normal(x.size)
    sets.append({"type": 58, "func_type": 4, "rsp_node": 3, "rsp_dir": 3, "ref_node": 7, "ref_dir": 3,
                 "x": x, "data": h_mm, "abscissa_spacing": 1, "abscissa_spec_data_type": 18,
                 "ordinate_spec_data_type": 8, "ordinate_len_unit_exp": 1, "orddenom_spec_data_type": 13,
                 "orddenom_force_unit_exp": 1, "ordinate_axis_units_lab": "mm", "binary": 0})
    path = tmp_path / "pyuff_written.unv"
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")

    back = read_uff(path)
    assert np.allclose(back.points.xyz, xyz_mm / 1000.0, rtol=1e-5, atol=1e-9)
    assert np.allclose(back.modes.frequencies, f, rtol=1e-5)
    assert np.allclose(back.modes.damping, zeta, rtol=1e-4)
    assert np.allclose(back.modes.mpc, 1.0, atol=1e-9)
    assert back.modes.dofs.codes().tolist() == [3] * 20  # zero x/y columns are not measured DOFs
    assert np.allclose(np.diag(mac(back.modes.shapes, phi)), 1.0, atol=1e-9)
    scale = back.modes.shapes / phi
    assert np.allclose(scale, scale[0], rtol=1e-4)  # each mode recovered up to one real factor
    assert back.frfs.kind == "receptance"
    assert rel(back.frfs.H[:, 0, 0], h_mm / 1000.0) < 1e-9  # mm/N -> m/N
    assert np.allclose(back.frfs.frequencies, x)


def write_text(path, text):
    path.write_text(text)
    return path



def test_dataset_55_with_fields_run_together_and_d_exponents_reads(tmp_path):
    """Some exporters fill 13-character fields completely ("missing spaces", pyuff issue 84) or write
    Fortran D exponents (pyuff issue 64)."""
    rec8 = "  1.50000D+02  0.00000D+00  1.00000D-02  0.00000D+00"
    body = ("         1\n-1.23456E+00-2.50000E-01 3.00000E+00\n"
            "         2\n 4.00000D-01-5.00000D-01-6.25000D+00\n    -1\n")
    path = write_text(tmp_path / "tight.unv", HEADER55.format(rec8=rec8) + body)
    back = read_uff(path, points=Points([1, 2], np.zeros((2, 3))))
    assert back.modes.frequencies.tolist() == [150.0]
    assert back.modes.damping.tolist() == [0.01]
    got = dict(zip(zip(back.modes.dofs.point_ids.tolist(), back.modes.dofs.codes().tolist()), back.modes.shapes[:, 0]))
    assert got == {(1, 1): -1.23456, (1, 2): -0.25, (1, 3): 3.0, (2, 1): 0.4, (2, 2): -0.5, (2, 3): -6.25}


def test_ascii_58_with_other_field_widths_and_padding_reads(tmp_path):
    """A 58 whose values are not in pyuff's fixed columns (pyuff issue 52) and whose last line is padded
    beyond num_pts (pyuff issue 22)."""
    head = """    -1
    58
NONE
NONE
NONE
NONE
NONE
    4         0    0         0 NONE               5   3 NONE               9   3
         6         3         1  1.00000e+01  2.00000e+00  0.00000e+00
        18    0    0    0 Frequency            Hz
         8    1    0    0 Displacement         m
        13    0    1    0 Force                N
         0    0    0    0 NONE                 NONE
"""
    vals = [1.5, -2.25, 3.125, 4.0, -5.5, 6.75, 0.0, 0.0]  # 3 complex values, then padding
    body = "".join(f"  {v:.9E}  " for v in vals[:4]) + "\n" + "".join(f"  {v:.9E}  " for v in vals[4:]) + "\n    -1\n"
    path = write_text(tmp_path / "wide.unv", head + body)
    back = read_uff(path, points=Points([5, 9], np.zeros((2, 3))))
    assert np.allclose(back.frfs.frequencies, [10.0, 12.0, 14.0])
    assert np.allclose(back.frfs.H[:, 0, 0], [1.5 - 2.25j, 3.125 + 4.0j, -5.5 + 6.75j])


def test_malformed_files_fail_with_a_message_naming_the_file_and_dataset(tmp_path):
    rec8 = "  1.50000E+02  0.00000E+00  1.00000E-02  0.00000E+00"
    bad55 = write_text(tmp_path / "short.unv", HEADER55.format(rec8=rec8) + "         1\n 1.0E+00 2.0E+00\n    -1\n")
    with pytest.raises(TestDataError, match=r"short\.unv: dataset #1 \(type 55\).*node 1"):
        read_uff(bad55, points=Points([1], np.zeros((1, 3))))
    good = tmp_path / "good.uff"
    write_uff(good, sample())
    text = good.read_text().splitlines(True)
    i = next(k for k, line in enumerate(text) if line.startswith("    58"))
    text[i + 8] = "   garbage where the frequency line should be\n"
    broken = tmp_path / "broken58.uff"
    broken.write_text("".join(text))
    with pytest.raises(TestDataError, match=r"broken58\.uff: dataset #\d+ \(type 58\)"):
        read_uff(broken)
    with pytest.raises(TestDataError, match="no such file"):
        read_uff(tmp_path / "missing.uff")
    empty = write_text(tmp_path / "empty.uff", "not a universal file\n")
    with pytest.raises(TestDataError, match="no UFF datasets"):
        read_uff(empty)
    no_geo = tmp_path / "nogeo.uff"
    write_uff(no_geo, sample())
    lines = no_geo.read_text()
    start = lines.index("    -1\n  2411")
    end = lines.index("    -1\n", start + 8) + 7
    (tmp_path / "nogeo2.uff").write_text(lines[:start] + lines[end:])
    with pytest.raises(TestDataError, match=r"nogeo2\.uff: point ids .* have no coordinates"):
        read_uff(tmp_path / "nogeo2.uff")


@pytest.mark.parametrize("freq, zeta", [(150.0, -0.02), (150.0, 1.0), (150.0, 1.5), (0.0, 0.01), (-150.0, 0.01),
                                        (150.0, 0.0), (150.0, 0.99)])
def test_a_uff_mode_obeys_the_rules_of_modes(tmp_path, freq, zeta):
    """A dataset 55 is refused exactly when MeasuredModes refuses the same mode, in MeasuredModes' words after the dataset and
    record: a frequency above 0, a damping ratio from 0 to below 1 (a negative one, a curve fit's artefact, too)."""
    rec8 = f"{freq:13.5E}{0.0:13.5E}{zeta:13.5E}{0.0:13.5E}"
    path = write_text(tmp_path / "one.uff", HEADER55.format(rec8=rec8) + "         1\n 1.0E+00 2.0E+00 3.0E+00\n    -1\n")
    point = Points([1], np.zeros((1, 3)))
    try:
        MeasuredModes(point, Dofs.from_codes([1, 1, 1], [1, 2, 3]), [freq], [[1.0], [2.0], [3.0]], [zeta])
    except TestDataError as exc:
        rule = str(exc).removeprefix("modes: ").replace(" (mode 1)", "")  # the dataset names the mode
        with pytest.raises(TestDataError) as uff_exc:
            read_uff(path, points=point)
        assert str(uff_exc.value) == f"{path}: dataset #1 (type 55): record 8: {rule}"
        assert ("above 0" if freq <= 0 else "from 0 to below 1") in rule
        assert ("artefact of the curve fit" in rule) == (freq > 0 and zeta < 0)
    else:
        assert read_uff(path, points=point).modes.damping.tolist() == [zeta]


@pytest.mark.parametrize("freq, shape, fault", [
    (150.0, "0.0E+00 0.0E+00 0.0E+00", "record 10: the mode shape is zero at every DOF"),
    (1e-9, "1.0E+00 2.0E+00 3.0E+00", "record 8: frequency 1e-09 Hz is below 0.01 Hz"),
    (0.00999, "1.0E+00 2.0E+00 3.0E+00", "record 8: frequency 0.00999 Hz is below 0.01 Hz")])
def test_a_file_mode_without_motion_or_below_the_elastic_floor_is_refused(tmp_path, freq, shape, fault):
    """A dataset 55 record whose shape is zero at every node, or whose frequency is positive but below the 0.01 Hz
    floor of an elastic mode (a rigid-body mode, or kHz read as Hz), is refused naming the dataset and record,
    while modes pcbdyn simulates keep their own rule (any frequency above 0, a zero shape allowed); at the
    floor itself a mode reads."""
    point = Points([1], np.zeros((1, 3)))
    rec8 = f"{freq:13.5E}{0.0:13.5E}{0.01:13.5E}{0.0:13.5E}"
    path = write_text(tmp_path / "m.uff", HEADER55.format(rec8=rec8) + f"         1\n {shape}\n    -1\n")
    with pytest.raises(TestDataError, match=rf"m\.uff: dataset #1 \(type 55\): {re.escape(fault)}"):
        read_uff(path, points=point)
    values = [[float(v)] for v in shape.split()]
    assert MeasuredModes(point, Dofs.from_codes([1, 1, 1], [1, 2, 3]), [freq], values).frequencies[0] == freq
    at_floor = write_text(tmp_path / "f.uff", HEADER55.format(rec8=f"{0.01:13.5E}{0.0:13.5E}{0.01:13.5E}{0.0:13.5E}")
                          + "         1\n 1.0E+00 2.0E+00 3.0E+00\n    -1\n")
    assert read_uff(at_floor, points=point).modes.frequencies.tolist() == [0.01]


def test_a_frequency_table_row_below_the_elastic_floor_is_refused(tmp_path):
    from pcbdyn.testdata.measured import read_frequency_table

    table = write_text(tmp_path / "freq.csv", "configuration,mode,frequency_hz\nbase,1,1e-9\nbase,2,250.0\n")
    with pytest.raises(TestDataError, match=r"freq\.csv: configuration base: frequency 1e-09 Hz \(mode 1\) is below"):
        read_frequency_table(table, None)


def test_a_failed_write_leaves_the_old_file_untouched(tmp_path, monkeypatch):
    from pcbdyn.testdata import uff_write

    path = tmp_path / "keep.uff"
    path.write_text("previous results\n")

    def boom(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(uff_write, "frf58", boom)  # fails after the points and modes are written
    with pytest.raises(OSError):
        write_uff(path, sample())
    assert path.read_text() == "previous results\n"
    assert os.listdir(tmp_path) == ["keep.uff"]


def test_complex_modes_become_real_normal_modes_with_their_phase_collinearity():
    rng = np.random.default_rng(8)
    phi = rng.standard_normal((30, 2))
    psi = phi * np.exp(1j * np.array([0.3, 2.0]))
    real, mpc = real_modes(psi)
    assert np.allclose(np.abs(np.sum(real * phi, 0)) / np.linalg.norm(phi, axis=0) ** 2, 1.0)
    assert np.allclose(mpc, 1.0)
    wave = phi[:, 0] + 1j * phi[:, 1]  # two shapes in quadrature: far from a normal mode
    _, mpc = real_modes(wave[:, None])
    assert mpc[0] < 0.5


def test_binary_58b_with_a_stray_line_break_before_the_end_tag_reads(tmp_path):
    """Test.Lab-style 58b files end their binary data with CRLF before '    -1' (pyuff issues 61, 88)."""
    data = sample()
    path = tmp_path / "b.uff"
    write_uff(path, data, binary=True)
    raw = path.read_bytes()
    head = raw.index(b"    58b")
    end = raw.index(b"    -1", head + 100)
    path.write_bytes(raw[:end] + b"\r\n" + raw[end:])
    back = read_uff(path)
    assert rel(back.frfs.H, data.frfs.H) < 1e-12


def test_node_coordinate_systems_place_points_and_turn_directions_global():
    """tests/data/uff/node_systems.uff (written by hand, checked by hand): SYS1 (dataset 18: origin at x = 10 mm,
    +x towards the origin, xz point below) has axes -X, +Y, -Z; SYS2 is defined in SYS1 (its origin, +x along
    SYS1's y, xz point on SYS1's x) and has axes +Y, -Z, -X; CS3 (dataset 2420, rows the axes) is a quarter
    turn about z: +Y, -X, +Z. Node 1's displacements refer to SYS1, node 2's to SYS2, node 3's coordinates
    and displacements to CS3, node 4 is global. Each measured value keeps its number and takes its axis' global
    direction; the trace line and the elements give the wireframe's edges once each."""
    data = read_uff(Path(__file__).resolve().parents[1] / "data" / "uff" / "node_systems.uff")
    np.testing.assert_allclose(data.points.xyz, [[0, 0, 0], [0.1, 0, 0], [-0.1, 0.1, 0], [0, 0.1, 0]], atol=1e-15)
    m = data.modes
    want = {1: ([[-1, 0, 0], [0, 1, 0], [0, 0, -1]], [1.0, 2.0, 3.0]), 2: ([[-1, 0, 0]], [1.0]),
            3: ([[0, 1, 0], [-1, 0, 0], [0, 0, 1]], [-1.0, 0.5, 2.0]), 4: ([[0, 0, 1]], [-1.0])}
    scale = m.shapes[0, 0]  # the real shape keeps the file's values up to one factor
    for node, (axes, values) in want.items():
        rows = np.flatnonzero(m.dofs.point_ids == node)
        np.testing.assert_array_equal(m.dofs.directions[rows], axes)
        np.testing.assert_allclose(m.shapes[rows, 0] / scale, values, rtol=1e-6)
    assert data.wireframe.tolist() == [[1, 2], [1, 3], [1, 4], [2, 3], [3, 4]]
    assert data.elements == [(44, [1, 2, 3, 4]), (11, [1, 3])]
