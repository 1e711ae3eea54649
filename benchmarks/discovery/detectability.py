"""How visible each hidden effect of a case is in its test, measured with the truth's own values on
pcbdyn's model mesh: the change the effect makes to the test's frequencies and shapes (at the test's
points, modes paired by MAC), in units of the stated measurement noise (uniform bounds: a standard
deviation of bound / sqrt(3)), with what the declared parameters can absorb projected out (their
columns by central differences at the truth). ``chi2`` is that signal's squared norm: an effect is
of detectable size when it is at least :data:`DETECTABLE_CHI2` (about 7 standard deviations), well
above the chi^2 a selection among thousands of candidates asks of one more effect (~25).
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from cases import Case
from seen import EXTRA_MODES, MIN_BENDING, bending_share
from toml_text import board_text

DETECTABLE_CHI2 = 50.0


def _state(case: Case, h_mm: float, points):
    """(frequencies, unit shapes at the points (n_points, n_modes)) of ``case``'s truth at the model mesh."""
    from pcbdyn.board import build_model, load_board
    from pcbdyn.fe.modal import solve_modes
    from pcbdyn.fe.probe import model_probe

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "truth.toml"
        path.write_text(board_text(case, truth=True, mesh_mm=h_mm))
        model = build_model(load_board(path), None, 1e-3 * h_mm, shared_mesh=True).model
    modes = solve_modes(model, n_modes=case.test_modes + EXTRA_MODES)
    u = np.asarray(modes.shapes).reshape(-1, 6, modes.shapes.shape[1])[:, :3]
    keep = np.flatnonzero(bending_share(u) >= MIN_BENDING)
    P = model_probe(model, points, (0.0, 0.0, 1.0), tol=0.02).P
    z = np.asarray(P @ modes.shapes[:, keep])
    return modes.frequencies[keep], z / np.linalg.norm(z, axis=0)


def _rows(ref, other, n: int, sf: float, ss: float) -> np.ndarray:
    """Residual rows of ``other`` against the first ``n`` modes of ``ref``, paired by MAC."""
    (f0, z0), (f1, z1) = ref, other
    mac = (z0[:, :n].T @ z1) ** 2
    j = np.argmax(mac, axis=1)
    rows_f = (f1[j] / f0[:n] - 1.0) / sf
    sign = np.sign(np.einsum("ij,ij->j", z0[:, :n], z1[:, j]))
    rms = np.sqrt(np.mean(z0[:, :n] ** 2, axis=0))
    rows_s = ((z1[:, j] * sign - z0[:, :n]) / (ss * rms)).ravel()
    return np.concatenate([rows_f, rows_s])


def effect_chi2(case, state=None) -> list:
    """[chi^2 of each hidden effect's signature beyond the declared parameters]; ``state(case)``: the
    (frequencies, unit shapes at the points) of a case's truth at the model mesh (default: a board's,
    measured in z)."""
    if state is None:
        points = np.column_stack([1e-3 * np.asarray(case.points, float), np.zeros(len(case.points))])

        def state(c):
            return _state(c, c.mesh_mm, points)
    n = case.test_modes
    sf, ss = case.noise[0] / 100.0 / np.sqrt(3.0), case.noise[1] / 100.0 / np.sqrt(3.0)
    ref = state(case)
    cols = []
    for k, p in enumerate(case.parameters):
        pm = []
        for step in (1.02, 1.0 / 1.02):
            params = [dict(q) for q in case.parameters]
            params[k]["true"] = p["true"] * step
            pm.append(_rows(ref, state(replace(case, parameters=params)), n, sf, ss))
        cols.append((pm[0] - pm[1]) / 2.0)
    Q = np.linalg.qr(np.column_stack(cols))[0] if cols else np.zeros((0, 0))
    out = []
    for i in range(len(case.effects)):
        others = [e for j, e in enumerate(case.effects) if j != i]
        r = _rows(ref, state(replace(case, effects=others)), n, sf, ss)
        if Q.size:
            r = r - Q @ (Q.T @ r)
        out.append(float(r @ r))
    return out
