"""Universal File Format (UFF/UNV) in and out: points (15, 2411), modes (55), FRFs (58, 58b), units (164).

pyuff splits the file into datasets and reads 15, 2411, 58b, 164 and the headers of 58. Values
are taken here by pattern where pyuff cuts fixed columns: dataset 55 (pyuff reads 13-character
fields only, so other widths or 'D' exponents are misread, and it writes single precision only)
and ASCII 58 data (pyuff expects 13 or 20 characters per field: pyuff issue 52). The pattern
accepts fields run together ("missing spaces", pyuff issue 84), any width and 'D' exponents; the
record headers say how many values to expect. Also tolerated: 58 data padded past num_pts
(pyuff issue 22), complex 55 written by pyuff with NDV = 6 for three complex values, 58b blocks
whose trailing line break pyuff ignores. Any other defect raises :class:`TestDataError` naming
the file, the dataset (1-based position and type) and, for 58b, the pyuff.fix_58b repair.

Writing: dataset 55 in ``precision="double"`` (default) puts three E25.16 values per line (the
double-precision layout of datasets 2411 and 164) so a round trip is exact to ~1e-16; pcbdyn and
any reader that splits on blanks read it, but pyuff's own 55 reader does not: use
``precision="single"`` (standard 6E13.5, ~6 significant digits) for such tools. Points go to 2411
(double precision); FRFs to 58 in double precision, as binary 58b when asked, or when the
frequency axis would not survive the ASCII header's 6 digits.

Units: a 164 dataset gives the file's length and force units; coordinates and FRFs are converted
to SI (mode shapes keep their scaling: it is arbitrary anyway). Files are written in SI.
"""

from __future__ import annotations

import os
import re

import numpy as np

from ..atomic import atomic_path
from .data import Dofs, FRFs, Modes, Points, TestData, TestDataError

_NUM = re.compile(rb"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[EeDd][-+]?\d+)?")
_SPEC_KIND = {8: "receptance", 11: "mobility", 12: "accelerance"}
_KIND_SPEC = {v: k for k, v in _SPEC_KIND.items()}
_G = 9.80665


def _numbers(line: bytes) -> list:
    return [float(t.replace(b"D", b"E").replace(b"d", b"e")) for t in _NUM.findall(line)]


class _Cursor:
    """Reads the numbers of a text block record by record, across line breaks.

    ``take(n, what, end=True)`` returns the next n numbers; with ``end`` the record must finish
    there (no numbers left on its last line)."""

    def __init__(self, lines):
        self.lines = lines
        self.i = 0
        self.buf = []

    def take(self, n: int, what: str, end: bool = True) -> list:
        while len(self.buf) < n:
            if self.i >= len(self.lines):
                raise TestDataError(f"the dataset ends before {what} ({len(self.buf)} of {n} values found)")
            self.buf.extend(_numbers(self.lines[self.i]))
            self.i += 1
        out, self.buf = self.buf[:n], self.buf[n:]
        if end and self.buf:
            raise TestDataError(f"{what}: expected {n} values, found {n + len(self.buf)} (line {self.i} of the data)")
        return out


# ---------------------------------------------------------------------------------------- reading


def _parse55(raw: bytes) -> dict:
    """One dataset 55 block (from its leading '-1' line) as a dict of header values and node data."""
    lines = raw.splitlines()
    if len(lines) < 9:
        raise TestDataError("the dataset is shorter than its header (8 records)")
    cur = _Cursor(lines[7:])
    _, analysis, data_ch, spec, dtype, ndv = (int(v) for v in cur.take(6, "record 6"))
    nint, nrval = (int(v) for v in cur.take(2, "record 7", end=False))
    ints = [int(v) for v in cur.take(nint, "record 7")]
    reals = cur.take(nrval, "record 8")
    if dtype not in (2, 5):
        raise TestDataError(f"data type {dtype} is neither real (2) nor complex (5)")
    nodes, vals = _node_records(lines[7 + cur.i :])
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


