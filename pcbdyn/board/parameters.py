"""Named, bounded model parameters and their stiffness and mass derivatives.

A parameter is one scalar shared by one or more quantities of a board model (e.g. the thickness
of both PGA regions, the k_rot of both card guides). Its dK/dp and dM/dp come from the element
sets that depend on those quantities only (``fe.assembly.assemble(model, sets=..., props=...)``),
by a central difference of the element matrices: (A(p + h) - A(p - h)) / 2h. Every board quantity
enters the element matrices as a polynomial of degree <= 3 (E, rho, k, m linearly; a thickness
through t, t^2 and t^3, the eq. 7.7 density keeping rho t fixed), for which the central
difference is exact up to h^2/6 times the third derivative, i.e. a relative error of about
(h/p)^2 / 3 = 3e-9 with the default step; no full re-assembly is needed.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..fe.assembly import assemble


@dataclass
class Parameter:
    """``targets`` (quantity names) share one value within ``bounds`` (SI); ``unit`` is the unit
    used in board.toml for display."""

    name: str
    targets: tuple
    bounds: tuple
    unit: str
    value: float
    sets: tuple  # element sets touched

    @classmethod
    def from_spec(cls, spec, bm) -> "Parameter":
        targets = tuple(spec.targets)
        missing = [t for t in targets if t not in bm.quantities]
        if missing:
            raise KeyError(f"parameter '{spec.name}': quantities {missing} are not in the model")
        return cls(spec.name, targets, tuple(spec.bounds), spec.unit, bm.quantities[targets[0]],
                   tuple(bm.sets_depending_on(targets)))

    def quantities(self, value: float) -> dict:
        return {t: float(value) for t in self.targets}

    def derivatives(self, bm, rel_step: float = 1e-4):
        """(dK/dp, dM/dp) as full-size sparse matrices (before constraints)."""
        p = bm.quantities[self.targets[0]]
        h = rel_step * (abs(p) if p != 0 else max(abs(self.bounds[0]), abs(self.bounds[1]), 1.0))
        sets = list(self.sets)
        Kp, Mp = assemble(bm.model, sets=sets, props=bm.properties(self.quantities(p + h)))
        Km, Mm = assemble(bm.model, sets=sets, props=bm.properties(self.quantities(p - h)))
        return (Kp - Km) / (2 * h), (Mp - Mm) / (2 * h)
