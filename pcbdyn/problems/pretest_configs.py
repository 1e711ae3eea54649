"""Perturbed-boundary configurations designed before the test (thesis ch. 6): each candidate is one added
mass (from an offered set) at one usable candidate point; its frequency equations (thesis eq. 3.2, rows
relative and in units of the stated frequency noise, columns x = dp/p, eq. 4.41) come from the base model
with the mass on, re-solved. K of them are chosen D-optimally with the base test's equations
(:func:`pcbdyn.updating.design.d_optimal`), and each parameter's predicted 1-sigma is reported for the base
test alone, with the structure's own configurations, and with the designed ones. The design is linear at
the starting values: the information the frequencies of a test carry, as the ``freq`` update uses them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import tomlkit

from .. import targets
from ..atomic import write_checked
from ..domain import StructureError
from ..inputs import entry_name, new_entry_name
from ..updating import design
from ..updating.equations import frequency_equations
from ..updating.pbc import condition_number
from .error_budget import noise_sigma
from .pretest import PretestModel, configuration_model
from .pretest_points import Candidates, is_box


#: a configuration none of whose target frequencies moves by this many sigma of the frequency noise cannot
#: be told from the base test: it would count as a replicate of it (more information, the same directions)
NOT_TOLD = 3.0


def frequency_block(lam, phi, model: PretestModel, dKs, dMs, sigma_rel: float) -> np.ndarray:
    """Rows d(f_i)/f_i per x_j (eq. 3.2, relative rows, column-weighted), over the relative noise."""
    f = np.sqrt(lam) / (2 * np.pi)
    return frequency_equations(lam, phi, f, dKs, dMs, p=model.p0, relative_rows=True).A / sigma_rel


def identifiability(model: PretestModel, blocks) -> dict:
    """{"std_pct": {name: predicted 1-sigma in % of the value}, "condition": of the stacked weighted A}."""
    std = design.predicted_std(design.fisher(blocks))
    return {"std_pct": dict(zip(model.names, (100.0 * std).tolist())),
            "condition": condition_number(np.vstack(blocks))}


@dataclass
class Design:
    """``chosen``: [(candidate index, mass [kg])] of each designed configuration; ``before``/``after``/
    ``existing`` (the structure's own configurations with the base test; None without any):
    :func:`identifiability` dicts; ``candidates``: how many (place, mass) candidates were weighed (those
    that move a target mode by at least :data:`NOT_TOLD` sigma of the frequency noise)."""

    chosen: list
    before: dict
    after: dict
    existing: dict | None
    candidates: int


def places(cand: Candidates, max_places: int | None) -> np.ndarray:
    """The usable candidates, thinned evenly to at most ``max_places``."""
    use = np.flatnonzero(cand.usable)
    if max_places is not None and use.size > max_places:
        use = use[np.round(np.linspace(0, use.size - 1, max_places)).astype(int)]
    return use


def design_configurations(model: PretestModel, cand: Candidates, masses, k: int, frequency_pct: float,
                          max_places: int | None = None, progress=None) -> Design:
    """Choose ``k`` configurations of one added mass each (module docstring). ``frequency_pct``: the stated
    frequency noise (uniform bounds, eq. 5.72: 1-sigma = pct / sqrt 3). ``progress(done, total)`` is
    called as candidates are solved. With ``k`` 0 nothing is weighed: the identifiability of the base test
    and of the structure's own configurations (``after`` is then ``before``)."""
    if not model.names:
        raise StructureError(f"{model.structure.path.name}: no parameters to design configurations for; name "
                             "them with --parameters or declare [[parameters]]")
    sigma = noise_sigma(frequency_pct)
    _, _, dKs, dMs = model.matrices()
    base = frequency_block(model.lam, model.phi, model, dKs, dMs, sigma)
    where = places(cand, max_places) if k else np.zeros(0, dtype=np.int64)
    blocks, which = [], []
    for n, i in enumerate(where):
        unit = model.point_mass(cand.xyz[i], 1.0)
        for m in masses:
            lam, phi = model.modes(extra_M=m * unit)
            if np.max(np.abs(np.sqrt(lam / model.lam) - 1.0)) < NOT_TOLD * sigma:
                continue  # the base test again, within the noise: a replicate, not a perturbation
            blocks.append(frequency_block(lam, phi, model, dKs, dMs, sigma))
            which.append((int(i), float(m)))
        if progress is not None:
            progress(n + 1, where.size)
    if len({i for i, _ in which}) < k:
        raise StructureError(f"{model.structure.path.name}: only {len({i for i, _ in which})} candidate places move "
                             f"a target mode by more than {NOT_TOLD:g} sigma of the frequency noise with the masses "
                             f"offered; offer heavier --masses, more places (--max-places), or fewer --configurations")
    pick = design.d_optimal(base.T @ base, np.stack([A.T @ A for A in blocks]), k, [i for i, _ in which]) if k else []
    existing = None
    names = model.structure.configuration_names()
    if names:
        own = []
        for c in names:
            other = replace(configuration_model(model.structure, c, model.names, model.mesh_size), lam=model.lam,
                            position=model.position)
            lam, phi = other.modes()
            _, _, dK, dM = other.matrices()
            own.append(frequency_block(lam, phi, model, dK, dM, sigma))
        existing = identifiability(model, [base] + own)
    return Design([which[j] for j in pick], identifiability(model, [base]),
                  identifiability(model, [base] + [blocks[j] for j in pick]), existing, len(blocks))


def configuration_entries(structure, cand: Candidates, chosen) -> list:
    """[{"name", "masses": [{"mass_kg", "at_mm", ...}]}] of the designed configurations, named ``pretestN``
    clear of the structure's own names."""
    used = {entry_name("configurations", {"name": n}, 0) for n in structure.configuration_names()}
    out = []
    for i, m in chosen:
        mass = {"mass_kg": m, "at_mm": (cand.ab[i] * 1e3).tolist()}
        if is_box(structure):
            mass["plate"] = cand.plate[i]
        out.append({"name": new_entry_name(f"pretest{len(out) + 1}", used, "pretest"), "masses": [mass]})
    return out


def write_configurations(structure, entries, dst, load, source: str = "pcbdyn pretest"):
    """``dst``: the structure's file with ``entries`` (:func:`configuration_entries`) added as
    ``[[configurations]]`` (the one TOML writer, :func:`pcbdyn.targets.append_entry`; comments and layout
    kept), checked by ``load`` before it is written."""
    doc = tomlkit.parse(structure.path.read_text(encoding="utf-8"))
    for e in entries:
        masses = tomlkit.array()
        for m in e["masses"]:
            t = tomlkit.inline_table()
            if "plate" in m:
                t["plate"] = m["plate"]
            t["at"] = [targets.quantity(v * 1e-3, "mm") for v in m["at_mm"]]
            t["mass"] = targets.quantity(m["mass_kg"], "g")
            masses.append(t)
        targets.append_entry(doc, "configurations", {"name": e["name"], "masses": masses},
                             f"designed by {source}: an added mass that makes the parameters identifiable")
    return write_checked(dst, tomlkit.dumps(doc), load, StructureError)
