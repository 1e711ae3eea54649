"""Measured data as plain arrays in SI units: points, measured DOFs, modes, FRFs.

Every measured quantity belongs to a *DOF*: a point (an id into :class:`Points`) and a unit
direction in the board frame (a laser vibrometer gives +z at each point). Shapes and FRFs are
stored per DOF, so a test with several directions at one point is just several rows.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class TestDataError(ValueError):
    """Measured data that cannot be read, written or used, with the file, the dataset and the fix."""

    __test__ = False  # not a pytest test class


#: UFF direction codes 1..3 (x, y, z) and their negatives
AXES = {1: (1.0, 0.0, 0.0), 2: (0.0, 1.0, 0.0), 3: (0.0, 0.0, 1.0)}
_AXIS_NAMES = {"x": 1, "y": 2, "z": 3}


@dataclass
class Points:
    """Measurement points: integer ids and coordinates (n, 3) [m] in the board frame."""

    ids: np.ndarray
    xyz: np.ndarray

    def __post_init__(self):
        self.ids = np.asarray(self.ids, dtype=np.int64).ravel()
        self.xyz = np.asarray(self.xyz, dtype=float).reshape(-1, 3)
        if self.ids.size != self.xyz.shape[0]:
            raise TestDataError(f"points: {self.ids.size} ids but {self.xyz.shape[0]} coordinates")
        bad = ~np.isfinite(self.xyz).all(axis=1)
        if bad.any():
            raise TestDataError(f"points: {self.ids[bad].tolist()[:20]} have coordinates that are not finite numbers; "
                                "give each point three numbers")
        uniq, counts = np.unique(self.ids, return_counts=True)
        if np.any(counts > 1):
            raise TestDataError(
                f"points: ids {uniq[counts > 1].tolist()[:20]} appear more than once; give each point one id"
            )

    def __len__(self):
        return self.ids.size

    def index(self, ids) -> np.ndarray:
        """Row of each id in ``ids``; unknown ids raise :class:`TestDataError`."""
        ids = np.asarray(ids, dtype=np.int64)
        order = np.argsort(self.ids)
        pos = np.clip(np.searchsorted(self.ids[order], ids), 0, max(self.ids.size - 1, 0))
        rows = order[pos] if self.ids.size else np.zeros(ids.shape, dtype=np.int64)
        bad = (self.ids[rows] != ids) if self.ids.size else np.ones(ids.shape, dtype=bool)
        if np.any(bad):
            raise TestDataError(
                f"point ids {np.unique(ids[bad]).tolist()[:20]} have no coordinates; add them to the geometry "
                "(UFF dataset 2411/15 or the points CSV)"
            )
        return rows


@dataclass
class Dofs:
    """Measured DOFs: the point id and the unit direction (board frame) of each measured quantity."""

    point_ids: np.ndarray
    directions: np.ndarray

    def __post_init__(self):
        self.point_ids = np.asarray(self.point_ids, dtype=np.int64).ravel()
        d = np.asarray(self.directions, dtype=float)
        if d.ndim == 1 and d.size == 3:
            d = np.tile(d, (self.point_ids.size, 1))
        d = d.reshape(-1, 3)
        if d.shape[0] != self.point_ids.size:
            raise TestDataError(f"dofs: {self.point_ids.size} points but {d.shape[0]} directions")
        norm = np.linalg.norm(d, axis=1)
        if not np.isfinite(norm).all():
            raise TestDataError("dofs: a measured direction holds a value that is not a finite number")
        if np.any(norm == 0):
            raise TestDataError("dofs: a measured direction is the zero vector; give a direction such as +z")
        self.directions = d / norm[:, None]

    def __len__(self):
        return self.point_ids.size

    @classmethod
    def from_codes(cls, point_ids, codes) -> "Dofs":
        """DOFs from UFF direction codes (+-1, +-2, +-3 for x, y, z) or names ('+z', 'x', '-y')."""
        point_ids = np.atleast_1d(point_ids)
        codes = np.broadcast_to(np.asarray(codes, dtype=object), point_ids.shape)
        dirs = np.array([_code_vector(c) for c in codes]).reshape(-1, 3)
        return cls(point_ids, dirs)

    def codes(self) -> np.ndarray:
        """UFF direction code of each DOF (+-1..3); a direction not along an axis raises."""
        d = self.directions
        k = np.argmax(np.abs(d), axis=1)
        val = d[np.arange(len(d)), k]
        off = np.abs(np.abs(val) - 1.0) > 1e-12
        if np.any(off):
            i = int(np.flatnonzero(off)[0])
            raise TestDataError(
                f"DOF at point {self.point_ids[i]} has direction {d[i].tolist()}, not along x, y or z: "
                "UFF stores axis directions only; write CSV instead"
            )
        return (np.sign(val) * (k + 1)).astype(int)

    def take(self, rows) -> "Dofs":
        return Dofs(self.point_ids[rows], self.directions[rows])


def _code_vector(code):
    if isinstance(code, str):
        s = code.strip().lower()
        sign = -1.0 if s.startswith("-") else 1.0
        s = s.lstrip("+-")
        if s not in _AXIS_NAMES:
            raise TestDataError(f"direction {code[:20]!r} is not one of x, y, z (optionally signed, e.g. '+z')")
        code = int(sign) * _AXIS_NAMES[s]
    if isinstance(code, (bool, np.bool_)) or not isinstance(code, (int, float, np.integer, np.floating)) \
            or not np.isfinite(code) or code != int(code):
        raise TestDataError(f"direction code {str(code)[:20]!r} is not a translation (use +-1, +-2, +-3 for x, y, z)")
    code = int(code)
    if abs(code) not in AXES:
        raise TestDataError(f"direction code {code} is not a translation (use +-1, +-2, +-3 for x, y, z)")
    return np.sign(code) * np.array(AXES[abs(code)])


#: the largest shape value of a measured mode: beyond it no scaling of a shape explains it (a misread file)
MAX_SHAPE = 1e30


def _at(where: str) -> str:
    return f"{where}: " if where else ""


def _which(i: int, n: int, numbers) -> str:
    """' (mode k)' naming the i-th of ``n`` modes by its number, or nothing for a lone unnumbered mode."""
    if numbers is None:
        return "" if n == 1 else f" (mode {i + 1})"
    return f" (mode {int(numbers[i])})"


#: [Hz] the lowest frequency a file's elastic mode may have: below it a mode is a rigid-body mode (which a
#: file marks as such, with 0 Hz, and pcbdyn does not pair) or a value written in the wrong unit
FILE_FLOOR_HZ = 0.01


def check_frequencies(frequencies, where: str = "modes", numbers=None, floor: float = 0.0) -> np.ndarray:
    """Measured natural frequencies [Hz] as floats: each a finite number above 0 (0 Hz or below is a rigid-body
    mode or a mistyped value) and, with ``floor`` (the readers of files pass :data:`FILE_FLOOR_HZ`), not below
    it. The one home of this rule: :class:`MeasuredModes` (whose simulated modes keep floor 0) and the readers (which
    give ``where``: the file, dataset or table row) call it. ``numbers``: the modes' numbers, to name the one
    refused."""
    f = np.asarray(frequencies, dtype=float).ravel()
    bad = np.flatnonzero(~(np.isfinite(f) & (f > 0)))
    if bad.size:
        i = int(bad[0])
        raise TestDataError(f"{_at(where)}frequency {f[i]:g} Hz{_which(i, f.size, numbers)}: a measured mode's "
                            "frequency is a finite number above 0")
    low = np.flatnonzero(f < floor)
    if low.size:
        i = int(low[0])
        raise TestDataError(f"{_at(where)}frequency {f[i]:g} Hz{_which(i, f.size, numbers)} is below {floor:g} Hz, "
                            "where no elastic mode is measured: a rigid-body mode (remove it from the file) or a "
                            "value in another unit (give it in Hz)")
    return f


def check_damping(damping, n: int, where: str = "modes", numbers=None) -> np.ndarray:
    """Measured viscous damping ratios as floats, one per mode (None: n zeros), each from 0 to below 1. A
    negative ratio is an artefact of a curve fit (an unstable pole), not a measured property: it is refused
    rather than passed on to correlation. The one home of this rule (see :func:`check_frequencies`)."""
    z = np.zeros(n) if damping is None else np.asarray(damping, dtype=float).ravel()
    if z.size != n:
        raise TestDataError(f"{_at(where)}{z.size} damping ratios for {n} modes; give one per mode")
    bad = np.flatnonzero(~((z >= 0) & (z < 1)))
    if bad.size:
        i = int(bad[0])
        fit = "; a negative one is an artefact of the curve fit: refit the mode, or give 0" if z[i] < 0 else ""
        raise TestDataError(f"{_at(where)}the damping ratio {z[i]:g}{_which(i, n, numbers)} is not from 0 to below "
                            f"1 (a measured mode's viscous damping ratio, e.g. 0.02{fit})")
    return z


def check_shapes(shapes, where: str = "modes", numbers=None, nonzero: bool = True) -> None:
    """Measured shapes (n_dof, n_modes), real or complex: every value a finite number at most MAX_SHAPE in size,
    and (``nonzero``) no shape zero at every DOF (it pairs with nothing). The one home of this rule (see
    :func:`check_frequencies`). :class:`MeasuredModes` itself admits a zero shape: a test simulated on a flat board's
    model reads its in-plane modes as zero at out-of-plane DOFs; a file's record may not hold one."""
    a = np.abs(np.asarray(shapes))
    if not np.isfinite(a).all():
        raise TestDataError(f"{_at(where)}a shape holds a value that is not a finite number (NaN or infinity); "
                            "give every measured DOF a number")
    if a.size and a.max() > MAX_SHAPE:
        raise TestDataError(f"{_at(where)}a shape value of {a.max():.3g} is beyond any scaling of a mode shape (at "
                            f"most {MAX_SHAPE:g}); check the shape's values")
    zero = np.flatnonzero(~np.any(a != 0, axis=0)) if nonzero and a.ndim == 2 and a.shape[0] else []
    if len(zero):
        i = int(zero[0])
        raise TestDataError(f"{_at(where)}the mode shape{_which(i, a.shape[1], numbers)} is zero at every DOF; "
                            "remove the mode or give its shape")