def _node_records(lines):
    """Node numbers and their values: a line holding one integer starts a node record (record 9);
    the numbers on the following lines, up to the next such line, are its values (record 10)."""
    nodes, vals = [], []
    for k, line in enumerate(lines):
        if not line.strip():
            continue
        if _INT_LINE.match(line):
            nodes.append(int(line))
            vals.append([])
        elif not nodes:
            raise TestDataError(f"values before the first node number (line {k + 1} of the node records)")
        else:
            vals[-1].extend(_numbers(line))
    return nodes, vals


def _mode_from55(d: dict):
    """(frequency, damping, {node: 3 translations (complex)}) of one parsed 55 dataset, or None."""
    a, r = d["analysis"], d["reals"]
    if a == 2:
        freq, zeta = r[0], (r[2] if len(r) > 2 else 0.0)
    elif a in (3, 7):
        lam = complex(r[0], r[1])
        freq, zeta = abs(lam) / (2 * np.pi), (-lam.real / abs(lam) if abs(lam) > 0 else 0.0)
    else:
        return None
    if d["values"].shape[1] < 3:
        raise TestDataError("a mode shape needs 3 values per node (x, y, z); this one has fewer")
    return freq, zeta, d["nodes"], d["values"][:, :3]


def real_modes(psi: np.ndarray):
    """Real normal modes from complex shapes (n_dof, n_modes), and the phase collinearity of each.

    Each complex shape is rotated by the angle that makes its real part as large as possible
    (theta = arg(sum psi^2) / 2) and the real part is kept. MPC = |psi^T psi|^2 / (psi^H psi)^2 is 1
    for a mode whose components are all in phase (a true normal mode) and 0 for a travelling wave.
    """
    psi = np.asarray(psi, dtype=complex)
    s = np.sum(psi * psi, axis=0)
    n2 = np.sum(np.abs(psi) ** 2, axis=0)
    theta = 0.5 * np.angle(s)
    phi = np.real(psi * np.exp(-1j * theta))
    with np.errstate(invalid="ignore", divide="ignore"):
        mpc = np.where(n2 > 0, np.abs(s) ** 2 / n2**2, 1.0)
    return phi, mpc


def _units(dsets) -> tuple:
    """(length, force) factors of dataset 164: file value = SI value * factor."""
    for d in dsets:
        if d.get("type") == 164:
            return float(d["length"]), float(d["force"])
    return 1.0, 1.0


def read_uff(path, points: Points | None = None, frf_kind: str | None = None) -> TestData:
    """Points, modes and FRFs of a UFF file, in SI units and the board frame.

    ``points``: coordinates to use when the file has no geometry (15/2411), or to replace it.
    ``frf_kind``: receptance, mobility or accelerance, for FRFs whose dataset does not say
    (ordinate data type 0). Unsupported datasets are listed in ``TestData.skipped``. FRFs share
    one frequency axis; response/reference pairs absent from the file are NaN in ``H``. A DOF
    written along a negative axis comes back along the positive axis with its values negated.
    """
    import pyuff

    path = os.fspath(path)
    if not os.path.exists(path):
        raise TestDataError(f"{path}: no such file")
    try:
        uff = pyuff.UFF(path)
    except Exception as exc:
        raise TestDataError(f"{path}: not a readable UFF file ({exc})") from None
    types = [int(t) for t in uff.get_set_types()]
    if not types:
        raise TestDataError(f"{path}: no UFF datasets found (each dataset is enclosed in '    -1' lines)")
    with open(path, "rb") as fh:
        blob = fh.read()
    dsets, skipped, modes55, frf58 = [], [], [], []
    for k, t in enumerate(types):
        where = f"{path}: dataset #{k + 1} (type {t})"
        try:
            if t == 55:
                s, e = uff._block_ind[k]  # pyuff's block offsets; 55 is parsed here (see module doc)
                m = _mode_from55(_parse55(blob[s : e + 1]))
                if m is None:
                    skipped.append((k + 1, t, "not a mode (analysis type other than 2, 3, 7)"))
                else:
                    modes55.append(m)
                continue
            if t not in (15, 2411, 58, 164):
                skipped.append((k + 1, t, "dataset type not used by pcbdyn"))
                continue
            d = _read_pyuff(uff, k, t, blob)
        except TestDataError as exc:
            raise TestDataError(f"{where}: {exc}") from None
        except Exception as exc:
            hint = ""
            if t == 58 and _is_binary(blob, uff._block_ind[k][0]):
                hint = "; a binary 58b written by some tools needs pyuff.fix_58b(path) first"
            raise TestDataError(f"{where} cannot be read: {exc}{hint}") from None
        dsets.append(d)
        if t == 58:
            if d.get("func_type") == 4:
                frf58.append((k + 1, d))
            else:
                skipped.append((k + 1, t, f"function type {d.get('func_type')} is not an FRF (4)"))
    L, F = _units(dsets)
    geo = _points(dsets, L)
    if points is not None:
        geo = points
    try:
        modes = _assemble_modes(modes55, geo) if modes55 else None
        frfs = _assemble_frfs(frf58, geo, L, F, frf_kind) if frf58 else None
    except TestDataError as exc:
        raise TestDataError(f"{path}: {exc}") from None
    return TestData(geo, modes, frfs, skipped)


