"""Simulated tests from a model: modes and FRFs read at measurement DOFs, with the thesis' noise.

The model is read at the test DOFs through an interpolation matrix (:mod:`pcbdyn.fe.probe`), so
points need not be nodes. FRFs are modal sums (:func:`pcbdyn.fe.frf.frf_modal`) over the modes given
for them: :func:`frf_modes` gives every mode up to ``FRF_SPAN`` times the band's top, so that the modes
above the band add their stiffness-like part as a measured FRF has it (summing only the modes written
left an FRF update on its own simulated test 2.6 % off in frequency).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from pcbdyn.fe.frf import frf_modal
from pcbdyn.fe.modal import Modes as ModelModes

from .data import Dofs, FRFs, MeasuredModes, Points, TestData
from .noise import Noise, noisy_frequencies, noisy_frfs, noisy_shapes

#: FRFs sum every mode up to this multiple of the band's top frequency
FRF_SPAN = 4.0


def simulate_test(
    modes: ModelModes,
    points: Points,
    dofs: Dofs,
    read,
    *,
    reference: Dofs | None = None,
    read_reference=None,
    f_axis=None,
    zeta=0.01,
    kind: str = "accelerance",
    noise: Noise = Noise(),
    seed=None,
    frf_modes: ModelModes | None = None,
    residual=None,
) -> TestData:
    """A test as it would be measured on the model.

    ``modes``: the model's modes (mass-normalised); ``read`` (n_dof_test, n_model_dof): interpolation
    rows giving the model's response at each test DOF in ``dofs``. Modes: frequencies and shapes at
    the DOFs with noise (eq. 5.72, 5.73) and damping ``zeta``. FRFs (when ``reference`` and
    ``read_reference`` give the excitation DOFs and ``f_axis`` [Hz] the lines): modal sums with
    viscous damping ``zeta`` (of the modes written; the modes beyond them in ``frf_modes``, default
    ``modes``, get the last mode's) as ``kind``, plus ``residual`` (n_dof_test, n_reference: the static
    compliance of the modes not summed), with noise (eq. 5.74). ``seed`` makes the noise repeatable.
    """
    rng = np.random.default_rng(seed)
    at = np.asarray(read @ modes.shapes)
    n = modes.frequencies.size
    z = np.broadcast_to(np.asarray(zeta, dtype=float), (n,)).copy()
    f = noisy_frequencies(modes.frequencies, noise.frequency_pct, rng)
    shapes = noisy_shapes(at, noise.shape_pct, rng)
    test_modes = MeasuredModes(points, dofs, f, shapes, z)
    frfs = None
    if reference is not None:
        if read_reference is None or f_axis is None:
            raise ValueError("FRFs need read_reference (interpolation rows of the excitation) and f_axis")
        summed = modes if frf_modes is None else frf_modes
        if summed.frequencies.size < n or not np.allclose(summed.frequencies[:n], modes.frequencies):
            raise ValueError("frf_modes must begin with the modes written")
        z_all = np.r_[z, np.full(summed.frequencies.size - n, z[-1] if n else 0.0)]
        at_all = np.asarray(read @ summed.shapes)
        ref_at = np.asarray(read_reference @ summed.shapes)
        rigid = np.vstack([np.asarray(read @ summed.rigid_shapes), np.asarray(read_reference @ summed.rigid_shapes)])
        sub = ModelModes(summed.frequencies, np.vstack([at_all, ref_at]), rigid, None)
        H = frf_modal(sub, f_axis, np.arange(at.shape[0]), at.shape[0] + np.arange(ref_at.shape[0]), zeta=z_all,
                      residual=residual, kind=kind)
        frfs = FRFs(points, f_axis, noisy_frfs(H, noise.frf_pct, rng), kind, dofs, reference)
    return TestData(points, test_modes, frfs)


def simulate_on_model(
    model,
    modes: ModelModes,
    points: Points,
    dofs: Dofs,
    *,
    excite=None,
    excite_direction=(0.0, 0.0, 1.0),
    excite_id: int | None = None,
    f_axis=None,
    zeta=0.01,
    kind: str = "accelerance",
    noise: Noise = Noise(),
    seed=None,
    tol=None,
    frf_modes: ModelModes | None = None,
    K=None,
    M=None,
) -> TestData:
    """A modal test as it would be measured on a shell model (:func:`simulate_test`), the model read at
    the points through the shape functions, with the thesis' noise (eqs. 5.72-5.74).

    Parameters
    ----------
    model : pcbdyn.fe.Model
        The structure tested (a board's: ``board.build().model``).
    modes : pcbdyn.fe.modal.Modes
        Its modes (:func:`pcbdyn.fe.modal.solve_modes`).
    points, dofs : Points, Dofs
        Where and in which directions the test measures (:func:`pcbdyn.testdata.read_points_csv`).
    noise : Noise
        Noise levels [%] of the frequencies, shapes and FRFs; ``seed`` makes the draw repeatable.

    Returns
    -------
    TestData
        ``points``, ``modes`` (:class:`pcbdyn.testdata.MeasuredModes`) and, with ``excite`` and
        ``f_axis``, ``frfs``.

    Notes
    -----
    ``excite`` (x, y, z) [m]: the excitation point (FRFs are written when it and ``f_axis`` are
    given); it joins the points with id ``excite_id`` (default: one above the largest id) unless a
    point already sits there. ``frf_modes`` (e.g. :func:`frf_modes`): when given, the FRFs sum them and add
    the static compliance of all the model's other modes (:func:`pcbdyn.fe.frf.residual_flexibility`; ``K,
    M``: the assembled matrices, if at hand), the model's complete FRF but for the dynamics of the modes far
    above the band; else they sum ``modes`` alone.

    Examples
    --------
    >>> from pcbdyn.board import load_board
    >>> from pcbdyn.fe.modal import solve_modes
    >>> from pcbdyn.testdata import Noise, read_points_csv
    >>> card = "examples/six_part_card/"
    >>> model = load_board(card + "board.toml").build().model
    >>> points, dofs = read_points_csv(card + "points.csv")
    >>> test = simulate_on_model(model, solve_modes(model, n_modes=7), points, dofs,
    ...                          noise=Noise(frequency_pct=0.2, shape_pct=2.0), seed=1)
    >>> test.modes.n_modes, test.modes.shapes.shape
    (7, (81, 7))
    """
    from pcbdyn.fe.probe import model_probe

    read = model_probe(model, points.xyz[points.index(dofs.point_ids)], dofs.directions, tol=tol).P
    if excite is None:
        return simulate_test(modes, points, dofs, read, zeta=zeta, kind=kind, noise=noise, seed=seed)
    e = np.asarray(excite, dtype=float).ravel()
    e = np.append(e, 0.0) if e.size == 2 else e
    same = np.flatnonzero(np.linalg.norm(points.xyz - e, axis=1) < 1e-9)
    if same.size:
        pid = int(points.ids[same[0]])
    else:
        pid = int(points.ids.max() + 1 if excite_id is None and len(points) else (excite_id or 1))
        points = Points(np.append(points.ids, pid), np.vstack([points.xyz, e]))
    ref = Dofs([pid], np.asarray(excite_direction, dtype=float))
    read_ref = model_probe(model, e[None], ref.directions, tol=tol).P
    residual = None if frf_modes is None else _residual(model, frf_modes, read, read_ref, K, M)
    return simulate_test(modes, points, dofs, read, reference=ref, read_reference=read_ref, f_axis=f_axis,
                         zeta=zeta, kind=kind, noise=noise, seed=seed, frf_modes=frf_modes, residual=residual)


def _residual(model, modes: ModelModes, read, read_ref, K, M) -> np.ndarray:
    """The static compliance of the modes not in ``modes`` between the test DOFs (rows of ``read``) and the
    excitation (rows of ``read_ref``), from that of the model DOFs they interpolate."""
    from pcbdyn.fe.frf import residual_flexibility

    read, read_ref = sp.csr_matrix(read), sp.csr_matrix(read_ref)
    i, j = np.unique(read.indices), np.unique(read_ref.indices)
    R = residual_flexibility(model, modes, i, j, K, M)
    return np.asarray(read[:, i] @ R @ read_ref[:, j].T.toarray())


def frf_modes(model, modes: ModelModes, f_axis, K=None, M=None) -> ModelModes:
    """``modes`` when they reach ``FRF_SPAN`` times the top of ``f_axis``, else every mode of ``model`` up to
    there (they begin with ``modes``); ``K, M``: its assembled matrices, if at hand."""
    from pcbdyn.fe.modal import solve_modes

    top = FRF_SPAN * float(np.max(f_axis))
    if modes.frequencies.size and modes.frequencies.max() >= top:
        return modes
    more = solve_modes(model, f_max=top, K=K, M=M)
    return more if more.frequencies.size >= modes.frequencies.size else modes


def frequency_axis(f_range, df: float, f_top: float) -> np.ndarray:
    """Lines from f_lo to f_hi every ``df`` Hz; without a range, ``df`` (a free structure's receptance is
    infinite at 0 Hz) to 1.2 times ``f_top``."""
    lo, hi = f_range if f_range is not None else (df, df * np.ceil(1.2 * f_top / df))
    return lo + df * np.arange(int(np.floor((hi - lo) / df + 1e-9)) + 1)