@dataclass
class MeasuredModes:
    """Measured (real, normal) modes: frequencies [Hz], viscous damping ratios, shapes (n_dof, n_modes)
    at the measured DOFs; the one measured-modes type of correlation, updating and diagnosis.

    ``mpc`` is the modal phase collinearity of each mode before it was made real (1 for a mode
    that was real already); shapes are in whatever scaling the test gave. A test of frequencies only
    (a table of measured frequencies) has no points, DOFs or shapes: its modes pair with the model's by
    ``numbers``, the test's mode numbers (default 1..n).
    """

    points: Points | None
    dofs: Dofs | None
    frequencies: np.ndarray
    shapes: np.ndarray | None
    damping: np.ndarray | None = None
    mpc: np.ndarray | None = None
    numbers: np.ndarray | None = None

    def __post_init__(self):
        self.frequencies = np.asarray(self.frequencies, dtype=float).ravel()
        n = self.frequencies.size
        self.numbers = np.arange(1, n + 1) if self.numbers is None else np.asarray(self.numbers, int).ravel()
        if self.numbers.size != n:
            raise TestDataError(f"modes: {n} frequencies but {self.numbers.size} mode numbers")
        check_frequencies(self.frequencies, "modes", self.numbers)
        if self.shapes is not None:
            if self.dofs is None or self.points is None:
                raise TestDataError("modes: measured shapes need the points and DOFs they were measured at")
            self.shapes = np.asarray(self.shapes, dtype=float).reshape(len(self.dofs), -1)
            if self.shapes.shape[1] != n:
                raise TestDataError(f"modes: {n} frequencies but {self.shapes.shape[1]} shape columns")
            check_shapes(self.shapes, "modes", self.numbers, nonzero=False)
            self.points.index(np.unique(self.dofs.point_ids))
        self.damping = check_damping(self.damping, n, "modes", self.numbers)
        self.mpc = np.ones(n) if self.mpc is None else np.asarray(self.mpc, float).ravel()

    @classmethod
    def frequencies_only(cls, frequencies, numbers=None) -> "MeasuredModes":
        """Measured frequencies [Hz] without shapes, of the test's mode ``numbers`` (default 1..n)."""
        return cls(None, None, frequencies, None, numbers=numbers)

    @property
    def n_modes(self) -> int:
        return self.frequencies.size

    @property
    def xyz(self) -> np.ndarray | None:
        """Coordinates of the point of each measured DOF (n_dof, 3) [m], or None without shapes."""
        return None if self.shapes is None else self.dof_xyz()

    @property
    def directions(self) -> np.ndarray | None:
        """Unit direction of each measured DOF (n_dof, 3), or None without shapes."""
        return None if self.shapes is None else self.dofs.directions

    def dof_xyz(self) -> np.ndarray:
        """Coordinates of the point of each DOF, (n_dof, 3)."""
        return self.points.xyz[self.points.index(self.dofs.point_ids)]

    def measured_points(self) -> Points:
        """The points that carry a measured DOF."""
        used = self.points.index(np.unique(self.dofs.point_ids))
        return Points(self.points.ids[used], self.points.xyz[used])

    def subset(self, keep) -> "MeasuredModes":
        """The modes ``keep`` (a boolean mask or indices), with their numbers."""
        k = np.asarray(keep)
        return MeasuredModes(self.points, self.dofs, self.frequencies[k], None if self.shapes is None else self.shapes[:, k],
                     self.damping[k], self.mpc[k], self.numbers[k])

    def without_shapes(self) -> "MeasuredModes":
        """The frequencies alone (pairing by the test's mode numbers)."""
        return MeasuredModes.frequencies_only(self.frequencies, self.numbers)


