"""FE models whose element sets are functions of named quantities, and parameters on them.

Each element set is made by a function of a dictionary of named quantities (``board.E``,
``components.U1.thickness``, ``ribs.left_v1.height``, ...) and records which quantities it depends on
(:class:`SetMaker`). Changing quantities re-makes only the sets that depend on them
(:meth:`ParametricModel.with_quantities`), which is also how a parameter's dK/dp and dM/dp are formed.

A :class:`Parameter` is a named, bounded scalar shared by one or more quantities (the thickness of
both PGA regions, the k_rot of both card guides). Its derivatives come from the element sets that
depend on those quantities only, by a central difference of their element matrices,
(A(p + h) - A(p - h)) / 2h. Most quantities enter element matrices as polynomials of degree <= 3 (E,
rho, k, m linearly; a thickness through t, t^2, t^3), for which the central difference is exact up to
h^2/6 times the third derivative: a relative error of about (h/p)^2 / 3 = 3e-9 with the default
step, and no full re-assembly. A beam's section sides are not (its shear term and torsion constant):
its maker says so (:attr:`SetMaker.powers`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .assembly import assemble
from .model import Model, ModelError


@dataclass
class SetMaker:
    """How to make one element set: its type, connectivity, the quantities it depends on,
    ``make(q) -> property`` and its ``frame`` (:class:`.model.ElementSet`); ``powers``: {quantity of
    ``deps``: the highest power it enters the matrices with (a modulus or a density 1), or None where
    it enters otherwise (a beam's shear term and torsion constant in its section's sides)}, for
    :class:`.parametric_matrices.ParametricMatrices`, which interpolates on that many points."""

    etype: str
    conn: np.ndarray
    deps: tuple
    make: object
    frame: object = None
    powers: dict = field(default_factory=dict)


@dataclass
class Parameter:
    """``targets`` (quantity names) share one value within ``bounds`` [SI]; ``unit`` is the display
    unit of the input file; ``log``: a stiffness, updated on a log scale; ``sets``: the element sets
    it touches."""

    name: str
    targets: tuple
    bounds: tuple
    unit: str
    value: float
    sets: tuple
    log: bool = False

    def quantities(self, value: float) -> dict:
        return {t: float(value) for t in self.targets}

    def step(self, value: float, rel_step: float = 1e-4) -> float:
        """The step of a central difference at ``value``: relative to it, or to the bounds at zero."""
        return rel_step * (abs(value) if value != 0 else max(abs(self.bounds[0]), abs(self.bounds[1]), 1.0))

    def derivatives(self, pm: "ParametricModel", rel_step: float = 1e-4):
        """(dK/dp, dM/dp) at ``pm``'s value as full-size sparse matrices (before constraints)."""
        p = pm.quantities[self.targets[0]]
        h = self.step(p, rel_step)
        sets = list(self.sets)
        Kp, Mp = assemble(pm.model, sets=sets, props=pm.properties(self.quantities(p + h)))
        Km, Mm = assemble(pm.model, sets=sets, props=pm.properties(self.quantities(p - h)))
        return (Kp - Km) / (2 * h), (Mp - Mm) / (2 * h)


@dataclass
class ParametricModel:
    """An FE ``model`` made from named ``quantities`` by ``makers`` ({set name: SetMaker}), its named
    nodes (``point_nodes``: {name: node}) and ``parameters`` ({name: Parameter})."""

    model: Model
    quantities: dict
    makers: dict
    point_nodes: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)

    @classmethod
    def assemble_from(cls, model: Model, quantities: dict, makers: dict, **fields) -> "ParametricModel":
        """``model`` (nodes and constraints) with every maker's set added at ``quantities``."""
        for name, mk in makers.items():
            model.add(name, mk.etype, mk.conn, mk.make(quantities), mk.frame)
        return cls(model, quantities, makers, **fields)

    def bind(self, specs) -> None:
        """Parameters from specs (name, targets, bounds, unit, log) on this model's quantities."""
        for spec in specs:
            targets = tuple(spec.targets)
            missing = [t for t in targets if t not in self.quantities]
            if missing:
                raise ModelError(f"parameter '{spec.name}': quantities {missing} are not in the model")
            self.parameters[spec.name] = Parameter(spec.name, targets, tuple(spec.bounds), spec.unit,
                                                   self.quantities[targets[0]], tuple(self.sets_depending_on(targets)),
                                                   bool(getattr(spec, "log", False)))

    def sets_depending_on(self, keys) -> list:
        keys = set(keys)
        return [n for n, mk in self.makers.items() if keys & set(mk.deps)]

    def properties(self, values: dict) -> dict:
        """{set name: property} of the sets touched when the quantities ``values`` change."""
        q = {**self.quantities, **values}
        return {n: self.makers[n].make(q) for n in self.sets_depending_on(values)}

    def with_quantities(self, values: dict):
        """A copy whose quantities are changed (the FE model shares nodes and unchanged sets)."""
        for k in values:
            if k not in self.quantities:
                raise ModelError(f"'{k}' is not a quantity of this model")
        model = self.model.copy()
        for name, prop in self.properties(values).items():
            es = model.sets[name]
            model.sets[name] = replace(es, prop=prop)
        return replace(self, model=model, quantities={**self.quantities, **values})

    def with_parameters(self, values: dict):
        """A copy with parameters set, each value going to all its targets.

        Parameters
        ----------
        values : dict
            {parameter name: value [SI]}.

        Returns
        -------
        ParametricModel
            A copy (of the same class) whose ``model`` shares the nodes and the unchanged element
            sets; the sets that depend on the parameters are made anew.
        """
        q = {}
        for name, v in values.items():
            q.update(self.parameters[name].quantities(v))
        return self.with_quantities(q)

    def mass(self) -> float:
        """Total translational mass [kg] from the assembled mass matrix (u = 1 in z everywhere)."""
        _, M = assemble(self.model)
        r = np.zeros(self.model.n_dof)
        r[2::6] = 1.0
        return float(r @ (M @ r))