def _is_binary(blob: bytes, start: int) -> bool:
    """A '58b' dataset: the type line (second line of the block) has 'b' after the number."""
    lines = blob[start : start + 200].splitlines()
    return len(lines) > 1 and lines[1][6:7].lower() == b"b"


def _read_pyuff(uff, k, t, blob) -> dict:
    """Dataset k through pyuff, except the values of an ASCII 58: pyuff cuts those into fixed
    columns (13 or 20 characters), which silently misreads other widths (pyuff issue 52); they are
    taken here by pattern, and only the num_pts announced are kept (padded files, pyuff issue 22)."""
    s, e = uff._block_ind[k]
    if t != 58 or _is_binary(blob, s):
        return uff.read_sets(k)
    d = uff.read_sets(k, header_only=True)
    vals = []
    for line in blob[s : e + 1].splitlines()[13:]:
        vals.extend(_numbers(line))
    v = np.array(vals)
    n = int(d["num_pts"])
    complex_ = d["ord_data_type"] in (5, 6)
    even = d["abscissa_spacing"] == 1
    step = (2 if complex_ else 1) + (0 if even else 1)
    if v.size < n * step:
        raise TestDataError(f"{v.size} values found, {n * step} expected for {n} points")
    v = v[: n * step].reshape(n, step)
    d["x"] = d["abscissa_min"] + np.arange(n) * d["abscissa_inc"] if even else v[:, 0]
    y = v[:, 0 if even else 1 :]
    d["data"] = y[:, 0] + 1j * y[:, 1] if complex_ else y[:, 0]
    return d


def _points(dsets, L) -> Points:
    ids, xyz = [], []
    for d in dsets:
        if d.get("type") in (15, 2411):
            ids.append(np.asarray(d["node_nums"], dtype=float).astype(np.int64))
            xyz.append(np.column_stack([d["x"], d["y"], d["z"]]).astype(float))
    if not ids:
        return Points(np.zeros(0, np.int64), np.zeros((0, 3)))
    return Points(np.concatenate(ids), np.vstack(xyz) / L)


def _assemble_modes(modes55, geo: Points) -> Modes:
    """One Modes object from the 55 datasets: DOFs are the (node, axis) pairs nonzero in any mode.

    Nodes absent from a dataset are zero there (dataset 55, note 9)."""
    all_nodes = np.unique(np.concatenate([m[2] for m in modes55]))
    n = len(modes55)
    psi = np.zeros((all_nodes.size, 3, n), dtype=complex)
    for j, (_, _, nodes, vals) in enumerate(modes55):
        psi[np.searchsorted(all_nodes, nodes), :, j] = vals
    used = np.any(psi != 0, axis=2)
    node_of, axis_of = np.nonzero(used)
    dofs = Dofs.from_codes(all_nodes[node_of], axis_of + 1)
    shapes, mpc = real_modes(psi[node_of, axis_of, :])
    return Modes(geo, dofs, [m[0] for m in modes55], shapes, [m[1] for m in modes55], mpc)