#: FRF kinds and the power of (i omega) that turns a receptance into each
FRF_KINDS = {"receptance": 0, "mobility": 1, "accelerance": 2}
FRF_UNITS = {"receptance": "m/N", "mobility": "m/s/N", "accelerance": "m/s^2/N"}


@dataclass
class FRFs:
    """Measured FRFs: frequency axis [Hz], H (n_freq, n_resp, n_ref) in SI, kind, response/reference DOFs."""

    points: Points
    frequencies: np.ndarray
    H: np.ndarray
    kind: str
    response: Dofs
    reference: Dofs

    def __post_init__(self):
        self.frequencies = np.asarray(self.frequencies, dtype=float).ravel()
        self.H = np.asarray(self.H, dtype=complex)
        if self.kind not in FRF_KINDS:
            raise TestDataError(f"FRF kind '{self.kind}' is not one of {', '.join(FRF_KINDS)}")
        want = (self.frequencies.size, len(self.response), len(self.reference))
        if self.H.shape != want:
            raise TestDataError(f"FRFs: H has shape {self.H.shape}, expected (n_freq, n_resp, n_ref) = {want}")

    @property
    def units(self) -> str:
        return FRF_UNITS[self.kind]

    def as_kind(self, kind: str) -> "FRFs":
        """The same FRFs converted to another kind (multiplying by (i omega)^k)."""
        if kind not in FRF_KINDS:
            raise TestDataError(f"FRF kind '{kind}' is not one of {', '.join(FRF_KINDS)}")
        p = FRF_KINDS[kind] - FRF_KINDS[self.kind]
        w = 2j * np.pi * self.frequencies
        with np.errstate(divide="ignore", invalid="ignore"):
            H = self.H * (w**p)[:, None, None]
        return FRFs(self.points, self.frequencies, H, kind, self.response, self.reference)


