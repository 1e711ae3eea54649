"""The stabilisation chart and the choice of poles from it.

A pole at model order n is compared with the nearest pole (in frequency) at the order below:
stable in frequency when they differ by less than TOL_F, in damping by less than TOL_D
(relative), in shape when the MAC of their residue vectors (all FRFs) exceeds TOL_MAC. A physical
mode shows as a column of poles stable in all three over many orders; noise and the modes outside
the band give poles that wander from order to order.

Automatic choice: the poles stable in all three are grouped by frequency (a gap of more than
CLUSTER_GAP between neighbours starts a new group; a group holding two poles of one order is cut
at its largest gaps into as many modes); a group seen at MIN_SUPPORT of the orders or more is a
mode, represented by its pole of median frequency. Manual choice: the pole of median frequency
among the most stable ones within TOL_PICK of each frequency given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..correlation.mac import mac
from ..testdata import TestDataError
from .lscf import physical, residues

TOL_F, TOL_D, TOL_MAC = 0.01, 0.05, 0.98
CLUSTER_GAP = 0.005
MIN_SUPPORT = 0.25
TOL_PICK = 0.02
#: stability codes, least to most stable: new (o), frequency (f), frequency and damping (d),
#: frequency and shape (v), all three (s)
RANK = {"o": 0, "f": 1, "d": 2, "v": 2, "s": 3}


@dataclass
class Chart:
    """Every physical pole of every order: order (number of poles of the polynomial), pole,
    frequency [Hz], damping ratio, stability code."""

    order: np.ndarray
    pole: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray
    code: np.ndarray

    @property
    def n_orders(self) -> int:
        return int(np.unique(self.order).size)


def _status(p, A, prev_p, prev_A) -> str:
    if prev_p is None or len(prev_p) == 0:
        return "o"
    j = int(np.argmin(np.abs(np.abs(prev_p) - abs(p))))
    f0, f1 = abs(prev_p[j]), abs(p)
    if abs(f1 - f0) > TOL_F * f0:
        return "o"
    z0, z1 = -prev_p[j].real / f0, -p.real / f1
    damp = abs(z1 - z0) <= TOL_D * z0
    shape = mac(A, prev_A[:, j])[0, 0] >= TOL_MAC
    return "s" if damp and shape else "d" if damp else "v" if shape else "f"


def chart(all_poles, f, rows, kind, band) -> Chart:
    """The chart of the LSCF poles of every order (``all_poles[k]`` at order 2 (k + 1)), with the
    residues of each order's physical poles for the shape test."""
    out = ([], [], [])
    prev_p = prev_A = None
    for k, raw in enumerate(all_poles):
        p = physical(raw, band)
        A = residues(p, f, rows, kind)
        for i, pole in enumerate(p):
            out[0].append(2 * (k + 1))
            out[1].append(pole)
            out[2].append(_status(pole, A[:, i], prev_p, prev_A))
        prev_p, prev_A = p, A
    poles = np.array(out[1], dtype=complex)
    return Chart(np.array(out[0], dtype=int), poles, np.abs(poles) / (2.0 * np.pi),
                 -poles.real / np.maximum(np.abs(poles), 1e-300), np.array(out[2], dtype="<U1"))


def _median_pole(c: Chart, idx) -> int:
    idx = np.asarray(idx)
    return int(idx[np.argsort(c.frequency[idx])][(idx.size - 1) // 2])


def _groups(c: Chart, idx) -> list:
    """Stable poles ``idx`` grouped by frequency, groups with two poles of one order split."""
    idx = idx[np.argsort(c.frequency[idx])]
    if idx.size == 0:
        return []
    f = c.frequency[idx]
    cuts = np.flatnonzero(np.diff(f) > CLUSTER_GAP * f[:-1]) + 1
    out = []
    for g in np.split(idx, cuts):
        n = int(np.bincount(c.order[g]).max())
        if n > 1:  # two modes closer than CLUSTER_GAP: cut at the n - 1 largest gaps
            gaps = np.sort(np.argsort(np.diff(c.frequency[g]))[-(n - 1):]) + 1
            out.extend(np.split(g, gaps))
        else:
            out.append(g)
    return out


def auto_select(c: Chart) -> list:
    """Indices (into the chart) of one pole per physical mode, by frequency."""
    stable = np.flatnonzero(c.code == "s")
    need = max(3, int(np.ceil(MIN_SUPPORT * c.n_orders)))
    keep = [g for g in _groups(c, stable) if np.unique(c.order[g]).size >= need]
    return sorted((_median_pole(c, g) for g in keep), key=lambda i: c.frequency[i])


def pick(c: Chart, frequencies) -> list:
    """Indices of the poles chosen near each of ``frequencies`` [Hz] (manual override)."""
    chosen = []
    rank = np.array([RANK[s] for s in c.code], dtype=int)
    for f0 in frequencies:
        near = np.flatnonzero(np.abs(c.frequency - f0) <= TOL_PICK * f0)
        if near.size == 0:
            raise TestDataError(f"--select: no pole within {TOL_PICK:.0%} of {f0:g} Hz in the stabilisation chart; "
                                "pick frequencies where the chart shows a column of poles")
        best = near[rank[near] == rank[near].max()]
        chosen.append(_median_pole(c, best))
    if len(set(chosen)) < len(chosen):
        raise TestDataError("--select: two of the frequencies given pick the same pole; give each mode once")
    return sorted(chosen, key=lambda i: c.frequency[i])
