"""Every UFF dataset pcbdyn writes is in the standard's fixed layout: pyuff, an independent reader,
gets the same values back (to the precision each layout holds); and a file that is cut short or
has junk in a record is an error naming the file and the dataset, never fewer modes."""

import numpy as np
import pytest
import pyuff
from uff_helpers import E13, E20, fixed

from pcbdyn.testdata import Dofs, FRFs, MeasuredModes, Points, TestData, TestDataError, read_uff, write_uff


def card(n_modes=3):
    rng = np.random.default_rng(21)
    pts = Points(np.arange(1, 31), np.column_stack([rng.uniform(0, 0.162, 30), rng.uniform(0, 0.178, 30),
                                                    rng.uniform(-1e-3, 3e-3, 30)]))
    dofs = Dofs.from_codes(np.r_[pts.ids, [4, 9]], ["+z"] * 30 + ["+x", "-y"])
    modes = MeasuredModes(pts, dofs, 200.0 + 97.123456789 * np.arange(n_modes), rng.standard_normal((32, n_modes)),
                  0.01 + 0.00123456789 * np.arange(n_modes))
    f = np.arange(0.0, 800.0, 0.5)
    H = 1e-4 * (rng.standard_normal((f.size, 2, 1)) + 1j * rng.standard_normal((f.size, 2, 1)))
    frfs = FRFs(pts, f, H, "receptance", Dofs.from_codes([3, 17], [3, -3]), Dofs.from_codes([12], [3]))
    return TestData(pts, modes, frfs)


@pytest.mark.parametrize("binary,geometry", [(False, "2411"), (True, "15")])
def test_pyuff_reads_every_dataset_pcbdyn_writes_value_for_value(tmp_path, binary, geometry):
    data = card()
    path = tmp_path / "card.uff"
    write_uff(path, data, binary=binary, geometry=geometry)
    sets = pyuff.UFF(str(path)).read_sets()
    assert [d["type"] for d in sets] == [164, int(geometry)] + [55] * 3 + [58] * 2

    units = sets[0]
    assert (units["units_code"], units["length"], units["force"], units["temp"], units["temp_offset"]) == (
        1, 1.0, 1.0, 1.0, 273.15)

    nodes = sets[1]
    xyz = np.column_stack([nodes["x"], nodes["y"], nodes["z"]])
    assert np.array_equal(np.asarray(nodes["node_nums"], dtype=int), data.points.ids)
    assert np.array_equal(xyz, data.points.xyz if geometry == "2411" else fixed(data.points.xyz, E13))

    m = data.modes
    w = m.shapes[:30]  # +z at points 1..30, then +x at 4 and -y at 9
    for j, d in enumerate(sets[2:5]):
        assert (d["analysis_type"], d["data_ch"], d["spec_data_type"], d["mode_n"]) == (2, 2, 8, j + 1)
        assert d["freq"] == fixed(m.frequencies[j], E13)
        assert d["modal_damp_vis"] == fixed(m.damping[j], E13)
        assert np.array_equal(d["node_nums"], data.points.ids)
        assert np.array_equal(d["r3"], fixed(w[:, j], E13))
        r1, r2 = np.zeros(30), np.zeros(30)
        r1[3], r2[8] = m.shapes[30, j], -m.shapes[31, j]
        assert np.array_equal(d["r1"], fixed(r1, E13)) and np.array_equal(d["r2"], fixed(r2, E13))

    fr = data.frfs
    for i, d in enumerate(sets[5:]):
        assert (d["func_type"], d["rsp_node"], d["rsp_dir"], d["ref_node"], d["ref_dir"]) == (
            4, [3, 17][i], [3, -3][i], 12, 3)
        assert d["ord_data_type"] == 6 and d["ordinate_spec_data_type"] == 8
        assert d["orddenom_spec_data_type"] == 13 and d["abscissa_spec_data_type"] == 18
        want = fr.H[:, i, 0] if binary else fixed(fr.H[:, i, 0], E20)
        assert np.array_equal(d["data"][: fr.frequencies.size], want)
        assert np.allclose(d["x"][: fr.frequencies.size], fr.frequencies, rtol=0, atol=1e-9)


