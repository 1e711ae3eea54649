"""Universal File Format (UFF/UNV) in and out: points (15, 2411), modes (55), FRFs (58, 58b), units (164).

Reading: pyuff finds the datasets (blocks between '    -1' lines) and reads the headers of 58 and
the data of 58b. pyuff pairs the '-1' lines and drops an unpaired last one, so a file cut short is
read as one dataset fewer without a word; the structure is checked here first (every block
closed, nothing outside the blocks, a dataset number after each opening line). Values are taken
here by pattern where pyuff cuts fixed columns or skips checks: 15, 2411 and 164 (pyuff splits on
blanks and misaligns a record that is cut short), dataset 55 (pyuff reads 13-character fields only,
so other widths or 'D' exponents are misread) and ASCII 58 data (pyuff expects 13 or 20 characters
per field: pyuff issue 52). The pattern accepts fields run together ("missing spaces", pyuff issue
84), any width and 'D' exponents; every other character on a data line is an error, and the
record headers say how many values to expect. Also tolerated: 58 data padded with zeros past
num_pts (pyuff issue 22), complex 55 written by pyuff with NDV = 6 for three complex values, 58b
blocks whose trailing line break pyuff ignores. Any defect raises :class:`TestDataError` naming
the file, the dataset (1-based position and type) and, for 58b, the pyuff.fix_58b repair.

Writing (:mod:`.uff_write`): the standard's fixed layouts; the precision each dataset keeps is
listed there (2411, 164 and 58b exact; 58 ASCII 13 digits; 55 and 15 six digits).

Units: a 164 dataset gives the file's length and force units; coordinates and FRFs are converted
to SI (mode shapes keep their scaling: it is arbitrary anyway). Files are written in SI.
"""

from __future__ import annotations

import math
import os
import re

import numpy as np

from .data import (
    FILE_FLOOR_HZ,
    Dofs,
    FRFs,
    MeasuredModes,
    Points,
    TestData,
    TestDataError,
    check_damping,
    check_frequencies,
    check_shapes,
)
from .uff_fields import Cursor, label, numbers
from .uff_geometry import PARSERS, Geometry, geometry
from .uff_write import write_uff

_SPEC_KIND = {8: "receptance", 11: "mobility", 12: "accelerance"}
_G = 9.80665
_TAG = b"    -1"


# ---------------------------------------------------------------------------------------- structure


def _blocks(uff, blob: bytes, path) -> list:
    """[(type, start, end)] of the datasets pyuff found, once the file's structure is checked:
    nothing outside the datasets, a dataset number after each opening '-1' line, and no dataset
    left open at the end (pyuff silently drops an unclosed last dataset: a file cut short)."""
    ind = [(int(a), int(b)) for a, b in uff._block_ind] if uff.get_n_sets() else []
    types = [int(t) for t in uff.get_set_types()] if ind else []
    pos = 0
    for k, ((s, e), t) in enumerate(zip(ind, types)):
        if k and blob[pos:s].strip():
            raise TestDataError(f"{path}: text between datasets #{k} and #{k + 1} belongs to neither "
                                f"({_show(blob[pos:s])}); a '    -1' line is missing or doubled there")
        if t <= 0:
            raise TestDataError(f"{path}: dataset #{k + 1} has no dataset number on the line after its opening "
                                "'    -1' (a '    -1' line is missing or doubled before it)")
        pos = e + 1 + len(_TAG)
    rest = blob[pos:] if ind else blob[_first_tag(blob):]
    head = rest.lstrip()
    if head:
        if head.startswith(b"-1") and head[2:3] in (b"", b" ", b"\r", b"\n"):
            lines = head.splitlines()
            t = lines[1][:6].strip().decode("latin-1") if len(lines) > 1 else "?"
            raise TestDataError(f"{path}: dataset #{len(ind) + 1} (type {t}) is cut short: the file ends before its "
                                "closing '    -1' line (truncated in copying or writing?); write or copy it again")
        if ind:
            raise TestDataError(f"{path}: text after the last dataset (#{len(ind)}) belongs to none "
                                f"({_show(rest)}); remove it or restore its '    -1' lines")
    return [(t, s, e) for (s, e), t in zip(ind, types)]


def _first_tag(blob: bytes) -> int:
    """Offset of the first line that is a '    -1' tag, or the end of the file."""
    m = re.search(rb"(?m)^    -1[ \t]*\r?$", blob)
    return m.start() if m else len(blob)


