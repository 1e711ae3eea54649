"""Response of a supported structure to an acceleration of its supports (base excitation), by
modal superposition with modal damping and a static residual for the modes left out.

With every support moving rigidly by u_b along the unit rigid translation r, the motion relative
to the supports, u = u_abs - r u_b, obeys M u'' + C u' + K u = -M r u_b'' (the springs to the
base stretch only by u, since K r = 0): the thesis' eq. 3.27 with the inertial load -M r u_b''.
With mass-normalised modes phi_r and participation factors Gamma_r = phi_r^T M r, per unit base
acceleration at circular frequency w:

    u(w)     = -sum_r phi_r Gamma_r / (w_r^2 - w^2 + 2 i zeta_r w_r w)  -  R
    a_abs(w) = r - w^2 u(w)

where R = K^-1 M r - sum_r phi_r Gamma_r / w_r^2 is the static response of the modes not
computed (all modes together give K^-1 M r); it keeps the response of a truncated mode set
right below the first omitted mode. A response "basis" is then a few full-length columns times
a transfer g_k(f) per column, so that the covariance of the outputs is B C B^T with the small
matrix C = integral of g g^H W df (W the input PSD): RMS values at every node cost one product.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fe.linsolve import SingularMatrixError, factorize
from ..fe.model import ModelError
from .spectra import VibrationError, trapezoid_weights

AXES = ("x", "y", "z")


@dataclass
class BaseExcitation:
    """Modal data of a base-excited model: frequencies [Hz], damping ratios, participation factors
    Gamma_r [kg^0.5], the columns ``basis`` = [phi_1 .. phi_n, R] (n_dof, n + 1), the influence
    vector ``r`` and the mass that the rigid translation moves, r^T M r [kg]."""

    axis: str
    frequencies: np.ndarray
    zeta: np.ndarray
    gamma: np.ndarray
    basis: np.ndarray
    r: np.ndarray
    total_mass: float

    def transfer(self, freqs, quantity: str = "displacement") -> np.ndarray:
        """g_k(f) (n_f, n_columns) per unit base acceleration: relative displacement of each basis
        column, or, for "acceleration", [1, -w^2 g] on the columns [r, basis]."""
        w = 2.0 * np.pi * np.asarray(freqs, dtype=float)[:, None]
        wr = 2.0 * np.pi * self.frequencies
        h = -self.gamma / (wr**2 - w**2 + 2j * self.zeta * wr * w)
        g = np.hstack([h, -np.ones((w.shape[0], 1))])
        if quantity == "displacement":
            return g
        if quantity == "acceleration":
            return np.hstack([np.ones((w.shape[0], 1)), -(w**2) * g])
        raise ValueError(f"quantity must be 'displacement' or 'acceleration', got '{quantity}'")

    def columns(self, P, quantity: str = "displacement") -> np.ndarray:
        """B = P [basis] (or P [r, basis] for "acceleration"): the outputs read by ``P`` (n_out, n_dof)."""
        cols = self.basis if quantity == "displacement" else np.column_stack([self.r, self.basis])
        return np.asarray(P @ cols)

    def covariance(self, psd, grid, quantity: str = "displacement", moment: int = 0) -> np.ndarray:
        """C = integral of f^moment g(f) g(f)^H W(f) df over ``grid`` (trapezoid rule)."""
        g = self.transfer(grid, quantity) * np.sqrt(trapezoid_weights(grid) * psd.at(grid) * grid**moment)[:, None]
        return g.T @ g.conj()

    @staticmethod
    def variance(B: np.ndarray, C: np.ndarray) -> np.ndarray:
        """Mean square of each output row of B, Re(b C b^T) (>= 0)."""
        return np.maximum(np.einsum("ik,kl,il->i", B, C, B).real, 0.0)

    def seen_by(self, nodes, R) -> "BaseExcitation":
        """The excitation as a part of the model sees it in its own axes: the six rows of each of
        ``nodes`` (in their order) of ``basis`` and ``r``, turned by R^T (R: the part's axes as columns),
        so that the part's own model reads them (a card in a housing)."""
        dofs = (6 * np.asarray(nodes)[:, None] + np.arange(6)).ravel()

        def turn(A):
            A = A[dofs].reshape(len(nodes), 2, 3, -1)
            return np.einsum("ji,nbjm->nbim", R, A).reshape(len(dofs), -1)

        return BaseExcitation(self.axis, self.frequencies, self.zeta, self.gamma, turn(self.basis),
                              turn(self.r[:, None])[:, 0], self.total_mass)

    def response_psd(self, B: np.ndarray, psd, freqs, quantity: str = "displacement") -> np.ndarray:
        """|B g(f)|^2 W(f) (n_f, n_out): the response PSD of each output."""
        return np.abs(self.transfer(freqs, quantity) @ B.T) ** 2 * psd.at(freqs)[:, None]


def influence_vector(n_dof: int, axis: str) -> np.ndarray:
    """Unit rigid translation along ``axis`` of every node (6 DOFs per node)."""
    r = np.zeros(n_dof)
    r[AXES.index(axis)::6] = 1.0
    return r


def base_excitation(model, modes, K, M, zeta, axis: str = "z") -> BaseExcitation:
    """The :class:`BaseExcitation` of ``model`` (solved ``modes``, assembled ``K``, ``M``) with
    modal damping ratios ``zeta``, shaken along ``axis``. A free model has nothing to shake it:
    refused."""
    if axis not in AXES:
        raise VibrationError(f"--axis '{axis}' must be one of {', '.join(AXES)}")
    if model.free or modes.n_rigid:
        raise VibrationError("the model is free (no fixture holds it): a base excitation needs supports; declare "
                             "how the board is held in [[fixtures]] (wedge_lock, clamped_edge, hinged_edge, standoff)")
    zeta = np.asarray(zeta, dtype=float)
    r = influence_vector(M.shape[0], axis)
    Mr = M @ r
    gamma = modes.shapes.T @ Mr
    red = modes.reduction
    try:
        static = red.expand(factorize(red.reduce(K)).solve(red.T.T @ Mr))
    except SingularMatrixError as exc:
        raise ModelError(f"the stiffness matrix is singular: the supports do not hold the board ({exc})") from exc
    residual = static - modes.shapes @ (gamma / (2.0 * np.pi * modes.frequencies) ** 2)
    return BaseExcitation(axis, modes.frequencies.copy(), zeta, gamma, np.column_stack([modes.shapes, residual]), r,
                          float(r @ Mr))
