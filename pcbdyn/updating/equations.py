"""Sensitivity-based updating equations A x = b on plain matrices (thesis chapter 3, appendix A).

Every builder returns a :class:`Block` (A, b). With ``p`` given (the current parameter values),
the unknowns are relative design variables x_j = dp_j / p_j: column j of A is multiplied by p_j
(column weighting, thesis eq. 4.41). With ``p=None`` the unknowns are the absolute changes dp_j.

Shapes and FRFs are given on the DOFs of the matrices passed in: either reduce the model onto
the measured DOFs or expand the measurements first (:mod:`.matching`). Complex equations are
split into real rows followed by imaginary rows.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .sensitivity import as_dense, frequencies_hz, frequency_derivatives


class Block(NamedTuple):
    """One set of updating equations A x = b."""

    A: np.ndarray
    b: np.ndarray


def _columns(A, p):
    if p is None:
        return A
    p = np.asarray(p, float)
    if p.shape != (A.shape[1],):
        raise ValueError(f"p has shape {p.shape}, expected ({A.shape[1]},): one value per parameter")
    return A * p[None, :]


def _split(A, b):
    """Complex rows -> [real rows; imaginary rows]; real input is returned unchanged."""
    if np.iscomplexobj(A) or np.iscomplexobj(b):
        return np.vstack([A.real, A.imag]), np.concatenate([np.real(b), np.imag(b)])
    return np.asarray(A, float), np.asarray(b, float)


def frequency_equations(lam, Phi, f_x, dKs, dMs, p=None, relative_rows: bool = False) -> Block:
    """Resonance-frequency equations (thesis eqs. 3.2-3.3): sum_j df_ai/dp_j dp_j = f_xi - f_ai.

    ``lam``/``Phi`` are the paired analytical eigenpairs (same order as ``f_x`` [Hz]). With
    ``relative_rows`` each row is divided by f_xi, so that b holds relative frequency errors and
    every mode weighs the same.
    """
    f_x = np.asarray(f_x, float)
    if f_x.size != np.size(lam):
        raise ValueError(f"f_x has {f_x.size} frequencies but {np.size(lam)} analytical modes are paired")
    A = _columns(frequency_derivatives(lam, Phi, dKs, dMs), p)
    b = f_x - frequencies_hz(lam)
    if relative_rows:
        A, b = A / f_x[:, None], b / f_x
    return Block(A, b)


def _shapes(phi_x, omega_x, n):
    phi_x = np.asarray(phi_x)
    if phi_x.ndim == 1:
        phi_x = phi_x[:, None]
    omega_x = np.atleast_1d(np.asarray(omega_x, float))
    if phi_x.shape[0] != n or phi_x.shape[1] != omega_x.size:
        raise ValueError(
            f"phi_x has shape {phi_x.shape}; expected ({n}, {omega_x.size}): one column per measured "
            "mode on the model's DOFs (reduce the model or expand the shapes first)"
        )
    return phi_x, omega_x


def fbm_equations(K, M, omega_x, phi_x, dKs, dMs, p=None) -> Block:
    """Force-balance equations (thesis eq. 3.23), one block of rows per measured mode:
    sum_j (dK_j - w_x^2 dM_j) phi_x dp_j = -(K - w_x^2 M) phi_x. ``omega_x`` in rad/s."""
    phi_x, omega_x = _shapes(phi_x, omega_x, K.shape[0])
    A, b = [], []
    for w2, phi in zip(omega_x**2, phi_x.T):
        A.append(np.column_stack([dK @ phi - w2 * (dM @ phi) for dK, dM in zip(dKs, dMs)]))
        b.append(-(K @ phi - w2 * (M @ phi)))
    A, b = _split(np.vstack(A), np.concatenate(b))
    return Block(_columns(A, p), b)


def qms_equations(K, M, omega_x, phi_x, dKs, dMs, p=None, n_exclude: int = 1) -> Block:
    """Quasi-modeshape equations (thesis eqs. 3.24-3.26): the force-balance rows of each mode
    pre-multiplied by the pseudo-inverse of Z = K - w_x^2 M in which the ``n_exclude`` smallest
    singular values (near-singular at the test frequency; one per repeated mode) are dropped.

    Z is symmetric, so its singular vectors come from a dense eigen-decomposition; intended for
    reduced (measured-DOF) models. Right side: -V1 V1^T phi_x, the quasi-modeshape.
    """
    phi_x, omega_x = _shapes(phi_x, omega_x, K.shape[0])
    Kd, Md = as_dense(K), as_dense(M)
    n = Kd.shape[0]
    if not 0 <= n_exclude < n:
        raise ValueError(f"n_exclude={n_exclude} must be in [0, {n - 1}]")
    A, b = [], []
    for w2, phi in zip(omega_x**2, phi_x.T):
        ev, Q = np.linalg.eigh(Kd - w2 * Md)
        keep = np.argsort(np.abs(ev))[n_exclude:]
        V1, s1 = Q[:, keep], ev[keep]
        F = np.column_stack([dK @ phi - w2 * (dM @ phi) for dK, dM in zip(dKs, dMs)])
        A.append(V1 @ ((V1.T @ F) / s1[:, None]))
        b.append(-V1 @ (V1.T @ phi))
    A, b = _split(np.vstack(A), np.concatenate(b))
    return Block(_columns(A, p), b)


def dynamic_stiffness(K, M, omega: float, C=None, D=None):
    """Z(w) = K + i(w C + D) - w^2 M (thesis eq. 3.28); real when C and D are None."""
    Z = K - omega**2 * M
    if C is not None or D is not None:
        Z = Z + 1j * ((omega * C if C is not None else 0) + (D if D is not None else 0))
    return Z


def _frf_data(H_x, omegas, n):
    H_x = np.asarray(H_x)
    omegas = np.atleast_1d(np.asarray(omegas, float))
    if H_x.ndim == 1:
        H_x = H_x[:, None]
    if H_x.shape != (n, omegas.size):
        raise ValueError(
            f"H_x has shape {H_x.shape}; expected ({n}, {omegas.size}): the response at every model "
            "DOF (one column per updating frequency) for one excitation DOF"
        )
    return H_x, omegas


DAMPING_TREATMENTS = ("undamped", "proportional", "diagonal", "light")


def frf_excitation_equations(
    K, M, omegas, H_x, j: int, dKs, dMs, p=None, damping: str = "undamped", C=None, D=None
) -> Block:
    """Excitation-residual equations (thesis eq. 3.34) with the damping treatments of appendix A:
    sum_l dZ_l h_x dp_l = e_j - Z h_x at each updating frequency (``omegas`` rad/s).

    ``H_x`` (n_dof, n_freq): measured receptances at every model DOF for a unit force at DOF ``j``.
    ``damping``: "undamped" (A.3-A.6, Z real, rows split Re/Im), "proportional" (A.14-A.19: the
    terms i w alpha M h and i (w beta + eta) K h are fitted per frequency and removed from b),
    "diagonal" (A.7-A.13: rows weighted by conj(h)/|h| and only the real part kept, which removes
    any diagonal imaginary dynamic stiffness), "light" (A.23-A.26: rows multiplied by conj(h_t),
    t the DOF whose column of Im(h h^H) is smallest, and only the real part kept). Damping known
    in the model enters through C (viscous) and D (structural) in Z (eq. 3.28).
    """
    if damping not in DAMPING_TREATMENTS:
        raise ValueError(f"damping={damping!r}; choose one of {DAMPING_TREATMENTS}")
    n = K.shape[0]
    H_x, omegas = _frf_data(H_x, omegas, n)
    A_rows, b_rows = [], []
    for w, h in zip(omegas, H_x.T):
        A, b = _excitation_rows(dynamic_stiffness(K, M, w, C, D), K, M, w, h, j, dKs, dMs, damping)
        A_rows.append(A)
        b_rows.append(b)
    A, b = _split(np.vstack(A_rows), np.concatenate(b_rows))
    return Block(_columns(A, p), b)


def _excitation_rows(Z, K, M, w, h, j, dKs, dMs, damping):
    """Rows of eq. 3.34 at one frequency (Z = model dynamic stiffness) after the damping
    treatment of the unknown damping in the data (appendix A)."""
    A = np.column_stack([dK @ h - w**2 * (dM @ h) for dK, dM in zip(dKs, dMs)])
    b = -(Z @ h)
    b[j] += 1.0
    if damping == "proportional":
        G = np.column_stack([1j * (M @ h), 1j * (K @ h)])
        c = np.linalg.lstsq(np.vstack([G.real, G.imag]), np.concatenate([b.real, b.imag]), rcond=None)[0]
        b = b - G @ c
    elif damping == "diagonal":
        Wd = np.conj(h) / np.where(np.abs(h) > 0, np.abs(h), 1.0)
        A, b = (Wd[:, None] * A).real, (Wd * b).real
    elif damping == "light":
        P = np.outer(h.imag, h.real) - np.outer(h.real, h.imag)
        t = int(np.argmin(np.linalg.norm(P, axis=0)))
        A, b = (np.conj(h[t]) * A).real, (np.conj(h[t]) * b).real
    return A, b


def _factor(Z):
    """Complex LU of Z (dense or sparse); returns a solve(rhs) function."""
    if sp.issparse(Z):
        return spla.splu(sp.csc_matrix(Z, dtype=complex)).solve
    lu = sla.lu_factor(np.asarray(Z, dtype=complex))
    return lambda rhs: sla.lu_solve(lu, rhs)


def frf_receptance_equations(
    K, M, omegas, H_x, j: int, dKs, dMs, p=None, variant: str = "indirect", P=None, C=None, D=None,
    damping: str = "undamped",
) -> Block:
    """Receptance-residual equations: sum_l H_a dZ_l h dp_l = h_aj - h_xj at each updating
    frequency, with h = h_x ("indirect", thesis eq. 3.35) or h = h_aj ("direct", eq. 3.40).

    ``j``: excited DOF of the model. ``P`` (n_meas, n_dof), optional: keeps only the measured
    responses P h (rows), so the direct form needs the measurements only at measured DOFs;
    ``H_x`` is then (n_meas, n_freq) for "direct" and (n_dof, n_freq) (expanded) for "indirect".
    Known damping enters through C (viscous) and D (structural) in Z (eq. 3.28); with the
    parameters not acting on damping (eq. A.1) dZ_l = dK_l - w^2 dM_l. Unknown damping in the
    data: ``damping="proportional"`` (indirect only) fits and removes the proportional terms from
    the excitation residual first (eqs. A.14-A.18) and then applies H_a (eq. 3.35 = H_a x 3.34).
    """
    if damping not in ("undamped", "proportional") or (damping == "proportional" and variant != "indirect"):
        raise ValueError(
            f"damping={damping!r} with variant={variant!r}: the receptance equations take 'undamped' "
            "(damping known through C, D) or 'proportional' with the indirect variant"
        )
    if variant not in ("indirect", "direct"):
        raise ValueError(f"variant={variant!r}; choose 'indirect' (eq. 3.35) or 'direct' (eq. 3.40)")
    n = K.shape[0]
    omegas = np.atleast_1d(np.asarray(omegas, float))
    n_rows = n if P is None else P.shape[0]
    if P is not None and P.shape[1] != n:
        raise ValueError(f"P has shape {P.shape}; it must map the {n} model DOFs to measured DOFs")
    H_x = np.asarray(H_x)
    H_x = H_x[:, None] if H_x.ndim == 1 else H_x
    need = (n if variant == "indirect" else n_rows, omegas.size)
    if H_x.shape != need:
        raise ValueError(f"H_x has shape {H_x.shape}; expected {need} for the {variant} receptance equations")
    Pd = None if P is None else as_dense(P)
    A_rows, b_rows = [], []
    for k, w in enumerate(omegas):
        Z = dynamic_stiffness(K, M, w, C, D)
        solve = _factor(Z)
        e = np.zeros(n, dtype=complex)
        e[j] = 1.0
        h_a = solve(e)
        h = H_x[:, k] if variant == "indirect" else h_a
        if damping == "proportional":
            F, r = _excitation_rows(Z, K, M, w, h, j, dKs, dMs, damping)
        else:
            F = np.column_stack([dK @ h - w**2 * (dM @ h) for dK, dM in zip(dKs, dMs)])
        if P is None:
            A_rows.append(solve(F.astype(complex)))
            h_a_rows = h_a
        else:
            X = solve(Pd.T.astype(complex))  # Z symmetric: P H_a = (H_a P^T)^T
            A_rows.append(X.T @ F)
            h_a_rows = Pd @ h_a
        if damping == "proportional":
            b_rows.append(solve(r.astype(complex)) if P is None else X.T @ r)
            continue
        h_x_rows = H_x[:, k] if (variant == "direct" or P is None) else Pd @ H_x[:, k]
        b_rows.append(h_a_rows - h_x_rows)
    A, b = _split(np.vstack(A_rows), np.concatenate(b_rows))
    return Block(_columns(A, p), b)