def _show(text: bytes) -> str:
    return repr(text.strip()[:40].decode("latin-1"))


# ---------------------------------------------------------------------------------------- reading


def _parse55(raw: bytes) -> dict:
    """One dataset 55 block (from its leading '-1' line) as a dict of header values and node data."""
    lines = raw.splitlines()
    if len(lines) < 9:
        raise TestDataError("the dataset is shorter than its header (8 records)")
    cur = Cursor(lines[7:], 7)
    _, analysis, data_ch, spec, dtype, ndv = (int(v) for v in cur.take(6, "record 6"))
    nint, nrval = (int(v) for v in cur.take(2, "record 7", end=False))
    ints = [int(v) for v in cur.take(nint, "record 7")]
    reals = cur.take(nrval, "record 8")
    if dtype not in (2, 5):
        raise TestDataError(f"data type {dtype} is neither real (2) nor complex (5)")
    nodes, vals = _node_records(lines[7 + cur.i :], 7 + cur.i)
    per = {len(v) for v in vals}
    if len(per) > 1:
        raise TestDataError(f"nodes carry different numbers of values ({sorted(per)}); expected {ndv} each")
    want = ndv * (2 if dtype == 5 else 1)
    got = per.pop() if per else want
    # pyuff writes complex 3-DOF data with NDV = 6 in record 6: trust the data when it is whole
    if got != want and not (dtype == 5 and got % 2 == 0 and got >= 6):
        raise TestDataError(f"node {nodes[0]} has {got} values; record 6 announces {want}")
    v = np.array(vals, dtype=float).reshape(len(nodes), got)
    if dtype == 5:
        v = v[:, 0::2] + 1j * v[:, 1::2]
    return {"analysis": analysis, "data_ch": data_ch, "spec": spec, "ints": ints, "reals": reals,
            "nodes": np.array(nodes, dtype=np.int64), "values": v}


_INT_LINE = re.compile(rb"^\s*[-+]?\d+\s*$")


def _node_records(lines, first: int):
    """Node numbers and their values: a line holding one integer starts a node record (record 9);
    the numbers on the following lines, up to the next such line, are its values (record 10)."""
    nodes, vals = [], []
    for k, line in enumerate(lines):
        if not line.strip():
            continue
        if _INT_LINE.match(line):
            nodes.append(label(int(line), f"line {first + k + 1} of the dataset"))
            vals.append([])
        elif not nodes:
            raise TestDataError(f"values before the first node number (line {first + k + 1} of the dataset)")
        else:
            vals[-1].extend(numbers(line, f"node {nodes[-1]}, line {first + k + 1} of the dataset"))
    return nodes, vals


def _mode_from55(d: dict):
    """(frequency, damping, {node: 3 translations (complex)}) of one parsed 55 dataset, or None."""
    a, r = d["analysis"], d["reals"]
    if a == 2:
        if not r:
            raise TestDataError("record 8 holds no frequency")
        freq, zeta = r[0], (r[2] if len(r) > 2 else 0.0)
    elif a in (3, 7):
        if len(r) < 2:
            raise TestDataError("record 8 holds no eigenvalue (real and imaginary parts)")
        lam = complex(r[0], r[1])
        freq, zeta = abs(lam) / (2 * np.pi), (-lam.real / abs(lam) if abs(lam) > 0 else 0.0)
    else:
        return None
    if d["values"].shape[1] < 3:
        raise TestDataError("a mode shape needs 3 values per node (x, y, z); this one has fewer")
    check_frequencies([freq], "record 8", floor=FILE_FLOOR_HZ)
    check_damping([zeta], 1, "record 8")
    nodes, counts = np.unique(d["nodes"], return_counts=True)
    if (counts > 1).any():
        raise TestDataError(f"node {int(nodes[counts > 1][0])} is given twice; give each node's values once")
    check_shapes(d["values"][:, :3].reshape(-1, 1), "record 10")
    return freq, zeta, d["nodes"], d["values"][:, :3]


