"""Reports of a correlation (``pcbdyn correlate``): the pair table, CSV tables and the pictures (MAC
matrix, AutoMAC of the model at the test points, frequency plot, COMAC map, shape overlays of the
z-measured DOFs)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import correlation_plots as plots
from .files import write_text

HEADER = ("test mode", "model mode", "f_test [Hz]", "f_model [Hz]", "df [%]", "MAC")


def format_pairs(pairs) -> str:
    """The pair table as fixed-width text (df = (f_model - f_test) / f_test)."""
    rows = ["  ".join(f"{h:>12}" for h in HEADER)]
    for p in pairs:
        rows.append("  ".join([f"{p.test + 1:>12d}", f"{p.model + 1:>12d}", f"{p.f_test:>12.2f}",
                               f"{p.f_model:>12.2f}", f"{p.df_pct:>+12.2f}", f"{p.mac_combined:>12.3f}"])
                    + ("" if p.used else "  (beyond the frequency limit: not used for updating)"))
    return "\n".join(rows)


def pairs_csv(pairs) -> str:
    lines = [",".join(HEADER) + ",combined with"]
    for p in pairs:
        combo = " ".join(str(c + 1) for c in p.cluster if c != p.model)
        lines.append(f"{p.test + 1},{p.model + 1},{p.f_test!r},{p.f_model!r},{p.df_pct!r},{p.mac_combined!r},{combo}")
    return "\n".join(lines) + "\n"


def comac_csv(labels, xyz, values) -> str:
    lines = ["dof,x [m],y [m],z [m],COMAC"]
    lines += [f"{lab},{x!r},{y!r},{z!r},{float(c)!r}" for lab, (x, y, z), c in zip(labels, xyz.tolist(), values)]
    return "\n".join(lines) + "\n"


def z_rows(test_modes):
    """Rows of the DOFs measured along +-z and their sign (the shape pictures show w only)."""
    d = test_modes.dofs.directions
    rows = np.flatnonzero(np.abs(np.abs(d[:, 2]) - 1.0) < 1e-9)
    return rows, np.sign(d[rows, 2])


def write_outputs(out: Path, board, bm, modes, test_modes, corr, wireframe=None) -> list:
    """CSV tables and PNG pictures under ``out``; returns the names written (relative to ``out``).
    ``wireframe`` (n, 2): the test's lines between point ids (UFF trace lines and elements), drawn under the
    points."""
    pairing = corr.pairing
    written = ["pairs.csv", "comac.csv", "mac_matrix.png", "automac.png", "frequencies.png", "comac.png"]
    write_text(out / "pairs.csv", pairs_csv(pairing.pairs))
    xyz = test_modes.dof_xyz()
    write_text(out / "comac.csv", comac_csv(corr.dof_labels, xyz, corr.comac))
    plots.mac_matrix(out / "mac_matrix.png", pairing.mac, pairing.pairs, test_modes.frequencies, modes.frequencies)
    plots.mac_matrix(out / "automac.png", pairing.automac, [], modes.frequencies, modes.frequencies,
                     "AutoMAC of the model at the test points (high off the diagonal: aliased)", "model mode")
    plots.frequency_plot(out / "frequencies.png", pairing.pairs)
    outline = getattr(board, "outline", None)  # a board's; a structure in 3-D has none
    pts = test_modes.points
    lines = None if wireframe is None or not len(wireframe) else pts.xyz[pts.index(np.asarray(wireframe).ravel())]
    plots.comac_map(out / "comac.png", outline, xyz if outline is None else xyz[:, :2], corr.comac, corr.dof_labels,
                    None if lines is None else lines.reshape(-1, 2, 3))
    rows, sign = z_rows(test_modes)
    if rows.size and outline is not None:  # the overlays show w on a plate
        model_w = pairing.model_shapes(modes.shapes)[2::6]
        at = pairing.model_shapes(corr.model_at_test)[rows] * sign[:, None]
        test_w = test_modes.shapes[np.ix_(rows, pairing.test_index)] * sign[:, None]
        written += plots.shape_overlays(out, bm.model, board.outline, pairing.pairs, xyz[rows, :2], test_w, at,
                                        model_w)
    return written


def comac_line(corr) -> str:
    """The mean COMAC over the pairs and the five lowest DOFs."""
    order = np.argsort(corr.comac)
    return (f"COMAC over the pairs: mean {float(np.mean(corr.comac)):.3f}; lowest: "
            + ", ".join(f"{corr.dof_labels[i]} {corr.comac[i]:.3f}" for i in order[:5]))
