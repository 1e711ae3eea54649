"""UFF writing in the standard's fixed layouts, so that any UFF reader (pyuff, I-DEAS, Test.Lab,
ME'scope, ...) reads what pcbdyn writes.

What each dataset keeps (the layouts of the UFF standard, records as the standard numbers them):

- 164 units: record 2 in D25.17, exact (the file is in SI: factors 1, 1, 1, 273.15).
- 2411 nodes (default geometry): coordinates in 1P3D25.16, 17 significant digits: exact.
- 15 nodes (``geometry="15"``, for tools that read only it): 1P3E13.5, 6 significant digits.
- 55 modes: records 8 and 10 in 6E13.5 (the standard has no double-precision form): frequency,
  damping ratio and shape values keep 6 significant digits.
- 58 FRFs, ASCII: complex double precision, values in 4E20.12 (13 significant digits); record 7
  holds the frequency axis' start and step in E13.5, so ASCII is used only when both survive that
  exactly and the axis is even.
- 58b FRFs, binary: IEEE doubles, exact; chosen for uneven axes or when asked. As pyuff does,
  every value (abscissa included) is a double, little-endian.

Real exponents use 'E' except where the standard says D (164, 2411).
"""

from __future__ import annotations

import os

import numpy as np

from ..atomic import atomic_path
from .data import FRFs, MeasuredModes, TestData, TestDataError

_KIND_SPEC = {"receptance": 8, "mobility": 11, "accelerance": 12}
_END = b"    -1\n"


def _atomic(path, write):
    """Run ``write(tmp_path)`` then move the finished file onto ``path`` (nothing half-written)."""
    with atomic_path(path) as tmp:
        write(os.fspath(tmp))


def _e(values, width: int, digits: int, d: bool = False) -> str:
    """Values in Fortran E (or D) fields of ``width`` with ``digits`` after the point, one string."""
    out = "".join("%*.*E" % (width, digits, v) for v in values)
    return out.replace("E", "D") if d else out


def _rows(values, per_line: int, width: int, digits: int) -> str:
    """Values ``per_line`` to a line (the last line may be shorter)."""
    v = np.asarray(values, dtype=float).ravel()
    return "".join(_e(v[i:i + per_line], width, digits) + "\n" for i in range(0, v.size, per_line))


def _head(dataset: int, tail: str = "") -> str:
    return "%6i\n%6i%s\n" % (-1, dataset, tail)


def _id_lines(*lines) -> str:
    """Records 1-5 (80A1): ID lines, 'NONE' where empty (they may not be blank)."""
    lines = list(lines) + ["NONE"] * (5 - len(lines))
    return "".join("%-80.80s\n" % (s or "NONE") for s in lines)


def units164() -> str:
    factors = _e([1.0, 1.0, 1.0], 25, 17, d=True) + "\n" + _e([273.15], 25, 17, d=True) + "\n"
    return _head(164) + "%10i%-20s%10i\n" % (1, "SI", 2) + factors + _END.decode()


def nodes2411(ids, xyz) -> str:
    body = "".join("%10i%10i%10i%10i\n%s\n" % (i, 1, 1, 1, _e(p, 25, 16, d=True)) for i, p in zip(ids, xyz))
    return _head(2411) + body + _END.decode()


def nodes15(ids, xyz) -> str:
    body = "".join("%10i%10i%10i%10i%s\n" % (i, 1, 1, 1, _e(p, 13, 5)) for i, p in zip(ids, xyz))
    return _head(15) + body + _END.decode()


def mode55(mode_n: int, freq: float, zeta: float, nodes, r) -> str:
    """One real normal mode (analysis type 2): 3 translations per node, displacement."""
    out = [_head(55), _id_lines("pcbdyn measured mode", "NONE", "NONE", "NONE", f"mode {mode_n}"),
           "%10i%10i%10i%10i%10i%10i\n" % (1, 2, 2, 8, 2, 3),
           "%10i%10i%10i%10i\n" % (2, 4, 1, mode_n), _e([freq, 0.0, zeta, 0.0], 13, 5) + "\n"]
    out += ["%10i\n%s\n" % (n, _e(v, 13, 5)) for n, v in zip(nodes, r)]
    return "".join(out) + _END.decode()


def node_table(modes: MeasuredModes):
    """Nodes and their (x, y, z) shape values (n_nodes, 3, n_modes) for dataset 55."""
    codes = modes.dofs.codes()
    nodes, row = np.unique(modes.dofs.point_ids, return_inverse=True)
    key = row * 3 + np.abs(codes) - 1
    if np.unique(key).size != key.size:
        raise TestDataError("modes: a point has two DOFs along the same axis; UFF 55 holds one value per axis")
    r = np.zeros((nodes.size * 3, modes.n_modes))
    r[key] = modes.shapes * np.sign(codes)[:, None]
    return nodes, r.reshape(nodes.size, 3, modes.n_modes)