def real_modes(psi: np.ndarray):
    """Real normal modes from complex shapes (n_dof, n_modes), and the phase collinearity of each.

    Each complex shape is rotated by the angle that makes its real part as large as possible
    (theta = arg(sum psi^2) / 2) and the real part is kept. MPC = |psi^T psi|^2 / (psi^H psi)^2 is 1
    for a mode whose components are all in phase (a true normal mode) and 0 for a travelling wave.
    """
    psi = np.asarray(psi, dtype=complex)
    big = np.max(np.abs(psi), axis=0) if psi.size else np.ones(psi.shape[1:])
    scale = np.ldexp(1.0, np.frexp(np.where(big > 0, big, 1.0))[1])  # a power of 2: scaling by it is exact
    psi = psi / scale  # MPC and the real part are unchanged by scale: no overflow in the squares
    s = np.sum(psi * psi, axis=0)
    n2 = np.sum(np.abs(psi) ** 2, axis=0)
    theta = 0.5 * np.angle(s)
    phi = np.real(psi * np.exp(-1j * theta)) * scale
    with np.errstate(invalid="ignore", divide="ignore"):
        mpc = np.where(n2 > 0, np.abs(s) ** 2 / n2**2, 1.0)
    return phi, mpc


def read_uff(path, points: Points | None = None, frf_kind: str | None = None) -> TestData:
    """Points, modes and FRFs of a UFF file, in SI units and the board frame.

    Parameters
    ----------
    path : str or pathlib.Path
        A Universal File (datasets 15/2411 points, 55 modes, 58/58b FRFs, 164 units).
    points : Points, optional
        Coordinates to use instead of the file's geometry.
    frf_kind : str, optional
        receptance, mobility or accelerance, for FRFs whose dataset does not say.

    Returns
    -------
    TestData
        ``points``, ``modes`` (:class:`pcbdyn.testdata.MeasuredModes`, or None), ``frfs`` (or None),
        ``skipped`` (the datasets not read).

    Examples
    --------
    Written by :func:`pcbdyn.testdata.write_uff` and read back:

    >>> import os, tempfile
    >>> import numpy as np
    >>> from pcbdyn.testdata import Dofs, MeasuredModes, Points, TestData, write_uff
    >>> points = Points([1, 2], [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    >>> dofs = Dofs([1, 2], [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    >>> modes = MeasuredModes(points, dofs, [120.0], [[0.5], [1.0]], damping=[0.01])
    >>> path = os.path.join(tempfile.mkdtemp(), "test.uff")
    >>> write_uff(path, TestData(points, modes))
    >>> back = read_uff(path).modes
    >>> back.frequencies, back.shapes.ravel(), back.damping
    (array([120.]), array([0.5, 1. ]), array([0.01]))

    Notes
    -----
    ``points`` replace the file's geometry (15/2411) or stand for a missing one (its directions are
    then global); ``frf_kind`` is for datasets of ordinate data type 0. Unsupported datasets are listed in
    ``TestData.skipped``. FRFs share one frequency axis; response/reference pairs absent from the file
    are NaN in ``H``. Every DOF's direction is global: a direction code means the axis of its node's
    displacement system (:mod:`.uff_geometry`), signed as written. Files without a dataset 164 are read
    in the units :func:`.uff_geometry.stated_units` states (metres by default).
    """
    import pyuff

    path = os.fspath(path)
    if not os.path.exists(path):
        raise TestDataError(f"{path}: no such file")
    try:
        uff = pyuff.UFF(path)
    except Exception as exc:
        raise TestDataError(f"{path}: not a readable UFF file ({exc})") from None
    with open(path, "rb") as fh:
        blob = fh.read()
    blocks = _blocks(uff, blob, path)
    if not blocks:
        raise TestDataError(f"{path}: no UFF datasets found (each dataset is enclosed in '    -1' lines)")
    dsets, skipped, modes55, frf58 = [], [], [], []
    for k, (t, s, e) in enumerate(blocks):
        where = f"{path}: dataset #{k + 1} (type {t})"
        raw = blob[s : e + 1]
        try:
            if t == 55:
                m = _mode_from55(_parse55(raw))
                if m is None:
                    skipped.append((k + 1, t, "not a mode (analysis type other than 2, 3, 7)"))
                else:
                    modes55.append(m)
                continue
            if t not in PARSERS and t != 58:
                skipped.append((k + 1, t, "dataset type not used by pcbdyn"))
                continue
            d = PARSERS[t](raw) if t in PARSERS else _read58(uff, k, raw)
        except TestDataError as exc:
            raise TestDataError(f"{where}: {exc}") from None
        except Exception as exc:
            hint = "; a binary 58b written by some tools needs pyuff.fix_58b(path) first" if _is_binary(raw) else ""
            raise TestDataError(f"{where} cannot be read: {exc}{hint}") from None
        dsets.append(d)
        if t == 58:
            if d.get("func_type") == 4:
                frf58.append((k + 1, d))
            else:
                skipped.append((k + 1, t, f"function type {d.get('func_type')} is not an FRF (4)"))
    try:
        geo = geometry(dsets, path)
        if points is not None:
            geo = Geometry(points, length=geo.length, force=geo.force)
        modes = _assemble_modes(modes55, geo) if modes55 else None
        frfs = _assemble_frfs(frf58, geo, frf_kind) if frf58 else None
    except TestDataError as exc:
        raise TestDataError(str(exc) if str(exc).startswith(path) else f"{path}: {exc}") from None
    return TestData(geo.points, modes, frfs, skipped, geo.wireframe, geo.elements)


