"""Step 1 of the wedge-lock fit (thesis section 7.4.2, Tables 7.8-7.9 and 7.12-7.13): a board with its
guides at one extreme (hinged or clamped) correlated with the tests, as the thesis tables show it:
pairs (by MAC through :func:`pcbdyn.correlation.correlate` when shapes are measured, by the test's mode
numbers otherwise), frequency differences, and the model's modes that no test mode pairs with."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..correlation import correlate
from ..fe.modal import solve_modes
from .error_budget import richardson


@dataclass
class Extreme:
    """One extreme (``kind``: "hinged" or "clamped") against the tests: per configuration a dict with
    ``configuration``, ``pairs`` (test_mode, model_mode, f_test_hz, f_model_hz, df_pct = (f_model -
    f_test) / f_test in %, mac or None), ``unpaired_test_modes`` and ``unpaired_model_modes`` (model
    modes in the tested band no test mode pairs with: model_mode, f_model_hz)."""

    kind: str
    configs: list

    @property
    def pairs(self) -> list:
        """Every pair, with its configuration."""
        return [{"configuration": c["configuration"], **q} for c in self.configs for q in c["pairs"]]

    @property
    def max_abs_freq_error_pct(self) -> float | None:
        errors = [abs(q["df_pct"]) for q in self.pairs]
        return max(errors) if errors else None

    def df(self) -> list:
        """Per configuration {test mode (1-based): df [%]} of the paired modes."""
        return [{q["test_mode"]: q["df_pct"] for q in c["pairs"]} for c in self.configs]

    def f_model(self) -> list:
        """Per configuration {test mode (1-based): paired model frequency [Hz]}."""
        return [{q["test_mode"]: q["f_model_hz"] for q in c["pairs"]} for c in self.configs]

    def to_dict(self) -> dict:
        return {"max_abs_freq_error_pct": self.max_abs_freq_error_pct, "pairs": self.pairs,
                "configurations": self.configs}


def model_modes_needed(test) -> int:
    """Model modes to solve for pairing ``test`` (:class:`pcbdyn.testdata.MeasuredModes`): room for modes the
    test missed and for a boundary condition that reorders them."""
    return max(math.ceil(1.5 * test.n_modes), test.n_modes + 4, int(test.numbers.max()) + 4)


def pairs_by_number(test, f_model) -> list:
    """Pairs of a test without shapes: test mode i with the model's elastic mode of its number."""
    return [{"test_mode": i + 1, "model_mode": int(n), "f_test_hz": float(ft), "f_model_hz": float(f_model[n - 1]),
             "df_pct": 100.0 * (float(f_model[n - 1]) - float(ft)) / float(ft), "mac": None}
            for i, (ft, n) in enumerate(zip(test.frequencies, test.numbers)) if n <= len(f_model)]


def correlate_configuration(pm, test, min_mac: float, probe_tol=None) -> dict:
    """A built model ``pm`` of one configuration against its ``test``: pairs (beyond the frequency limit
    too: an extreme brackets the test, it is not updated), unpaired test modes, the model modes in the
    tested band left without a partner and the pairing's warnings (aliased model modes)."""
    modes = solve_modes(pm.model, n_modes=model_modes_needed(test))
    f = modes.frequencies
    warnings = []
    if test.shapes is not None:
        pairing = correlate(test, pm.model, modes, min_mac=min_mac, tol=probe_tol).pairing
        pairs = [{k: q[k] for k in ("test_mode", "model_mode", "f_test_hz", "f_model_hz", "df_pct", "mac")}
                 for q in pairing.to_dict()["pairs"]]  # an extreme brackets the test: every pair counts
        warnings = pairing.warnings(f, beyond=False)
    else:
        pairs = pairs_by_number(test, f)
    paired_t, paired_m = {q["test_mode"] for q in pairs}, {q["model_mode"] for q in pairs}
    band = max([float(test.frequencies.max())] + [q["f_model_hz"] for q in pairs])
    return {"pairs": pairs, "unpaired_test_modes": [i + 1 for i in range(test.n_modes) if i + 1 not in paired_t],
            "unpaired_model_modes": [{"model_mode": j + 1, "f_model_hz": float(fj)} for j, fj in enumerate(f)
                                     if j + 1 not in paired_m and fj <= band], "warnings": warnings}


def correlate_extreme(board, kind: str, tests, mesh_size=None, min_mac: float = 0.5, probe_tol=None) -> Extreme:
    """``board`` (its guides already at the extreme ``kind``) against ``tests`` [(configuration or None,
    Modes)], each configuration built on ``mesh_size`` (default the board's)."""
    configs = []
    for config, test in tests:
        c = correlate_configuration(board.build(config, mesh_size), test, min_mac, probe_tol)
        configs.append({"configuration": config or "base", **c})
    return Extreme(kind, configs)


def mesh_errors(coarse: Extreme, fine: Extreme) -> list:
    """Per configuration {test mode: the model's discretisation error [%]} of the modes paired on both
    meshes, ``fine`` on a mesh twice as fine as ``coarse``: the coarse mesh's error
    (:func:`.error_budget.richardson`) relative to the finer frequency; positive where the model's mesh is
    too stiff."""
    out = []
    for fc, ff in zip(coarse.f_model(), fine.f_model()):
        out.append({t: 100.0 * float(richardson(fc[t], ff[t])[1]) / ff[t] for t in fc if t in ff})
    return out