def _frf_scale(d, kind, L, F) -> float:
    """Factor from file units to SI for one 58 dataset (exponents of records 9-11, dataset 164)."""
    lab = str(d.get("ordinate_axis_units_lab", "")).strip().lower()
    a, b = d.get("ordinate_len_unit_exp", 0), d.get("ordinate_force_unit_exp", 0)
    c, e = d.get("orddenom_len_unit_exp", 0), d.get("orddenom_force_unit_exp", 0)
    if a == 0 and b == 0:
        a = 1  # a displacement, velocity or acceleration: length in the numerator
    if c == 0 and e == 0:
        e = 1  # per unit force
    scale = (L**c) * (F**e) / ((L**a) * (F**b))
    if lab in ("g", "g/n"):
        scale = _G * (F**e)
    return scale


def _assemble_frfs(frf58, geo: Points, L, F, frf_kind) -> FRFs:
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
        y = np.asarray(d["data"])[:n] * _frf_scale(d, kind, L, F)
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
    rdofs = Dofs.from_codes([n for n, _ in resp], [c for _, c in resp])
    fdofs = Dofs.from_codes([n for n, _ in ref], [c for _, c in ref])
    return FRFs(geo, x0, H, kinds.pop(), rdofs, fdofs)


# ---------------------------------------------------------------------------------------- writing


def _atomic(path, write):
    """Run ``write(tmp_path)`` then move the finished file onto ``path`` (nothing half-written)."""
    with atomic_path(path) as tmp:
        write(os.fspath(tmp))


def _write55_double(fh, mode_n, freq, zeta, nodes, r):
    fh.write("%6i\n%6i%74s\n" % (-1, 55, " "))
    for line in ("pcbdyn measured mode", "NONE", "NONE", "NONE", f"mode {mode_n} frequency {freq:.10g} Hz"):
        fh.write("%-80s\n" % line)
    fh.write("%10i%10i%10i%10i%10i%10i\n" % (1, 2, 2, 8, 2, 3))
    fh.write("%10i%10i%10i%10i\n" % (2, 4, 1, mode_n))
    fh.write("%25.16E%25.16E%25.16E\n%25.16E\n" % (freq, 0.0, zeta, 0.0))
    for node, v in zip(nodes, r):
        fh.write("%10i\n%25.16E%25.16E%25.16E\n" % (node, v[0], v[1], v[2]))
    fh.write("%6i\n" % -1)


def _node_table(modes: Modes):
    """Nodes and their (x, y, z) shape values (n_nodes, 3, n_modes) for dataset 55."""
    codes = modes.dofs.codes()
    nodes, row = np.unique(modes.dofs.point_ids, return_inverse=True)
    key = row * 3 + np.abs(codes) - 1
    if np.unique(key).size != key.size:
        raise TestDataError("modes: a point has two DOFs along the same axis; UFF 55 holds one value per axis")
    r = np.zeros((nodes.size * 3, modes.n_modes))
    r[key] = modes.shapes * np.sign(codes)[:, None]
    return nodes, r.reshape(nodes.size, 3, modes.n_modes)


def _even_axis(x) -> bool:
    """True when x is evenly spaced and its start and step survive the 58 header's E13.5 fields."""
    if x.size < 2:
        return False
    x0, dx = x[0], x[1] - x[0]
    exact = float("%13.5e" % x0) == x0 and float("%13.5e" % dx) == dx
    return exact and np.allclose(x0 + np.arange(x.size) * dx, x, rtol=0, atol=1e-13 * np.abs(x).max())


