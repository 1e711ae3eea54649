"""A support the model lacks, shown by a measured mode of rigid-body shape (issue 26: a bracket on a
spring to the frame). A free model has its rigid-body modes at 0 Hz; a test mode whose shape at the
points is mostly a rigid-body motion of the model, and which no elastic mode resembles, is the
structure moving on something that holds it. Such a mode is the strongest evidence of a spring to
ground, yet the pairing leaves it out (no elastic partner), and without it what is left of a
bracket on the elastic modes is too small to be told from its mass alone.

A lone spring of stiffness k along n at a point a changes the modes' pencil by k w w^T, w = Phi^T n_a
(thesis eq. 3.11 with k = i for the eigenvalue derivative). In the basis of the model's modes
[rigid, elastic] every mode of the supported model has its rigid part along w_r, the rigid rows of
w (a mass at the same point keeps it so): the measured mode's rigid part at the points places the
spring, on a board at the point itself, between nodes (a rigid-body deflection is affine in x, y,
so the best match is a linear least-squares fit, the mode's elastic part fitted with it). Its
stiffness is the one that puts the Rayleigh-Ritz mode most like the measured one (MAC at the
points) at the measured frequency. Both are the start of the search, which then fits the spring
with the declared parameters and whatever else the data show (and may walk it, :class:`LocalMoves`
of :mod:`.pipeline`).

A held model (on standoffs, in guides) has no rigid-body modes; a point support it lacks (an undeclared
standoff) holds the board where its lowest modes move most, so those test modes find no partner at
all. There any mode without a partner is tried: the spring is placed where one that holds its point
makes a Rayleigh-Ritz mode of the model's modes most like the measured one, then sized as above, and
kept only if the mode then pairs.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh

from ..correlation.mac import mac
from ..fe.mesh import DOF_NAMES, NDOF
from .catalogue import effect_forms
from .ground_spring import KIND as SPRING
from .select import orth

#: a test mode without a model partner is a support's when at least this share of its shape at
#: the points lies in the span of the model's rigid-body modes there (a bracket's bounce: 0.99 on
#: pcbdyn's own data, 0.65 on OpenSees', where the spring is stiff enough to bend the card; the
#: elastic modes of the bench's cases: below 0.15)
RIGID_SHARE_MIN = 0.5
#: on a held model, a spring is placed where one of stiffness STIFF * lambda / |w|^2 (w: its row in
#: the modal basis; lambda: the measured mode's eigenvalue) makes a mode most like the measured one: a
#: spring that holds its point, as a standoff does
STIFF = 100.0


def rigid_share(ob, cs) -> np.ndarray:
    """Per measured mode of observation ``ob``, the share of its shape at the points that lies in
    the span of the rigid-body modes of the state ``cs`` there (zeros without shapes or rigid modes)."""
    nr = cs.modes.n_rigid
    if ob.shapes is None or nr == 0:
        return np.zeros(ob.f.size)
    Q = orth(cs.at_points(ob.read)[:, :nr])
    x = ob.shapes
    return np.sum((Q.T @ x) ** 2, axis=0) / np.sum(x**2, axis=0)


def support_modes(ob, cs) -> np.ndarray:
    """Mask of the measured modes of ``ob`` that may show a support: no elastic partner in the state
    ``cs`` and, where the model has rigid-body modes, a rigid-body shape (:data:`RIGID_SHARE_MIN`); on
    a held model any mode without a partner (a standoff left out of the model holds the board where
    its first modes move most, and they find no partner)."""
    if cs.modes.n_rigid == 0:
        return ~cs.matched
    return ~cs.matched & (rigid_share(ob, cs) >= RIGID_SHARE_MIN)


def locate(ob, cs, i: int, springs: list, layout) -> tuple:
    """(spring candidate, stiffness [N/m], Ritz MAC): the spring to ground that explains measured mode ``i``
    of ``ob`` in the state ``cs`` (module doc): the node of ``springs`` (``ground_spring``
    candidates on the state's mesh, ``layout``) whose rigid-body part best matches the mode's; on a
    board, the point itself (:func:`_between_nodes`). On a held model (no rigid-body modes), the node
    where a spring that holds it (:data:`STIFF`) makes a Rayleigh-Ritz mode most like the measured one.
    The Ritz MAC: of that mode with the spring found."""
    nr = cs.modes.n_rigid
    phi = np.column_stack([cs.modes.rigid_shapes, cs.modes.shapes])
    points = cs.at_points(ob.read)
    x = ob.shapes[:, i : i + 1]
    W = _rows(cs.model, phi, springs)
    lam = np.r_[np.zeros(nr), cs.modes.omega2]
    target = (2.0 * np.pi * ob.f[i]) ** 2
    if nr:
        best = springs[int(np.argmax(mac(points[:, :nr] @ W[:, :nr].T, x)[:, 0]))]
        if layout.planar:
            best = _between_nodes(layout, cs.modes.rigid_shapes, points, nr, x) or best
    else:
        best = springs[int(np.argmax([most_like(lam, points, x, STIFF * target / max(w @ w, 1e-300) * np.outer(w, w))[1]
                                      for w in W]))]
    w = _rows(cs.model, phi, [best])[0]

    def ritz(k: float) -> tuple:  # (eigenvalue, MAC) of the Rayleigh-Ritz mode most like the measured one
        return most_like(lam, points, x, k * np.outer(w, w))

    # the rigid modes alone: the elastic ones only lower it; on a held model, from a spring too soft
    # to move the mode to one that holds its point
    lo = target / max(w[:nr] @ w[:nr], 1e-300) if nr else target / max(w @ w, 1e-300) / STIFF
    hi = (1e3 if nr else STIFF**2) * lo
    k = hi if ritz(hi)[0] < target else sized(ritz, target, lo, hi) or lo
    return best, k, ritz(k)[1]


#: points of the log-spaced scan of :func:`sized` between its bounds
SIZE_SCAN = 25


def sized(ritz, target: float, lo: float, hi: float, steps: int = 60) -> float | None:
    """The magnitude in [``lo``, ``hi``] at which the Rayleigh-Ritz mode most like the measured one,
    ``ritz(magnitude)`` = (eigenvalue, MAC), has the eigenvalue ``target``; None where it has it at
    none. The mode most like the measured one need not be one mode throughout: a mass that makes a
    local mode brings it down through the model's lower modes, and at a small mass the mode most like
    the measured one is a lower mode. So the range is scanned (:data:`SIZE_SCAN` points, log scale),
    the crossing of ``target`` where that mode is most like the measured one on both sides taken, and
    refined by bisection on a log scale."""
    m = np.geomspace(lo, hi, SIZE_SCAN)
    ev = np.array([ritz(v) for v in m])
    d = ev[:, 0] - target
    k = np.flatnonzero(d[:-1] * d[1:] <= 0.0)
    if k.size == 0:
        return None
    k = int(k[np.argmax(np.minimum(ev[k, 1], ev[k + 1, 1]))])
    lo, hi, rising = m[k], m[k + 1], d[k + 1] > d[k]
    for _ in range(steps):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if (ritz(mid)[0] < target) == rising else (lo, mid)
    return float(np.sqrt(lo * hi))


def most_like(lam, points, x, dK=0.0, dM=0.0) -> tuple:
    """(eigenvalue, MAC) of the Rayleigh-Ritz mode most like measured shape ``x`` on the basis of the
    model's modes (eigenvalues ``lam``, unit modal masses, shapes ``points`` at the points) with
    stiffness ``dK`` and mass ``dM`` added in that basis (thesis eq. 3.11's pencil)."""
    val, vec = eigh(np.diag(lam) + dK, np.eye(lam.size) + dM)
    m = mac(points @ vec, x)[:, 0]
    j = int(np.argmax(m))
    return float(val[j]), float(m[j])


def _rows(model, phi, springs) -> np.ndarray:
    """(n_springs, n_basis): w = phi^T dK/dk's factor per spring (dK/dk = n n^T at its point: the
    bilinear form phi^T dK phi is w w^T)."""
    BK, _ = effect_forms(model, phi, phi, springs)
    idx = np.arange(len(springs))
    top = np.argmax(np.einsum("cii->ci", BK), axis=1)
    return BK[idx, :, top] / np.sqrt(np.maximum(BK[idx, top, top], 1e-300))[:, None]


def _between_nodes(layout, rigid, points, nr: int, x):
    """The spring at the point of a board whose rigid-body deflection kernel best matches the
    measured shape ``x`` at the points, its elastic part (on the state's elastic modes, ``points``:
    the modes [rigid, elastic] there, ``nr`` rigid) fitted with it, or None where the best match
    lies off the board or at infinity (a mode that only turns)."""
    nodes = layout.shell_nodes()
    X = np.column_stack([np.ones(nodes.size), layout.xy[nodes]])
    A = np.linalg.lstsq(X, rigid[NDOF * nodes + DOF_NAMES.index("uz")], rcond=None)[0]  # (3, nr): w_r = [1, x, y] A
    B = points[:, :nr] @ A.T  # the kernel's shape at the points, per [1, x, y]
    c = np.linalg.lstsq(np.column_stack([B, points[:, nr:]]), x[:, 0], rcond=None)[0][:3]
    if abs(c[0]) <= 1e-9 * np.abs(c).max():
        return None
    return SPRING.at_point(layout, None, c[1:] / c[0])


#: how far the mean MAC of the other paired modes may fall when a support is added (:func:`shapes_kept`)
MAC_SLACK = 0.01
#: a mode paired at least this well (the usual mark of a well-correlated pair) may not lose its partner
#: to an effect placed from another mode (:func:`shapes_kept`)
WELL_PAIRED = 0.9
#: effects located at most from the modes without a partner (:func:`.unpaired.partners`)
MAX_SUPPORTS = 3


def shapes_kept(before, after) -> bool:
    """Whether the modes paired in both states resemble their partners in ``after`` on average at least
    as well as in ``before`` (mean MAC, less :data:`MAC_SLACK`), and no mode that ``before`` paired well
    (MAC >= :data:`WELL_PAIRED`) has lost its partner: an effect the structure has makes the shapes of
    the modes it acts on more like the measured ones; one that only gives one mode a partner (where
    something else is what the model lacks) makes the others less so, or takes a good partner away
    (dev seed 0: a stiff spring placed for its fifth test mode left the first, paired at MAC 0.99,
    without one). Poorly paired modes may lose theirs: a standoff placed while the declared values are
    far off reshuffles them (dev seed 5)."""
    a = np.concatenate([cb.mac[cb.matched & ca.matched] for cb, ca in zip(before.configs, after.configs)])
    b = np.concatenate([ca.mac[cb.matched & ca.matched] for cb, ca in zip(before.configs, after.configs)])
    lost = any(np.any(cb.matched & ~ca.matched & (cb.mac >= WELL_PAIRED))
               for cb, ca in zip(before.configs, after.configs))
    return not lost and (a.size == 0 or float(b.mean()) >= float(a.mean()) - MAC_SLACK)