def even_axis(x) -> bool:
    """True when x is evenly spaced and its start and step survive the 58 header's E13.5 fields."""
    if x.size < 2:
        return False
    x0, dx = x[0], x[1] - x[0]
    exact = float("%13.5e" % x0) == x0 and float("%13.5e" % dx) == dx
    return exact and np.allclose(x0 + np.arange(x.size) * dx, x, rtol=0, atol=1e-13 * np.abs(x).max())


def _head58(frfs: FRFs, i: int, j: int, even: bool, binary: bool, n_bytes: int) -> str:
    """The type line and records 1-11 of one FRF (response i, reference j)."""
    rc, fc = frfs.response.codes(), frfs.reference.codes()
    x = frfs.frequencies
    tail = "b%6i%6i%12i%12i%6i%6i%12i%12i" % (1, 2, 11, n_bytes, 0, 0, 0, 0) if binary else ""
    start, step = (x[0], x[1] - x[0]) if even else (0.0, 0.0)
    label = "%10i%5i%5i%5i %-20.20s %-20.20s\n"
    return "".join([
        _head(58, tail), _id_lines(f"pcbdyn FRF ({frfs.kind})"),
        "%5i%10i%5i%10i %-10.10s%10i%4i %-10.10s%10i%4i\n" % (
            4, 1, 0, 0, "pcbdyn", frfs.response.point_ids[i], rc[i], "pcbdyn", frfs.reference.point_ids[j], fc[j]),
        "%10i%10i%10i%s\n" % (6, x.size, int(even), _e([start, step, 0.0], 13, 5)),
        label % (18, 0, 0, 0, "Frequency", "Hz"),
        label % (_KIND_SPEC[frfs.kind], 1, 0, 0, frfs.kind, frfs.units.split("/N")[0]),
        label % (13, 0, 1, 0, "Force", "N"),
        label % (0, 0, 0, 0, "NONE", "NONE"),
    ])


def frf58(frfs: FRFs, i: int, j: int, binary: bool) -> bytes:
    """One FRF as dataset 58 (complex double precision, 4E20.12) or 58b (IEEE doubles)."""
    x, y = frfs.frequencies, frfs.H[:, i, j]
    even = even_axis(x)
    if binary:
        cols = [y.real, y.imag] if even else [x, y.real, y.imag]
        data = np.column_stack(cols).astype("<f8").tobytes()
        return _head58(frfs, i, j, even, True, len(data)).encode() + data + _END
    if not even:
        raise TestDataError("an ASCII dataset 58 needs an even frequency axis whose start and step fit E13.5; "
                            "write binary 58b")
    values = np.column_stack([y.real, y.imag])
    return (_head58(frfs, i, j, True, False, 0) + _rows(values, 4, 20, 12)).encode() + _END


def write_uff(path, data: TestData, binary: bool | None = None, geometry: str = "2411") -> None:
    """Write units (164, SI), points (2411, or 15), modes (55) and FRFs (58/58b) atomically.

    Parameters
    ----------
    path : str or pathlib.Path
        The Universal File written.
    data : TestData
        Points, and modes and/or FRFs (:func:`pcbdyn.testdata.simulate.simulate_on_model` makes one);
        :func:`pcbdyn.testdata.read_uff` has an example of both.

    Notes
    -----
    ``binary``: FRFs as 58b; None chooses ASCII 58 unless the frequency axis is uneven or its start
    and step would lose digits in the ASCII header. ``geometry``: "2411" (double precision) or "15"
    (single precision, for older tools). The precision of each dataset is in the module notes.
    """
    if geometry not in ("2411", "15"):
        raise TestDataError(f"geometry '{geometry}' is not '2411' or '15'")

    def write(tmp):
        with open(tmp, "wb") as fh:
            fh.writelines(_datasets(data, binary, geometry))

    _atomic(path, write)


def _datasets(data: TestData, binary, geometry):
    """The datasets of ``data``, one bytes block each, in file order."""
    yield units164().encode()
    pts = data.points
    if len(pts):
        yield (nodes2411 if geometry == "2411" else nodes15)(pts.ids, pts.xyz).encode()
    m = data.modes
    if m is not None:
        nodes, r = node_table(m)
        for j in range(m.n_modes):
            yield mode55(j + 1, float(m.frequencies[j]), float(m.damping[j]), nodes, r[:, :, j]).encode()
    frfs = data.frfs
    if frfs is not None:
        use_binary = (not even_axis(frfs.frequencies)) if binary is None else bool(binary)
        for i in range(len(frfs.response)):
            for j in range(len(frfs.reference)):
                if not np.all(np.isnan(frfs.H[:, i, j])):
                    yield frf58(frfs, i, j, use_binary)


__all__ = ["write_uff"]
