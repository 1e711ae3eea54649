"""Every third-party test file of ../shared/realdata/pyuff (pyuff's test data, MIT; written by LMS Test.Lab,
ARTeMIS, OROS, NX, Simcenter, VKI, PERMAS and data recorders) read as a user's file arrives: with the counts
of points, elements, modes and FRFs the file holds, in global directions, or refused with the dataset and
the fault named. The files are not part of the project: these tests skip where the folder is absent."""

import re

import numpy as np
import pytest

from data_files import realdata
from uff_helpers import HEADER55

from pcbdyn.testdata import Points, TestDataError, read_uff
from pcbdyn.testdata.uff_geometry import stated_units

PYUFF, pytestmark = realdata("pyuff")
TESTLAB = "TestLab 161 164 18 15 82.uff"

#: file -> (points, elements, wireframe edges (shared edges once), FRF array shape or None, skipped datasets)
READS = {
    "1858.uff": (0, 0, 0, None, 2),
    "2411 and 2414.uff": (441, 400, 840, None, 11),  # a 20 x 20 quad grid: 2 * 20 * 21 edges
    "Artemis export - Geometry RPBC_setup_05_14102016_105117.uff": (74, 108, 162, None, 0),
    "MPSTD#Set001_2024_10_08_10_27_07.uff": (0, 0, 0, None, 4),
    "MPSTD#Set001_2024_10_08_10_27_07_fixed_test.uff": (0, 0, 0, None, 4),
    "NX simulation output.uff": (18, 17, 17, None, 178),
    "Sample_UFF58_ascii.uff": (0, 0, 0, None, 1),
    "Sample_UFF58b_bin.uff": (0, 0, 0, None, 1),
    "Simcenter_nxopen_thickness.uff": (0, 0, 0, None, 2),
    TESTLAB: (36, 0, 30, None, 1),
    "binary8byte.uff": (0, 0, 0, None, 1),
    "groups_test.uff": (74, 341, 294, None, 1),
    "heat_engine_housing.uff": (10, 8, 26, None, 2),
    "measurement_e2089be.uff": (0, 0, 0, (1001, 1, 3), 0),
    "mesh_test_uff2412_mixed.uff": (5, 5, 8, None, 0),  # a quad and four triangles around node 11
    "sample_dataset58_psd.uff": (0, 0, 0, None, 1),
    "time-history-not-all-columns-filled.uff": (0, 0, 0, None, 1),
}
#: files in mm without a dataset 164 -> (points, elements, the grid's width [m] read in mm)
IN_MM = {"mesh_Oros-modal_uff15_uff2412.uff": (96, 72, 0.1665), "mesh_set2412_to_convert.uff": (96, 72, 0.1665),
         "simcenter_exported_result.uff": (11520, 16688, 38.0)}
#: defective files -> what the refusal names
REFUSED = {"dataset_milestone_in_header.uff": r"dataset #1 \(type 58\): record 12 holds 42 values; record 7 announces",
           "non_ascii_header.uff": r"dataset #1: the FRF's ordinate data type 1 does not say"}
#: dataset 55 samples without geometry -> (modes, their frequencies [Hz])
NO_GEOMETRY = {"uff55 sample_test record10.uff": [6.54306], "uff55_translation.uff": [10.0, 12.0, 13.0],
               "uff55_translation_rotation.uff": [97.013]}


def test_every_file_of_the_folder_is_covered():
    assert sorted(p.name for p in PYUFF.glob("*.uff")) == sorted([*READS, *IN_MM, *REFUSED, *NO_GEOMETRY])


@pytest.mark.parametrize("name", sorted(READS))
def test_a_file_reads_with_its_counts(name):
    n_points, n_elements, n_edges, frfs, n_skipped = READS[name]
    data = read_uff(PYUFF / name)
    assert (len(data.points), len(data.elements), len(data.wireframe), len(data.skipped)) == \
        (n_points, n_elements, n_edges, n_skipped)
    assert data.modes is None
    assert (None if data.frfs is None else data.frfs.H.shape) == frfs
    if len(data.wireframe):
        assert np.isin(data.wireframe, data.points.ids).all()


@pytest.mark.parametrize("name", sorted(IN_MM))
def test_a_file_in_mm_without_units_is_refused_naming_the_option_and_reads_with_it(name):
    n_points, n_elements, width = IN_MM[name]
    with pytest.raises(TestDataError, match=rf"{re.escape(name)}: the test grid is [\d.]+ m wide .*--units mm"):
        read_uff(PYUFF / name)
    with stated_units("mm"):
        data = read_uff(PYUFF / name)
    assert (len(data.points), len(data.elements)) == (n_points, n_elements)
    assert np.ptp(data.points.xyz, axis=0).max() == pytest.approx(width, rel=1e-9)


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_a_defective_file_is_refused_naming_the_dataset_and_the_fault(name):
    with pytest.raises(TestDataError, match=rf"{re.escape(name)}: {REFUSED[name]}"):
        read_uff(PYUFF / name)


