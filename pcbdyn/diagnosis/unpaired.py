"""What a test mode without a model partner shows: a lumped effect the model lacks, placed and sized
from that mode before the search (issue 37: the modes the pairing leaves out are the strongest
evidence of what is missing, yet without a partner they give no residual rows).

A spring to ground (:mod:`.support`: a bracket's bounce on a free board, an undeclared standoff on a
held one) raises the modes near its point; a point mass (a relay on a housing's plate, a transducer)
lowers them and makes new local shapes. Either changes the pencil of the model's modes by a low-rank
term (thesis eq. 3.11: k w w^T in stiffness, m v v^T in mass per direction), so on the basis of the
model's modes a Rayleigh-Ritz problem says, for every candidate point, how like the measured mode the
nearest mode of the modified model is. Each kind is placed where that is greatest and sized so that
this mode has the measured frequency; the kind whose Ritz mode is more like the measured one is tried
first, and an effect is kept only if the mode then pairs and the other paired modes are no less like
their partners (:func:`.support.shapes_kept`).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from .catalogue import effect_forms
from .support import MAX_SUPPORTS, locate, most_like, shapes_kept, sized, support_modes

#: masses tried per candidate point in the placing scan, times 1 / (largest modal weight of the point)
SCAN_MASSES = (0.1, 0.3, 1.0, 3.0)
#: the points best in that scan that are sized, the one whose sized mass makes the mode most like the
#: measured one kept (the scan's masses are a coarse guess of the mass)
SIZED = 8


def locate_mass(ob, cs, i: int, masses: list) -> tuple:
    """(point-mass candidate, mass [kg], Ritz MAC): of the points of ``masses`` (``point_mass``
    candidates on the state's mesh), the one where a mass sized to give the Rayleigh-Ritz mode of the
    state ``cs`` most like measured mode ``i`` of ``ob`` the measured frequency (:func:`.support.sized`)
    makes that mode most like it; None where no mass can."""
    phi = np.column_stack([cs.modes.rigid_shapes, cs.modes.shapes])
    lam = np.r_[np.zeros(cs.modes.n_rigid), cs.modes.omega2]
    points, x = cs.at_points(ob.read), ob.shapes[:, i : i + 1]
    _, BM = effect_forms(cs.model, phi, phi, masses)
    unit = 1.0 / np.maximum(np.einsum("cii->ci", BM).max(axis=1), 1e-300)
    scores = [max(most_like(lam, points, x, dM=s * u * B)[1] for s in SCAN_MASSES) for B, u in zip(BM, unit)]
    best = None
    for c in np.argsort(scores)[::-1][:SIZED]:
        ritz = partial(_ritz_mass, lam, points, x, BM[c])
        m = sized(ritz, (2.0 * np.pi * ob.f[i]) ** 2, 1e-3 * unit[c], 1e2 * unit[c])
        like = None if m is None else ritz(m)[1]
        if like is not None and (best is None or like > best[2]):
            best = (masses[c], m, like)
    return best


def _ritz_mass(lam, points, x, B, m: float) -> tuple:
    """(eigenvalue, MAC) of the Rayleigh-Ritz mode most like measured shape ``x`` with mass ``m`` of
    modal form ``B`` added."""
    return most_like(lam, points, x, dM=m * B)


def partners(res, p, state, springs: list, masses: list, layout) -> tuple:
    """([(candidate, value)], the state of ``res`` at parameters ``p`` with them): effects located one
    after another (module doc) while some configuration of ``state`` has a measured mode without a
    partner: a spring (``springs``, where the mode may show a support: :func:`.support.support_modes`)
    or a mass (``masses``); the first of :data:`.support.MAX_SUPPORTS` such modes for which one is kept.
    A configuration's test showing the same mode as another's is explained by the same effect."""
    found = []
    while len(found) < MAX_SUPPORTS:
        more = _one_more(res, p, state, found, springs, masses, layout)
        if more is None:
            break
        found, state = more
    return found, state


def _one_more(res, p, state, found, springs, masses, layout):
    """(``found`` with one more effect, the state with them) for the first of :data:`.support.MAX_SUPPORTS`
    modes without a partner in ``state`` that one gives a partner to (:func:`partners`), or None."""
    todo = [(k, i) for k, (ob, cs) in enumerate(zip(res.observations, state.configs))
            if ob.shapes is not None for i in np.flatnonzero(~cs.matched)]
    for k, i in todo[:MAX_SUPPORTS]:
        ob, cs = res.observations[k], state.configs[k]
        options = [locate(ob, cs, i, springs, layout)] if springs and support_modes(ob, cs)[i] else []
        options += [o for o in [locate_mass(ob, cs, i, masses) if masses else None] if o is not None]
        for c, v, _ in sorted(options, key=lambda o: -o[2]):  # (candidate, value, Ritz MAC)
            trial = found + [(c, v)]
            st = res.evaluate(p, [t for t, _ in trial], [u for _, u in trial])
            if st.configs[k].matched[i] and shapes_kept(state, st):
                return trial, st
    return None
