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
first, then (where the declared parameters put every frequency off) the best point's mass sized to the
measured shape instead (:func:`shaped`), and an effect is kept only if the mode then pairs and the other
paired modes are no less like their partners (:func:`.support.shapes_kept`).
"""

from __future__ import annotations

from functools import partial

import numpy as np
from scipy.optimize import minimize_scalar

from .catalogue import effect_forms
from .support import MAX_SUPPORTS, SIZE_SCAN, locate, most_like, shapes_kept, sized, support_modes

#: masses tried per candidate point in the placing scan, times 1 / (largest modal weight of the point)
SCAN_MASSES = (0.1, 0.3, 1.0, 3.0)
#: the points best in that scan that are sized, the one whose sized mass makes the mode most like the
#: measured one kept (the scan's masses are a coarse guess of the mass)
SIZED = 8


def locate_mass(ob, cs, i: int, masses: list) -> tuple:
    """([(point-mass candidate, mass [kg], Ritz MAC)] sized to the measured frequency, the same shaped):
    of the points of ``masses`` (``point_mass`` candidates on the state's mesh), the one where a mass
    sized to give the Rayleigh-Ritz mode of the state ``cs`` most like measured mode ``i`` of ``ob`` the
    measured frequency (:func:`.support.sized`) makes that mode most like it (none where no mass can);
    and the point the placing scan ranks first with the mass that makes its Ritz mode most like the
    measured shape (:func:`shaped`; None where it is not like it at all)."""
    phi = np.column_stack([cs.modes.rigid_shapes, cs.modes.shapes])
    lam = np.r_[np.zeros(cs.modes.n_rigid), cs.modes.omega2]
    points, x = cs.at_points(ob.read), ob.shapes[:, i : i + 1]
    _, BM = effect_forms(cs.model, phi, phi, masses)
    unit = 1.0 / np.maximum(np.einsum("cii->ci", BM).max(axis=1), 1e-300)
    scores = [max(most_like(lam, points, x, dM=s * u * B)[1] for s in SCAN_MASSES) for B, u in zip(BM, unit)]
    best = None
    order = np.argsort(scores)[::-1]
    for c in order[:SIZED]:
        ritz = partial(_ritz_mass, lam, points, x, BM[c])
        m = sized(ritz, (2.0 * np.pi * ob.f[i]) ** 2, 1e-3 * unit[c], 1e2 * unit[c])
        like = None if m is None else ritz(m)[1]
        if like is not None and (best is None or like > best[2]):
            best = (masses[c], m, like)
    first = int(order[0])
    return [] if best is None else [best], shaped(partial(_ritz_mass, lam, points, x, BM[first]), masses[first],
                                                  1e-3 * unit[first], 1e2 * unit[first])


def shaped(ritz, candidate, lo: float, hi: float):
    """(``candidate``, mass, Ritz MAC) with the mass in [``lo``, ``hi``] whose Rayleigh-Ritz mode
    ``ritz(mass)`` = (eigenvalue, MAC) is most like the measured shape (a log-scale scan refined
    between its neighbours). Where the declared parameters are far off, every model frequency is, and a
    mass sized to the measured frequency can be hundreds of times too large (a 40 g mass on a card
    whose modes are 3-11 % off: 3.3 kg); the shape still says where the mass is and roughly how large,
    and the fit with the parameters that follows sizes it."""
    m = np.geomspace(lo, hi, SIZE_SCAN)
    like = np.array([ritz(v)[1] for v in m])
    k = int(np.argmax(like))
    if not like[k] > like[0]:
        return None
    a, b = np.log(m[max(k - 1, 0)]), np.log(m[min(k + 1, m.size - 1)])
    top = minimize_scalar(lambda t: -ritz(np.exp(t))[1], bounds=(a, b), method="bounded",
                          options={"xatol": 1e-3})
    v = float(np.exp(top.x)) if -top.fun > like[k] else float(m[k])
    return candidate, v, ritz(v)[1]


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
        sized_masses, shaped_mass = locate_mass(ob, cs, i, masses) if masses else ([], None)
        options = sorted(options + sized_masses, key=lambda o: -o[2])  # (candidate, value, Ritz MAC)
        for c, v, _ in options + ([shaped_mass] if shaped_mass is not None else []):
            trial = found + [(c, v)]
            st = res.evaluate(p, [t for t, _ in trial], [u for _, u in trial])
            if st.configs[k].matched[i] and shapes_kept(state, st):
                return trial, st
    return None
