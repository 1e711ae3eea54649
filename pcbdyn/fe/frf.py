"""Frequency response functions H(omega) between full-model DOFs: x_i = H_ij f_j.

Two routes:

* :func:`frf_modal` sums mass-normalised modes (rigid-body modes of a free model included),
  each with its own damping; :func:`residual_flexibility` supplies the optional upper residual
  (the static compliance of the modes left out).
* :func:`frf_direct` solves the dynamic stiffness Z(omega) = K + i(omega C + D) - omega^2 M
  (thesis eq. 3.27-3.29) on the constrained system at each frequency, with viscous proportional
  damping C = alpha M + beta K and structural damping D = eta K.

With the same proportional/structural damping and all modes, both routes agree to round-off.
Frequencies are in Hz; results are complex arrays of shape (n_freq, n_response, n_excitation),
as receptance [m/N], mobility [m/s/N] or accelerance [m/s^2/N].
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .linsolve import SingularMatrixError, factorize
from .modal import Modes, reduced_system
from .model import ModelError

KINDS = ("receptance", "mobility", "accelerance")


def _omega(freqs) -> np.ndarray:
    f = np.atleast_1d(np.asarray(freqs, dtype=float))
    if f.ndim != 1 or np.any(f < 0) or not np.all(np.isfinite(f)):
        raise ValueError("freqs must be a 1-D array of non-negative frequencies in Hz")
    return 2.0 * np.pi * f


def _dofs(dofs, n_dof: int, name: str) -> np.ndarray:
    d = np.atleast_1d(np.asarray(dofs, dtype=np.int64)).ravel()
    if d.size == 0 or d.min() < 0 or d.max() >= n_dof:
        raise ValueError(f"{name} must be global DOF numbers in 0..{n_dof - 1} (6 * node + dof)")
    return d


def _convert(H: np.ndarray, w: np.ndarray, kind: str) -> np.ndarray:
    """Receptance to mobility (i omega H) or accelerance (-omega^2 H)."""
    if kind == "receptance":
        return H
    if kind == "mobility":
        return (1j * w)[:, None, None] * H
    if kind == "accelerance":
        return (-(w**2))[:, None, None] * H
    raise ValueError(f"kind must be one of {', '.join(KINDS)}, got '{kind}'")


def _per_mode(value, n: int, name: str) -> np.ndarray:
    v = np.asarray(0.0 if value is None else value, dtype=float)
    if v.ndim == 0:
        return np.full(n, float(v))
    if v.shape != (n,):
        raise ValueError(f"{name} must be a scalar or one value per elastic mode ({n}), got shape {v.shape}")
    return v


def frf_modal(
    modes: Modes,
    freqs,
    response_dofs,
    excitation_dofs,
    *,
    zeta=None,
    eta=None,
    alpha: float = 0.0,
    beta: float = 0.0,
    residual=None,
    kind: str = "receptance",
) -> np.ndarray:
    """H(omega) by modal superposition: sum_r phi_ir phi_jr / (w_r^2 - w^2 + i w (2 zeta_r w_r + alpha
    + beta w_r^2) + i eta_r w_r^2).

    ``zeta``: modal viscous damping ratios (scalar or one per elastic mode); ``eta``: structural loss
    factors (scalar or per mode; D = eta K gives exactly eta_r = eta); ``alpha``, ``beta``: Rayleigh
    damping C = alpha M + beta K (exactly modal for mass-normalised modes). Rigid-body modes
    contribute 1 / (-w^2 + i w alpha) (at 0 Hz its limit, :func:`_rigid`). ``residual``: an (n_response, n_excitation) real compliance
    added at every frequency, typically :func:`residual_flexibility` for the truncated modes (divided
    by 1 + i eta when ``eta`` is a scalar, as the structural damping acts on those modes too).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got '{kind}'")
    w = _omega(freqs)
    n_full = modes.shapes.shape[0]
    i = _dofs(response_dofs, n_full, "response_dofs")
    j = _dofs(excitation_dofs, n_full, "excitation_dofs")
    wr2 = modes.omega2
    wr = np.sqrt(wr2)
    z = _per_mode(zeta, wr.size, "zeta")
    e = _per_mode(eta, wr.size, "eta")
    ww = w[:, None]
    den = wr2 - ww**2 + 1j * ww * (2.0 * z * wr + alpha + beta * wr2) + 1j * e * wr2
    H = np.einsum("im,fm,jm->fij", modes.shapes[i], 1.0 / den, modes.shapes[j])
    if residual is not None:
        R = np.asarray(residual)
        if R.shape != (i.size, j.size):
            raise ValueError(f"residual must have shape (n_response, n_excitation) = {(i.size, j.size)}, got {R.shape}")
        eta_all = float(eta) if eta is not None and np.ndim(eta) == 0 else 0.0
        H = H + R[None] / (1.0 + 1j * eta_all)  # the missing modes' static response with D = eta K
    H = _convert(H, w, kind)
    if modes.n_rigid:
        H = H + np.einsum("im,f,jm->fij", modes.rigid_shapes[i], _rigid(w, alpha, kind), modes.rigid_shapes[j])
    return H


