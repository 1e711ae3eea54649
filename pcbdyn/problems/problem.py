"""The bridge from structures and their tests to the plain-matrix updating driver (:mod:`pcbdyn.updating`).

An :class:`UpdateProblem` holds one or more structures (boards, boxes: the domain-model interface of
:mod:`pcbdyn.domain`) and the names of the parameters being updated; a parameter may belong to several
structures (a part family's equivalent thickness on every board of a library calibration). For each
test configuration of a structure it builds driver :class:`~pcbdyn.updating.iteration.Configuration`
blocks that carry their own pairing and rigid-mode count, so that configurations (PBC, thesis ch. 6)
and structures stack freely. Typical use::

    prob = UpdateProblem(load_board("board.toml"), ["t_PGA", "t_JLCC"])
    test = read_uff("test.uff").modes                               # pcbdyn.testdata.MeasuredModes
    check = [prob.configuration(None, test, "freq")]                # frequencies, MAC pairing
    cfgs = prob.mode_configurations(None, test, "qms")              # or: QMS, one block per mode
    res, before, after = run(prob, cfgs, solver="bounded", check=check)

Design variables are relative, x = dp/p (column weighting, thesis eq. 4.41); spring stiffnesses
(``Kind.log`` of :mod:`pcbdyn.targets`: wedge-lock k_rot, standoff k), which span decades, are
updated on a log scale. For shape methods (QMS, FBM) :meth:`UpdateProblem.mode_configurations` gives
one configuration per measured mode on the model dynamically condensed to the measured DOFs at that
mode's frequency (no Guyan bias); localisation reuses the same configurations.
"""

from __future__ import annotations

import numpy as np

from ..correlation.pairing import FREQ_LIMIT
from ..updating.frf_lines import choose_frf_frequencies, model_receptance
from ..updating.iteration import Configuration
from .system import ConfigSystem, DynamicReduced, ProblemError, ShapePairing


