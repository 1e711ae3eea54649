"""The standard quality indicators of an identified mode: its complex shape's phase collinearity (MPC),
mean phase deviation (MPD) and complexity, and the spread of frequency and damping over the stable poles
the mode was chosen from (how well the chart agrees with itself)."""

from __future__ import annotations

import numpy as np


def mpd(psi) -> float:
    """Mean phase deviation [deg] of a complex shape: the magnitude-weighted mean angle between each
    component and the straight line through the origin that fits the components best in the complex plane
    (from the SVD of [Re psi, Im psi]); 0 for a real (normal) mode."""
    psi = np.asarray(psi, dtype=complex).ravel()
    w = np.abs(psi)
    if not np.any(w > 0):
        return 0.0
    _, _, vt = np.linalg.svd(np.column_stack([psi.real, psi.imag]))
    v12, v22 = vt[1, 0], vt[1, 1]  # V's second column: the normal of the best line
    along = np.abs(psi.real * v22 - psi.imag * v12) / np.hypot(v12, v22)  # each component's length along it
    ang = np.arccos(np.clip(along / np.where(w > 0, w, 1.0), 0.0, 1.0))
    return float(np.degrees(np.sum(w * ang) / np.sum(w)))


def indicators(psi, mpc, chart, groups) -> list:
    """Per mode: MPC, MPD [deg], complexity (1 - MPC) and the mean and standard deviation of frequency [Hz]
    and damping ratio over the mode's stable poles (``groups``: chart indices per mode)."""
    out = []
    for k, g in enumerate(groups):
        g = np.asarray(g, dtype=int)
        f, z = chart.frequency[g], chart.damping[g]
        ddof = 1 if g.size > 1 else 0
        out.append({"mpc": float(mpc[k]), "mpd_deg": mpd(psi[:, k]), "complexity": float(1.0 - mpc[k]),
                    "frequency_mean_hz": float(f.mean()), "frequency_std_hz": float(f.std(ddof=ddof)),
                    "damping_mean": float(z.mean()), "damping_std": float(z.std(ddof=ddof)), "poles": int(g.size)})
    return out