@pytest.mark.parametrize("name", sorted(NO_GEOMETRY))
def test_modes_without_geometry_are_refused_and_read_with_points_given(name):
    import pyuff

    with pytest.raises(TestDataError, match=rf"{re.escape(name)}: point ids .* have no coordinates"):
        read_uff(PYUFF / name)
    uff = pyuff.UFF(str(PYUFF / name))
    ids = np.unique(np.concatenate([uff.read_sets(k)["node_nums"] for k in range(uff.get_n_sets())]).astype(int))
    modes = read_uff(PYUFF / name, points=Points(ids, np.zeros((ids.size, 3)))).modes
    np.testing.assert_allclose(modes.frequencies, NO_GEOMETRY[name], rtol=1e-5)


def test_the_testlab_units_and_trace_lines():
    """Units code 9 with factors 1 (metres), and the three trace lines 'Massif', 'Stator', 'Dalle' as drawn
    (0 lifts the pen): 7 + 16 + 7 edges."""
    data = read_uff(PYUFF / TESTLAB)
    edges = {tuple(e) for e in data.wireframe.tolist()}
    assert {(2, 5), (5, 6), (3, 6), (3, 4), (1, 4), (1, 2), (2, 3)} <= edges  # Massif: 2 5 6 3 4 1 2 3
    assert (19, 30) not in edges and (18, 30) in edges  # Stator: ... 19 | 30 18
    np.testing.assert_allclose(data.points.xyz[data.points.index([1, 36])], [[-2.4, -0.95, 0.0], [1.2, 8.4, 0.0]])


REC8 = "  1.50000E+02  0.00000E+00  1.00000E-02  0.00000E+00"

HEADER58 = """    -1
    58
NONE
NONE
NONE
NONE
NONE
    4         0    0         0 NONE      {rn:10d}{rd:4d} NONE      {fn:10d}{fd:4d}
         6         2         1  0.00000e+00  1.00000e+00  0.00000e+00
        18    0    0    0 Frequency            Hz
        12    1    0    0 Acceleration         m/s^2
        13    0    1    0 Force                N
         0    0    0    0 NONE                 NONE
  1.00000E+00  0.00000E+00  2.00000E+00  0.00000E+00
    -1
"""


def test_testlab_node_systems_turn_modes_and_frfs_into_global_directions(tmp_path):
    """The Test.Lab geometry gives node k displacement system k (dataset 18). By hand from its three points:
    SYS1 (origin, +x at X - 1, xz point at X - 1, Z - 1): x = -X, y = +Y, z = -Z; SYS7 (+x point at Z + 1, xz
    point at Y - 1): x = +Z, y = -X, z = -Y. A mode measured at nodes 1 and 7 with local values (1, 2, 3) and an
    FRF from node 7 +x to node 1 +z must come back along those global directions, values unchanged."""
    nodes = "".join(f"{n:10d}\n  1.00000E+00  2.00000E+00  3.00000E+00\n" for n in (1, 7))
    text = (PYUFF / TESTLAB).read_text(encoding="latin-1") + HEADER55.format(rec8=REC8) + nodes + "    -1\n" + \
        HEADER58.format(rn=1, rd=3, fn=7, fd=1)
    path = tmp_path / "testlab_with_data.uff"  # the file as a user adds measured data to it
    path.write_text(text, encoding="latin-1")
    data = read_uff(path)
    m = data.modes
    want = {1: [[-1, 0, 0], [0, 1, 0], [0, 0, -1]], 7: [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]}
    for node, axes in want.items():
        rows = np.flatnonzero(m.dofs.point_ids == node)
        np.testing.assert_array_equal(m.dofs.directions[rows], axes)
        np.testing.assert_allclose(m.shapes[rows, 0] / np.abs(m.shapes[rows, 0]).max(), [1 / 3, 2 / 3, 1.0],
                                   rtol=1e-6)
    np.testing.assert_array_equal(data.frfs.response.directions, [[0, 0, -1]])
    np.testing.assert_array_equal(data.frfs.reference.directions, [[0, 0, 1]])
    assert data.frfs.H[0, 0, 0] == pytest.approx(1.0) and data.frfs.kind == "accelerance"
