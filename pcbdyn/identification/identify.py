"""Modes from measured FRFs: LSCF poles over model orders, a stabilisation chart, the poles chosen
from it (automatically or near given frequencies), LSFD residues, and real mode shapes.

Shapes: for each mode the residues form a matrix over responses x references, ideally
psi L^T (rank one); its first singular pair gives psi, the shape seen by all references at once.
Where a reference DOF is also measured (a driving point), the shape is mass-normalised:
A_jj = phi_j^2 / (2 i omega_d) for the receptance residue. The complex shape is then made real
(:func:`pcbdyn.testdata.real_modes`, with its phase collinearity MPC).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..correlation.mac import automac
from ..testdata import MeasuredModes, TestDataError, real_modes
from . import lscf, stability
from .quality import indicators


@dataclass
class Identification:
    """Identified modes (shapes at the response DOFs), the chart they were chosen from, how they were
    chosen ("auto" or "manual"), the shapes' scaling ("mass" or "unit"), the band [Hz] and the
    highest model order used; ``mac_neighbours`` (n, 2): MAC of each shape with the previous and the
    next mode (NaN at the ends); ``quality``: per mode the indicators of :func:`.quality.indicators`;
    ``criteria``: the rules of the choice (:func:`.stability.criteria`); ``notes``: what the choice
    says to the user (requests of ``select`` that shared a pole)."""

    modes: MeasuredModes
    chart: stability.Chart
    chosen: list
    selection: str
    scaling: str
    band: tuple
    max_order: int
    mac_neighbours: np.ndarray
    quality: list = field(default_factory=list)
    criteria: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


def _driving_rows(frfs) -> dict:
    """{reference index: response index} of the references that are also measured responses."""
    out = {}
    for j, (pid, d) in enumerate(zip(frfs.reference.point_ids, frfs.reference.directions)):
        same = np.flatnonzero((frfs.response.point_ids == pid) & np.all(np.abs(frfs.response.directions - d) < 1e-9,
                                                                          axis=1))
        if same.size:
            out[j] = int(same[0])
    return out


def shapes(A, pairs, frfs, poles):
    """Complex shapes (n_resp, n_modes) from residues A (n_rows, n_modes) of the FRF rows ``pairs``,
    and the scaling used ("mass" when a driving point is measured, else "unit")."""
    n_resp, n_ref = len(frfs.response), len(frfs.reference)
    complete = [j for j in range(n_ref) if sum(1 for _, jj in pairs if jj == j) == n_resp]
    if not complete:
        raise TestDataError("no reference has FRFs at every response DOF; shapes need one full column of FRFs")
    drive = {j: i for j, i in _driving_rows(frfs).items() if j in complete}
    row = {p: k for k, p in enumerate(pairs)}
    out = np.zeros((n_resp, A.shape[1]), dtype=complex)
    for r in range(A.shape[1]):
        R = np.array([[A[row[(i, j)], r] for j in complete] for i in range(n_resp)])
        U, s, Vh = np.linalg.svd(R, full_matrices=False)
        psi, L = U[:, 0], s[0] * Vh[0].conj()
        if drive:
            k = max(drive, key=lambda j: abs(L[complete.index(j)] * psi[drive[j]]))
            c2 = 2j * poles[r].imag * L[complete.index(k)] / psi[drive[k]]
            out[:, r] = np.sqrt(c2) * psi
        else:
            out[:, r] = psi / np.abs(psi).max()
    return out, ("mass" if drive else "unit")


def _neighbours(phi) -> np.ndarray:
    n = phi.shape[1]
    out = np.full((n, 2), np.nan)
    if n > 1:
        M = automac(phi)
        out[1:, 0] = np.diag(M, -1)
        out[:-1, 1] = np.diag(M, 1)
    return out


def identify(frfs, band=None, max_order: int = 40, select=None) -> Identification:
    """The modes (:class:`pcbdyn.testdata.MeasuredModes`) of ``frfs`` (:class:`pcbdyn.testdata.FRFs`)
    in ``band`` (lo, hi) [Hz] (default: the FRF axis above 0 Hz), from model orders up to 2
    ``max_order`` (capped at a quarter of the band's lines); ``select``: frequencies [Hz] to pick
    poles near instead of the automatic choice."""
    f_all = frfs.frequencies
    if band is None:
        band = (float(f_all[f_all > 0].min()), float(f_all.max()))
    lo, hi = band
    if not (0 <= lo < hi) or hi <= f_all.min() or lo >= f_all.max():
        raise TestDataError(f"the band {lo:g}-{hi:g} Hz is not a range inside the FRFs' {f_all.min():g}-"
                            f"{f_all.max():g} Hz")
    f, rows, pairs = lscf.band_rows(frfs, band)
    order = int(max(2, min(max_order, f.size // 4)))
    all_poles = lscf.poles_by_order(f, rows, frfs.kind, order)
    c = stability.chart(all_poles, f, rows, frfs.kind, band)
    groups, notes = (stability.auto_select(c), []) if select is None else stability.pick(c, select)
    chosen = [stability.representative(c, g) for g in groups]
    poles = np.array([stability.group_pole(c, g) for g in groups])
    A = lscf.residues(poles, f, rows, frfs.kind)
    if select is None:  # the automatic choice keeps the modes the FRFs show (stability.MIN_SHARE)
        seen = stability.share(poles, A, f, rows, frfs.kind) >= stability.MIN_SHARE
        if not seen.all():
            groups = [g for g, s in zip(groups, seen) if s]
            chosen = [k for k, s in zip(chosen, seen) if s]
            poles = poles[seen]
            A = lscf.residues(poles, f, rows, frfs.kind)
    psi, scaling = shapes(A, pairs, frfs, poles)
    phi, mpc = real_modes(psi)
    big = np.argmax(np.abs(phi), axis=0)
    phi = phi * np.sign(phi[big, np.arange(phi.shape[1])])
    modes = MeasuredModes(frfs.points, frfs.response, np.abs(poles) / (2.0 * np.pi), phi, -poles.real / np.abs(poles),
                          mpc)
    return Identification(modes, c, chosen, "auto" if select is None else "manual", scaling,
                          (float(lo), float(hi)), order, _neighbours(phi), indicators(psi, mpc, c, groups),
                          stability.criteria(len(rows)), notes)
