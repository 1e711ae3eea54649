"""Mode tables: frequency, effective mass fraction in z, and a short shape description."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import griddata


def z_translation(n_dof: int) -> np.ndarray:
    r = np.zeros(n_dof)
    r[2::6] = 1.0
    return r


def effective_mass_fraction_z(M, shapes: np.ndarray) -> np.ndarray:
    """Effective modal mass in z over the total mass: (phi^T M r)^2 / (r^T M r) for
    mass-normalised phi and r the unit rigid translation in z."""
    r = z_translation(M.shape[0])
    Mr = M @ r
    return (shapes.T @ Mr) ** 2 / float(r @ Mr)


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


def mode_table(bm, modes, M) -> pd.DataFrame:
    """One row per elastic mode: n, frequency_hz, mass fraction in z, shape description (nodal lines of
    a plate; a structure in 3-D describes its modes itself, ``mode_descriptions``: the plates that move)."""
    frac = effective_mass_fraction_z(M, modes.shapes)
    w = modes.shapes[2::6]
    own = getattr(bm, "mode_descriptions", None)
    return pd.DataFrame({
        "mode": np.arange(1, modes.frequencies.size + 1),
        "frequency_hz": modes.frequencies,
        "eff_mass_z": frac,
        "shape": own(modes.shapes) if own else [describe(bm.model.nodes, w[:, j]) for j in range(w.shape[1])],
    })


def format_table(df: pd.DataFrame) -> str:
    out = df.rename(columns={"frequency_hz": "frequency [Hz]", "frequency_std_hz": "+- sd [Hz]",
                             "eff_mass_z": "eff. mass z [%]"}).copy()
    out["eff. mass z [%]"] = 100.0 * out["eff. mass z [%]"]
    return out.to_string(index=False, float_format=lambda v: f"{v:.2f}")
