"""Model matching between measured DOFs and the model for shape and FRF equations (thesis ch. 2.2).

Measurements live on n_meas DOFs given by a matrix P (n_meas, n_dof) with u_meas = P u. Two ways
to put the model and the test on the same DOFs:

* reduce the model onto the measured DOFs (Guyan, or dynamic at one frequency) and keep the
  measured data as they are: :func:`reduce_system`;
* expand the measured shapes/FRFs to all model DOFs (dynamic expansion): :func:`expand`.

When P is a plain selection of DOFs, :mod:`pcbdyn.fe.reduction` does the work (masters = the
selected DOFs). For a general P (shape-function interpolation between nodes) the same
transformations are the constrained stationary points: u = Z^-1 P^T (P Z^-1 P^T)^-1 u_meas
minimises u^T Z u subject to P u = u_meas, which for a selection P is exactly Guyan (Z = K) or
the Kidder/dynamic map (Z = K - w^2 M).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from pcbdyn.fe import reduction as fe_reduction

from .sensitivity import as_dense


def selected_dofs(P) -> np.ndarray | None:
    """The DOF numbers picked by P when every row of P holds a single 1 (a selection), else None."""
    Pc = sp.csr_matrix(P)
    Pc.eliminate_zeros()
    if not np.all(np.diff(Pc.indptr) == 1) or not np.allclose(Pc.data, 1.0):
        return None
    cols = Pc.indices
    return cols if np.unique(cols).size == cols.size else None


def coupled_dofs(Z, P) -> np.ndarray:
    """The DOFs that ``Z``'s pattern couples, directly or through others, with the DOFs ``P`` reads: the
    only rows of a map u = T u_meas that are not zero (a flat plate measured along its normal leaves out
    its whole membrane block)."""
    pattern = abs(sp.csr_matrix(Z))
    pattern.eliminate_zeros()
    _, label = connected_components(pattern, directed=False)
    read = np.unique(sp.csr_matrix(P).nonzero()[1])
    return np.flatnonzero(np.isin(label, np.unique(label[read])))


def dynamic_basis(K, M, P, omega: float | None = None) -> tuple:
    """(dofs, T_d): T (:func:`transformation`) on the DOFs it does not leave at zero
    (:func:`coupled_dofs`); the rest of T is zero. Exact, and a smaller system to factorise."""
    P = sp.csr_matrix(P)
    if P.shape[1] != K.shape[0]:
        raise ValueError(f"P has shape {P.shape}; it must map the {K.shape[0]} model DOFs to measured DOFs")
    masters = selected_dofs(P)
    if masters is not None:
        T = (fe_reduction.guyan(K, M, masters) if omega is None else
             fe_reduction.dynamic_reduction(K, M, masters, omega))[0]
        return np.arange(K.shape[0]), T
    Z = sp.csr_matrix(K) if omega is None else sp.csr_matrix(K) - omega**2 * sp.csr_matrix(M)
    dofs = coupled_dofs(Z, P)
    Zd, Pd = Z[dofs][:, dofs], P[:, dofs]
    n, n_m = dofs.size, P.shape[0]
    kkt = sp.bmat([[Zd, Pd.T], [Pd, None]], format="csc")
    rhs = np.vstack([np.zeros((n, n_m)), np.eye(n_m)])
    return dofs, spla.splu(kkt).solve(rhs)[:n]


def transformation(K, M, P, omega: float | None = None) -> np.ndarray:
    """T (n_dof, n_meas) with u = T u_meas and P T = I: Guyan when ``omega`` is None, else the
    dynamic map at ``omega`` [rad/s]."""
    dofs, Td = dynamic_basis(K, M, P, omega)
    if dofs.size == K.shape[0]:
        return Td
    T = np.zeros((K.shape[0], Td.shape[1]))
    T[dofs] = Td
    return T


def reduce_system(K, M, dKs, dMs, P, omega: float | None = None):
    """(K_r, M_r, dK_r, dM_r) = T^T (.) T on the measured DOFs, T from :func:`transformation`
    (held fixed within an iteration: the derivatives are those of the reduced model with a
    frozen basis)."""
    T = transformation(K, M, P, omega)

    def red(A):
        return np.asarray(T.T @ (A @ T))

    return red(K), red(M), [red(d) for d in dKs], [red(d) for d in dMs]


def expand(K, M, P, u_meas, omegas) -> np.ndarray:
    """Measured vectors (n_meas, k) at angular frequencies ``omegas`` (one per column) expanded to
    all model DOFs by the dynamic map (thesis eq. 2.25)."""
    U = np.asarray(u_meas)
    U2 = U.reshape(U.shape[0], -1)
    w = np.broadcast_to(np.asarray(omegas, float), (U2.shape[1],))
    masters = selected_dofs(P)
    if masters is not None:
        out = np.column_stack([fe_reduction.dynamic_expansion(K, M, masters, U2[:, c], w[c]) for c in range(U2.shape[1])])
    else:
        out = np.column_stack([transformation(K, M, P, w[c]) @ U2[:, c] for c in range(U2.shape[1])])
    return out.reshape((K.shape[0],) + U.shape[1:])


def measured_rows(P, dof: int, tol: float = 1e-9) -> int:
    """Row r of P that reads model DOF ``dof`` alone (P[r] = e_dof^T within ``tol``): the driving
    point of an FRF. The force e_dof = P^T e_r then condenses onto the measured DOFs as e_r, for any
    T with P T = I."""
    Pc = sp.csr_matrix(P)
    for r in np.flatnonzero(as_dense(Pc[:, dof]).ravel()):
        row = as_dense(Pc[r]).ravel()
        row[dof] -= 1.0
        if np.max(np.abs(row)) <= tol:
            return int(r)
    raise ValueError(f"excitation DOF {dof} must be measured directly (a row of P reading it alone: "
                     "a driving-point FRF at a mesh node)")
