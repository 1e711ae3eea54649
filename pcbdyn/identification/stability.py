"""The stabilisation chart and the choice of poles from it.

A pole at model order n is compared with the nearest pole (in frequency) at the order below:
stable in frequency when they differ by less than TOL_F, in damping by less than TOL_D (relative)
or TOL_D_ABS (absolute), in shape when the MAC of their residue vectors (all FRFs) exceeds TOL_MAC.
TOL_D_ABS equals TOL_F: the pole may move along the real axis as far as the frequency test lets it
move along the imaginary one (|delta zeta| omega <= TOL_F omega), the distance between poles as a
fraction of their modulus (Reynders, Houbrechts, De Roeck, "Fully automated (operational) modal
analysis", Mech. Syst. Signal Process. 29 (2012) 228-250). A tighter damping test suits clean data
only: on a measured single FRF of a lightly damped plate (damping ratio 0.2-2 %) the damping of a
mode's pole changes by a median 27 % from one order to the next above 300 Hz, whereas its frequency
changes by 0.16 % (plates 1-5 of bench_identify_plates.py). With one FRF the shape test cannot fail (a
residue vector of one value), so stability rests on frequency and damping. A physical mode shows as
a column of poles stable over many orders; noise and the modes outside the band give poles that
wander from order to order. Only physical poles enter the chart (:func:`.lscf.physical`: positive
frequency inside the band, damping ratio in (0, MAX_DAMPING)).

Automatic choice: the stable poles are grouped by frequency (a gap of more than CLUSTER_GAP between
neighbours starts a new group; a group holding two poles of one order is cut at its largest gaps
into as many modes); a group is a mode when it is seen at MIN_SUPPORT of the orders from the one it
first appears at (a mode of a wide band appears only once the order can hold it; on a noisy FRF the
noise poles take turns with it at the nearest-pole comparison, so its column has gaps) and at
MIN_ORDERS_FRACTION of all orders, at least 3; its most stable poles give it their median damping and
the frequency of their pole of median frequency (:func:`group_pole`). A mode must then be seen in the data
(:func:`share`): in the FRF where its modal term is largest, that term makes at least MIN_SHARE of the
measured FRF at its own frequency. A pole fitted to noise, or to the skirt of a strong neighbour or of
a mode outside the band, can be as stable on a single FRF as a mode is, but it is not what makes the
FRF there.
Manual choice: every pole stable in frequency is grouped likewise, and each frequency given takes the
nearest group within TOL_PICK, distinct ones where the groups allow, the most stable pole of median
frequency standing for it; requests that share one group are said so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..correlation.mac import mac
from ..testdata import TestDataError
from ..testdata.data import FRF_KINDS
from .lscf import MAX_DAMPING, physical, residues

TOL_F, TOL_D, TOL_MAC = 0.01, 0.05, 0.98
TOL_D_ABS = TOL_F
CLUSTER_GAP = 0.005
MIN_SUPPORT = 0.3
MIN_ORDERS_FRACTION = 0.15
MIN_SHARE = 0.5
TOL_PICK = 0.02
#: stability codes, least to most stable: new (o), frequency (f), frequency and damping (d),
#: frequency and shape (v), all three (s)
RANK = {"o": 0, "f": 1, "d": 2, "v": 2, "s": 3}


def criteria(n_rows: int) -> dict:
    """The rules of the choice, as the JSON states them (``n_rows``: the FRFs fitted)."""
    return {"frequency_tolerance": TOL_F, "damping_tolerance_relative": TOL_D, "damping_tolerance_absolute": TOL_D_ABS,
            "shape_mac_min": TOL_MAC if n_rows > 1 else None, "physical_damping": [0.0, MAX_DAMPING],
            "cluster_gap": CLUSTER_GAP, "min_support_from_first_order": MIN_SUPPORT,
            "min_orders_fraction": MIN_ORDERS_FRACTION, "min_share_of_frf": MIN_SHARE, "pick_tolerance": TOL_PICK,
            "shape_test": "MAC of the residues over all FRFs" if n_rows > 1 else "none: one FRF"}


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
    damp = abs(z1 - z0) <= max(TOL_D * z0, TOL_D_ABS)
    shape = mac(A, prev_A[:, j])[0, 0] >= TOL_MAC
    return "s" if damp and shape else "d" if damp else "v" if shape else "f"


def chart(all_poles, f, rows, kind, band) -> Chart:
    """The chart of the LSCF poles of every order (``all_poles[k]`` at order 2 (k + 1)), with the
    residues of each order's physical poles for the shape test (none fitted for one FRF: its test cannot
    fail)."""
    out = ([], [], [])
    prev_p = prev_A = None
    for k, raw in enumerate(all_poles):
        p = physical(raw, band)
        A = residues(p, f, rows, kind) if len(rows) > 1 else np.ones((1, p.size))
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
    """Poles ``idx`` grouped by frequency, groups with two poles of one order split."""
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
    """One group of chart indices (the mode's stable poles) per physical mode, by frequency."""
    orders = np.unique(c.order)
    least = max(3, int(np.ceil(MIN_ORDERS_FRACTION * orders.size)))
    keep = []
    for g in _groups(c, np.flatnonzero(c.code == "s")):
        seen = np.unique(c.order[g]).size
        span = int(np.sum(orders >= c.order[g].min()))
        if seen >= max(least, np.ceil(MIN_SUPPORT * span)):
            keep.append(g)
    return sorted(keep, key=lambda g: c.frequency[_median_pole(c, g)])


def share(poles, A, f, rows, kind: str) -> np.ndarray:
    """Per pole, |its modal term| / |measured FRF| at the line nearest its damped frequency, in the FRF
    (of ``rows``) where that term is largest; receptance form, as the LSFD residues ``A`` (n_rows,
    n_poles) are."""
    w = 2j * np.pi * np.asarray(f, float)
    H = np.asarray(rows) / w ** FRF_KINDS[kind]
    out = np.zeros(len(poles))
    for r, p in enumerate(poles):
        k = int(np.argmin(np.abs(w.imag - p.imag)))
        term = A[:, r] / (w[k] - p) + A[:, r].conj() / (w[k] - p.conj())
        i = int(np.argmax(np.abs(term)))
        out[r] = float(np.abs(term[i]) / max(np.abs(H[i, k]), 1e-300))
    return out


def _most_stable(c: Chart, g) -> np.ndarray:
    rank = np.array([RANK[s] for s in c.code[g]], dtype=int)
    return np.asarray(g)[rank == rank.max()]


def representative(c: Chart, g) -> int:
    """The pole standing for a group in the chart: of median frequency among its most stable poles."""
    return _median_pole(c, _most_stable(c, g))


def group_pole(c: Chart, g) -> complex:
    """The mode's pole: the representative's natural frequency and the median damping ratio of the
    group's most stable poles. One pole's damping scatters from order to order far more than its
    frequency does (on one noisy FRF a pole of median frequency had 0.18 % for a 0.8 % mode whose
    column's median was 0.70 %), so the column's median stands for it, as the cluster statistics of
    automated modal analysis do (Reynders et al. 2012)."""
    top = _most_stable(c, g)
    wn = 2.0 * np.pi * c.frequency[_median_pole(c, top)]
    z = float(np.median(c.damping[top]))
    return complex(-z * wn, wn * np.sqrt(1.0 - z * z))


def pick(c: Chart, frequencies) -> tuple:
    """(groups, notes): for each of ``frequencies`` [Hz] the nearest group of poles stable in frequency
    within TOL_PICK, each group given once (manual override); the notes say which requests shared one."""
    groups = _groups(c, np.flatnonzero(c.code != "o"))
    f_req = np.asarray(frequencies, dtype=float)
    f_grp = np.array([c.frequency[representative(c, g)] for g in groups])
    d = np.abs(f_grp[None, :] - f_req[:, None]) / f_req[:, None] if groups else np.zeros((f_req.size, 0))
    for k in np.flatnonzero(~np.any(d <= TOL_PICK, axis=1)):
        raise TestDataError(f"--select: no pole within {TOL_PICK:.0%} of {f_req[k]:g} Hz in the stabilisation chart; "
                            "pick frequencies where the chart shows a column of poles")
    rows, cols = linear_sum_assignment(np.where(d <= TOL_PICK, d, 1e6))
    taken = {int(r): int(g) for r, g in zip(rows, cols) if d[r, g] <= TOL_PICK}
    notes = []
    for k in range(f_req.size):
        if k not in taken:
            g = int(np.argmin(d[k]))
            other = next(r for r, gg in taken.items() if gg == g)
            notes.append(f"--select: {f_req[k]:g} Hz and {f_req[other]:g} Hz pick the same pole at {f_grp[g]:.2f} Hz "
                         "(no other column within 2 %): kept once")
    chosen = sorted(set(taken.values()), key=lambda g: f_grp[g])
    return [groups[g] for g in chosen], notes