@dataclass
class Excitation:
    """The receptances of one excitation in SI: ``frequencies`` [Hz] (n_f,), ``H`` (n_f, n_resp) [m/N]
    at points ``xyz`` (n_resp, 3) along unit ``directions`` (n_resp, 3), for a unit force at
    ``excite_xyz`` (3,) along ``excite_direction`` (3,)."""

    frequencies: np.ndarray
    H: np.ndarray
    xyz: np.ndarray
    directions: np.ndarray
    excite_xyz: np.ndarray
    excite_direction: np.ndarray


def excitations(frfs: FRFs) -> list:
    """One :class:`Excitation` per reference DOF of ``frfs`` (any kind, converted to receptance); the
    0 Hz line (no receptance from mobility or accelerance there) and responses with missing (NaN)
    FRFs are dropped."""
    rec = frfs.as_kind("receptance")
    pts = rec.points
    r_xyz = pts.xyz[pts.index(rec.response.point_ids)]
    e_xyz = pts.xyz[pts.index(rec.reference.point_ids)]
    f = np.asarray(rec.frequencies, float)
    lines = f > 0
    out = []
    for k in range(rec.H.shape[2]):
        H = rec.H[lines, :, k]
        ok = np.all(np.isfinite(H), axis=0)
        if ok.any():
            out.append(Excitation(f[lines], H[:, ok], r_xyz[ok], rec.response.directions[ok], e_xyz[k],
                                  rec.reference.directions[k]))
    if not out:
        raise TestDataError("the FRFs hold no complete response column for any reference")
    return out


@dataclass
class TestData:
    """What one test file holds: points, and optionally modes, FRFs; datasets that were skipped; the test's
    wireframe (n, 2) of point ids (trace lines, element edges) and its elements [(descriptor, node ids)]."""

    points: Points
    modes: MeasuredModes | None = None
    frfs: FRFs | None = None
    skipped: list = field(default_factory=list)
    wireframe: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    elements: list = field(default_factory=list)

    __test__ = False