def _rigid(w: np.ndarray, alpha: float, kind: str) -> np.ndarray:
    """A rigid-body mode's factor 1 / (-w^2 + i w alpha), as ``kind``, written so that 0 Hz gives its limit:
    a free body's accelerance there is 1 undamped (0 with alpha > 0), not 0 * inf; its receptance (and its
    undamped mobility) is infinite there."""
    d = -w + 1j * alpha
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "receptance":
            return np.where(w > 0, 1.0 / (w * d), np.inf)
        if kind == "mobility":
            return np.where(d != 0, 1j / np.where(d != 0, d, 1.0), np.inf)
        return np.where(w > 0, -w / np.where(w > 0, d, 1.0), 0.0 if alpha else 1.0)


def residual_flexibility(model, modes: Modes, response_dofs, excitation_dofs, K=None, M=None) -> np.ndarray:
    """Upper residual: the static compliance of the elastic modes not in ``modes``, (n_resp, n_exc).

    Constrained model: R = [K^-1]_ij - sum_r phi_ir phi_jr / w_r^2 (static flexibility minus its modal
    part). Free model: K is singular, so the load is first cleared of its rigid-body part
    (inertia relief, f - M Phi_R Phi_R^T f) and K is shifted by a tiny -sigma M; R is then the sum of
    the missing modes' phi phi^T / (w_r^2 - sigma), i.e. their static compliance to within
    sigma / w_r^2 ~ 1e-9.
    """
    red, Kr, Mr = reduced_system(model, K, M)
    n_full = red.T.shape[0]
    i = _dofs(response_dofs, n_full, "response_dofs")
    j = _dofs(excitation_dofs, n_full, "excitation_dofs")
    T = sp.csr_matrix(red.T)
    F = T[j].T.toarray()  # reduced loads of unit forces at the excitation DOFs
    sigma = 0.0
    if modes.n_rigid:
        dk, dm = Kr.diagonal(), Mr.diagonal()
        both = (dk > 0) & (dm > 0)
        sigma = -1e-9 * float(np.median(dk[both] / dm[both]))
        rig = modes.rigid_shapes[red.independent]  # T's rows at independent DOFs are identity rows
        F = F - Mr @ (rig @ (rig.T @ F))
    try:
        X = factorize(Kr - sigma * Mr).solve(F)
    except SingularMatrixError as exc:
        raise ModelError("the stiffness matrix is singular: the model needs supports, or model.free = True") from exc
    static = (T[i] @ X).reshape(i.size, j.size)
    modal = (modes.shapes[i] / (modes.omega2 - sigma)) @ modes.shapes[j].T
    return static - modal


def frf_direct(
    model,
    freqs,
    response_dofs,
    excitation_dofs,
    *,
    alpha: float = 0.0,
    beta: float = 0.0,
    eta: float = 0.0,
    kind: str = "receptance",
    K=None,
    M=None,
) -> np.ndarray:
    """H(omega) by solving Z(omega) h_j = e_j on the constrained system (thesis eq. 3.27-3.29), with
    C = alpha M + beta K and D = eta K. One sparse LU per frequency, all excitations at once.

    A force at a fixed DOF goes straight into the support (its column is zero), and the response at
    a fixed DOF is zero.
    """
    w = _omega(freqs)
    red, Kr, Mr = reduced_system(model, K, M)
    n_full = red.T.shape[0]
    i = _dofs(response_dofs, n_full, "response_dofs")
    j = _dofs(excitation_dofs, n_full, "excitation_dofs")
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got '{kind}'")
    T = sp.csr_matrix(red.T)
    F = T[j].T.toarray()
    Ti = T[i]
    H = np.empty((w.size, i.size, j.size), dtype=complex)
    for n, wn in enumerate(w):
        Z = (1.0 + 1j * (wn * beta + eta)) * Kr + (1j * wn * alpha - wn**2) * Mr
        try:
            X = factorize(Z, spd=False).solve(F)
        except SingularMatrixError as exc:
            raise ModelError(
                f"the dynamic stiffness is singular at {wn / (2 * np.pi):.6g} Hz (an undamped resonance, "
                "or 0 Hz on a free model): add damping or move the frequency"
            ) from exc
        H[n] = Ti @ X
    return _convert(H, w, kind)
