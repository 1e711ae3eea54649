"""Test against model in one call: read the model at the test DOFs, pair the modes, compute COMAC.

This is what ``pcbdyn correlate`` prints and plots; the CLI only builds the model and writes reports.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pcbdyn.fe.probe import model_probe

from .mac import comac
from .pairing import Pairing, pair_modes


@dataclass
class Correlation:
    """Pairing of test and model modes, the model read at the test DOFs and COMAC per test DOF."""

    pairing: Pairing
    model_at_test: np.ndarray  # (n_test_dof, n_model_modes)
    comac: np.ndarray  # (n_test_dof,), over the pairs
    dof_labels: list  # "point:+z" per test DOF
    read: object  # the interpolation matrix (n_test_dof, n_model_dof)

    def to_dict(self) -> dict:
        """JSON-ready: pairs (1-based modes, f in Hz, df in %, MAC), unpaired modes, COMAC per DOF."""
        out = self.pairing.to_dict()
        out["comac"] = {k: float(v) for k, v in zip(self.dof_labels, self.comac)}
        return out


def dof_labels(dofs) -> list:
    """'point:+z' for axis directions, 'point:(dx,dy,dz)' otherwise."""
    out = []
    for pid, d in zip(dofs.point_ids, dofs.directions):
        k = int(np.argmax(np.abs(d)))
        if abs(abs(d[k]) - 1.0) < 1e-12:
            out.append(f"{pid}:{'+' if d[k] > 0 else '-'}{'xyz'[k]}")
        else:
            out.append(f"{pid}:({d[0]:.3g},{d[1]:.3g},{d[2]:.3g})")
    return out


def correlate(test_modes, model, model_modes, min_mac: float = 0.5, close: float = 0.005, tol=None,
              sets=None) -> Correlation:
    """Pair measured modes with the modes of ``model`` by MAC (thesis eq. 2.3) and give the COMAC
    (eq. 2.4) of each measured DOF.

    The model is read at each test DOF through the shell shape functions (points off the model
    raise, naming them); pairing is by MAC with frequency as tie-breaker and best combinations for
    close model modes (:func:`pair_modes`); COMAC is over the pairs, with combinations applied.

    Parameters
    ----------
    test_modes : pcbdyn.testdata.MeasuredModes
        The measured modes, with shapes.
    model : pcbdyn.fe.Model
        The model (a board's: ``board.build().model``).
    model_modes : pcbdyn.fe.modal.Modes
        Its modes (:func:`pcbdyn.fe.modal.solve_modes`).
    min_mac : float
        Pairs below this MAC are left unpaired.

    Returns
    -------
    Correlation
        ``pairing.pairs`` (each with ``test``, ``model`` (0-based), ``df_pct``, ``mac``), the model at
        the test DOFs and the COMAC.

    Examples
    --------
    >>> from pcbdyn.board import load_board
    >>> from pcbdyn.fe.modal import solve_modes
    >>> from pcbdyn.testdata import read_points_csv
    >>> from pcbdyn.testdata.simulate import simulate_on_model
    >>> card = "examples/six_part_card/"
    >>> model = load_board(card + "board.toml").build().model
    >>> modes = solve_modes(model, n_modes=7)
    >>> points, dofs = read_points_csv(card + "points.csv")
    >>> test = simulate_on_model(model, modes, points, dofs).modes      # no noise: the model itself
    >>> [(p.test + 1, p.model + 1, round(p.mac, 3)) for p in correlate(test, model, modes).pairing.pairs][:3]
    [(1, 1, 1.0), (2, 2, 1.0), (3, 3, 1.0)]
    """
    probe = model_probe(model, test_modes.dof_xyz(), test_modes.dofs.directions, sets=sets, tol=tol)
    at = np.asarray(probe.P @ model_modes.shapes)
    pairing = pair_modes(test_modes.shapes, at, test_modes.frequencies, model_modes.frequencies,
                         min_mac=min_mac, close=close)
    if pairing.pairs:
        c = comac(test_modes.shapes[:, pairing.test_index], pairing.model_shapes(at))
    else:
        c = np.zeros(len(test_modes.dofs))
    return Correlation(pairing, at, c, dof_labels(test_modes.dofs), probe.P)