def _is_binary(raw: bytes) -> bool:
    """A '58b' dataset: the type line (second line of the block) has 'b' after the number."""
    lines = raw[:200].splitlines()
    return len(lines) > 1 and lines[1][6:7].lower() == b"b"


def _read58(uff, k, raw) -> dict:
    """Dataset k: the header through pyuff, and the values of a 58b; the values of an ASCII 58 are
    taken here by pattern (pyuff cuts them into 13 or 20 characters, which silently misreads other
    widths: pyuff issue 52). Values past num_pts must be zeros (padding, pyuff issue 22)."""
    if _is_binary(raw):
        d = uff.read_sets(k)
        n, got = int(d["num_pts"]), len(d["data"])
        if got < n:
            raise TestDataError(f"its binary data holds {got} values, record 7 announces {n}")
        return _checked58(d)
    d = uff.read_sets(k, header_only=True)
    vals = []
    for i, line in enumerate(raw.splitlines()[13:]):
        vals.extend(numbers(line, f"record 12, line {i + 14} of the dataset", nan=True))
    v = np.array(vals)
    n = int(d["num_pts"])
    complex_ = d["ord_data_type"] in (5, 6)
    even = d["abscissa_spacing"] == 1
    step = (2 if complex_ else 1) + (0 if even else 1)
    if v.size < n * step or np.any(v[n * step :] != 0):
        raise TestDataError(f"record 12 holds {v.size} values; record 7 announces {n} points, {n * step} values")
    v = v[: n * step].reshape(n, step)
    d["x"] = d["abscissa_min"] + np.arange(n) * d["abscissa_inc"] if even else v[:, 0]
    y = v[:, 0 if even else 1 :]
    d["data"] = y[:, 0] + 1j * y[:, 1] if complex_ else y[:, 0]
    return _checked58(d)


def _checked58(d: dict) -> dict:
    """A 58 dataset with at least one line, its frequency axis finite and rising from 0 Hz up, its values
    finite or NaN (a line not measured: pcbdyn writes NaN where no receptance exists, at 0 Hz)."""
    n = int(d["num_pts"])
    x, y = np.asarray(d["x"], dtype=float)[:n], np.asarray(d["data"])[:n]
    if n < 1:
        raise TestDataError("record 7 announces no data points")
    if not np.isfinite(x).all() or np.isinf(y).any():
        raise TestDataError("its abscissa or data hold infinite values (record 7 or 12); write numbers (or NaN for "
                            "a value not measured)")
    if x[0] < 0 or (n > 1 and not np.all(np.diff(x) > 0)):
        raise TestDataError(f"its frequency axis must start at 0 Hz or above and rise ({x[0]:g} Hz first, step "
                            f"{(x[1] - x[0]) if n > 1 else 0:g} Hz); check record 7 (abscissa minimum and increment)")
    return d


