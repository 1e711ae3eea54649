"""Mode tables: frequency, effective masses (:mod:`pcbdyn.fe.effective_mass`) in percent with their
running sums, and a short shape description. One table, with the units in its headers, is what the
console, the CSV file and the HTML page show."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import griddata

from ..fe.effective_mass import AXES


def nodal_lines(nodes: np.ndarray, w: np.ndarray, n_grid: int = 41) -> tuple[int, int]:
    """(m, n): nodal lines crossed going along x and along y (median over grid lines), from the
    out-of-plane displacement ``w`` at the nodes interpolated on a regular grid."""
    lo, hi = nodes[:, :2].min(axis=0), nodes[:, :2].max(axis=0)
    gx = np.linspace(lo[0], hi[0], n_grid)
    gy = np.linspace(lo[1], hi[1], n_grid)
    X, Y = np.meshgrid(gx, gy)
    W = griddata(nodes[:, :2], w, (X, Y), method="linear")
    W = W / np.nanmax(np.abs(W))
    W[np.abs(W) < 0.05] = np.nan  # ignore the small values near nodal lines and in holes

    def crossings(rows):
        out = []
        for row in rows:
            s = np.sign(row[~np.isnan(row)])
            if s.size > 1:
                out.append(int(np.count_nonzero(s[1:] != s[:-1])))
        return int(np.median(out)) if out else 0

    return crossings(W), crossings(W.T)


def describe(nodes, w) -> str:
    m, n = nodal_lines(nodes, w)
    return f"({m},{n}) nodal lines"


def mass_columns(em) -> dict:
    """{header: percent per mode}: each mode's effective mass in x, y, z and effective inertia about the
    axes rx, ry, rz through the centre of mass, then their running sums, rounded to 0.01 %."""
    cols = {f"m_eff {a} [%]": np.round(100.0 * em.fractions[:, k], 2) for k, a in enumerate(AXES)}
    cols.update({f"sum {a} [%]": np.round(100.0 * em.cumulative[:, k], 2) for k, a in enumerate(AXES)})
    return cols


#: what the effective-mass columns of a table are
MASS_NOTE = ("effective mass: each mode's share of the mass moved by a rigid translation along x, y, z and of the "
             "moment of inertia about the axes rx, ry, rz through the centre of mass; sum: the running sum over the "
             "modes")


def free_note(n_rigid: int) -> str | None:
    """Why the elastic modes of a free structure show no effective mass (None when it is held)."""
    if not n_rigid:
        return None
    return (f"free structure: its {n_rigid} rigid-body modes carry all of its mass and inertia; the elastic modes "
            "are mass-orthogonal to every rigid motion, so their effective masses are zero")


def mode_table(bm, modes, em) -> pd.DataFrame:
    """One row per elastic mode: mode, frequency [Hz], the effective masses of ``em``
    (:func:`mass_columns`) and the shape (nodal lines of a plate; a structure in 3-D describes its
    modes itself, ``mode_descriptions``: the plates that move)."""
    w = modes.shapes[2::6]
    own = getattr(bm, "mode_descriptions", None)
    return pd.DataFrame({
        "mode": np.arange(1, modes.frequencies.size + 1),
        "frequency [Hz]": modes.frequencies,
        **mass_columns(em),
        "shape": own(modes.shapes) if own else [describe(bm.model.nodes, w[:, j]) for j in range(w.shape[1])],
    })


def format_table(df: pd.DataFrame) -> str:
    return df.to_string(index=False, float_format=lambda v: f"{v:.2f}")