def test_the_layouts_are_the_standards_column_for_column(tmp_path):
    """Dataset 55 records 8 and 10 in 6E13.5 (pyuff 2.5.8 read none of pcbdyn's 55 before), 2411
    record 2 in 1P3D25.16, 58 data in 4E20.12."""
    path = tmp_path / "card.uff"
    write_uff(path, card(1))
    lines = path.read_text().splitlines()
    k = lines.index("    55")
    assert [len(s) for s in lines[k + 1 : k + 6]] == [80] * 5
    assert len(lines[k + 6]) == 60 and len(lines[k + 7]) == 40  # records 6 (6I10) and 7 (4I10)
    assert len(lines[k + 8]) == 4 * 13 and len(lines[k + 9]) == 10 and len(lines[k + 10]) == 3 * 13
    k = lines.index("  2411")
    assert len(lines[k + 1]) == 40 and len(lines[k + 2]) == 75 and lines[k + 2].count("D") == 3
    k = lines.index("    58")
    assert len(lines[k + 7]) == 69  # record 7: 3I10, 3E13.5
    assert all(len(s) == 80 for s in lines[k + 12 : k + 20])


def cut(path, marker, count, drop, tmp_path, name):
    """A copy of ``path`` ending ``drop`` bytes before the ``count``-th occurrence of ``marker``."""
    raw = path.read_bytes()
    at = -1
    for _ in range(count):
        at = raw.index(marker, at + 1)
    out = tmp_path / name
    out.write_bytes(raw[: at - drop])
    return out


def test_a_file_cut_inside_its_third_mode_is_an_error_not_two_modes(tmp_path):
    good = tmp_path / "modes.uff"
    data = card()
    write_uff(good, TestData(data.points, data.modes))
    assert read_uff(good).modes.n_modes == 3
    # datasets: 164, 2411, 55, 55, 55 -> the third mode is dataset #5
    third = good.read_bytes().index(b"    55", good.read_bytes().index(b"mode 3") - 600)
    for name, end in [("inside_node_records.uff", 1400), ("mid_line.uff", 1407), ("at_its_end.uff", -7),
                      ("after_header.uff", 650)]:
        raw = good.read_bytes()
        short = tmp_path / name
        short.write_bytes(raw[: third + end] if end > 0 else raw[:end])
        with pytest.raises(TestDataError, match=rf"{name}: dataset #5 \(type 55\) is cut short"):
            read_uff(short)


def test_a_lost_end_line_or_stray_text_between_datasets_is_an_error(tmp_path):
    good = tmp_path / "modes.uff"
    write_uff(good, card())
    text = good.read_text()
    k = text.index("    -1\n    -1\n    55")  # the end of the 2411 dataset and the start of mode 1
    (tmp_path / "lost_end.uff").write_text(text[:k] + text[k + 7 :])
    with pytest.raises(TestDataError, match=r"lost_end\.uff: .*datasets? #\d"):
        read_uff(tmp_path / "lost_end.uff")
    (tmp_path / "stray.uff").write_text(text[: k + 7] + "written by hand\n" + text[k + 7 :])
    with pytest.raises(TestDataError, match=r"stray\.uff: text between datasets #2 and #3"):
        read_uff(tmp_path / "stray.uff")
    (tmp_path / "tail.uff").write_text(text + "  0.5  0.7\n")
    with pytest.raises(TestDataError, match=r"tail\.uff: text after the last dataset"):
        read_uff(tmp_path / "tail.uff")


@pytest.mark.parametrize("dataset,line", [("55", 12), ("55", 9), ("2411", 3), ("2411", 4), ("58", 15),
                                          ("164", 4)])
def test_junk_in_a_record_is_an_error_naming_file_dataset_and_line(tmp_path, dataset, line):
    """``line``: a data line of the dataset, counted from its opening '-1' line."""
    good = tmp_path / "card.uff"
    write_uff(good, card())
    lines = good.read_text().splitlines(True)
    k = next(i for i, text in enumerate(lines) if text.rstrip() == f"{dataset:>6}") - 1 + line - 1
    lines[k] = lines[k].rstrip("\n") + " n/a\n"
    bad = tmp_path / f"junk{dataset}.uff"
    bad.write_text("".join(lines))
    with pytest.raises(TestDataError, match=rf"junk{dataset}\.uff: dataset #\d+ \(type {dataset}\).*line {line} "):
        read_uff(bad)
