"""The estimator: poles of FRFs by LSCF (least-squares complex frequency domain) at increasing
model orders, and residues by LSFD (least-squares frequency domain), both from sdypy-EMA.

LSCF fits one common denominator to every FRF (all responses of all references), so each
model order gives one set of poles for the whole test; LSFD then fits each FRF's residues for a
set of poles, with lower and upper residual terms for the modes outside the band.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..testdata import TestDataError

#: poles kept as physical: damping ratio in (0, MAX_DAMPING)
MAX_DAMPING = 0.2


def band_rows(frfs, band):
    """(frequency lines [Hz], FRF rows (n_rows, n_lines), (response index, reference index) of each
    row) of the FRFs inside ``band`` = (lo, hi) [Hz]; pairs absent from the file are skipped."""
    f = frfs.frequencies
    lo, hi = band
    keep = (f >= lo - 1e-9) & (f <= hi + 1e-9)
    if keep.sum() < 8:
        raise TestDataError(f"the band {lo:g}-{hi:g} Hz holds {int(keep.sum())} frequency lines of the FRFs "
                            f"({f[0]:g}-{f[-1]:g} Hz); give a band with more lines")
    fk = f[keep]
    step = np.diff(fk)
    if not np.allclose(step, step[0], rtol=1e-6, atol=0.0):
        raise TestDataError("the FRFs' frequency lines are not evenly spaced in the band; LSCF needs even "
                            "spacing: resample the FRFs to one step")
    H = frfs.H[keep]
    pairs = [(i, j) for i in range(H.shape[1]) for j in range(H.shape[2]) if np.all(np.isfinite(H[:, i, j]))]
    if not pairs:
        raise TestDataError("no FRF has finite values over the band")
    rows = np.array([H[:, i, j] for i, j in pairs])
    return fk, rows, pairs


def physical(poles, band) -> np.ndarray:
    """The poles with positive imaginary part, frequency inside ``band`` and damping in (0, MAX_DAMPING),
    sorted by frequency."""
    p = np.asarray(poles, dtype=complex)
    p = p[np.isfinite(p) & (p.imag > 0)]
    f = np.abs(p) / (2.0 * np.pi)
    z = -p.real / np.abs(p)
    p = p[(f >= band[0]) & (f <= band[1]) & (z > 0) & (z < MAX_DAMPING)]
    return p[np.argsort(np.abs(p))]


def poles_by_order(f, rows, kind: str, max_order: int) -> list:
    """LSCF poles at model orders 2, 4, ..., 2 ``max_order`` (the k-th entry has order 2 (k + 1)),
    all of them (conjugates, unstable and out-of-band roots included)."""
    from sdypy import EMA

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = EMA.Model(frf=rows, freq=f, lower=float(f[0]), upper=float(f[-1]), pol_order_high=int(max_order),
                          frf_form=kind)
        model.get_poles("lscf", show_progress=False)
    return [np.asarray(p, dtype=complex) for p in model.all_poles]


def residues(poles, f, rows, kind: str) -> np.ndarray:
    """LSFD residues (n_rows, n_poles) of the receptance form, H = sum A / (i w - p) + conj, for any
    FRF kind, with lower and upper residuals fitted alongside."""
    from sdypy.EMA.EMA import LSFD

    if len(poles) == 0:
        return np.zeros((rows.shape[0], 0), dtype=complex)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        A, _, _, _ = LSFD(np.asarray(poles), rows, np.asarray(f, float), True, True, 0, len(f), kind)
    return A
