"""Craig-Bampton reduction of parts of a model to their interface (component mode synthesis).

On the constrained system (:func:`.modal.reduced_system`), each part's unknowns I (its independent DOFs)
are replaced by the static constraint modes Psi = -K_II^-1 K_IC of the DOFs C outside it that it couples
to, plus its first k fixed-interface modes Phi (K_II Phi = M_II Phi Lambda, Phi^T M_II Phi = I):

    x_I = Psi x_C + Phi q,

and every other DOF B stays as it is. The reduced matrices are the projections (a Rayleigh-Ritz: every
frequency is an upper bound of the full model's):

    K^ = [[K_BB + K_CI Psi (on C x C), 0], [0, Lambda]],
    M^ = [[M_BB + M_CI Psi + Psi^T M_IC + Psi^T M_II Psi (on C x C), (M_CI + Psi^T M_II) Phi], [sym, I]].

The modes of (K^, M^) expand to full-length shapes through x_I. Psi is dense (n_I x n_C: the interface
of a card held along two edges is a few hundred DOFs, so Psi of a 80k-DOF card takes hundreds of MB): it
lives only while its part's blocks are formed; a part keeps the factor of K_II and K_IC, and the
expansion solves for Psi x_C.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .constraints import build_reduction
from .linsolve import factorize
from .modal import Modes, eigenpairs, select_modes
from .model import ModelError


@dataclass
class Part:
    """One reduced part: positions ``I`` of its unknowns and ``C`` of the outside ones it couples to
    (in the constrained system), the factor of K_II, K_IC (sparse), Phi (n_I, k) and its fixed-interface
    eigenvalues."""

    I: np.ndarray
    C: np.ndarray
    factor: object
    KIC: sp.csr_matrix
    phi: np.ndarray
    lam: np.ndarray

    def interior(self, xC: np.ndarray, q: np.ndarray) -> np.ndarray:
        """x_I = Psi x_C + Phi q."""
        return -self.factor.solve(np.asarray(self.KIC @ xC)) + self.phi @ q


@dataclass
class CraigBampton:
    """The reduced system: constraint reduction ``red`` of the full model, the kept positions ``B``, the
    ``parts`` and the reduced matrices ``K``, ``M`` (coordinates: x_B, then each part's q)."""

    red: object
    B: np.ndarray
    parts: list
    K: sp.csr_matrix
    M: sp.csr_matrix

    def expand(self, z: np.ndarray) -> np.ndarray:
        """Full-length vectors (n_dof, m) of reduced ones (n_reduced, m)."""
        z = np.atleast_2d(z.T).T
        x = np.zeros((self.red.independent.size, z.shape[1]))
        x[self.B] = z[:self.B.size]
        pos_in_B = np.full(self.red.independent.size, -1)
        pos_in_B[self.B] = np.arange(self.B.size)
        start = self.B.size
        for p in self.parts:
            k = p.phi.shape[1]
            x[p.I] = p.interior(z[pos_in_B[p.C]], z[start:start + k])
            start += k
        return self.red.expand(x)


#: columns of the constraint modes formed at a time (bounds the temporaries beside Psi)
CHUNK = 64


def _coupling(factor, MII, KIC, MIC, phi) -> tuple:
    """(K_CI Psi, M_CI Psi + Psi^T M_IC + Psi^T M_II Psi, Phi^T (M_IC + M_II Psi)) of one part, with
    Psi = -K_II^-1 K_IC solved and G = M_IC + M_II Psi formed :data:`CHUNK` columns at a time: only Psi
    is held whole."""
    nc = KIC.shape[1]
    psi = np.empty((KIC.shape[0], nc))
    for a in range(0, nc, CHUNK):
        psi[:, a:a + CHUNK] = -factor.solve(KIC[:, a:a + CHUNK].toarray())
    dK, dM, Mq = np.empty((nc, nc)), np.empty((nc, nc)), np.empty((phi.shape[1], nc))
    for a in range(0, nc, CHUNK):
        cols = slice(a, min(a + CHUNK, nc))
        G = MIC[:, cols].toarray() + MII @ psi[:, cols]
        dK[:, cols] = KIC.T @ psi[:, cols]
        dM[:, cols] = MIC.T @ psi[:, cols] + psi.T @ G
        Mq[:, cols] = phi.T @ G
    return dK, dM, Mq


def craig_bampton(model, K, M, parts) -> CraigBampton:
    """The reduction of ``model`` (assembled ``K``, ``M``) whose ``parts`` [(global DOFs, k modes)] are
    each replaced by their constraint modes and first k fixed-interface modes."""
    red = build_reduction(model, K, M)
    Kr, Mr = red.reduce(K).tocsr(), red.reduce(M).tocsr()
    n = Kr.shape[0]
    owner = np.full(n, -1)
    sets = []
    for i, (dofs, _) in enumerate(parts):
        pos = np.searchsorted(red.independent, np.asarray(dofs))
        pos = pos[(pos < n) & (red.independent[np.minimum(pos, n - 1)] == np.asarray(dofs))]
        owner[pos] = i
        sets.append(pos)
    B = np.flatnonzero(owner < 0)
    Kb, Mb = Kr[B][:, B].tocoo(), Mr[B][:, B].tocoo()
    K_ent, M_ent = [(Kb.row, Kb.col, Kb.data)], [(Mb.row, Mb.col, Mb.data)]
    done, start = [], B.size
    for I, (_, k) in zip(sets, parts):
        KI, MI = Kr[I], Mr[I]
        KII, MII = KI[:, I].tocsc(), MI[:, I].tocsc()
        KIB, MIB = KI[:, B], MI[:, B]
        cpos = np.unique(np.concatenate([KIB.tocoo().col, MIB.tocoo().col]))
        C = B[cpos]
        KIC, MIC = KIB[:, cpos].tocsc(), MIB[:, cpos].tocsc()
        factor = factorize(KII, spd=True)
        lam, phi, rigid = eigenpairs(KII, MII, n_modes=min(int(k), I.size - 1))
        if rigid.any():
            raise ModelError("a reduced part floats with its interface held: it must couple to the rest by stiffness")
        order = np.argsort(lam)
        lam, phi = lam[order], phi[:, order]
        kk = lam.size
        dK, dM, Mq = _coupling(factor, MII, KIC, MIC, phi)
        cc_r, cc_c = np.meshgrid(cpos, cpos, indexing="ij")
        K_ent.append((cc_r.ravel(), cc_c.ravel(), dK.ravel()))
        M_ent.append((cc_r.ravel(), cc_c.ravel(), dM.ravel()))
        q = start + np.arange(kk)
        K_ent.append((q, q, lam))
        M_ent.append((q, q, np.ones(kk)))
        qr, qc = np.meshgrid(q, cpos, indexing="ij")
        M_ent += [(qr.ravel(), qc.ravel(), Mq.ravel()), (qc.ravel(), qr.ravel(), Mq.ravel())]
        done.append(Part(I, C, factor, KIC.tocsr(), phi, lam))
        start += kk

    def matrix(entries):
        r, c, v = (np.concatenate(x) for x in zip(*entries))
        return sp.csr_matrix((v, (r, c)), shape=(start, start))

    return CraigBampton(red, B, done, matrix(K_ent), matrix(M_ent))


def solve_reduced(cb: CraigBampton, n_modes: int | None = None, f_max: float | None = None,
                  free: bool = False) -> Modes:
    """The first modes of the reduced system, as :class:`.modal.Modes` with full-length shapes."""
    lam, vec, rigid = eigenpairs(cb.K, cb.M, n_modes, f_max, free)
    return select_modes(lam, vec, rigid, cb.red, cb.expand, n_modes, f_max, free)
