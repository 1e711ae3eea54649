"""Shape correlation coefficients: MAC, AutoMAC (thesis eq. 2.3) and COMAC (eq. 2.4)."""

from __future__ import annotations

import numpy as np


def _cols(a, name):
    a = np.asarray(a)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2:
        raise ValueError(f"{name} must be a vector or a matrix of column shapes (n_dof, n_modes)")
    return a


def _unit_scale(a) -> np.ndarray:
    """Columns divided by their largest magnitude (the MAC does not change, and no square of a large or
    small shape value over- or underflows)."""
    big = np.max(np.abs(a), axis=0) if a.size else np.ones(a.shape[1])
    return a / np.where(big > 0, big, 1.0)


def mac(phi_x, phi_a) -> np.ndarray:
    """The modal assurance criterion of every pair of columns (thesis eq. 2.3).

    MAC_ij = |phi_x,i^H phi_a,j|^2 / ((phi_x,i^H phi_x,i)(phi_a,j^H phi_a,j)): 1 for shapes that
    differ by a factor only, 0 for orthogonal ones. The one MAC of pcbdyn: pairing, updating and
    diagnosis call it.

    Parameters
    ----------
    phi_x, phi_a : array_like, (n_dof,) or (n_dof, n_modes)
        Shapes as columns at the same DOFs (rows), real or complex, in any scaling. A zero shape
        gives 0.

    Returns
    -------
    numpy.ndarray, (n_x, n_a)

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[1.0, 0.0], [2.0, 1.0], [1.0, 0.0]])
    >>> print(mac(x, -3 * x).round(3))
    [[1.    0.667]
     [0.667 1.   ]]
    """
    X, A = _unit_scale(_cols(phi_x, "phi_x")), _unit_scale(_cols(phi_a, "phi_a"))
    if X.shape[0] != A.shape[0]:
        raise ValueError(f"shapes have {X.shape[0]} and {A.shape[0]} DOFs: read both at the same DOFs")
    num = np.abs(X.conj().T @ A) ** 2
    den = np.outer(np.sum(np.abs(X) ** 2, axis=0), np.sum(np.abs(A) ** 2, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)


def paired_mac(phi_x, phi_a) -> np.ndarray:
    """MAC of column i of ``phi_x`` with column i of ``phi_a``: the MAC of paired modes."""
    return np.diagonal(mac(phi_x, phi_a)).copy()


def automac(phi) -> np.ndarray:
    """MAC of a set with itself: off-diagonal terms show how distinguishable the modes are at these DOFs
    (spatial aliasing when a sensor set is too sparse)."""
    return mac(phi, phi)


def comac(phi_x, phi_a, normalize: bool = True) -> np.ndarray:
    """COMAC per DOF over paired modes (columns aligned): (sum_j |x_ij a_ij|)^2 / (sum_j x_ij^2 sum_j a_ij^2)
    (thesis eq. 2.4). A low value marks a DOF where test and model disagree across modes.

    COMAC depends on how each mode is scaled; with ``normalize`` every column of both sets is first
    scaled to unit length, so an arbitrary test scaling does not change the result.
    """
    X, A = _cols(phi_x, "phi_x"), _cols(phi_a, "phi_a")
    if X.shape != A.shape:
        raise ValueError(f"paired shape sets must have the same shape, got {X.shape} and {A.shape}")
    if normalize:
        X = X / np.linalg.norm(X, axis=0)
        A = A / np.linalg.norm(A, axis=0)
    num = np.sum(np.abs(X * A.conj()), axis=1) ** 2
    den = np.sum(np.abs(X) ** 2, axis=1) * np.sum(np.abs(A) ** 2, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