def write_uff(path, data: TestData, precision: str = "double", binary: bool | None = None) -> None:
    """Write points (2411), units (164, SI), modes (55) and FRFs (58/58b) atomically to ``path``.

    ``precision``: "double" or "single" for dataset 55 (see the module notes). ``binary``: write
    FRFs as 58b; None chooses ASCII unless the frequency axis would lose digits in ASCII.
    """
    import pyuff

    if precision not in ("double", "single"):
        raise TestDataError(f"precision '{precision}' is not 'double' or 'single'")
    dsets_head = [{"type": 164, "units_code": 1, "units_description": "SI", "temp_mode": 2,
                   "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 273.15}]
    pts = data.points
    if len(pts):
        n = len(pts)
        dsets_head.append({"type": 2411, "node_nums": pts.ids, "def_cs": np.ones(n, int),
                           "disp_cs": np.ones(n, int), "color": np.ones(n, int),
                           "x": pts.xyz[:, 0], "y": pts.xyz[:, 1], "z": pts.xyz[:, 2]})
    mode_sets = []
    if data.modes is not None:
        nodes, r = _node_table(data.modes)
        for j in range(data.modes.n_modes):
            mode_sets.append((j + 1, float(data.modes.frequencies[j]), float(data.modes.damping[j]), nodes, r[:, :, j]))
    frf_sets = _frf_dsets(data.frfs, binary) if data.frfs is not None else []

    def write(tmp):
        uff = pyuff.UFF(tmp)
        uff.write_sets(dsets_head, mode="overwrite")
        if precision == "double":
            with open(tmp, "a") as fh:
                for m in mode_sets:
                    _write55_double(fh, *m)
        elif mode_sets:
            uff.write_sets([_dset55(*m) for m in mode_sets], mode="add")
        if frf_sets:
            uff.write_sets(frf_sets, mode="add")

    _atomic(path, write)


def _dset55(mode_n, freq, zeta, nodes, r) -> dict:
    return {"type": 55, "analysis_type": 2, "data_ch": 2, "spec_data_type": 8, "model_type": 1,
            "id1": "pcbdyn measured mode", "id5": f"mode {mode_n}", "load_case": 1, "mode_n": mode_n,
            "freq": freq, "modal_m": 0.0, "modal_damp_vis": zeta, "modal_damp_his": 0.0,
            "node_nums": nodes, "r1": r[:, 0], "r2": r[:, 1], "r3": r[:, 2]}


def _frf_dsets(frfs: FRFs, binary) -> list:
    x = frfs.frequencies
    even = _even_axis(x)
    if binary is None:
        binary = not even
    rc, fc = frfs.response.codes(), frfs.reference.codes()
    out = []
    for i in range(len(frfs.response)):
        for j in range(len(frfs.reference)):
            y = frfs.H[:, i, j]
            if np.all(np.isnan(y)):
                continue
            out.append({
                "type": 58, "binary": int(binary), "func_type": 4, "id1": f"pcbdyn FRF ({frfs.kind})",
                "rsp_node": int(frfs.response.point_ids[i]), "rsp_dir": int(rc[i]), "rsp_ent_name": "pcbdyn",
                "ref_node": int(frfs.reference.point_ids[j]), "ref_dir": int(fc[j]), "ref_ent_name": "pcbdyn",
                "x": x, "data": y.astype(complex), "abscissa_spacing": int(even),
                "abscissa_spec_data_type": 18, "abscissa_axis_lab": "Frequency", "abscissa_axis_units_lab": "Hz",
                "ordinate_spec_data_type": _KIND_SPEC[frfs.kind], "ordinate_len_unit_exp": 1,
                "ordinate_axis_lab": frfs.kind, "ordinate_axis_units_lab": frfs.units.split("/N")[0],
                "orddenom_spec_data_type": 13, "orddenom_force_unit_exp": 1,
                "orddenom_axis_lab": "Force", "orddenom_axis_units_lab": "N",
            })
    return out


__all__ = ["read_uff", "write_uff", "real_modes"]