class UpdateProblem:
    """Structures, the parameters being updated and their scaling (see the module docstring).

    ``structures``: one structure or a list; ``names``: parameter names of their ``[[parameters]]``
    (default: all, in order of first appearance). ``mesh_size`` [m] overrides the structures' own.
    Attributes: ``parameters`` (:class:`pcbdyn.fe.parametric.Parameter` of each name, from the first
    structure that has it), ``p0`` (their values, SI), ``bounds`` ((lower, upper) arrays),
    ``log_scale`` (indices of stiffness parameters), ``units`` (display units of the files).

    Examples
    --------
    >>> from pcbdyn.board import load_board
    >>> problem = UpdateProblem(load_board("examples/six_part_card/board.toml"), ["t_PGA", "E_board"])
    >>> problem.names, problem.units
    (['t_PGA', 'E_board'], ['mm', 'Pa'])
    >>> problem.p0.tolist()                                            # SI: 3.5 mm, 26 GPa
    [0.0035, 26000000000.0]
    """

    def __init__(self, structures, names=None, mesh_size=None):
        self.structures = list(structures) if isinstance(structures, (list, tuple)) else [structures]
        self.mesh_size = mesh_size
        known = list(dict.fromkeys(p.name for s in self.structures for p in s.parameters))
        files = ", ".join(s.path.name for s in self.structures)
        if not known:
            raise ProblemError(f"{files}: no [[parameters]] to update; add e.g. [[parameters]] name = \"t_U1\", "
                             "target = \"components.U1.thickness\", bounds = [\"2 mm\", \"10 mm\"]")
        self.names = list(names) if names else known
        bad = [n for n in self.names if n not in known]
        if bad:
            raise ProblemError(f"--params: {bad} are not parameters of {files} (known: {', '.join(known)})")
        self.systems: dict = {}
        self.parameters = []
        for n in self.names:
            k = next(i for i, s in enumerate(self.structures) if any(p.name == n for p in s.parameters))
            self.parameters.append(self.system(None, k).pm.parameters[n])
        self._check_shared()
        self.p0 = np.array([p.value for p in self.parameters], float)
        self.bounds = (np.array([p.bounds[0] for p in self.parameters]), np.array([p.bounds[1] for p in self.parameters]))
        self.log_scale = [i for i, p in enumerate(self.parameters) if p.log]
        self.units = [p.unit for p in self.parameters]
        bad0 = [p.name for p in self.parameters if p.value == 0]
        if bad0:
            raise ProblemError(f"parameters {bad0} start at zero; relative updating (x = dp/p, thesis eq. 4.41) needs "
                             "a non-zero starting value in the structure's file")

    def _check_shared(self) -> None:
        """A parameter shared by several structures must start from one value with one unit."""
        for par in self.parameters:
            for s in self.structures:
                spec = next((p for p in s.parameters if p.name == par.name), None)
                if spec is not None and (spec.unit != par.unit or not np.isclose(spec.value, par.value, rtol=1e-12)):
                    raise ProblemError(f"parameter '{par.name}' starts at {spec.value:g} in {s.path.name} but at "
                                     f"{par.value:g} elsewhere; a shared parameter needs one starting value and unit")

    def label(self, config, structure: int = 0) -> str:
        """The name of a configuration in tables: ``base``/the configuration, prefixed by the structure's
        file stem when the problem has several structures."""
        name = config or "base"
        return name if len(self.structures) == 1 else f"{self.structures[structure].path.stem}:{name}"

    def system(self, config, structure: int = 0) -> ConfigSystem:
        """The (cached) :class:`ConfigSystem` of a configuration name (None: the base one) of a structure."""
        key = (structure, config)
        if key not in self.systems:
            pm = self.structures[structure].build(config, self.mesh_size)
            self.systems[key] = ConfigSystem(pm, self.names, self.label(config, structure))
        return self.systems[key]

    def configuration(self, config, measured, method: str = "freq", n_modes=None, min_mac: float = 0.5,
                      structure: int = 0, limit: float = FREQ_LIMIT, **options) -> Configuration:
        """A driver Configuration of ``config`` with its measured modes (:class:`pcbdyn.testdata.MeasuredModes`).

        Shapes give P and MAC pairing (pairs more than ``limit`` apart in frequency left out); frequencies
        only pair by the test's mode numbers. ``n_modes`` analytical modes are solved per iteration
        (default: rigid-body modes + the highest measured mode number + 4). ``options`` go to
        Configuration (matching, sigma, ...).

        On a system (a box with cards), frequency rows default to units of their own frequency (eq. 4.28
        with the same percentage of noise on every mode, as library calibration weights them): most of a
        system's modes do not depend on a given card's or plate's parameters, and rows of unit length
        (eq. 4.42) would blow up the residuals of the modes a parameter cannot reach (a test of the
        example with the back plate's E and a shelf's guides off drove both to their bounds)."""
        if method == "freq" and "sigma" not in options and getattr(self.structures[structure], "cards", None):
            options["sigma"] = measured.frequencies
        sysm = self.system(config, structure)
        P = None if measured.shapes is None else sysm.measurement_matrix(measured.xyz, measured.directions)
        n = n_modes or sysm.n_rigid + int(max(measured.numbers.max(), measured.frequencies.size)) + 4
        return Configuration(model=sysm.model, f_x=measured.frequencies, phi_x=measured.shapes, P=P, method=method,
                             n_modes=n, name=sysm.label, pairing=sysm.pairing(measured, min_mac, limit),
                             n_rigid=sysm.n_rigid, **options)

    def mode_configurations(self, config, measured, method: str = "qms", min_mac: float = 0.5, structure: int = 0,
                            **options) -> list:
        """One driver Configuration per measured mode, each on the structure dynamically reduced onto the
        measured DOFs at that mode's frequency (:class:`DynamicReduced`), for the shape methods ("qms",
        "fbm"). Pairing in the reduced space by MAC; every reduced mode is solved (the reduced systems
        are small)."""
        sysm = self.system(config, structure)
        if measured.shapes is None:
            raise ProblemError(f"configuration {sysm.label!r}: {method} needs measured shapes")
        P = sysm.measurement_matrix(measured.xyz, measured.directions)
        return [Configuration(model=DynamicReduced(sysm, P, 2 * np.pi * f), f_x=measured.frequencies[k:k + 1],
                              phi_x=measured.shapes[:, k:k + 1], method=method, n_modes=P.shape[0],
                              name=f"{sysm.label}:{k + 1}", pairing=ShapePairing(min_mac), **options)
                for k, f in enumerate(measured.frequencies)]

    def frf_configurations(self, config, measured: list, method: str = "frf-out", freqs=None,
                           damping: str = "undamped", n_max: int = 8, structure: int = 0, **options) -> tuple:
        """Driver Configurations (one per excitation in ``measured``, a list of
        :class:`pcbdyn.testdata.Excitation`) for the FRF methods "frf-in" (eq. 3.34), "frf-out" (indirect
        eq. 3.35) or "frf-direct" (eq. 3.40), and notes for the user.

        ``freqs`` [Hz]: updating frequencies (the nearest measured line of each is used); None picks
        them with :func:`~pcbdyn.updating.frf_lines.choose_frf_frequencies` against the model's FRFs at
        the initial parameters. ``damping``: treatment of the unknown damping in the data (appendix A).
        The measured responses are expanded to the model DOFs at each iteration (matching "expand")."""
        if not method.startswith("frf"):
            raise ValueError(f"method={method!r}: frf_configurations builds 'frf-in', 'frf-out' or 'frf-direct'")
        sysm = self.system(config, structure)
        cfgs, notes = [], []
        for k, m in enumerate(measured):
            P = sysm.measurement_matrix(m.xyz, m.directions)
            j, note = sysm.excitation_dof(m.excite_xyz, m.excite_direction)
            notes += [note] if note else []
            f = np.asarray(m.frequencies, float)
            if freqs is None:
                K, M, _, _ = sysm.model(self.p0)
                H_a = model_receptance(K, M, P, j, 2 * np.pi * f)
                idx, _, note = choose_frf_frequencies(f, m.H, H_a, n_max=n_max, free=sysm.n_rigid > 0)
                notes += [note] if note else []
            else:
                want = np.atleast_1d(np.asarray(freqs, float))
                if want.min() < f.min() or want.max() > f.max():
                    raise ProblemError(f"--frf-freqs: {want.tolist()} Hz must lie within the measured lines "
                                     f"{f.min():g}-{f.max():g} Hz")
                idx = np.unique(np.argmin(np.abs(f[:, None] - want[None, :]), axis=0))
            H = m.H[idx].T
            if np.iscomplexobj(H) and not np.any(H.imag) and damping == "undamped":
                H = H.real
            cfgs.append(Configuration(model=sysm.model, P=P, frf_omegas=2 * np.pi * f[idx], H_x=H, excitation=j,
                                      method=method, damping=damping, name=f"{sysm.label}:frf{k + 1}",
                                      n_rigid=sysm.n_rigid, **options))
        return cfgs, notes

    def values(self, p) -> dict:
        """{parameter name: value [SI]}."""
        return dict(zip(self.names, np.asarray(p, float).tolist()))

    def write_updated(self, p, dst, structure: int = 0, source: str = "pcbdyn update"):
        """The structure's file with its parameters at ``p`` written to ``dst`` (comments kept).

        Parameters
        ----------
        p : array_like
            The parameters [SI], in the order of ``names`` (a fit's ``p``).
        dst : str or pathlib.Path
            The file written (atomically).
        structure : int
            Which of the problem's structures.
        source : str
            Named in the comment that marks each updated value.

        Examples
        --------
        >>> import os, tempfile
        >>> from pcbdyn.board import load_board
        >>> problem = UpdateProblem(load_board("examples/six_part_card/board.toml"), ["t_PGA"])
        >>> dst = os.path.join(tempfile.mkdtemp(), "board.updated.toml")
        >>> _ = problem.write_updated([4.2e-3], dst)
        >>> round(load_board(dst).quantity("components.U1.thickness"), 9)   # SI: 4.2 mm
        0.0042
        """
        s = self.structures[structure]
        own = {p.name for p in s.parameters}
        return s.write_updated({n: v for n, v in self.values(p).items() if n in own}, dst, source)