def _assemble_modes(modes55, geo: Geometry) -> MeasuredModes:
    """One MeasuredModes object from the 55 datasets: DOFs are the (node, axis) pairs nonzero in any mode, each
    along its node's displacement axis in the global frame.

    Nodes absent from a dataset are zero there (dataset 55, note 9)."""
    all_nodes = np.unique(np.concatenate([m[2] for m in modes55]))
    n = len(modes55)
    psi = np.zeros((all_nodes.size, 3, n), dtype=complex)
    for j, (_, _, nodes, vals) in enumerate(modes55):
        psi[np.searchsorted(all_nodes, nodes), :, j] = vals
    used = np.any(psi != 0, axis=2)
    node_of, axis_of = np.nonzero(used)
    dirs = [geo.direction(n, a + 1) for n, a in zip(all_nodes[node_of], axis_of)]
    dofs = Dofs(all_nodes[node_of], np.array(dirs, float).reshape(-1, 3))
    shapes, mpc = real_modes(psi[node_of, axis_of, :])
    return MeasuredModes(geo.points, dofs, [m[0] for m in modes55], shapes, [m[1] for m in modes55], mpc)


def _frf_scale(d, kind, L, F) -> float:
    """Factor from file units to SI for one 58 dataset (exponents of records 9-11, dataset 164)."""
    lab = str(d.get("ordinate_axis_units_lab", "")).strip().lower()
    a, b = d.get("ordinate_len_unit_exp", 0), d.get("ordinate_force_unit_exp", 0)
    c, e = d.get("orddenom_len_unit_exp", 0), d.get("orddenom_force_unit_exp", 0)
    if any(not isinstance(v, (int, float)) or abs(v) > 4 for v in (a, b, c, e)):
        raise TestDataError(f"the unit exponents of records 9 and 10 ({a}, {b}, {c}, {e}) "
                            "are not small whole numbers (an FRF has length, force exponents -2 to 2)")
    if a == 0 and b == 0:
        a = 1  # a displacement, velocity or acceleration: length in the numerator
    if c == 0 and e == 0:
        e = 1  # per unit force
    scale = (L**c) * (F**e) / ((L**a) * (F**b))
    if lab in ("g", "g/n"):
        scale = _G * (F**e)
    return scale


def _assemble_frfs(frf58, geo: Geometry, frf_kind) -> FRFs:
    x0 = None
    resp, ref, kinds, entries = {}, {}, set(), []
    for k, d in frf58:
        spec = int(d.get("ordinate_spec_data_type", 0))
        kind = _SPEC_KIND.get(spec, frf_kind)
        if kind is None:
            raise TestDataError(
                f"dataset #{k}: the FRF's ordinate data type {spec} does not say receptance (8), mobility (11) "
                "or accelerance (12); pass frf_kind='receptance'|'mobility'|'accelerance'"
            )
        kinds.add(kind)
        n = int(d.get("num_pts", len(d["data"])))
        x = np.asarray(d["x"], dtype=float)[:n]  # some tools pad the last line (pyuff issue 22)
        try:
            y = np.asarray(d["data"])[:n] * _frf_scale(d, kind, geo.length, geo.force)
        except TestDataError as exc:
            raise TestDataError(f"dataset #{k}: {exc}") from None
        if x0 is None:
            x0 = x
        elif x.size != x0.size or not np.allclose(x, x0, rtol=1e-9, atol=0):
            raise TestDataError(f"dataset #{k}: its frequency axis differs from the first FRF's; resample to one axis")
        rk = (int(d["rsp_node"]), int(d["rsp_dir"]))
        fk = (int(d["ref_node"]), int(d["ref_dir"]))
        if fk[1] == 0:
            raise TestDataError(f"dataset #{k}: the FRF names no reference (excitation) DOF (node {fk[0]}, direction "
                                "0); write each FRF with the node and direction it was excited at (record 6)")
        resp.setdefault(rk, len(resp))
        ref.setdefault(fk, len(ref))
        entries.append((resp[rk], ref[fk], y))
    if len(kinds) > 1:
        raise TestDataError(f"the FRFs mix kinds {sorted(kinds)}; give one kind per file")
    for (node, code) in list(resp) + list(ref):
        if abs(code) not in (1, 2, 3):
            raise TestDataError(f"an FRF at node {node} has direction code {code}; only translations (+-1..3) are used")
    H = np.full((x0.size, len(resp), len(ref)), np.nan + 0j)
    for i, j, y in entries:
        H[:, i, j] = y
    rdofs, fdofs = (Dofs([n for n, _ in keys], np.array([geo.direction(n, c) for n, c in keys]).reshape(-1, 3))
                    for keys in (list(resp), list(ref)))
    return FRFs(geo.points, x0, H, kinds.pop(), rdofs, fdofs)


__all__ = ["read_uff", "write_uff", "real_modes"]
