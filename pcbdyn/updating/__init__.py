"""Sensitivity-based model updating and error localisation on plain matrices (thesis ch. 3-6).

Inputs are K, M (dense or scipy sparse), the parameter derivatives (dK/dp_j, dM/dp_j) and measured
frequencies, shapes or FRFs as arrays; outputs are weighted equation blocks A x = b (x = dp/p),
their solutions, localised parameter subsets, the iteration history and the bounded Gauss-Newton fit
of a residual (diagnosis). Parameters bound to structures' quantities live in :mod:`pcbdyn.problems`
above; nothing here builds a model.
"""

from .equations import (
    Block,
    dynamic_stiffness,
    fbm_equations,
    frequency_equations,
    frf_excitation_equations,
    frf_receptance_equations,
    qms_equations,
)
from .gauss_newton import GaussNewton, gauss_newton
from .driver import UpdateResult, update
from .iteration import Configuration, build_equations, mac_pairing
from .pbc import condition_number, condition_numbers, stack, svd_reduce
from .sensitivity import (
    bilinear_forms,
    eigen_derivatives,
    eigenvalue_derivatives,
    eigenvector_derivative_nelson,
    eigenvector_derivatives_modal,
    frequencies_hz,
    frequency_derivatives,
    pencil_modes,
    perturbation_derivatives,
)
from .solvers import (
    RankDeficiencyWarning,
    Solution,
    bayes_alpha,
    bounded_lsq,
    choose_rank,
    condition_curve,
    covariance,
    frequency_residue,
    line_search,
    solve_bayes,
    solve_bounded,
    solve_ls,
    solve_tls,
)
from .subset import Subset, qr_basic_solution, svd_qr, threshold_selection, tls_qrf
from .success import success_ratio, success_statistics
from .weighting import std_row_weights, tls_column_weight, unit_row_weights, weight_rows

__all__ = [
    "bayes_alpha",
    "bilinear_forms",
    "Block",
    "bounded_lsq",
    "build_equations",
    "choose_rank",
    "condition_curve",
    "condition_number",
    "condition_numbers",
    "Configuration",
    "covariance",
    "dynamic_stiffness",
    "eigen_derivatives",
    "eigenvalue_derivatives",
    "eigenvector_derivative_nelson",
    "eigenvector_derivatives_modal",
    "fbm_equations",
    "frequencies_hz",
    "frequency_derivatives",
    "frequency_equations",
    "frequency_residue",
    "frf_excitation_equations",
    "frf_receptance_equations",
    "gauss_newton",
    "GaussNewton",
    "line_search",
    "mac_pairing",
    "perturbation_derivatives",
    "qms_equations",
    "qr_basic_solution",
    "RankDeficiencyWarning",
    "Solution",
    "solve_bayes",
    "solve_bounded",
    "solve_ls",
    "pencil_modes",
    "solve_tls",
    "stack",
    "std_row_weights",
    "Subset",
    "success_ratio",
    "success_statistics",
    "svd_qr",
    "svd_reduce",
    "threshold_selection",
    "tls_column_weight",
    "tls_qrf",
    "unit_row_weights",
    "update",
    "UpdateResult",
    "weight_rows",
]
